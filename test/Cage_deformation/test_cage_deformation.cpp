// Tests of the Cage_deformation package: cage validation, mean value, Green and harmonic
// coordinates (reproduction, partition of unity, precision under affine maps / similarities,
// degenerate probes, scale invariance, continuity of the exterior extension, an independent
// quadrature of MVC on the shared cages), binding and the deformation kernel.
#include <CMGeom/Cage_deformation.h>

#include "cmgeom_test_config.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <fstream>
#include <map>
#include <sstream>
#include <random>
#include <set>
#include <vector>

using namespace CMGeom::Cage_deformation;

// The same tests run twice: with the AVX2 kernels (when the CPU has them) and, in the executable
// built with CMGEOM_CAGE_NO_SIMD, with the portable scalar kernels.
#ifdef CMGEOM_CAGE_NO_SIMD
#define CAGE_SUITE(name) name##_scalar
#else
#define CAGE_SUITE(name) name
#endif
using CMGeom::Cage_deformation::internal::add;
using CMGeom::Cage_deformation::internal::cross;
using CMGeom::Cage_deformation::internal::dot;
using CMGeom::Cage_deformation::internal::mul;
using CMGeom::Cage_deformation::internal::norm;
using CMGeom::Cage_deformation::internal::sub;

namespace {

// ------------------------------------------------------------------ test cages
// The boundary of a union of unit voxels, as outward quads (then fan-triangulated). Non-convex
// voxel sets give face planes that pass through the interior and the exterior of the cage.
Triangle_cage voxel_cage(const std::vector<std::array<int, 3>>& cells, double scale = 1.0,
                         Vec3 offset = {0, 0, 0}) {
  std::set<std::array<int, 3>> occ(cells.begin(), cells.end());
  std::map<std::array<int, 3>, std::uint32_t> vid;
  std::vector<Vec3> pts;
  std::vector<std::vector<std::uint32_t>> quads;
  auto vertex = [&](std::array<int, 3> p) {
    auto it = vid.find(p);
    if (it != vid.end()) return it->second;
    std::uint32_t i = std::uint32_t(pts.size());
    vid[p] = i;
    pts.push_back({offset[0] + scale * p[0], offset[1] + scale * p[1], offset[2] + scale * p[2]});
    return i;
  };
  for (const auto& c : cells)
    for (int axis = 0; axis < 3; ++axis)
      for (int dir = -1; dir <= 1; dir += 2) {
        std::array<int, 3> nb = c;
        nb[axis] += dir;
        if (occ.count(nb)) continue;
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        std::array<int, 3> base = c;
        if (dir > 0) base[axis] += 1;
        std::array<int, 3> p0 = base, p1 = base, p2 = base, p3 = base;
        p1[u] += 1;
        p2[u] += 1;
        p2[v] += 1;
        p3[v] += 1;
        // (u, v, axis) is right-handed: p0 p1 p2 p3 is counter-clockwise around +axis.
        if (dir > 0)
          quads.push_back({vertex(p0), vertex(p1), vertex(p2), vertex(p3)});
        else
          quads.push_back({vertex(p0), vertex(p3), vertex(p2), vertex(p1)});
      }
  Triangle_cage cage = make_triangle_cage(pts, quads);
  EXPECT_FALSE(validate_cage(cage, "voxel cage", Cage_orientation::require_outward));
  return cage;
}

Triangle_cage cube_cage(double scale = 1.0, Vec3 offset = {0, 0, 0}) {
  return voxel_cage({{0, 0, 0}}, scale, offset);
}
// L-shaped prism: three unit cubes.
Triangle_cage l_cage(double scale = 1.0, Vec3 offset = {0, 0, 0}) {
  return voxel_cage({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, scale, offset);
}

template <class Coords>
std::vector<double> coordinates(const Coords& c, const Vec3& x, Coordinate_status* st = nullptr) {
  std::vector<double> w;
  Coordinate_status s = c(x, std::back_inserter(w));
  if (st) *st = s;
  EXPECT_EQ(w.size(), c.number_of_coordinates());
  return w;
}

template <class Rule>
std::vector<Vec3> basis_of(const Rule& rule, const std::vector<Vec3>& deformed) {
  std::vector<Vec3> b;
  rule(deformed, std::back_inserter(b));
  return b;
}

Vec3 combine(const std::vector<double>& w, const std::vector<Vec3>& basis) {
  Vec3 r{0, 0, 0};
  for (std::size_t k = 0; k < w.size(); ++k) r = add(r, mul(w[k], basis[k]));
  return r;
}

double sum_of(const std::vector<double>& w, std::size_t n) {
  double s = 0;
  for (std::size_t i = 0; i < n; ++i) s += w[i];
  return s;
}

bool all_finite(const std::vector<double>& w) {
  for (double x : w)
    if (!std::isfinite(x)) return false;
  return true;
}

struct Affine {
  double A[3][3];
  Vec3 t;
  Vec3 operator()(const Vec3& p) const {
    Vec3 r = t;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r[i] += A[i][j] * p[j];
    return r;
  }
};

Affine random_affine(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  Affine a;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a.A[i][j] = (i == j ? 1.0 : 0.0) + U(rng);
    a.t[i] = 3 * U(rng);
  }
  return a;
}

// Rotation about a random axis by a random angle, times scale, plus translation.
Affine random_similarity(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> U(-1, 1);
  Vec3 axis{U(rng), U(rng), U(rng)};
  axis = mul(1.0 / norm(axis), axis);
  const double a = 3.0 * U(rng), c = std::cos(a), s = std::sin(a);
  Affine r;
  const double x = axis[0], y = axis[1], z = axis[2];
  const double R[3][3] = {{c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s},
                          {y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s},
                          {z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.A[i][j] = scale * R[i][j];
  r.t = {U(rng), 2 * U(rng), U(rng)};
  return r;
}

std::vector<Vec3> transformed(const std::vector<Vec3>& v, const Affine& a) {
  std::vector<Vec3> r;
  for (const Vec3& p : v) r.push_back(a(p));
  return r;
}

std::vector<Vec3> random_points(std::mt19937& rng, Vec3 lo, Vec3 hi, int count) {
  std::vector<Vec3> r;
  for (int i = 0; i < count; ++i) {
    Vec3 p;
    for (int c = 0; c < 3; ++c) p[c] = std::uniform_real_distribution<double>(lo[c], hi[c])(rng);
    r.push_back(p);
  }
  return r;
}

// ------------------------------------------------------------------ shared data
std::string data_dir() { return CMGEOM_DATA_DIR; }

// Points and polygons of a mesh or cage file, with the project's reader.
bool read_soup(const std::string& path, std::vector<Vec3>& pts,
               std::vector<std::vector<std::size_t>>& polys) {
  try {
    read_polygons(path, pts, polys);
  } catch (const CMGeom::Error& e) {
    ADD_FAILURE() << e.what();
    return false;
  }
  return !pts.empty();
}

struct Model {
  std::string name, mesh, cage;
};
std::vector<Model> data_models() {
  const std::string d = data_dir() + "/cages/";
  return {{"hand", d + "pgc/hand/hand.obj", d + "pgc/hand/cage.obj"},
          {"armadilloman", d + "pgc/armadilloman/armadilloman.obj", d + "pgc/armadilloman/cage.obj"},
          {"octopus", d + "pgc/octopus/octupus.obj", d + "pgc/octopus/cage.obj"},
          {"elephant", d + "pgc/elephant/elephant.obj", d + "pgc/elephant/cage.obj"},
          {"Ogre", d + "qmvc/Ogre.obj", d + "qmvc/Ogre_Cage.obj"},
          {"ManHead", d + "qmvc/ManHead.obj", d + "qmvc/ManHead_Cage.obj"},
          {"Beast", d + "qmvc/Beast.obj", d + "qmvc/Beast_Cage.obj"},
          {"giraffe", d + "pgc/giraffe/giraffe.obj", d + "pgc/giraffe/cage.obj"}};
}

}  // namespace

// ================================================================== cage validation
TEST(CAGE_SUITE(Cage_validation), fan_triangulation_in_file_order) {
  std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}};
  std::vector<std::vector<int>> f = {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  Triangle_cage c = make_triangle_cage(p, f);
  ASSERT_EQ(c.triangles.size(), 6u);
  EXPECT_EQ(c.triangles[0], (std::array<std::uint32_t, 3>{0, 3, 2}));
  EXPECT_EQ(c.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 1}));
  EXPECT_FALSE(validate_cage(c));
  EXPECT_NEAR(c.signed_volume(), 1.0 / 3.0, 1e-15);
}

