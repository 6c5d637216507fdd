// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CMGEOM_TS_INSTANTIATE_FOR_VISITOR(V): the explicit instantiation definitions, for the collapse
// visitor V, of the functions CMGeom::Textured_simplification precompiles (simplify_mesh(), both
// forms; simplify_textured_mesh() with the default resampler; simplify_to_levels()), for CMGeom's
// mesh type. Used inside namespace CMGeom::Textured_simplification by the library's sources, one
// visitor per source file so that they compile at once; the matching `extern template`
// declarations are at the end of the public headers.
#ifndef CMGEOM_SRC_TEXTURED_SIMPLIFICATION_INSTANTIATIONS_H
#define CMGEOM_SRC_TEXTURED_SIMPLIFICATION_INSTANTIATIONS_H

#include <CMGeom/Textured_simplification/level_of_detail.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

#define CMGEOM_TS_INSTANTIATE_FOR_VISITOR(V)                                                            \
  template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, V>(                    \
      internal::Precompiled_mesh&, const Mesh_simplification_options&, V);                              \
  template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, V>(                    \
      internal::Precompiled_mesh&, std::size_t, const Mesh_simplification_options&, V);                 \
  template Textured_simplification_result simplify_textured_mesh<Index_texture_resampler, V>(           \
      Textured_mesh&, const Textured_simplification_options&, V);                                       \
  template Level_of_detail_result internal::simplify_to_levels<V>(const Textured_mesh&, Textured_mesh*, \
                                                                  const Level_of_detail_options&, V)

#endif  // CMGEOM_SRC_TEXTURED_SIMPLIFICATION_INSTANTIATIONS_H
