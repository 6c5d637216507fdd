// Helpers of the tests of the geometry part of the Textured_simplification package (thesis §3.4,
// §3.5.1): shared meshes, mesh measures, surface error, checking visitors, synthetic meshes and
// the invariants every simplification keeps. Included by test_heap.cpp, test_quadric.cpp,
// test_quadric_policies.cpp, test_engine*.cpp, test_placement_filters_and_stop.cpp and
// test_simplify_cli.cpp.
#ifndef CMGEOM_TEST_TEXTURED_SIMPLIFICATION_UTIL_H
#define CMGEOM_TEST_TEXTURED_SIMPLIFICATION_UTIL_H

#include "cmgeom_test_config.h"

#include <CMGeom/Textured_simplification.h>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polyhedron_3.h>
#include <CGAL/Polyhedron_items_with_id_3.h>
#include <CGAL/boost/graph/copy_face_graph.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_profile.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace TS = CMGeom::Textured_simplification;
namespace SMS = CGAL::Surface_mesh_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;
namespace fs = std::filesystem;

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Vector = K::Vector_3;
using Mesh = CGAL::Surface_mesh<Point>;
using vertex_descriptor = Mesh::Vertex_index;
using face_descriptor = Mesh::Face_index;
using halfedge_descriptor = Mesh::Halfedge_index;
using Policy = TS::Area_weighted_quadric_policies<Mesh>;
using Quadric = TS::internal::Symmetric_quadric;

namespace {

// ------------------------------------------------------------------------- helpers

inline std::string data_dir() { return CMGEOM_DATA_DIR; }

// Reads a mesh, gunzipping .gz files into the test temp directory first. False if unreadable.
inline bool read_mesh(const std::string& path, Mesh& m) {
  std::string p = path;
  if (p.size() > 3 && p.substr(p.size() - 3) == ".gz") {
    const std::string out = std::string(CMGEOM_TEST_TMP_DIR) + "/" + fs::path(p).stem().string();
    if (!fs::exists(out)) {
      const std::string cmd = "gunzip -c '" + p + "' > '" + out + ".part' && mv '" + out + ".part' '" + out + "'";
      if (std::system(cmd.c_str()) != 0) return false;
    }
    p = out;
  }
  m.clear();
  return CGAL::IO::read_polygon_mesh(p, m) && !m.is_empty();
}

inline std::size_t live_faces(const Mesh& m) { return m.number_of_faces(); }

/// The coordinates of m's vertices, sorted (two meshes with the same points compare equal whatever
/// their vertex order).
inline std::vector<std::array<double, 3>> sorted_points(const Mesh& m) {
  std::vector<std::array<double, 3>> p;
  for (auto v : m.vertices()) p.push_back({m.point(v).x(), m.point(v).y(), m.point(v).z()});
  std::sort(p.begin(), p.end());
  return p;
}

inline long euler_characteristic(const Mesh& m) {
  return long(m.number_of_vertices()) - long(m.number_of_edges()) + long(m.number_of_faces());
}

inline std::size_t component_count(Mesh m) {
  m.collect_garbage();
  auto fcc = m.add_property_map<face_descriptor, std::size_t>("f:cc_test", 0).first;
  return PMP::connected_components(m, fcc);
}

inline double bbox_diagonal(const Mesh& m) {
  CGAL::Bbox_3 b;
  for (vertex_descriptor v : m.vertices()) b += m.point(v).bbox();
  return std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
                   CGAL::square(b.zmax() - b.zmin()));
}

inline Vector face_area_vector(const Mesh& m, face_descriptor f) {
  const halfedge_descriptor h = m.halfedge(f);
  const Point& a = m.point(m.source(h));
  const Point& b = m.point(m.target(h));
  const Point& c = m.point(m.target(m.next(h)));
  return CGAL::cross_product(b - a, c - a);
}

// Distances from points to a mesh (closest point on its triangles).
class Distance_to_mesh {
public:
  using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;
  explicit Distance_to_mesh(const Mesh& m) : tree_(faces(m).first, faces(m).second, m) {
    tree_.accelerate_distance_queries();
  }
  double operator()(const Point& p) const { return std::sqrt(tree_.squared_distance(p)); }

private:
  Tree tree_;
};