TEST(CAGE_SUITE(Cage_validation), rejects_open_mixed_and_flips_inward) {
  Triangle_cage c = cube_cage();
  Triangle_cage open = c;
  open.triangles.pop_back();
  EXPECT_THROW(validate_cage(open), CMGeom::Invalid_input);
  Triangle_cage mixed = c;
  std::swap(mixed.triangles[0][1], mixed.triangles[0][2]);
  EXPECT_THROW(validate_cage(mixed), CMGeom::Invalid_input);
  Triangle_cage inward = c;
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  EXPECT_THROW(validate_cage(inward, "c", Cage_orientation::require_outward), CMGeom::Invalid_input);
  EXPECT_TRUE(validate_cage(inward));
  EXPECT_GT(inward.signed_volume(), 0);
  Triangle_cage nan = c;
  nan.vertices[3][1] = std::nan("");
  EXPECT_THROW(validate_cage(nan), CMGeom::Invalid_input);
}

TEST(CAGE_SUITE(Cage_validation), from_surface_mesh_and_flipped_orientation) {
  // make_triangle_cage on a CGAL FaceGraph gives the same cage as from the polygons.
  Triangle_cage c = cube_cage();
  CGAL::Surface_mesh<CGAL::Epick::Point_3> sm;
  std::vector<CGAL::Surface_mesh<CGAL::Epick::Point_3>::Vertex_index> vi;
  for (const Vec3& p : c.vertices) vi.push_back(sm.add_vertex(CGAL::Epick::Point_3(p[0], p[1], p[2])));
  for (const auto& t : c.triangles) sm.add_face(vi[t[0]], vi[t[1]], vi[t[2]]);
  Triangle_cage d = make_triangle_cage(sm);
  EXPECT_EQ(d.vertices, c.vertices);
  EXPECT_EQ(d.triangles.size(), c.triangles.size());
  EXPECT_FALSE(validate_cage(d));
  // MVC do not depend on the orientation; an inward cage is flipped back by validate_cage.
  Triangle_cage l = l_cage(), f = l;
  for (auto& t : f.triangles) std::swap(t[1], t[2]);
  Mean_value_coordinates_3 a(l), b(f);
  std::mt19937 rng(2);
  for (const Vec3& x : random_points(rng, {-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}, 100)) {
    std::vector<double> wa = coordinates(a, x), wb = coordinates(b, x);
    for (std::size_t k = 0; k < wa.size(); ++k) EXPECT_NEAR(wa[k], wb[k], 1e-12);
  }
}

TEST(CAGE_SUITE(Cage_validation), duplicated_vertices_still_closed) {
  // Split vertex 6 of the cube into two coincident copies used by different faces.
  Triangle_cage c = cube_cage();
  const std::uint32_t dup = std::uint32_t(c.vertices.size());
  c.vertices.push_back(c.vertices[6]);
  int changed = 0;
  for (auto& t : c.triangles)
    for (auto& i : t)
      if (i == 6 && changed < 2) {
        i = dup;
        ++changed;
        break;
      }
  EXPECT_NO_THROW(validate_cage(c));
  Mean_value_coordinates_3 mvc(c);
  std::vector<double> w = coordinates(mvc, {0.3, 0.6, 0.7});
  EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-13);
  Vec3 r = combine(w, c.vertices);
  EXPECT_LT(norm(sub(r, {0.3, 0.6, 0.7})), 1e-13);
}

