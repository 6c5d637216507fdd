// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Triangle_cage: the control polyhedron of a cage deformation (thesis §5.1, §5.3.1: "a cage is a
// low polygon-count polyhedron which encloses the object"). It is a plain indexed triangle list,
// because the coordinate kernels (Mean_value_coordinates_3, Green_coordinates_3,
// Harmonic_coordinates_3) run over flat arrays; construct it from polygons (fan-triangulated in
// file order: (c0,c1,c2), (c0,c2,c3), ...) or from any CGAL FaceListGraph.
//
// `validate_cage()` checks what every coordinate type needs: finite coordinates, no repeated
// vertex in a triangle, non-zero area, and a closed, consistently oriented surface. Closedness is
// decided on vertex *positions* (coincident vertices are welded for the check only), because real
// cages often duplicate a vertex without opening the surface; coordinates keep one value per
// stored vertex. A cage whose signed volume is negative (inward normals) is either reported or
// flipped (Cage_orientation).
//
// Complexity: construction O(n + m); validation O(m log m).
#ifndef CMGEOM_CAGE_DEFORMATION_TRIANGLE_CAGE_H
#define CMGEOM_CAGE_DEFORMATION_TRIANGLE_CAGE_H

#include <CMGeom/Error.h>

#include <CGAL/boost/graph/iterator.h>
#include <CGAL/boost/graph/properties.h>
#include <boost/graph/graph_traits.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// 3-vector of doubles used by the numeric kernels.
using Vec3 = std::array<double, 3>;

namespace internal {
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 mul(double s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

/// Converts a CGAL point (x(), y(), z()) or anything indexable by [0..2] to Vec3.
template <class P>
auto to_vec3(const P& p, int) -> decltype(p.x(), Vec3()) {
  return {double(p.x()), double(p.y()), double(p.z())};
}
template <class P>
Vec3 to_vec3(const P& p, long) {
  return {double(p[0]), double(p[1]), double(p[2])};
}
template <class P>
Vec3 to_vec3(const P& p) {
  return to_vec3(p, 0);
}
}  // namespace internal

/// An indexed triangle cage. Triangles are counter-clockwise seen from outside once validated.
struct Triangle_cage {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  std::size_t number_of_vertices() const { return vertices.size(); }
  std::size_t number_of_triangles() const { return triangles.size(); }

  /// Length of the diagonal of the axis-aligned bounding box; every tolerance is relative to it.
  double bbox_diagonal() const {
    if (vertices.empty()) return 0;
    Vec3 lo = vertices[0], hi = vertices[0];
    for (const Vec3& v : vertices)
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(lo[i], v[i]);
        hi[i] = std::max(hi[i], v[i]);
      }
    return internal::norm(internal::sub(hi, lo));
  }

  /// Signed enclosed volume: positive when the triangles are oriented outwards.
  double signed_volume() const {
    double v = 0;
    for (const auto& t : triangles) v += internal::dot(vertices[t[0]], internal::cross(vertices[t[1]], vertices[t[2]]));
    return v / 6.0;
  }

  /// Same cage with other vertex positions (a deformed pose): connectivity is shared.
  Triangle_cage with_vertices(std::vector<Vec3> v) const {
    Triangle_cage c;
    c.vertices = std::move(v);
    c.triangles = triangles;
    return c;
  }
};

/// Builds a cage from points and polygons (any range of index ranges). Polygons with more than
/// three corners are split into fans in the order the corners are given, so a rest cage and a
/// deformed cage read from files with the same faces get the same triangles (§3.0 of the
/// formula sheet: the split of a non-planar quad changes the coordinates).
template <class PointRange, class PolygonRange>
Triangle_cage make_triangle_cage(const PointRange& points, const PolygonRange& polygons) {
  Triangle_cage cage;
  for (const auto& p : points) cage.vertices.push_back(internal::to_vec3(p));
  std::size_t f = 0;
  for (const auto& poly : polygons) {
    std::vector<std::uint32_t> c(poly.begin(), poly.end());
    if (c.size() < 3) throw Invalid_input("cage polygon " + std::to_string(f) + " has fewer than 3 corners");
    for (std::uint32_t i : c)
      if (i >= cage.vertices.size())
        throw Invalid_input("cage polygon " + std::to_string(f) + " uses vertex " + std::to_string(i) +
                            " but the cage has " + std::to_string(cage.vertices.size()) + " vertices");
    for (std::size_t k = 1; k + 1 < c.size(); ++k) cage.triangles.push_back({c[0], c[k], c[k + 1]});
    ++f;
  }
  return cage;
}

