// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Explicit instantiation definitions of simplify_mesh(), simplify_textured_mesh() and
// simplify_to_levels() with Removed_faces_visitor, for CMGeom's mesh type and the default
// resampler (see textured_simplification_instantiations.cpp).
#include "instantiations.h"

namespace CMGeom {
namespace Textured_simplification {

CMGEOM_TS_INSTANTIATE_FOR_VISITOR(Removed_faces_visitor);

}  // namespace Textured_simplification
}  // namespace CMGeom
