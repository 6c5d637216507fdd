// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Explicit instantiation definitions of the Compact_model function templates for the arguments
// the package's own programs use: the thesis' quadric traits and the cubic traits (with the
// weighted-quadric simplifier, and for textured inputs), and the regular and adaptive
// reconstructions with the three criteria of reconstruct.h. The matching declarations (`extern
// template`) are at the end of build_compact_model.h, build_textured_compact_model.h and
// reconstruct.h, active when CMGEOM_COMPACT_MODEL_PRECOMPILED is defined (linking
// CMGeom::Compact_model defines it).
#include <CMGeom/Compact_model.h>

namespace CMGeom {
namespace CM {

template Compact_model build_compact_model<Quadric_surface_traits, Weighted_quadric_simplifier>(
    const CMGeom::Surface_mesh&, std::size_t, const Build_options&, const Quadric_surface_traits&,
    const Weighted_quadric_simplifier&, Build_statistics*);
template Compact_model build_compact_model<Cubic_surface_traits, Weighted_quadric_simplifier>(
    const CMGeom::Surface_mesh&, std::size_t, const Build_options&, const Cubic_surface_traits&,
    const Weighted_quadric_simplifier&, Build_statistics*);

template Compact_model build_textured_compact_model<Quadric_surface_traits>(
    const Textured_mesh&, std::size_t, const Build_options&, const Quadric_surface_traits&, Textured_build_result*,
    Build_statistics*, const CMGeom::Textured_simplification::Textured_simplification_options&);
template Compact_model build_textured_compact_model<Cubic_surface_traits>(
    const Textured_mesh&, std::size_t, const Build_options&, const Cubic_surface_traits&, Textured_build_result*,
    Build_statistics*, const CMGeom::Textured_simplification::Textured_simplification_options&);

template class Regular_reconstructor<Quadric_surface_traits>;
template void reconstruct_regular<Quadric_surface_traits>(const Compact_model&, int, Reconstruction&,
                                                          const Reconstruction_options&, const Quadric_surface_traits&);
template Reconstruction reconstruct_regular<Quadric_surface_traits>(const Compact_model&, int,
                                                                    const Reconstruction_options&,
                                                                    const Quadric_surface_traits&);
template Reconstruction reconstruct_adaptive<Edge_length_criterion, Quadric_surface_traits>(
    const Compact_model&, const Edge_length_criterion&, int, const Reconstruction_options&,
    const Quadric_surface_traits&);
template Reconstruction reconstruct_adaptive<Region_of_interest_criterion, Quadric_surface_traits>(
    const Compact_model&, const Region_of_interest_criterion&, int, const Reconstruction_options&,
    const Quadric_surface_traits&);
template Reconstruction reconstruct_adaptive<Silhouette_criterion, Quadric_surface_traits>(
    const Compact_model&, const Silhouette_criterion&, int, const Reconstruction_options&,
    const Quadric_surface_traits&);

}  // namespace CM
}  // namespace CMGeom
