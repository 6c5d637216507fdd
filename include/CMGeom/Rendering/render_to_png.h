// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// render_to_png(): one finished picture of a mesh in a PNG file — rendered by the Renderer,
// decorated on the CPU (colour-bar legend for scalar fields, caption) and written opaque RGB
// with CMGeom::IO::write_image (atomic). Also render_picture(), the same picture in memory.
//
// Needs the targets CMGeom::OSMesa (rendering) and CMGeom::Image_IO (PNG). When the library was
// built without OSMesa (CMGEOM_HAS_OSMESA undefined) these functions throw CMGeom::Error with a
// one-line explanation instead of rendering.
//
// Complexity: that of Renderer::render() plus O(W H) for decoration and encoding.
#ifndef CMGEOM_RENDERING_RENDER_TO_PNG_H
#define CMGEOM_RENDERING_RENDER_TO_PNG_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Image.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Rendering/Render_mesh.h>
#include <CMGeom/Rendering/Render_options.h>
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/compose.h>

#include <cmath>
#include <string>

namespace CMGeom {
namespace Rendering {

/// The message of the error raised when rendering is not compiled in.
inline const char* rendering_unavailable_message() {
  return "this build of CMGeom has no renderer (configure with CMGEOM_WITH_OSMESA=ON and libOSMesa installed)";
}

/// Legend (for Shading::Field) and caption over an RGBA render; returns opaque RGB.
inline Image decorate(const Image& rendered, const Render_mesh& mesh, const Render_options& o) {
  Image img = to_rgb(rendered);
  if (o.shading == Shading::Field && o.legend && mesh.has_scalars()) {
    const double lo = std::isnan(o.field_min) ? mesh.scalar_min : o.field_min;
    const double hi = std::isnan(o.field_max) ? mesh.scalar_max : o.field_max;
    draw_legend(img, lo, hi, o.legend_label);
  }
  draw_caption(img, o.caption);
  return img;
}

/// Rendered and decorated picture (opaque RGB, row 0 at the top).
inline Image render_picture(Renderer& renderer, const Render_mesh& mesh, const Render_options& o) {
  return decorate(renderer.render(mesh, o), mesh, o);
}

/// Renders `mesh` with `options` into the PNG file `path` (written atomically).
inline void render_to_png(const std::string& path, const Render_mesh& mesh, const Render_options& options) {
#ifdef CMGEOM_HAS_OSMESA
  Renderer renderer;
  IO::write_image(path, render_picture(renderer, mesh, options));
#else
  (void)path;
  (void)mesh;
  (void)options;
  throw Error(rendering_unavailable_message());
#endif
}

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_RENDER_TO_PNG_H
