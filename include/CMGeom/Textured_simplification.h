// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Textured_simplification package (thesis chapter 3): weighted quadric
// policies (§3.4), CMGeom's edge-collapse engine, the fold-over filter for CGAL's engine, O(1)
// stop predicates, edge flips (§3.5.1); chart constraints and UV placement (§3.5), the index
// texture and its CPU resampler (§3.3, §3.6) and simplify_textured_mesh() (the whole pipeline).
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_H

#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Chart_constraints.h>
#include <CMGeom/Textured_simplification/Index_texture.h>
#include <CMGeom/Textured_simplification/Collapse_profile.h>
#include <CMGeom/Textured_simplification/Endpoint_placement.h>
#include <CMGeom/Textured_simplification/Hausdorff_bound.h>
#include <CMGeom/Textured_simplification/No_normal_flip_filter.h>
#include <CMGeom/Textured_simplification/Removed_faces_visitor.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/Surface_memory.h>
#include <CMGeom/Textured_simplification/edge_collapse.h>
#include <CMGeom/Textured_simplification/parameters.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_H
