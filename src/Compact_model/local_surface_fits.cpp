// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The local-surface fits of Local_surface_traits.h (fit_quadric, fit_plane, fit_cone,
// fit_cubic), compiled once for the programs that link CMGeom::Compact_model.
#include <CMGeom/Compact_model/Local_surface_traits.h>
#include <CMGeom/Compact_model/internal/Local_surface_traits_impl.h>
