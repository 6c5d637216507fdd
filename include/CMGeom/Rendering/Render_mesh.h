// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Render_mesh: what a renderer draws, as flat float arrays ready for upload — one record per
// triangle corner (position, smooth normal, optional UV, optional scalar), grouped into ranges
// that share a texture, plus line lists for the wireframe, the chart boundaries and the UV
// layout. Corners are not shared: UV seams and per-face materials need split vertices anyway,
// and it keeps the GL and any CPU backend trivially identical. Build one with
// make_render_mesh() (make_render_mesh.h) from any CGAL face graph or a Textured_mesh.
//
// Memory: 36 bytes per corner without UVs/scalars (about 110 bytes per triangle).
#ifndef CMGEOM_RENDERING_RENDER_MESH_H
#define CMGEOM_RENDERING_RENDER_MESH_H

#include <CMGeom/Mesh_IO/Image.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace CMGeom {
namespace Rendering {

struct Render_mesh {
  /// Triangles [first, first + count) are drawn with `texture` (may be null: no texture).
  struct Range {
    std::size_t first = 0, count = 0;
    const Image* texture = nullptr;
  };

  std::vector<float> positions;                    ///< 3 floats per corner, 3 corners per triangle
  std::vector<float> normals;                      ///< 3 floats per corner (area-weighted vertex normals)
  std::vector<float> uvs;                          ///< 2 floats per corner; empty when the mesh has no UVs
  std::vector<float> scalars;                      ///< 1 float per corner; empty when there is no field
  std::vector<Range> ranges;                       ///< cover all triangles
  std::vector<float> wire_lines;                   ///< 3 floats per end point, 2 end points per edge
  std::vector<float> chart_lines;                  ///< same, for the chart boundaries (UV seams)
  std::vector<float> uv_lines;                     ///< 2 floats per end point: every edge of the UV layout
  std::array<double, 6> bbox{{0, 0, 0, 0, 0, 0}};  ///< xmin ymin zmin xmax ymax zmax
  double scalar_min = 0., scalar_max = 0.;         ///< finite range of `scalars`

  std::size_t triangle_count() const { return positions.size() / 9; }
  bool has_uvs() const { return !uvs.empty(); }
  bool has_scalars() const { return !scalars.empty(); }
  /// First texture of the ranges (null if none).
  const Image* texture() const {
    for (const Range& r : ranges)
      if (r.texture) return r.texture;
    return nullptr;
  }
};

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_RENDER_MESH_H
