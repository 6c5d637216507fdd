// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Explicit instantiation definitions of the Textured_simplification function templates for
// CMGeom's mesh type (CGAL::Surface_mesh of Epick points) and the default resampler and visitor:
// the parts' stage of simplify_mesh() (which every visitor shares), simplify_mesh(),
// simplify_textured_mesh() and simplify_to_levels(); removed_faces_instantiations.cpp holds the
// same with Removed_faces_visitor (two files: the two halves compile at once). The matching
// declarations (`extern template`) are at the end of simplify_mesh.h, simplify_textured_mesh.h
// and level_of_detail.h, active when CMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED is defined
// (linking CMGeom::Textured_simplification defines it).
#include <CMGeom/Textured_simplification/level_of_detail.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

namespace CMGeom {
namespace Textured_simplification {

namespace internal {
template void simplify_in_parts<Precompiled_point, Precompiled_memory>(
    Precompiled_mesh&, std::size_t, int, const Mesh_simplification_options&,
    Area_weighted_quadric_policies<Precompiled_mesh>&, std::optional<Precompiled_memory>&);
}  // namespace internal

template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Edge_collapse_visitor_base>(
    internal::Precompiled_mesh&, const Mesh_simplification_options&, Edge_collapse_visitor_base);
template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Edge_collapse_visitor_base>(
    internal::Precompiled_mesh&, std::size_t, const Mesh_simplification_options&, Edge_collapse_visitor_base);

template Textured_simplification_result simplify_textured_mesh<Index_texture_resampler, Edge_collapse_visitor_base>(
    Textured_mesh&, const Textured_simplification_options&, Edge_collapse_visitor_base);

template Level_of_detail_result simplify_to_levels<Edge_collapse_visitor_base>(const Textured_mesh&,
                                                                               const Level_of_detail_options&,
                                                                               Edge_collapse_visitor_base);

}  // namespace Textured_simplification
}  // namespace CMGeom
