// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Named camera directions and the fixed 26-view set of the image-space error (thesis §2.3.2.1:
// the appearance difference is "integrated over all possible views"; we use the 26 directions
// from the centre of a cube towards its 6 faces, 12 edges and 8 corners, i.e. every
// (i, j, k) in {-1, 0, 1}^3 except (0, 0, 0), in lexicographic order).
//
// Complexity: O(1).
#ifndef CMGEOM_RENDERING_VIEWS_H
#define CMGEOM_RENDERING_VIEWS_H

#include <CMGeom/Error.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Rendering {

/// A camera direction: azimuth and elevation in degrees (see Render_options).
struct View {
  double azimuth = 0., elevation = 0.;
  std::string name;
};

/// Azimuth/elevation of the eye direction (x, y, z) (Y up, azimuth 0 = +Z).
inline View view_from_direction(double x, double y, double z, std::string name = std::string()) {
  const double pi = 3.14159265358979323846;
  const double l = std::sqrt(x * x + y * y + z * z);
  View v;
  v.elevation = std::asin(y / l) * 180. / pi;
  v.azimuth = (x == 0. && z == 0.) ? 0. : std::atan2(x, z) * 180. / pi;
  v.name = std::move(name);
  return v;
}

/// The 26 cube directions (faces, edges, corners).
inline std::vector<View> cube_views_26() {
  std::vector<View> out;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        if (!i && !j && !k) continue;
        const std::string name = "(" + std::to_string(i) + "," + std::to_string(j) + "," + std::to_string(k) + ")";
        out.push_back(view_from_direction(i, j, k, name));
      }
  return out;
}

/// Presets: front, back, left, right, top, bottom, iso (azimuth 30, elevation 20 — the
/// default of Render_options), or "az,el" in degrees. Throws Invalid_input otherwise.
inline View parse_view(const std::string& s) {
  struct P {
    const char* name;
    double az, el;
  };
  static const P presets[] = {{"front", 0, 0}, {"back", 180, 0},   {"left", -90, 0}, {"right", 90, 0},
                              {"top", 0, 90},  {"bottom", 0, -90}, {"iso", 30, 20}};
  for (const P& p : presets)
    if (s == p.name) return View{p.az, p.el, p.name};
  const auto comma = s.find(',');
  if (comma != std::string::npos) {
    char* e1 = nullptr;
    char* e2 = nullptr;
    const std::string a = s.substr(0, comma), b = s.substr(comma + 1);
    const double az = std::strtod(a.c_str(), &e1), el = std::strtod(b.c_str(), &e2);
    if (!a.empty() && !b.empty() && *e1 == 0 && *e2 == 0 && std::isfinite(az) && std::isfinite(el) &&
        std::abs(el) <= 90.)
      return View{az, el, s};
  }
  throw Invalid_input("bad view '" + s +
                      "': expected az,el in degrees (|el| <= 90) or one of front, back, left, right, top, bottom, iso");
}

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_VIEWS_H