// Uniform area samples (fixed seed) of a mesh.
inline std::vector<Point> sample_surface(const Mesh& m, std::size_t n, unsigned seed = 7) {
  std::vector<face_descriptor> fs_;
  std::vector<double> cdf;
  double total = 0;
  for (face_descriptor f : m.faces()) {
    total += std::sqrt(face_area_vector(m, f).squared_length()) / 2;
    fs_.push_back(f);
    cdf.push_back(total);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Point> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = U(rng) * total;
    const std::size_t k =
        std::min<std::size_t>(std::lower_bound(cdf.begin(), cdf.end(), r) - cdf.begin(), fs_.size() - 1);
    const halfedge_descriptor h = m.halfedge(fs_[k]);
    const Point& a = m.point(m.source(h));
    const Point& b = m.point(m.target(h));
    const Point& c = m.point(m.target(m.next(h)));
    double s = U(rng), t = U(rng);
    if (s + t > 1) {
      s = 1 - s;
      t = 1 - t;
    }
    out.push_back(a + s * (b - a) + t * (c - a));
  }
  return out;
}

struct Error_stats {
  double hausdorff = 0, rms = 0;
};
// Symmetric sampled Hausdorff and RMS (max of the two directions), absolute units.
inline Error_stats surface_error(const Mesh& a, const Mesh& b, std::size_t n = 20000) {
  Error_stats e;
  for (int dir = 0; dir < 2; ++dir) {
    const Mesh& from = dir == 0 ? a : b;
    const Mesh& to = dir == 0 ? b : a;
    Distance_to_mesh dist(to);
    double mx = 0, sum2 = 0;
    const auto pts = sample_surface(from, n);
    for (const Point& p : pts) {
      const double d = dist(p);
      mx = std::max(mx, d);
      sum2 += d * d;
    }
    e.hausdorff = std::max(e.hausdorff, mx);
    e.rms = std::max(e.rms, std::sqrt(sum2 / double(pts.size())));
  }
  return e;
}

// Visitor that checks, for every collapse, that no surviving star triangle flips its normal,
// and counts the hook calls.
struct Checking_visitor : TS::Edge_collapse_visitor_base {
  struct Stats {
    std::size_t collapsing = 0, collapsed = 0, flipped_faces = 0, flips = 0;
    std::vector<std::pair<face_descriptor, Vector>> star;
  };
  Stats* stats;
  explicit Checking_visitor(Stats* s) : stats(s) {}

  template <class Profile, class OP>
  void OnCollapsing(const Profile& p, const OP&) const {
    ++stats->collapsing;
    const Mesh& m = p.surface_mesh();
    stats->star.clear();
    const face_descriptor fL = m.face(p.v0_v1()), fR = m.face(m.opposite(p.v0_v1()));
    for (vertex_descriptor v : {p.v0(), p.v1()})
      for (face_descriptor f : CGAL::faces_around_target(m.halfedge(v), m))
        if (f != Mesh::null_face() && f != fL && f != fR) stats->star.emplace_back(f, face_area_vector(m, f));
  }
  template <class Profile, class V>
  void OnCollapsed(const Profile& p, const V&) const {
    ++stats->collapsed;
    const Mesh& m = p.surface_mesh();
    for (const auto& [f, n_old] : stats->star)
      if (!(face_area_vector(m, f) * n_old > 0)) ++stats->flipped_faces;
  }
  template <class TM, class H>
  void OnFlipped(const TM&, const H&) const {
    ++stats->flips;
  }
};

// A policy wrapper counting the Update_tag hook calls made by an engine.
struct Counting_policy : Policy {
  struct Counts {
    std::size_t init = 0, update = 0;
  };
  Counts* counts;
  Counting_policy(Mesh& m, Counts* c, const TS::Quadric_options& o = {}) : Policy(m, o), counts(c) {}
  using Get_cost = Counting_policy;
  using Get_placement = Counting_policy;
  template <class VPM, class GT>
  void initialize(const Mesh& m, const VPM& vpm, const GT& gt) const {
    ++counts->init;
    Policy::initialize(m, vpm, gt);
  }
  template <class Profile>
  void update_after_collapse(const Profile& p, vertex_descriptor v) const {
    ++counts->update;
    Policy::update_after_collapse(p, v);
  }
};

