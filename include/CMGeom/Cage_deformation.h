// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Cage_deformation package (thesis chapter 5): triangle cages, the
// CageCoordinates models (mean value, Green, harmonic), binding and the deformation kernel, and
// the *Cages system of several cages joined C1 (§5.3) with its JSON file format.
// Cage_system_io.h needs the CMGeom::Mesh_IO library (cage files are read with its readers).
// See doc/Cage_deformation/README.md. Complexity: see each header.
#ifndef CMGEOM_CAGE_DEFORMATION_H
#define CMGEOM_CAGE_DEFORMATION_H

#include <CMGeom/Cage_deformation/Triangle_cage.h>
#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Cage_deformation/Mean_value_coordinates_3.h>
#include <CMGeom/Cage_deformation/Green_coordinates_3.h>
#include <CMGeom/Cage_deformation/Harmonic_coordinates_3.h>
#include <CMGeom/Cage_deformation/Cage_binding.h>
#include <CMGeom/Cage_deformation/Any_cage_coordinates.h>
#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Cage_deformation/Grid_cage_system.h>
#include <CMGeom/Cage_deformation/Cage_system.h>
#include <CMGeom/Cage_deformation/Cage_system_io.h>
#include <CMGeom/Cage_deformation/deform.h>

#endif  // CMGEOM_CAGE_DEFORMATION_H