// ================================================================== mean value coordinates
TEST(CAGE_SUITE(Cage_MVC), rest_pose_and_partition_of_unity) {
  std::mt19937 rng(7);
  for (const Triangle_cage& cage : {cube_cage(), l_cage()}) {
    Mean_value_coordinates_3 mvc(cage);
    const double L = cage.bbox_diagonal();
    // Inside and outside the cage (MVC are defined everywhere).
    for (const Vec3& x : random_points(rng, {-1, -1, -1}, {3, 3, 2}, 3000)) {
      std::vector<double> w = coordinates(mvc, x);
      ASSERT_TRUE(all_finite(w));
      EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-12);
      EXPECT_LT(norm(sub(combine(w, cage.vertices), x)), 1e-9 * L) << x[0] << " " << x[1] << " " << x[2];
    }
  }
}

TEST(CAGE_SUITE(Cage_MVC), positive_inside_convex_cage) {
  std::mt19937 rng(3);
  Mean_value_coordinates_3 mvc(cube_cage());
  for (const Vec3& x : random_points(rng, {0.01, 0.01, 0.01}, {0.99, 0.99, 0.99}, 500))
    for (double w : coordinates(mvc, x)) EXPECT_GT(w, 0.0);
}

TEST(CAGE_SUITE(Cage_MVC), linear_precision_under_random_affine_maps) {
  std::mt19937 rng(11);
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  std::vector<Vec3> pts = random_points(rng, {-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}, 500);
  Cage_binding<double> b = bind_points(mvc, pts);
  for (int trial = 0; trial < 5; ++trial) {
    Affine a = random_affine(rng);
    std::vector<Vec3> def = transformed(cage.vertices, a), out;
    b.deform(mvc.deformation_rule(), def, out);
    for (std::size_t i = 0; i < pts.size(); ++i)
      EXPECT_LT(norm(sub(out[i], a(pts[i]))), 1e-9 * cage.bbox_diagonal());
  }
}

TEST(CAGE_SUITE(Cage_MVC), exact_on_vertices_edges_faces) {
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  const std::size_t n = cage.vertices.size();
  Coordinate_status st;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> w = coordinates(mvc, cage.vertices[i], &st);
    EXPECT_EQ(st, Coordinate_status::on_boundary);
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(w[k], k == i ? 1.0 : 0.0);
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.05, 0.95);
  for (const auto& t : cage.triangles) {
    // edge midpoint: 1/2, 1/2
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k], b = t[(k + 1) % 3];
      std::vector<double> w = coordinates(mvc, mul(0.5, add(cage.vertices[a], cage.vertices[b])), &st);
      EXPECT_EQ(st, Coordinate_status::on_boundary);
      EXPECT_NEAR(w[a], 0.5, 1e-14);
      EXPECT_NEAR(w[b], 0.5, 1e-14);
      EXPECT_NEAR(sum_of(w, n), 1.0, 1e-14);
    }
    // random point on the face: its barycentric coordinates
    double b0 = U(rng), b1 = U(rng) * (1 - b0), b2 = 1 - b0 - b1;
    Vec3 x = add(add(mul(b0, cage.vertices[t[0]]), mul(b1, cage.vertices[t[1]])),
                 mul(b2, cage.vertices[t[2]]));
    std::vector<double> w = coordinates(mvc, x, &st);
    EXPECT_EQ(st, Coordinate_status::on_boundary);
    EXPECT_NEAR(w[t[0]], b0, 1e-12);
    EXPECT_NEAR(w[t[1]], b1, 1e-12);
    EXPECT_NEAR(w[t[2]], b2, 1e-12);
  }
}

TEST(CAGE_SUITE(Cage_MVC), face_planes_and_continuity) {
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  const double L = cage.bbox_diagonal();
  // (0.5, 1, 0.5) is inside the cage, in the plane y = 1 of the top face of cube (1,0,0);
  // (2.5, 1, 0.5) is outside, in the same plane; (1.5, 1, 0.5) is on that face.
  for (Vec3 x : {Vec3{0.5, 1, 0.5}, Vec3{2.5, 1, 0.5}, Vec3{1.5, 1, 0.5}, Vec3{1, 1, 0.5},
                 Vec3{3, 1, 1}, Vec3{1, 3, 0}}) {
    std::vector<double> w0 = coordinates(mvc, x);
    ASSERT_TRUE(all_finite(w0));
    EXPECT_LT(norm(sub(combine(w0, cage.vertices), x)), 1e-9 * L);
    // approaching from both sides of the plane: values converge to the value in the plane
    for (double eps : {1e-3, 1e-5, 1e-7, 1e-10, 1e-12}) {
      for (double sgn : {-1.0, 1.0}) {
        std::vector<double> w = coordinates(mvc, add(x, {0, sgn * eps, 0}));
        ASSERT_TRUE(all_finite(w));
        double diff = 0;
        for (std::size_t k = 0; k < w.size(); ++k) diff = std::max(diff, std::abs(w[k] - w0[k]));
        EXPECT_LT(diff, 50 * eps + 1e-7) << "eps " << eps << " at " << x[0] << "," << x[2];
      }
    }
  }
}

TEST(CAGE_SUITE(Cage_MVC), scale_invariance) {
  std::mt19937 rng(9);
  Triangle_cage c1 = l_cage();
  std::vector<Vec3> pts = random_points(rng, {-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}, 200);
  // some points on the cage too
  pts.push_back({1.5, 1, 0.5});
  pts.push_back({1, 1, 0.5});
  pts.push_back({0.5, 1, 0.5});
  Mean_value_coordinates_3 m1(c1);
  Green_coordinates_3 g1(c1);
  for (double s : {1e-3, 1e3}) {
    const Vec3 off{7 * s, -3 * s, 2 * s};
    Triangle_cage cs = l_cage(s, off);
    Mean_value_coordinates_3 ms(cs);
    Green_coordinates_3 gs(cs);
    for (const Vec3& x : pts) {
      const Vec3 xs = add(mul(s, x), off);
      std::vector<double> a = coordinates(m1, x), b = coordinates(ms, xs);
      for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-9);
      std::vector<double> ga = coordinates(g1, x), gb = coordinates(gs, xs);
      // vertex terms are scale free, face terms scale like a length
      for (std::size_t k = 0; k < ga.size(); ++k)
        EXPECT_NEAR(ga[k], k < c1.vertices.size() ? gb[k] : gb[k] / s, 1e-8);
    }
  }
}

