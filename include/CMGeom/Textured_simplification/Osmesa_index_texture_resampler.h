// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Osmesa_index_texture_resampler: the per-collapse index-texture resampling of thesis §3.6 on
// OpenGL (Mesa llvmpipe through OSMesa), the second model of the IndexTextureResampler concept
// beside the CPU Index_texture_resampler (Index_texture.h). Both give bit-identical index
// textures, coverage included:
//  * every per-collapse quantity (old-triangle barycentrics in π, the maps PM_{t'} and the
//    composed maps PM_{t_j}⁻¹ ∘ PM_{t'}, the copied regions) comes from the same
//    internal::Resampling_plan, computed on the CPU;
//  * the new texture triangles are drawn with their corners snapped to the rasteriser's 1/256
//    texel grid, so GL's coverage (texel centres, top-left rule) is the CPU rasteriser's;
//  * the fragment shader repeats the CPU's per-texel rule at gl_FragCoord in the same order of
//    operations: old-triangle selection in double, the flat affine map and the chart-aware
//    bilinear lookup in float, every temporary `precise` (no fused multiply-add), while the CPU
//    side is compiled with -ffp-contract=off (set by the CMGeom target).
// Collapses whose read regions do not touch texels written by earlier collapses of the pending
// batch are drawn together: one copy of their read regions, then one draw (the per-draw cost of
// llvmpipe dominates small collapses). A collapse that reads what the batch writes starts a new
// batch, so the result equals collapse-by-collapse resampling.
//
// The index texture lives in GL memory between synchronize() calls: call synchronize() before
// reading the Index_texture (simplify_textured_mesh() does).
//
// Availability: compiled into CMGeom::OSMesa (defines CMGEOM_HAS_OSMESA) when the library is built
// with OSMesa, which Mesa removed in 25.1; the CPU backend is always available.
// Memory: two RG32F copies of the index texture and its chart map (20 bytes per texel) in GL.
// Threads: one resampler per thread (it owns its OpenGL context).
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_OSMESA_INDEX_TEXTURE_RESAMPLER_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_OSMESA_INDEX_TEXTURE_RESAMPLER_H

#include <CMGeom/Textured_simplification/Index_texture.h>

#include <cstddef>
#include <memory>
#include <string>

namespace CMGeom {
namespace Textured_simplification {

struct Osmesa_resampler_options {
  /// Most collapses drawn in one batch (1 = one draw per collapse).
  std::size_t max_batch = 4096;
};

class Osmesa_index_texture_resampler {
public:
  /// Uploads `it` (its index values and chart map) to a new OpenGL context. Throws CMGeom::Error
  /// when OSMesa cannot give an OpenGL 4.3 core context, Invalid_input for an empty texture.
  explicit Osmesa_index_texture_resampler(Index_texture& it, const Osmesa_resampler_options& options = {});
  ~Osmesa_index_texture_resampler();
  Osmesa_index_texture_resampler(const Osmesa_index_texture_resampler&) = delete;
  Osmesa_index_texture_resampler& operator=(const Osmesa_index_texture_resampler&) = delete;

  /// Queues the resampling of one collapse (drawn when the batch is full or must end).
  void operator()(const Collapse_record& record);
  /// Draws what is queued and reads the index texture back into the Index_texture.
  void synchronize();

  /// "renderer, GL version" of the context.
  std::string description() const;
  std::size_t collapses() const;  ///< collapses resampled so far
  std::size_t draws() const;      ///< batches drawn so far

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_OSMESA_INDEX_TEXTURE_RESAMPLER_H
