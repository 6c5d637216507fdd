// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The perceptual colour map of scalar-field pictures: viridis (van der Walt and Smith, the
// matplotlib default), which is perceptually uniform, readable in grey scale and by colour-blind
// readers — unlike the rainbow maps of older error pictures. Eleven sRGB samples of the published
// table at t = 0, 0.1, ..., 1 are interpolated linearly; the table is then sampled at 256 levels
// so that the GL texture and the CPU legend use the very same colours.
//
// Complexity: O(1) per lookup.
#ifndef CMGEOM_RENDERING_COLORMAP_H
#define CMGEOM_RENDERING_COLORMAP_H

#include <array>
#include <cmath>
#include <cstdint>

namespace CMGeom {
namespace Rendering {

/// sRGB colour of t in [0,1] (clamped), as 8-bit values.
inline std::array<std::uint8_t, 3> viridis(double t) {
  static const double k[11][3] = {
      {0.267004, 0.004874, 0.329415}, {0.282623, 0.140926, 0.457517}, {0.253935, 0.265254, 0.529983},
      {0.206756, 0.371758, 0.553117}, {0.163625, 0.471133, 0.558148}, {0.127568, 0.566949, 0.550556},
      {0.134692, 0.658636, 0.517649}, {0.266941, 0.748751, 0.440573}, {0.477504, 0.821444, 0.318195},
      {0.741388, 0.873449, 0.149561}, {0.993248, 0.906157, 0.143936}};
  if (!(t > 0.)) t = 0.;  // also maps NaN to the low end
  if (t > 1.) t = 1.;
  // Quantise to the 256 levels of the GL texture first, so CPU and GL agree exactly.
  const double level = std::floor(t * 255. + 0.5) / 255.;
  const double x = level * 10.;
  const int i = x >= 10. ? 9 : int(x);
  const double f = x - i;
  std::array<std::uint8_t, 3> c{};
  for (int d = 0; d < 3; ++d) c[d] = std::uint8_t(std::lround(255. * (k[i][d] + f * (k[i + 1][d] - k[i][d]))));
  return c;
}

/// The 256-entry table (RGBA, alpha 255) uploaded as the colour-map texture.
inline std::array<std::uint8_t, 256 * 4> viridis_table() {
  std::array<std::uint8_t, 256 * 4> t{};
  for (int i = 0; i < 256; ++i) {
    const auto c = viridis(i / 255.);
    t[4 * i] = c[0];
    t[4 * i + 1] = c[1];
    t[4 * i + 2] = c[2];
    t[4 * i + 3] = 255;
  }
  return t;
}

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_COLORMAP_H