/// Builds a cage from a CGAL FaceListGraph (e.g. Surface_mesh). Vertices are numbered in the
/// graph's vertex iteration order; faces with more than three sides are fan-triangulated.
template <class FaceGraph>
Triangle_cage make_triangle_cage(const FaceGraph& g) {
  std::map<typename boost::graph_traits<FaceGraph>::vertex_descriptor, std::uint32_t> index;
  std::vector<Vec3> pts;
  auto vpm = get(CGAL::vertex_point, g);
  for (auto v : vertices(g)) {
    index[v] = std::uint32_t(pts.size());
    pts.push_back(internal::to_vec3(get(vpm, v)));
  }
  std::vector<std::vector<std::uint32_t>> polys;
  for (auto f : faces(g)) {
    std::vector<std::uint32_t> p;
    for (auto v : vertices_around_face(halfedge(f, g), g)) p.push_back(index[v]);
    polys.push_back(std::move(p));
  }
  return make_triangle_cage(pts, polys);
}

/// What validate_cage() does with a cage whose normals point inwards.
enum class Cage_orientation { require_outward, make_outward };

/// Checks that `cage` is usable by the coordinate classes; throws Invalid_input (one line,
/// naming `name`) otherwise. With make_outward, a consistently inward-oriented cage is flipped.
/// Returns true when the cage was flipped.
inline bool validate_cage(Triangle_cage& cage, const std::string& name = "cage",
                          Cage_orientation orient = Cage_orientation::make_outward) {
  using namespace internal;
  if (cage.vertices.size() < 4 || cage.triangles.size() < 4)
    throw Invalid_input(name + ": a cage needs at least 4 vertices and 4 triangles");
  for (std::size_t i = 0; i < cage.vertices.size(); ++i)
    for (double c : cage.vertices[i])
      if (!std::isfinite(c)) throw Invalid_input(name + ": vertex " + std::to_string(i) + " is not finite");
  const double L = cage.bbox_diagonal();
  if (!(L > 0)) throw Invalid_input(name + ": all vertices coincide");

  // Weld coincident positions for the topology check only.
  std::map<Vec3, std::uint32_t> first;
  std::vector<std::uint32_t> weld(cage.vertices.size());
  for (std::size_t i = 0; i < cage.vertices.size(); ++i)
    weld[i] = first.emplace(cage.vertices[i], std::uint32_t(i)).first->second;

  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;  // (a,b) -> count
  for (std::size_t t = 0; t < cage.triangles.size(); ++t) {
    const auto& tr = cage.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (weld[tr[k]] == weld[tr[(k + 1) % 3]])
        throw Invalid_input(name + ": triangle " + std::to_string(t) + " repeats a vertex");
    const Vec3 n =
        cross(sub(cage.vertices[tr[1]], cage.vertices[tr[0]]), sub(cage.vertices[tr[2]], cage.vertices[tr[0]]));
    if (!(norm(n) > 1e-14 * L * L)) throw Invalid_input(name + ": triangle " + std::to_string(t) + " has zero area");
    for (int k = 0; k < 3; ++k) ++directed[{weld[tr[k]], weld[tr[(k + 1) % 3]]}];
  }
  for (const auto& [e, count] : directed) {
    if (count > 1)
      throw Invalid_input(name +
                          ": triangles are not consistently oriented or not manifold "
                          "(edge " +
                          std::to_string(e.first) + "-" + std::to_string(e.second) +
                          " is used twice in the same direction)");
    auto it = directed.find({e.second, e.first});
    if (it == directed.end())
      throw Invalid_input(name + ": the cage is not closed (edge " + std::to_string(e.first) + "-" +
                          std::to_string(e.second) + " has one triangle)");
  }
  const double vol = cage.signed_volume();
  if (std::abs(vol) <= 1e-12 * L * L * L) throw Invalid_input(name + ": the cage encloses no volume");
  if (vol < 0) {
    if (orient == Cage_orientation::require_outward)
      throw Invalid_input(name + ": triangles are oriented inwards (negative volume)");
    for (auto& t : cage.triangles) std::swap(t[1], t[2]);
    return true;
  }
  return false;
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_TRIANGLE_CAGE_H
