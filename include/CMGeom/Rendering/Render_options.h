// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Render_options: everything that defines one picture of a mesh (size, shading mode, overlays,
// camera, colours). The camera is fitted to a box (the mesh's bounding box unless `fit_box` is
// set, e.g. to frame two meshes identically): it looks at the box centre from the direction given
// by azimuth/elevation, at a distance such that the bounding sphere of the box (radius R = half
// the box diagonal), scaled by `margin`, fits the smaller image dimension. With an orthographic
// projection a sphere of radius r centred in the box therefore covers a disc of radius
// r / (R margin) x min(width, height) / 2 pixels (used by the tests).
//
// Azimuth turns around the +Y (up) axis, 0 = looking from +Z towards -Z, 90 = from +X;
// elevation lifts the eye towards +Y (90 = from above). Colours are sRGB values in [0,1].
//
// Complexity: plain data.
#ifndef CMGEOM_RENDERING_RENDER_OPTIONS_H
#define CMGEOM_RENDERING_RENDER_OPTIONS_H

#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace CMGeom {
namespace Rendering {

/// How faces are coloured.
enum class Shading {
  Smooth,    ///< per-vertex normals interpolated (Phong lighting), uniform base colour
  Flat,      ///< one normal per face (derived from screen-space derivatives)
  Textured,  ///< diffuse texture through per-corner UVs, sRGB-correct filtering and lighting
  Field      ///< per-vertex scalar through the perceptual colour map (see colormap.h)
};

enum class Projection { Perspective, Orthographic };

struct Render_options {
  int width = 1024;
  int height = 1024;
  Shading shading = Shading::Smooth;
  bool lighting = true;    ///< false: faces show their base/texture/field colour unshaded
  bool wireframe = false;  ///< draw every edge over the faces
  bool charts = false;     ///< draw the chart boundaries (UV seams) in `chart_color`
  double azimuth = 30.;    ///< degrees
  double elevation = 20.;  ///< degrees
  Projection projection = Projection::Perspective;
  double field_of_view = 30.;     ///< vertical, degrees (perspective only)
  double margin = 1.05;           ///< bounding sphere radius multiplier
  double ortho_half_height = 0.;  ///< > 0: orthographic half extent of the smaller side (world units)
  bool has_fit_box = false;
  std::array<double, 6> fit_box{{0, 0, 0, 0, 0, 0}};  ///< xmin ymin zmin xmax ymax zmax
  std::array<double, 3> background{{1., 1., 1.}};
  std::array<double, 3> base_color{{0.80, 0.78, 0.74}};
  std::array<double, 3> wire_color{{0.12, 0.14, 0.22}};
  std::array<double, 3> chart_color{{1., 0., 0.}};
  float wire_width = 1.f;   ///< pixels
  float chart_width = 2.f;  ///< pixels
  /// Colour-map range of Shading::Field; NaN = range of the data.
  double field_min = std::numeric_limits<double>::quiet_NaN();
  double field_max = std::numeric_limits<double>::quiet_NaN();
  int samples = 4;  ///< MSAA samples (1 = none)

  // Decorations composited after rendering (render_to_png() and the grid helpers).
  bool legend = true;        ///< colour bar with the range when shading == Field
  std::string legend_label;  ///< text above the colour bar
  std::string caption;       ///< text in the bottom-left corner

  /// Frames the camera on `box` instead of the mesh's own bounding box.
  Render_options& fit_to(const std::array<double, 6>& box) {
    fit_box = box;
    has_fit_box = true;
    return *this;
  }
  Render_options& view(double az, double el) {
    azimuth = az;
    elevation = el;
    return *this;
  }
};

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_RENDER_OPTIONS_H