TEST(CAGE_SUITE(Cage_MVC), permuting_vertices_permutes_weights) {
  Triangle_cage c = l_cage();
  const std::size_t n = c.vertices.size();
  std::vector<std::uint32_t> perm(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = std::uint32_t((i * 7 + 3) % n);
  Triangle_cage p;
  p.vertices.resize(n);
  for (std::size_t i = 0; i < n; ++i) p.vertices[perm[i]] = c.vertices[i];
  for (auto t : c.triangles) p.triangles.push_back({perm[t[0]], perm[t[1]], perm[t[2]]});
  Mean_value_coordinates_3 a(c), b(p);
  Vec3 x{0.4, 0.7, 0.3};
  std::vector<double> wa = coordinates(a, x), wb = coordinates(b, x);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(wa[i], wb[perm[i]], 1e-14);
}

// Independent slow reference: w_i(x) = integral over the cage of hat_i(xi) n.(xi - x)/|xi - x|^4
// (the mean value definition of Ju et al. written over the surface instead of the unit sphere;
// the signed solid-angle element handles rays that cross the cage several times), by a degree-5
// Dunavant rule on a 32 x 32 subdivision of every triangle.
std::vector<double> mvc_quadrature(const Triangle_cage& cage, const Vec3& x) {
  static const double W[7] = {0.225, 0.132394152788506, 0.132394152788506, 0.132394152788506,
                              0.125939180544827, 0.125939180544827, 0.125939180544827};
  const double a1 = 0.059715871789770, b1 = 0.470142064105115;
  const double a2 = 0.797426985353087, b2 = 0.101286507323456;
  const double P[7][3] = {{1. / 3, 1. / 3, 1. / 3}, {a1, b1, b1}, {b1, a1, b1}, {b1, b1, a1},
                          {a2, b2, b2},             {b2, a2, b2}, {b2, b2, a2}};
  const int S = 32;
  std::vector<double> w(cage.vertices.size(), 0.0);
  for (const auto& t : cage.triangles) {
    const Vec3 &A = cage.vertices[t[0]], &B = cage.vertices[t[1]], &C = cage.vertices[t[2]];
    const Vec3 nn = cross(sub(B, A), sub(C, A));
    const double area = 0.5 * norm(nn) / (S * S);
    const Vec3 n = mul(1.0 / norm(nn), nn);
    // sub-triangles in barycentric (i, j) grid, both orientations
    for (int i = 0; i < S; ++i)
      for (int j = 0; i + j < S; ++j)
        for (int up = 0; up < 2; ++up) {
          if (up && i + j + 1 >= S) continue;
          std::array<std::array<double, 2>, 3> c;  // (beta1, beta2) corners
          if (!up)
            c = {{{double(i), double(j)}, {double(i + 1), double(j)}, {double(i), double(j + 1)}}};
          else
            c = {{{double(i + 1), double(j)}, {double(i + 1), double(j + 1)}, {double(i), double(j + 1)}}};
          for (int q = 0; q < 7; ++q) {
            const double b1q = (P[q][0] * c[0][0] + P[q][1] * c[1][0] + P[q][2] * c[2][0]) / S;
            const double b2q = (P[q][0] * c[0][1] + P[q][1] * c[1][1] + P[q][2] * c[2][1]) / S;
            const double b0q = 1 - b1q - b2q;
            const Vec3 xi = add(add(mul(b0q, A), mul(b1q, B)), mul(b2q, C));
            const Vec3 d = sub(xi, x);
            const double r2 = dot(d, d);
            const double f = W[q] * area * dot(n, d) / (r2 * r2);
            w[t[0]] += f * b0q;
            w[t[1]] += f * b1q;
            w[t[2]] += f * b2q;
          }
        }
  }
  double s = 0;
  for (double v : w) s += v;
  for (double& v : w) v /= s;
  return w;
}

TEST(CAGE_SUITE(Cage_MVC), matches_independent_quadrature_on_shared_cages) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  int checked = 0;
  for (const Model& m : data_models()) {
    std::vector<Vec3> cp, mp;
    std::vector<std::vector<std::size_t>> cf, mf;
    ASSERT_TRUE(read_soup(m.cage, cp, cf)) << m.cage;
    ASSERT_TRUE(read_soup(m.mesh, mp, mf)) << m.mesh;
    Triangle_cage cage = make_triangle_cage(cp, cf);
    validate_cage(cage, m.cage);
    Mean_value_coordinates_3 mvc(cage);
    internal::Cage_geometry geom(cage);
    const double L = cage.bbox_diagonal();
    int used = 0;
    for (std::size_t v = 0; v < mp.size() && used < 6; v += mp.size() / 97 + 1) {
      double dmin = 1e300;
      for (std::size_t t = 0; t < geom.m; ++t) dmin = std::min(dmin, geom.distance_to_triangle(t, mp[v]));
      if (dmin < 0.015 * L) continue;  // the quadrature needs a smooth integrand
      std::vector<double> w = coordinates(mvc, mp[v]);
      std::vector<double> ref = mvc_quadrature(cage, mp[v]);
      double wmax = 0;
      for (double x : ref) wmax = std::max(wmax, std::abs(x));
      for (std::size_t k = 0; k < w.size(); ++k)
        EXPECT_NEAR(w[k], ref[k], 1e-6 * wmax) << m.name << " vertex " << v << " coord " << k;
      ++used;
      ++checked;
    }
    EXPECT_GT(used, 0) << m.name;
  }
  EXPECT_GT(checked, 10);
}

