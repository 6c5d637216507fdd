// Helpers of the Compact_model tests (thesis chapter 4): progress-hook records, synthetic meshes
// (sphere, box, height fields, a plane joined to a fillet), reconstruction checks (closed and
// shared, identical results, radius and vertex errors) and a CM of a fine sphere. Included by the
// test_*.cpp files of this folder that test the surfaces, build, reconstruction and CM files.
#ifndef CMGEOM_TEST_COMPACT_MODEL_UTIL_H
#define CMGEOM_TEST_COMPACT_MODEL_UTIL_H

#include "cmgeom_test_support.h"
#include "cmgeom_test_textured_grid.h"

#include <CMGeom/Compact_model.h>
#include <CMGeom/Compact_model/error_criterion.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <thread>

namespace {

using namespace CMGeom::CM;
using CMGeom::Point_3;
using CMGeom::Surface_mesh;
using Vtx = Surface_mesh::Vertex_index;

// What a progress hook (CMGeom/Progress.h) received, and from which threads.
struct Progress_record {
  std::vector<double> fractions;
  bool other_thread = false;
  // The hook; call it on the thread that runs the algorithm.
  CMGeom::Progress_callback hook() {
    const std::thread::id caller = std::this_thread::get_id();
    return [this, caller](double f) {
      if (std::this_thread::get_id() != caller) other_thread = true;
      fractions.push_back(f);
    };
  }
  // The contract: called, from the calling thread only, with fractions in [0, 1] that never
  // decrease and end at 1, at most `max_calls` times.
  void check(std::size_t max_calls) const {
    ASSERT_FALSE(fractions.empty());
    EXPECT_FALSE(other_thread);
    EXPECT_GE(fractions.front(), 0.);
    EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
    EXPECT_EQ(fractions.back(), 1.);
    EXPECT_LE(fractions.size(), max_calls);
  }
};

// ------------------------------------------------------------------ synthetic meshes
// Unit sphere: subdivided octahedron projected on the sphere (closed, genus 0).
inline Surface_mesh make_sphere(int subdivisions, double radius = 1.0) {
  std::vector<std::array<double, 3>> P = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<std::array<int, 3>> F = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto m = [&](int a, int b) {
      auto key = std::make_pair(std::min(a, b), std::max(a, b));
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      P.push_back({(P[a][0] + P[b][0]) / 2, (P[a][1] + P[b][1]) / 2, (P[a][2] + P[b][2]) / 2});
      return mid[key] = int(P.size()) - 1;
    };
    std::vector<std::array<int, 3>> G;
    for (auto f : F) {
      const int a = m(f[0], f[1]), b = m(f[1], f[2]), c = m(f[2], f[0]);
      G.push_back({f[0], a, c});
      G.push_back({a, f[1], b});
      G.push_back({c, b, f[2]});
      G.push_back({a, b, c});
    }
    F = G;
  }
  Surface_mesh mesh;
  std::vector<Vtx> v;
  for (auto p : P) {
    const double l = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) / radius;
    v.push_back(mesh.add_vertex(Point_3(p[0] / l, p[1] / l, p[2] / l)));
  }
  for (auto f : F) mesh.add_face(v[f[0]], v[f[1]], v[f[2]]);
  return mesh;
}

// Box [-1,1] x [-1,1] x [-h,h]: each face an n x n grid of quads split into triangles.
inline Surface_mesh make_box(int n, double h = 0.6) {
  Surface_mesh mesh;
  std::map<std::array<long, 3>, Vtx> index;
  auto vertex = [&](double x, double y, double z) {
    const std::array<long, 3> key = {std::lround(x * 1e6), std::lround(y * 1e6), std::lround(z * 1e6)};
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    return index[key] = mesh.add_vertex(Point_3(x, y, z));
  };
  const double ext[3] = {1., 1., h};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          Vtx q[4];
          const int di[4] = {0, 1, 1, 0}, dj[4] = {0, 0, 1, 1};
          for (int k = 0; k < 4; ++k) {
            double c[3];
            c[axis] = side * ext[axis];
            c[u] = -ext[u] + 2 * ext[u] * double(i + di[k]) / n;
            c[w] = -ext[w] + 2 * ext[w] * double(j + dj[k]) / n;
            q[k] = vertex(c[0], c[1], c[2]);
          }
          // Outward orientation: (u, w, axis) is right-handed, so CCW in (u, w) faces +axis.
          if (side > 0) {
            mesh.add_face(q[0], q[1], q[2]);
            mesh.add_face(q[0], q[2], q[3]);
          } else {
            mesh.add_face(q[0], q[2], q[1]);
            mesh.add_face(q[0], q[3], q[2]);
          }
        }
    }
  return mesh;
}

