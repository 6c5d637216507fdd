// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Metrics package: geometric error in the Metro convention
// (thesis §2.3.2.2), texture deviation (Cohen et al. 1998) and image-space error (§2.3.2.1,
// eq. 2.1). See doc/Metrics/README.md.
#ifndef CMGEOM_METRICS_H
#define CMGEOM_METRICS_H

#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Metrics/image_error.h>
#include <CMGeom/Metrics/soup_metrics.h>
#include <CMGeom/Metrics/texture_deviation.h>

#endif  // CMGEOM_METRICS_H