TEST(CAGE_SUITE(Cage_MVC), rest_pose_on_shared_models) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  for (const Model& m : data_models()) {
    std::vector<Vec3> cp, mp;
    std::vector<std::vector<std::size_t>> cf, mf;
    ASSERT_TRUE(read_soup(m.cage, cp, cf));
    ASSERT_TRUE(read_soup(m.mesh, mp, mf));
    Triangle_cage cage = make_triangle_cage(cp, cf);
    validate_cage(cage, m.cage);
    const double L = cage.bbox_diagonal();
    std::vector<Vec3> pts;
    for (std::size_t v = 0; v < mp.size(); v += 7) pts.push_back(mp[v]);
    Mean_value_coordinates_3 mvc(cage);
    Green_coordinates_3 gc(cage);
    Cage_binding<double> bm = bind_points(mvc, pts);
    Cage_binding<double> bg = bind_points(gc, pts);
    std::vector<Vec3> om, og;
    bm.deform(mvc.deformation_rule(), cage.vertices, om);
    bg.deform(gc.deformation_rule(), cage.vertices, og);
    double em = 0, eg = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      em = std::max(em, norm(sub(om[i], pts[i])));
      if (bg.status()[i] == Coordinate_status::regular) eg = std::max(eg, norm(sub(og[i], pts[i])));
    }
    EXPECT_LT(em, 1e-9 * L) << m.name;
    EXPECT_LT(eg, 1e-9 * L) << m.name;
    EXPECT_GT(bg.count(Coordinate_status::regular), pts.size() * 9 / 10) << m.name;
  }
}

// ================================================================== Green coordinates
TEST(CAGE_SUITE(Cage_Green), rest_pose_and_sum_of_vertex_terms) {
  std::mt19937 rng(21);
  for (const Triangle_cage& cage : {cube_cage(), l_cage()}) {
    Green_coordinates_3 gc(cage);
    const double L = cage.bbox_diagonal();
    const std::size_t n = cage.vertices.size();
    std::vector<Vec3> B = basis_of(gc.deformation_rule(), cage.vertices);
    for (const Vec3& x : random_points(rng, {-1, -1, -1}, {3, 3, 2}, 2000)) {
      Coordinate_status st;
      std::vector<double> w = coordinates(gc, x, &st);
      ASSERT_TRUE(all_finite(w));
      // interior: the integrals alone; exterior: with the exit-face continuation
      EXPECT_LT(norm(sub(combine(w, B), x)), 1e-9 * L);
      EXPECT_NEAR(sum_of(w, n), 1.0, 1e-9);
      const double wind = gc.winding_number(x);
      EXPECT_TRUE(std::abs(wind) < 1e-9 || std::abs(wind - 1) < 1e-9) << wind;
      EXPECT_EQ(st, wind > 0.5 ? Coordinate_status::regular : Coordinate_status::extended);
    }
  }
}