// A model on the height field z = g(x, y) over a regular grid, every frame normal (0, 0, 1), each
// vertex's quadric the exact Taylor expansion of g at the vertex (exact for quadratic g).
inline Compact_model height_field_model(double a, double b, double c, double d, double e, int n) {
  auto g = [&](double x, double y) { return a * x * x + b * x * y + c * y * y + d * x + e * y; };
  Compact_model m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -1 + 2. * i / n, y = -1 + 2. * j / n;
      m.vertices.push_back(Vec3(x, y, g(x, y)));
      m.normals.push_back(Vec3(0, 0, 1));
      Local_surface s;
      // g(x0+u, y0+v) - g(x0, y0) in the frame (U, V) = (x, y) since N = z (U = (1,0,0)).
      s.c = {a, b, c, 2 * a * x + b * y + d, b * x + 2 * c * y + e, 0, 0, 0, 0};
      m.surfaces.push_back(s);
    }
  auto id = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      auto corner = [&](std::uint32_t v) { return Corner{v, v, v}; };
      m.faces.push_back({corner(id(i, j)), corner(id(i + 1, j)), corner(id(i + 1, j + 1))});
      m.faces.push_back({corner(id(i, j)), corner(id(i + 1, j + 1)), corner(id(i, j + 1))});
    }
  return m;
}

inline std::vector<Vec3> sample_local(const Local_frame& f, std::mt19937& rng, int n, double r,
                                      const std::function<double(double, double)>& h, bool positive_x = false) {
  std::uniform_real_distribution<double> u(-r, r);
  std::vector<Vec3> pts;
  while (int(pts.size()) < n) {
    double x = u(rng), y = u(rng);
    if (positive_x) x = std::abs(x);
    pts.push_back(f.to_local(f.to_world(x, y, h(x, y))));
  }
  return pts;
}

inline bool is_closed_and_shared(const Reconstruction& r, std::string* why) {
  // Every undirected edge used exactly twice, once in each direction; no two points equal.
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : r.triangles)
    for (int k = 0; k < 3; ++k) {
      if (t[k] == t[(k + 1) % 3]) {
        *why = "degenerate triangle";
        return false;
      }
      if (++directed[{t[k], t[(k + 1) % 3]}] > 1) {
        *why = "directed edge used twice";
        return false;
      }
    }
  for (const auto& [e, n] : directed)
    if (!directed.count({e.second, e.first})) {
      *why = "border edge " + std::to_string(e.first) + "-" + std::to_string(e.second);
      return false;
    }
  std::set<std::array<double, 3>> pts;
  for (const Vec3& p : r.points)
    if (!pts.insert({p.x, p.y, p.z}).second) {
      *why = "duplicated point";
      return false;
    }
  return true;
}

inline bool same(const Reconstruction& a, const Reconstruction& b) {
  if (a.points.size() != b.points.size() || a.triangles != b.triangles) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    if (a.points[i] != b.points[i] || a.normals[i] != b.normals[i]) return false;
  return true;
}

inline double max_radius_error(const Reconstruction& r, double radius = 1.0) {
  double e = 0;
  for (const Vec3& p : r.points) e = std::max(e, std::abs(CMGeom::CM::internal::length(p) - radius));
  return e;
}

// Length of the bounding-box diagonal of `m`.
inline double bbox_diagonal(const Surface_mesh& m) {
  const auto box = CGAL::Polygon_mesh_processing::bbox(m);
  return std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                   CGAL::square(box.zmax() - box.zmin()));
}

// Symmetric RMS of vertex-to-surface distances (each mesh's vertices against the other mesh),
// an independent reference measure computed with CGAL's AABB tree.
inline double symmetric_vertex_rms(const Surface_mesh& a, const Surface_mesh& b) {
  using Primitive = CGAL::AABB_face_graph_triangle_primitive<Surface_mesh>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<CMGeom::Kernel, Primitive>>;
  double sum = 0;
  std::size_t n = 0;
  for (int side = 0; side < 2; ++side) {
    const Surface_mesh& from = side ? b : a;
    const Surface_mesh& to = side ? a : b;
    Tree tree(faces(to).first, faces(to).second, to);
    tree.accelerate_distance_queries();
    for (auto v : from.vertices()) {
      sum += CGAL::to_double(tree.squared_distance(from.point(v)));
      ++n;
    }
  }
  return std::sqrt(sum / double(n));
}

// A CM of a fine sphere with a coarse base, shared by several tests.
inline const Compact_model& sphere_model() {
  static const Compact_model m = [] {
    const Surface_mesh s = make_sphere(5);  // 8192 faces
    return build_compact_model(s, 120);
  }();
  return m;
}

// The n x n grid over [-1, 1]^2 of a plane joined to a parabolic fillet: z = 0 for x <= 0,
// 0.8 x^2 beyond (tangent-continuous, with a jump in curvature, as on Fandisk).
inline Surface_mesh plane_and_fillet(int n) {
  Surface_mesh grid;
  std::vector<Surface_mesh::Vertex_index> v;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -1 + 2. * i / n, y = -1 + 2. * j / n;
      v.push_back(grid.add_vertex(CMGeom::Point_3(x, y, x > 0 ? 0.8 * x * x : 0.)));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t a = std::size_t(j * (n + 1) + i), b = a + 1, c = a + std::size_t(n) + 1, d = c + 1;
      grid.add_face(v[a], v[b], v[d]);
      grid.add_face(v[a], v[d], v[c]);
    }
  return grid;
}

}  // namespace

#endif  // CMGEOM_TEST_COMPACT_MODEL_UTIL_H
