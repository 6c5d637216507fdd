// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Compact_model package (thesis chapter 4): local-surface traits
// (§4.4.1), point gathering (§4.3), sharp-edge detection and CM generation (§4.4.2-4.4.3), the CM
// file format (§4.4.3), regular and adaptive reconstruction (§4.5) and error control (§4.5.3).
#ifndef CMGEOM_COMPACT_MODEL_H
#define CMGEOM_COMPACT_MODEL_H

#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Compact_model/Local_surface_traits.h>
#include <CMGeom/Compact_model/Point_gathering_visitor.h>
#include <CMGeom/Compact_model/build_compact_model.h>
#include <CMGeom/Compact_model/build_textured_compact_model.h>
#include <CMGeom/Compact_model/cm_io.h>
#include <CMGeom/Compact_model/local_surface_projection.h>
#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Compact_model/reconstruction_to_mesh.h>

#endif  // CMGEOM_COMPACT_MODEL_H
