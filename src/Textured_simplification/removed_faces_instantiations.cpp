// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Explicit instantiation definitions of simplify_mesh(), simplify_textured_mesh() and
// simplify_to_levels() with Removed_faces_visitor, for CMGeom's mesh type and the default
// resampler (see textured_simplification_instantiations.cpp).
#include <CMGeom/Textured_simplification/level_of_detail.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

namespace CMGeom {
namespace Textured_simplification {

template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Removed_faces_visitor>(
    internal::Precompiled_mesh&, const Mesh_simplification_options&, Removed_faces_visitor);
template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Removed_faces_visitor>(
    internal::Precompiled_mesh&, std::size_t, const Mesh_simplification_options&, Removed_faces_visitor);

template Textured_simplification_result simplify_textured_mesh<Index_texture_resampler, Removed_faces_visitor>(
    Textured_mesh&, const Textured_simplification_options&, Removed_faces_visitor);

template Level_of_detail_result simplify_to_levels<Removed_faces_visitor>(const Textured_mesh&,
                                                                          const Level_of_detail_options&,
                                                                          Removed_faces_visitor);

}  // namespace Textured_simplification
}  // namespace CMGeom
