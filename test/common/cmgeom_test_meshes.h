// Meshes built from scratch for the tests of several packages.
#ifndef CMGEOM_TEST_MESHES_H
#define CMGEOM_TEST_MESHES_H

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace cmgeom_test {

/// Icosphere with vertices on the unit sphere: 20 * 4^level triangles (outward), inscribed in
/// the sphere. Writes its points `p` and triangles `f`.
inline void icosphere(int level, std::vector<std::array<double, 3>>& p, std::vector<std::array<std::size_t, 3>>& f) {
  const double t = (1. + std::sqrt(5.)) / 2.;
  p = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
       {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
       {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
       {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  auto normalize = [](std::array<double, 3> a) {
    const double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    return std::array<double, 3>{{a[0] / l, a[1] / l, a[2] / l}};
  };
  for (auto& q : p) q = normalize(q);
  for (int s = 0; s < level; ++s) {
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> mid;
    auto midpoint = [&](std::size_t a, std::size_t b) {
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      p.push_back(normalize({{(p[a][0] + p[b][0]) / 2, (p[a][1] + p[b][1]) / 2, (p[a][2] + p[b][2]) / 2}}));
      return mid[key] = p.size() - 1;
    };
    std::vector<std::array<std::size_t, 3>> nf;
    for (const auto& tri : f) {
      const std::size_t ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]), ca = midpoint(tri[2], tri[0]);
      nf.push_back({tri[0], ab, ca});
      nf.push_back({tri[1], bc, ab});
      nf.push_back({tri[2], ca, bc});
      nf.push_back({ab, bc, ca});
    }
    f.swap(nf);
  }
}

/// icosphere(level) of radius `r` as OBJ text (full precision). A non-empty `bad_vertex` replaces
/// the line of vertex 4 (to make malformed files).
inline std::string icosphere_obj(int level, double r = 1.0, const std::string& bad_vertex = "") {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  icosphere(level, p, f);
  std::ostringstream o;
  o.precision(17);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (i == 3 && !bad_vertex.empty())
      o << bad_vertex << "\n";
    else
      o << "v " << r * p[i][0] << " " << r * p[i][1] << " " << r * p[i][2] << "\n";
  }
  for (const auto& t : f) o << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  return o.str();
}

}  // namespace cmgeom_test

#endif
