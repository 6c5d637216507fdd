// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// build_textured_compact_model(), Textured_quadric_simplifier, Textured_build_result: the Compact
// Model of a textured mesh (thesis §4.5.4: texture coordinates per face corner and a texture
// reference). Choice (the thesis gives the file's texture fields, not how the base's uvs are
// made): the base is simplified exactly as a textured mesh is in chapter 3 (chart constraints of
// §3.5, UV placement, index texture of §3.3/§3.6) with the point gathering of §4.3 as visitor and
// base vertices kept on input vertices; so every base face lies in one chart and, when the input's
// texture is decoded, a new atlas comes with the model. The rest of the build is
// build_compact_model()'s. Complexity: simplify_textured_mesh()'s plus build_compact_model()'s.
//
// Manual: doc/Compact_model/README.md, "Textured Compact Models (§4.5.4)".
#ifndef CMGEOM_COMPACT_MODEL_BUILD_TEXTURED_COMPACT_MODEL_H
#define CMGEOM_COMPACT_MODEL_BUILD_TEXTURED_COMPACT_MODEL_H

#include <CMGeom/Compact_model/build_compact_model.h>
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

#include <utility>
#include <vector>

namespace CMGeom {
namespace CM {

/// What build_textured_compact_model() returns besides the model.
struct Textured_build_result {
  /// The base's atlas (diffuse), generated through the index texture; empty when the input's
  /// texture was not decoded (then the uvs point into the input's texture).
  Image texture;
  /// The texture-preserving simplification's report (charts, refusals, times).
  CMGeom::Textured_simplification::Textured_simplification_result simplification;
};

/// The simplification options of a textured CM base: the weighted quadrics of §3.4.2 (as
/// Weighted_quadric_simplifier, the geometry-only base's simplifier), charts kept.
inline CMGeom::Textured_simplification::Textured_simplification_options textured_base_options() {
  CMGeom::Textured_simplification::Textured_simplification_options o;
  o.quadric.weighted = true;
  o.keep_charts = true;
  return o;
}

/// Simplifier (see build_compact_model.h) running the textured simplification of chapter 3 on
/// the build's working copy, whose "h:uv" map it keeps up to date (`keeps_uvs`). The materials
/// (with their decoded images) are the input's; the new atlas goes to `result`.
struct Textured_quadric_simplifier {
  static constexpr bool keeps_uvs = true;
  const std::vector<Material>* materials = nullptr;
  /// textured_base_options() by default, as build_textured_compact_model()'s (not the default
  /// Textured_simplification_options, whose quadrics are plain)
  CMGeom::Textured_simplification::Textured_simplification_options options = textured_base_options();
  Textured_build_result* result = nullptr;

  template <class Visitor>
  void operator()(CMGeom::Surface_mesh& mesh, std::size_t target_faces, Visitor visitor) const {
    namespace TS = CMGeom::Textured_simplification;
    Textured_mesh tm(std::move(mesh));
    tm.set_has_uvs(true);
    if (materials) tm.materials() = *materials;
    TS::Textured_simplification_options o = options;
    o.target_faces = target_faces;
    o.endpoint_placement = true;
    o.keep_charts = true;  // the base keeps the input's charts (§4.5.4): its UVs address the input's atlas
    const TS::Textured_simplification_result r = TS::simplify_textured_mesh(tm, o, visitor);
    mesh = std::move(tm.mesh());
    if (result) {
      result->simplification = r;
      result->texture = Image();
      for (const Material& m : tm.materials())
        if (!m.diffuse_image.empty()) {
          result->texture = m.diffuse_image;
          break;
        }
    }
  }
};

/// The Compact Model of a textured mesh (see the file comment): `input` must have uvs
/// (Invalid_input otherwise) and at most one texture atlas. `texture_options` (default:
/// textured_base_options(), the weighted quadrics of §3.4.2 as the geometry-only CM base uses) tunes the
/// simplification's texture work (texture size, threads, ...; its target and placement are set
/// here): start from textured_base_options() to keep the base's quadrics. The returned model's `texture` is the input
/// material's texture path when the atlas was not regenerated, empty otherwise (the caller names the file it writes
/// `result->texture` to).
template <class Traits = Quadric_surface_traits>
Compact_model build_textured_compact_model(
    const Textured_mesh& input, std::size_t target_faces, const Build_options& opt = Build_options(),
    const Traits& traits = Traits(), Textured_build_result* result = nullptr, Build_statistics* stats = nullptr,
    const CMGeom::Textured_simplification::Textured_simplification_options& texture_options = textured_base_options()) {
  if (!input.has_uvs())
    throw Invalid_input("build_textured_compact_model: '" + input.source() + "' has no texture coordinates");
  Textured_build_result local;
  Textured_build_result& res = result ? *result : local;
  Textured_quadric_simplifier simplify;
  simplify.materials = &input.materials();
  simplify.options = texture_options;
  simplify.result = &res;
  res = Textured_build_result();
  // (when nothing is simplified the simplifier does not run: the uvs are the input's, and so is
  // the texture)
  Compact_model model = build_compact_model(input.mesh(), target_faces, opt, traits, simplify, stats);
  if (res.texture.empty()) {
    for (const Material& m : input.materials())
      if (!m.diffuse_texture.empty()) {
        model.texture = m.diffuse_texture;
        break;
      }
  }
  return model;
}

#ifdef CMGEOM_COMPACT_MODEL_PRECOMPILED
// Compiled once in CMGeom::Compact_model (src/Compact_model/compact_model_instantiations.cpp);
// linking that library defines the macro.
extern template Compact_model build_textured_compact_model<Quadric_surface_traits>(
    const Textured_mesh&, std::size_t, const Build_options&, const Quadric_surface_traits&, Textured_build_result*,
    Build_statistics*, const CMGeom::Textured_simplification::Textured_simplification_options&);
extern template Compact_model build_textured_compact_model<Cubic_surface_traits>(
    const Textured_mesh&, std::size_t, const Build_options&, const Cubic_surface_traits&, Textured_build_result*,
    Build_statistics*, const CMGeom::Textured_simplification::Textured_simplification_options&);
#endif

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_BUILD_TEXTURED_COMPACT_MODEL_H
