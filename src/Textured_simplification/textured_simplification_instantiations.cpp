// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Explicit instantiation definitions of the Textured_simplification function templates for
// CMGeom's mesh type (CGAL::Surface_mesh of Epick points) and the default resampler and visitor:
// the parts' stage of simplify_mesh() (which every visitor shares), simplify_mesh(),
// simplify_textured_mesh() and simplify_to_levels() (instantiations.h). Beside it,
// removed_faces_instantiations.cpp holds the same with Removed_faces_visitor (two files: the two
// halves compile at once). The matching declarations (`extern template`) are at the end of
// simplify_mesh.h, simplify_textured_mesh.h and level_of_detail.h, active when
// CMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED is defined (linking CMGeom::Textured_simplification
// defines it).
#include "instantiations.h"

namespace CMGeom {
namespace Textured_simplification {

namespace internal {
template void simplify_in_parts<Precompiled_point, Precompiled_memory>(
    Precompiled_mesh&, std::size_t, int, const Mesh_simplification_options&,
    Area_weighted_quadric_policies<Precompiled_mesh>&, std::optional<Precompiled_memory>&, Parts_progress*, bool,
    const Precompiled_mesh*);
}  // namespace internal

CMGEOM_TS_INSTANTIATE_FOR_VISITOR(Edge_collapse_visitor_base);

}  // namespace Textured_simplification
}  // namespace CMGeom