// The closed, manifold, triangulated meshes of shared/data/classic (by path).
inline std::vector<std::string> closed_classic_meshes() {
  std::vector<std::string> out;
  const fs::path dir = fs::path(data_dir()) / "classic";
  if (!fs::exists(dir)) return out;
  for (const auto& entry : fs::directory_iterator(dir)) out.push_back(entry.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// Icosphere-like mesh: a lat-long sphere with poles, refined near the north pole.
// With horn_height > 0 a thin curved horn grows from the north pole.
inline Mesh make_sphere_with_horn(double horn_height, int n_theta = 120, int n_phi = 96) {
  Mesh m;
  const double sigma = 0.06;  // angular radius of the horn base
  auto position = [&](double theta, double phi) {
    const double g = std::exp(-(theta / sigma) * (theta / sigma));
    const double r = 1.0 + horn_height * g;
    Point p(r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi), r * std::cos(theta));
    // bend: push the horn sideways quadratically with its height (a curved horn)
    const double h = horn_height * g;
    return Point(p.x() + 0.6 * h * h, p.y(), p.z());
  };
  // theta samples: dense near the pole (the horn), uniform elsewhere
  std::vector<double> thetas;
  for (int i = 1; i < n_theta; ++i) {
    const double s = double(i) / n_theta;
    thetas.push_back(CGAL_PI * (0.35 * s * s * s + 0.65 * s));  // smooth, denser near 0
  }
  std::vector<std::vector<vertex_descriptor>> rings;
  const vertex_descriptor north = m.add_vertex(position(0.0, 0.0));
  for (double t : thetas) {
    rings.emplace_back();
    for (int j = 0; j < n_phi; ++j) rings.back().push_back(m.add_vertex(position(t, 2 * CGAL_PI * j / n_phi)));
  }
  const vertex_descriptor south = m.add_vertex(Point(0, 0, -1));
  for (int j = 0; j < n_phi; ++j) m.add_face(north, rings[0][j], rings[0][(j + 1) % n_phi]);
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    for (int j = 0; j < n_phi; ++j) {
      const int k = (j + 1) % n_phi;
      m.add_face(rings[i][j], rings[i + 1][j], rings[i + 1][k]);
      m.add_face(rings[i][j], rings[i + 1][k], rings[i][k]);
    }
  for (int j = 0; j < n_phi; ++j) m.add_face(rings.back()[j], south, rings.back()[(j + 1) % n_phi]);
  return m;
}

inline Mesh make_flat_grid(int n) {
  Mesh m;
  std::vector<vertex_descriptor> v;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) v.push_back(m.add_vertex(Point(double(j) / n, double(i) / n, 0)));
  auto id = [&](int i, int j) { return v[i * (n + 1) + j]; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.add_face(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      m.add_face(id(i, j), id(i + 1, j + 1), id(i + 1, j));
    }
  return m;
}

template <class Engine>
void check_simplification_invariants(const std::string& name, Mesh m, std::size_t target, Engine engine) {
  const long chi = euler_characteristic(m);
  const std::size_t cc = component_count(m);
  Checking_visitor::Stats stats;
  engine(m, target, Checking_visitor(&stats));
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m)) << name;
  EXPECT_TRUE(CGAL::is_triangle_mesh(m)) << name;
  EXPECT_TRUE(CGAL::is_closed(m)) << name;
  EXPECT_EQ(euler_characteristic(m), chi) << name << ": genus changed";
  EXPECT_EQ(component_count(m), cc) << name;
  EXPECT_EQ(stats.flipped_faces, 0u) << name << ": a collapse flipped a face normal";
  // closed mesh: every collapse removes 2 faces, so an even target is reached exactly
  EXPECT_EQ(live_faces(m), target) << name;
  for (vertex_descriptor v : m.vertices()) {
    const Point& p = m.point(v);
    ASSERT_TRUE(std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z())) << name;
  }
  // manifold: every vertex has a single fan of faces: the fans around all vertices together
  // cover every halfedge exactly once
  std::size_t fan_total = 0, fan_halfedges = 0;
  for (vertex_descriptor v : m.vertices()) {
    for (halfedge_descriptor h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
      (void)h;
      ++fan_halfedges;
    }
    std::size_t around = 0;
    for (halfedge_descriptor h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
      (void)h;
      ++around;
    }
    ASSERT_GE(around, 3u) << name;
    ++fan_total;
  }
  EXPECT_EQ(fan_halfedges, m.number_of_halfedges()) << name << ": a vertex has more than one fan";
  EXPECT_EQ(fan_total, m.number_of_vertices());
}

// A sphere (n x n grid) with random radial noise of relative amplitude `amplitude`: distinct
// collapse costs, no ties.
inline Mesh make_noisy_sphere(int n, unsigned seed, double amplitude) {
  Mesh m = make_sphere_with_horn(0.0, n, n);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-amplitude, amplitude);
  for (vertex_descriptor v : m.vertices()) m.point(v) = CGAL::ORIGIN + (m.point(v) - CGAL::ORIGIN) * (1 + U(rng));
  return m;
}

// The collapse profile of CMGeom's engine on a Mesh.
using Engine_profile = TS::Collapse_profile<Mesh, Mesh::Property_map<vertex_descriptor, Point>, K>;

}  // namespace

#endif  // CMGEOM_TEST_TEXTURED_SIMPLIFICATION_UTIL_H
