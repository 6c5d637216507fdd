// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Renderer: headless OpenGL pictures of a Render_mesh (the Rendering package's engine; thesis
// figures: shaded models, chart boundaries in red, error and influence maps). Backend: an OSMesa
// (Mesa llvmpipe) OpenGL 4.5 core context with the package's own GL loader; pictures are drawn
// into a multisampled sRGB framebuffer object, so lighting and filtering happen in linear space,
// and their alpha channel is the mesh's coverage (used by the image-space error). Compiled only
// with CMGEOM_WITH_OSMESA and libOSMesa (target CMGeom::OSMesa, defining CMGEOM_HAS_OSMESA); OSMesa
// was removed from Mesa 25.1. A Renderer serves one thread at a time; results are deterministic.
// Complexity: O(F + W H samples) per picture.
//
// Manual: doc/Rendering/README.md, "The engine".
#ifndef CMGEOM_RENDERING_RENDERER_H
#define CMGEOM_RENDERING_RENDERER_H

#include <CMGeom/Mesh_IO/Image.h>
#include <CMGeom/Rendering/Render_mesh.h>
#include <CMGeom/Rendering/Render_options.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace CMGeom {
namespace Rendering {

class Renderer {
public:
  /// Creates the GL context. Throws CMGeom::Error when no context can be created.
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// One picture: 8-bit RGBA, row 0 at the top, alpha = coverage. Decorations (legend,
  /// caption) are not drawn here: see render_to_png.h / compose.h.
  /// Throws Invalid_input for unusable options (size, Field shading without a field).
  Image render(const Render_mesh& mesh, const Render_options& options);

  /// Several pictures of one mesh (uploaded once), e.g. the 26 views of the image error.
  std::vector<Image> render_views(const Render_mesh& mesh, const std::vector<Render_options>& options);

  /// The texture atlas of `mesh` (its first texture, or a light grey square when it has none)
  /// with its UV layout drawn over it in `line_color`; square picture of size x size covering
  /// UV space [0,1]^2, v = 1 at the top. Requires mesh.has_uvs().
  Image render_uv_atlas(const Render_mesh& mesh, int size, std::array<double, 3> line_color = {{0.05, 0.15, 0.75}});

  /// "renderer, GL version" of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6".
  std::string description() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_RENDERER_H
