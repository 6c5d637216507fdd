// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Rendering package: headless pictures of meshes (shaded, textured,
// wireframe, chart boundaries, scalar fields with legend, grids, UV atlases) and the
// image-space error over a fixed view set (thesis §2.3.2.1). See doc/Rendering/README.md.
// Rendering itself needs the target CMGeom::OSMesa (CMGEOM_HAS_OSMESA); PNG output needs
// CMGeom::Image_IO.
#ifndef CMGEOM_RENDERING_H
#define CMGEOM_RENDERING_H

#include <CMGeom/Rendering/Render_mesh.h>
#include <CMGeom/Rendering/Render_options.h>
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/colormap.h>
#include <CMGeom/Rendering/compose.h>
#include <CMGeom/Rendering/image_space_error.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#include <CMGeom/Rendering/render_to_png.h>
#include <CMGeom/Rendering/views.h>

#endif  // CMGEOM_RENDERING_H
