// Helpers of the Cage_deformation tests built twice (the AVX2 and the scalar kernels): test cages
// made of unit voxels, coordinate evaluation, random affine maps and similarities, and the shared
// cages and models. Included by test_cage_validation.cpp, test_mean_value_coordinates.cpp,
// test_green_coordinates.cpp, test_cage_binding.cpp, test_harmonic_coordinates.cpp and
// test_cage_deform_cli.cpp.
#ifndef CMGEOM_TEST_CAGE_COORDINATES_UTIL_H
#define CMGEOM_TEST_CAGE_COORDINATES_UTIL_H

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
inline Triangle_cage voxel_cage(const std::vector<std::array<int, 3>>& cells, double scale = 1.0,
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

inline Triangle_cage cube_cage(double scale = 1.0, Vec3 offset = {0, 0, 0}) {
  return voxel_cage({{0, 0, 0}}, scale, offset);
}
// L-shaped prism: three unit cubes.
inline Triangle_cage l_cage(double scale = 1.0, Vec3 offset = {0, 0, 0}) {
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

inline Vec3 combine(const std::vector<double>& w, const std::vector<Vec3>& basis) {
  Vec3 r{0, 0, 0};
  for (std::size_t k = 0; k < w.size(); ++k) r = add(r, mul(w[k], basis[k]));
  return r;
}

inline double sum_of(const std::vector<double>& w, std::size_t n) {
  double s = 0;
  for (std::size_t i = 0; i < n; ++i) s += w[i];
  return s;
}

inline bool all_finite(const std::vector<double>& w) {
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

inline Affine random_affine(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-0.5, 0.5);
  Affine a;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a.A[i][j] = (i == j ? 1.0 : 0.0) + U(rng);
    a.t[i] = 3 * U(rng);
  }
  return a;
}

// Rotation about a random axis by a random angle, times scale, plus translation.
inline Affine random_similarity(std::mt19937& rng, double scale) {
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

inline std::vector<Vec3> transformed(const std::vector<Vec3>& v, const Affine& a) {
  std::vector<Vec3> r;
  for (const Vec3& p : v) r.push_back(a(p));
  return r;
}

inline std::vector<Vec3> random_points(std::mt19937& rng, Vec3 lo, Vec3 hi, int count) {
  std::vector<Vec3> r;
  for (int i = 0; i < count; ++i) {
    Vec3 p;
    for (int c = 0; c < 3; ++c) p[c] = std::uniform_real_distribution<double>(lo[c], hi[c])(rng);
    r.push_back(p);
  }
  return r;
}

// ------------------------------------------------------------------ shared data
// Points and polygons of a mesh or cage file, with the project's reader.
inline bool read_soup(const std::string& path, std::vector<Vec3>& pts, std::vector<std::vector<std::size_t>>& polys) {
  try {
    read_polygons(path, pts, polys);
  } catch (const CMGeom::Error& e) {
    ADD_FAILURE() << e.what();
    return false;
  }
  return !pts.empty();
}

}  // namespace

#endif  // CMGEOM_TEST_CAGE_COORDINATES_UTIL_H
