// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Osmesa_index_texture_resampler: the per-collapse index-texture resampling of thesis §3.6 on
// OpenGL (Mesa llvmpipe through OSMesa), the second model of the IndexTextureResampler concept
// beside the CPU Index_texture_resampler (Index_texture.h). Key choice: both give bit-identical
// index textures, coverage included (same CPU-side resampling plan, corners snapped to the
// rasteriser's grid, the per-texel rule repeated in a `precise` shader), and collapses that do
// not read each other's texels are drawn in one batch. Call synchronize() before reading the
// Index_texture (simplify_textured_mesh() does). Compiled into CMGeom::OSMesa (CMGEOM_HAS_OSMESA)
// when OSMesa is found (Mesa removed it in 25.1). One resampler per thread (it owns its context).
//
// Manual: doc/Textured_simplification/README.md, "Two resampling backends".
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
