// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Textured_simplification package (geometry part, thesis chapter 3,
// §3.4 and §3.5.1): weighted quadric policies, CMGeom's edge-collapse engine, the fold-over
// filter for CGAL's engine, O(1) stop predicates and edge flips.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_H

#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Collapse_profile.h>
#include <CMGeom/Textured_simplification/No_normal_flip_filter.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/edge_collapse.h>
#include <CMGeom/Textured_simplification/parameters.h>

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_H