TEST(CAGE_SUITE(Cage_Green), exact_under_similarities_not_under_shear) {
  std::mt19937 rng(23);
  Triangle_cage cage = l_cage();
  Green_coordinates_3 gc(cage);
  const double L = cage.bbox_diagonal();
  std::vector<Vec3> pts = random_points(rng, {-0.7, -0.7, -0.7}, {2.7, 2.7, 1.7}, 400);
  Cage_binding<double> b = bind_points(gc, pts);
  for (double scale : {1.0, 1.5, 0.3}) {
    Affine a = random_similarity(rng, scale);
    std::vector<Vec3> out;
    b.deform(gc.deformation_rule(), transformed(cage.vertices, a), out);
    for (std::size_t i = 0; i < pts.size(); ++i)
      EXPECT_LT(norm(sub(out[i], a(pts[i]))), 1e-9 * L * scale);
  }
  // A non-uniform scale is not reproduced (Green coordinates are quasi-conformal).
  Affine s{{{2, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  std::vector<Vec3> out;
  b.deform(gc.deformation_rule(), transformed(cage.vertices, s), out);
  double emax = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) emax = std::max(emax, norm(sub(out[i], s(pts[i]))));
  EXPECT_GT(emax, 1e-3);
}

TEST(CAGE_SUITE(Cage_Green), stretch_factor) {
  Triangle_cage cage = cube_cage();
  Green_rule rule(cage);
  std::vector<Vec3> B = basis_of(rule, cage.vertices);
  const std::size_t n = cage.vertices.size();
  for (std::size_t j = 0; j < cage.triangles.size(); ++j) EXPECT_NEAR(norm(B[n + j]), 1.0, 1e-15);
  std::vector<Vec3> scaled;
  for (const Vec3& p : cage.vertices) scaled.push_back(mul(2.5, p));
  B = basis_of(rule, scaled);
  for (std::size_t j = 0; j < cage.triangles.size(); ++j) EXPECT_NEAR(norm(B[n + j]), 2.5, 1e-14);
}

TEST(CAGE_SUITE(Cage_Green), boundary_probes_finite_and_reproducing) {
  Triangle_cage cage = l_cage();
  Green_coordinates_3 gc(cage);
  const double L = cage.bbox_diagonal();
  const std::size_t n = cage.vertices.size();
  std::vector<Vec3> B = basis_of(gc.deformation_rule(), cage.vertices);
  std::vector<Vec3> probes = cage.vertices;
  for (const auto& t : cage.triangles) {
    probes.push_back(mul(0.5, add(cage.vertices[t[0]], cage.vertices[t[1]])));
    probes.push_back(mul(1.0 / 3, add(add(cage.vertices[t[0]], cage.vertices[t[1]]), cage.vertices[t[2]])));
  }
  probes.push_back({0.5, 1, 0.5});  // interior point in a face plane
  probes.push_back({2.5, 1, 0.5});  // exterior point in a face plane
  // exterior points on the lines of cage edges (the edge integral's two forms meet there)
  probes.push_back({3, 0, 0});
  probes.push_back({-1, 0, 0});
  probes.push_back({0, 0, -1.5});
  probes.push_back({2, 2, 2});
  for (const Vec3& x : probes) {
    Coordinate_status st;
    std::vector<double> w = coordinates(gc, x, &st);
    ASSERT_TRUE(all_finite(w));
    EXPECT_LT(norm(sub(combine(w, B), x)), 1e-9 * L);
    EXPECT_NEAR(sum_of(w, n), 1.0, 1e-8);
  }
}

TEST(CAGE_SUITE(Cage_Green), exterior_extension_continuous_across_face) {
  std::mt19937 rng(29);
  Triangle_cage cage = l_cage();
  Green_coordinates_3 gc(cage);
  // A deformation that is not a similarity, so continuity is a real property.
  std::vector<Vec3> def = cage.vertices;
  std::uniform_real_distribution<double> U(-0.2, 0.2);
  for (Vec3& p : def)
    for (double& c : p) c += U(rng);
  std::vector<Vec3> B = basis_of(gc.deformation_rule(), def);
  for (std::size_t t = 0; t < cage.triangles.size(); ++t) {
    const auto& tr = cage.triangles[t];
    const Vec3 c = mul(1.0 / 3, add(add(cage.vertices[tr[0]], cage.vertices[tr[1]]), cage.vertices[tr[2]]));
    internal::Cage_geometry geom(cage);
    const Vec3 nrm = geom.normal[t];
    const Vec3 on = combine(coordinates(gc, c), B);
    double prev = 1e300;
    for (double eps : {1e-2, 1e-3, 1e-4, 1e-6}) {
      Coordinate_status si, so;
      const Vec3 in = combine(coordinates(gc, sub(c, mul(eps, nrm)), &si), B);
      const Vec3 out = combine(coordinates(gc, add(c, mul(eps, nrm)), &so), B);
      EXPECT_EQ(si, Coordinate_status::regular);
      EXPECT_EQ(so, Coordinate_status::extended);
      const double jump = norm(sub(in, out));
      EXPECT_LT(jump, 20 * eps) << "face " << t << " eps " << eps;
      EXPECT_LT(norm(sub(on, out)), 20 * eps);
      EXPECT_LE(jump, prev * 1.01 + 1e-12);
      prev = jump;
    }
  }
}

// ================================================================== binding and deformation
TEST(CAGE_SUITE(Cage_binding), dense_sparse_float_agree_and_thread_independent) {
  std::mt19937 rng(31);
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  Green_coordinates_3 gc(cage);
  std::vector<Vec3> pts = random_points(rng, {0.05, 0.05, 0.05}, {1.95, 0.95, 0.95}, 3000);
  pts.push_back(cage.vertices[2]);  // exact zeros in a sparse row
  std::vector<Vec3> def = cage.vertices;
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  for (Vec3& p : def)
    for (double& c : p) c += U(rng);
  const double L = cage.bbox_diagonal();
  auto check = [&](const auto& coords) {
    auto rule = coords.deformation_rule();
    Cage_binding<double> dd = bind_points(coords, pts);
    Cage_binding<float> df = bind_points<float>(coords, pts);
    Binding_options so;
    so.storage = Weight_storage::sparse;
    Cage_binding<double> sd = bind_points(coords, pts, so);
    so.storage = Weight_storage::grouped;
    Cage_binding<double> gd = bind_points(coords, pts, so);
    std::vector<Vec3> a, b, c, d, e;
    dd.deform(rule, def, a);
    df.deform(rule, def, b);
    sd.deform(rule, def, c);
    gd.deform(rule, def, e);
    EXPECT_EQ(df.weights_bytes() * 2, dd.weights_bytes());
    EXPECT_LE(sd.number_of_stored_weights(), dd.number_of_stored_weights());
    // Grouping keeps every stored weight; rows with exact zeros (if the coordinates give any at
    // the cage vertex) make patterns of their own.
    EXPECT_EQ(gd.number_of_stored_weights(), sd.number_of_stored_weights());
    std::set<std::vector<std::uint32_t>> patterns;
    for (std::size_t i = 0; i < pts.size(); ++i)
      patterns.emplace(sd.columns().begin() + std::ptrdiff_t(sd.row_start()[i]),
                       sd.columns().begin() + std::ptrdiff_t(sd.row_start()[i + 1]));
    EXPECT_EQ(gd.number_of_groups(), patterns.size());
    EXPECT_LT(gd.weights_bytes(), sd.weights_bytes());
    for (std::size_t i : {std::size_t(0), std::size_t(17), pts.size() - 1})
      for (std::size_t k = 0; k < gd.number_of_coordinates(); ++k) EXPECT_EQ(gd.weight(i, k), sd.weight(i, k));
    for (std::size_t i = 0; i < pts.size(); ++i) {
      EXPECT_LT(norm(sub(a[i], b[i])), 1e-6 * L);
      EXPECT_LT(norm(sub(a[i], c[i])), 1e-13 * L);
      EXPECT_LT(norm(sub(a[i], e[i])), 1e-13 * L);
      // against a direct evaluation
      std::vector<double> w = coordinates(coords, pts[i]);
      EXPECT_LT(norm(sub(a[i], combine(w, basis_of(rule, def)))), 1e-12 * L);
    }
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      Cage_binding<double> d1 = bind_points(coords, pts);
      d1.deform(rule, def, d);
      EXPECT_EQ(d1.values(), dd.values());
    }
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(a[i], d[i]);
  };
  check(mvc);
  check(gc);
}

// ================================================================== harmonic coordinates
namespace {
Harmonic_options harmonic_options(int R, Harmonic_interpolation interp,
                                  Harmonic_boundary_values bv = Harmonic_boundary_values::mean_value) {
  Harmonic_options o;
  o.resolution = R;
  o.interpolation = interp;
  o.boundary_values = bv;
  return o;
}
}  // namespace

TEST(CAGE_SUITE(Cage_Harmonic), rest_pose_affine_maps_partition_of_unity) {
  std::mt19937 rng(41);
  // A rotated L so that the cage is not aligned with the grid: points near the cage then have
  // stencils that leave the domain (status approximate) and must still reproduce affine maps.
  const Affine rot = random_similarity(rng, 1.0);
  Triangle_cage cage = l_cage();
  cage.vertices = transformed(cage.vertices, rot);
  const double L = cage.bbox_diagonal();
  for (auto interp : {Harmonic_interpolation::trilinear, Harmonic_interpolation::tricubic}) {
    Harmonic_coordinates_3 hc(cage, harmonic_options(24, interp));
    EXPECT_LT(hc.solver_residual(), 1e-11);
    std::vector<Vec3> pts;
    for (const Vec3& p : random_points(rng, {0, 0, 0}, {2, 2, 1}, 3000))
      if (!(p[0] > 1 && p[1] > 1)) pts.push_back(rot(p));
    Cage_binding<double> b = bind_points(hc, pts);
    EXPECT_GT(b.count(Coordinate_status::approximate), 10u);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      ASSERT_NE(b.status()[i], Coordinate_status::undefined);
      double s = 0;
      for (std::size_t k = 0; k < b.number_of_coordinates(); ++k) s += b.weight(i, k);
      EXPECT_NEAR(s, 1.0, 1e-9);
    }
    for (int trial = 0; trial < 3; ++trial) {
      Affine a = trial == 0 ? Affine{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}} : random_affine(rng);
      std::vector<Vec3> out;
      b.deform(hc.deformation_rule(), transformed(cage.vertices, a), out);
      double emax = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) emax = std::max(emax, norm(sub(out[i], a(pts[i]))));
      EXPECT_LT(emax, 1e-9 * L) << "trial " << trial;
    }
  }
}

