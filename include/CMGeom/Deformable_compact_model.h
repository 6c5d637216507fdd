// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Deformable_compact_model package (thesis chapter 6): local
// deformations of the CM base (§6.3), their transfer to the reconstruction (§6.4), and the
// BaseDeformer models (affine, vertex moves, one cage, *Cages system). See doc/Deformable_compact_model/README.md.
// Complexity: see each header.
#ifndef CMGEOM_DEFORMABLE_COMPACT_MODEL_H
#define CMGEOM_DEFORMABLE_COMPACT_MODEL_H

#include <CMGeom/Deformable_compact_model/Local_deformations.h>
#include <CMGeom/Deformable_compact_model/Base_deformers.h>
#include <CMGeom/Deformable_compact_model/Cage_system_deformer.h>
#include <CMGeom/Deformable_compact_model/Deformable_compact_model.h>

#endif  // CMGEOM_DEFORMABLE_COMPACT_MODEL_H