TEST(CAGE_SUITE(Cage_Harmonic), non_negative_and_interpolating_with_closest_point_values) {
  std::mt19937 rng(43);
  Triangle_cage cage = l_cage();
  Harmonic_coordinates_3 hc(cage, harmonic_options(32, Harmonic_interpolation::trilinear,
                                                   Harmonic_boundary_values::closest_point));
  const double h = hc.spacing();
  double worst_repro = 0;
  for (const Vec3& x : random_points(rng, {0, 0, 0}, {2, 2, 1}, 2000)) {
    if (x[0] > 1 && x[1] > 1) continue;
    Coordinate_status st;
    std::vector<double> w = coordinates(hc, x, &st);
    ASSERT_NE(st, Coordinate_status::undefined);
    for (double v : w) {
      EXPECT_GE(v, -1e-12);
      EXPECT_LE(v, 1 + 1e-12);
    }
    EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-9);
    worst_repro = std::max(worst_repro, norm(sub(combine(w, cage.vertices), x)));
  }
  // linear precision only up to the discretisation: O(h)
  EXPECT_LT(worst_repro, h);
  // close to a cage vertex the coordinate of that vertex dominates
  std::vector<double> w = coordinates(hc, Vec3{0.02, 0.02, 0.02});
  EXPECT_GT(w[0], 0.8);
}

TEST(CAGE_SUITE(Cage_Harmonic), outside_points_flagged) {
  Triangle_cage cage = l_cage();
  Harmonic_coordinates_3 hc(cage, harmonic_options(16, Harmonic_interpolation::tricubic));
  Coordinate_status st;
  for (Vec3 x : {Vec3{1.5, 1.5, 0.5}, Vec3{-0.3, 0.5, 0.5}, Vec3{5, 5, 5}, Vec3{0.5, 0.5, 1.01}}) {
    std::vector<double> w = coordinates(hc, x, &st);
    EXPECT_EQ(st, Coordinate_status::undefined);
    for (double v : w) EXPECT_EQ(v, 0.0);
  }
  // just inside a face: the tricubic stencil reaches exterior nodes
  std::vector<double> w = coordinates(hc, Vec3{0.5, 0.5, 0.99}, &st);
  EXPECT_EQ(st, Coordinate_status::approximate);
  EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-9);
  w = coordinates(hc, Vec3{0.5, 0.5, 0.5}, &st);
  EXPECT_EQ(st, Coordinate_status::regular);
  // on the cage: the hat functions exactly (vertices, edge midpoints)
  for (std::size_t i = 0; i < cage.vertices.size(); ++i) {
    w = coordinates(hc, cage.vertices[i], &st);
    EXPECT_EQ(st, Coordinate_status::on_boundary);
    for (std::size_t k = 0; k < w.size(); ++k) EXPECT_EQ(w[k], k == i ? 1.0 : 0.0);
  }
  const auto& t = cage.triangles[5];
  w = coordinates(hc, mul(0.5, add(cage.vertices[t[0]], cage.vertices[t[2]])), &st);
  EXPECT_EQ(st, Coordinate_status::on_boundary);
  EXPECT_NEAR(w[t[0]], 0.5, 1e-14);
  EXPECT_NEAR(w[t[2]], 0.5, 1e-14);
}

TEST(CAGE_SUITE(Cage_Harmonic), tricubic_lookup_is_C1) {
  // Gradient (central differences) on both sides of a grid plane: continuous for the cubic
  // B-spline lookup, jumping for the trilinear one.
  Triangle_cage cage = cube_cage();
  Harmonic_coordinates_3 cub(cage, harmonic_options(16, Harmonic_interpolation::tricubic));
  Harmonic_coordinates_3 lin(cage, harmonic_options(16, Harmonic_interpolation::trilinear));
  const double h = cub.spacing();
  // find a grid plane x = origin + i h near the middle: origin = -3 h
  const double plane = -3 * h + 11 * h;
  const double d = 1e-4 * h;
  auto grad_x = [&](const Harmonic_coordinates_3& hc, double x0, std::size_t k) {
    std::vector<double> a = coordinates(hc, Vec3{x0 + d, 0.43, 0.37});
    std::vector<double> b = coordinates(hc, Vec3{x0 - d, 0.43, 0.37});
    return (a[k] - b[k]) / (2 * d);
  };
  double jump_cub = 0, jump_lin = 0;
  for (std::size_t k = 0; k < 8; ++k) {
    jump_cub = std::max(jump_cub, std::abs(grad_x(cub, plane + 3 * d, k) - grad_x(cub, plane - 3 * d, k)));
    jump_lin = std::max(jump_lin, std::abs(grad_x(lin, plane + 3 * d, k) - grad_x(lin, plane - 3 * d, k)));
  }
  EXPECT_LT(jump_cub, 1e-3);
  EXPECT_GT(jump_lin, 10 * jump_cub);
}

// ================================================================== cmgeom deform
namespace {
// One directory per test and per executable, so that `ctest -j` may run them concurrently.
std::string cli_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string d = std::string(CMGEOM_TEST_TMP_DIR) + "/" + info->test_suite_name() + "_" +
                        info->name();
  std::filesystem::create_directories(d + "/cages");
  return d;
}
void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }
std::string cube_obj(const Affine& a) {
  std::ostringstream s;
  s.precision(17);
  const Vec3 c[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const Vec3& p : c) {
    const Vec3 q = a(p);
    s << "v " << q[0] << " " << q[1] << " " << q[2] << "\n";
  }
  s << "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  return s.str();
}
int run(const std::string& cmd, std::string* out = nullptr, std::string* err = nullptr) {
  const std::string d = cli_dir();
  const int rc = std::system((cmd + " > " + d + "/stdout.txt 2> " + d + "/stderr.txt").c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  if (out) *out = slurp(d + "/stdout.txt");
  if (err) *err = slurp(d + "/stderr.txt");
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST(CAGE_SUITE(Cage_cli), deform_keeps_vertex_order_and_reproduces_maps) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built";
  const std::string d = cli_dir();
  std::mt19937 rng(51);
  const Affine id{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  // a mesh inside the cube: an octahedron around (0.4, 0.5, 0.55), vertex order scrambled
  std::vector<Vec3> mv = {{0.4, 0.5, 0.85}, {0.1, 0.5, 0.55}, {0.4, 0.2, 0.55},
                          {0.7, 0.5, 0.55}, {0.4, 0.8, 0.55}, {0.4, 0.5, 0.25}};
  {
    std::ostringstream s;
    s.precision(17);
    for (const Vec3& p : mv) s << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    s << "f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 6 3 2\nf 6 4 3\nf 6 5 4\nf 6 2 5\n";
    write_text(d + "/mesh.obj", s.str());
  }
  write_text(d + "/cages/rest.obj", cube_obj(id));
  struct Case {
    std::string coords;
    Affine map;
    std::string extra;
  };
  std::vector<Case> cases = {{"mean_value", random_affine(rng), ""},
                             {"harmonic", random_affine(rng), ", \"harmonic\": {\"resolution\": 16}"},
                             {"green", random_similarity(rng, 1.3), ""}};
  for (const Case& c : cases) {
    write_text(d + "/cages/deformed.obj", cube_obj(c.map));
    write_text(d + "/system.json", "{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": "
                                   "\"cages/deformed.obj\", \"coordinates\": \"" +
                                       c.coords + "\"" + c.extra + "}]}");
    const std::string out = d + "/out_" + c.coords + ".obj";
    std::string so, se;
    ASSERT_EQ(run(std::string(CMGEOM_CMGEOM_EXE) + " deform " + d + "/mesh.obj --cages " + d +
                      "/system.json -o " + out + " --json",
                  &so, &se),
              0)
        << se;
    for (const char* key : {"\"bind_seconds\"", "\"deform_seconds\"", "\"weights_bytes\""})
      EXPECT_NE(so.find(key), std::string::npos) << key;
    std::vector<Vec3> pts;
    std::vector<std::vector<std::size_t>> polys;
    ASSERT_TRUE(read_soup(out, pts, polys));
    ASSERT_EQ(pts.size(), mv.size());
    for (std::size_t i = 0; i < mv.size(); ++i)
      EXPECT_LT(norm(sub(pts[i], c.map(mv[i]))), 1e-9) << c.coords << " vertex " << i;
  }
  // A deformed cage whose file lists other faces (here: triangles, in another order) is accepted:
  // only its vertex positions are used, with the rest cage's triangles.
  const Affine a = random_affine(rng);
  std::string obj = cube_obj(a);
  obj = obj.substr(0, obj.find("f "));
  obj += "f 2 3 7\nf 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 7 6\nf 3 4 8\n"
         "f 3 8 7\nf 4 1 5\nf 4 5 8\n";
  write_text(d + "/cages/deformed.obj", obj);
  write_text(d + "/system.json", "{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": "
                                 "\"cages/deformed.obj\"}]}");
  std::string se;
  ASSERT_EQ(run(std::string(CMGEOM_CMGEOM_EXE) + " deform " + d + "/mesh.obj --cages " + d +
                    "/system.json -o " + d + "/out_faces.obj",
                nullptr, &se),
            0)
      << se;
  EXPECT_NE(se.find("faces differ"), std::string::npos) << se;
  std::vector<Vec3> pts;
  std::vector<std::vector<std::size_t>> polys;
  ASSERT_TRUE(read_soup(d + "/out_faces.obj", pts, polys));
  ASSERT_EQ(pts.size(), mv.size());
  for (std::size_t i = 0; i < mv.size(); ++i) EXPECT_LT(norm(sub(pts[i], a(mv[i]))), 1e-9);
}

TEST(CAGE_SUITE(Cage_cli), errors_are_one_line_and_leave_no_output) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built";
  const std::string d = cli_dir();
  const Affine id{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};
  write_text(d + "/cages/rest.obj", cube_obj(id));
  write_text(d + "/cages/other.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n");
  write_text(d + "/outside.obj", "v 0.5 0.5 0.5\nv 2 0.5 0.5\nv 0.5 0.6 0.5\nf 1 2 3\n");
  if (!std::filesystem::exists(d + "/mesh.obj"))
    write_text(d + "/mesh.obj", "v 0.5 0.5 0.5\nv 0.6 0.5 0.5\nv 0.5 0.6 0.5\nf 1 2 3\n");
  struct Bad {
    std::string json, mesh, expect;
  };
  const std::vector<Bad> bad = {
      {"{\"cages\": [", "mesh.obj", "invalid JSON"},
      {"{\"cages\": [{\"deformed\": \"cages/rest.obj\"}]}", "mesh.obj", "/cages/0/rest: missing"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/missing.obj\"}]}", "mesh.obj", "missing.obj"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/other.obj\"}]}", "mesh.obj", "same vertices"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/rest.obj\", \"coordinates\": \"bogus\"}]}", "mesh.obj", "unknown coordinates"},
      {"{\"cages\": [{\"rest\": \"cages/rest.obj\", \"deformed\": \"cages/rest.obj\", \"coordinates\": \"harmonic\", \"harmonic\": {\"resolution\": 16}}]}", "outside.obj", "outside the cage"}};
  for (const Bad& b : bad) {
    write_text(d + "/bad.json", b.json);
    const std::string out = d + "/bad_out.obj";
    std::filesystem::remove(out);
    std::string se;
    EXPECT_EQ(run(std::string(CMGEOM_CMGEOM_EXE) + " deform " + d + "/" + b.mesh + " --cages " + d +
                      "/bad.json -o " + out,
                  nullptr, &se),
              1)
        << b.json;
    EXPECT_NE(se.find(b.expect), std::string::npos) << se;
    EXPECT_EQ(std::count(se.begin(), se.end(), '\n'), 1) << se;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}
