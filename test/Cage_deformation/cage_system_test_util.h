// Helpers of the *Cages system tests (thesis §5.3): a smooth non-affine map of space, random
// points, one-sided Jacobians probed on every border face, scratch files and a one-cube cage.
// Included by the test_cage_system_*.cpp files.
#ifndef CMGEOM_TEST_CAGE_SYSTEM_UTIL_H
#define CMGEOM_TEST_CAGE_SYSTEM_UTIL_H

#include <CMGeom/Cage_deformation.h>

#include "cmgeom_test_config.h"
#include "cage_coordinates_test_util.h"  // random_points, the namespace and vector helpers in scope

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace {

using Mat3 = std::array<Vec3, 3>;  // columns

// A smooth, clearly non-affine map of space, applied to the cage vertices.
inline Vec3 bend(const Vec3& p) {
  return {p[0] + 0.15 * std::sin(1.3 * p[1] + 0.4) + 0.1 * p[2] * p[2],
          p[1] + 0.2 * std::cos(1.1 * p[0]) + 0.05 * p[0] * p[2], p[2] + 0.12 * std::sin(0.9 * p[0] + 1.7 * p[1])};
}

inline void deform_all(Cage_system_description& d, Vec3 (*map)(const Vec3&)) {
  for (auto& c : d.cages)
    for (std::size_t k = 0; k < c.deformed.size(); ++k) c.deformed[k] = map(c.rest.vertices[k]);
}

inline double max_abs(const Mat3& a) {
  double m = 0;
  for (const Vec3& c : a)
    for (double x : c) m = std::max(m, std::abs(x));
  return m;
}

// Jacobian of S_cage at q (a point of a face with outward unit normal n of `cage`), from that
// cage's side only: tangential central differences on the face, a one-sided second-order
// difference along -n. Returned in the frame (t1, t2, n).
template <class Fh>
Mat3 one_sided_jacobian(const Cage_system& s, std::size_t cage, const std::vector<Vec3>& B, const Vec3& q,
                        const Vec3& n, const Vec3& t1, const Vec3& t2, double delta, const Fh& fh) {
  auto S = [&](const Vec3& p) { return s.evaluate(p, cage, B, Sine_smoothing(), fh); };
  Mat3 J;
  J[0] = mul(1 / (2 * delta), sub(S(add(q, mul(delta, t1))), S(add(q, mul(-delta, t1)))));
  J[1] = mul(1 / (2 * delta), sub(S(add(q, mul(delta, t2))), S(add(q, mul(-delta, t2)))));
  const Vec3 s0 = S(q), s1 = S(add(q, mul(-delta, n))), s2 = S(add(q, mul(-2 * delta, n)));
  // f'(0) along +n from samples at 0, -δ, -2δ: (3 f(0) - 4 f(-δ) + f(-2δ)) / (2δ)
  J[2] = mul(1 / (2 * delta), add(sub(mul(3, s0), mul(4, s1)), s2));
  return J;
}

struct Border_result {
  double max_rel_jump = 0, max_value_gap = 0;
  int probes = 0;
};

// Probes every border face of every leaf cage: the Jacobians of S from both sides.
template <class Fh>
Border_result probe_borders(const Cage_system& s, const std::vector<Vec3>& B, const Fh& fh, std::mt19937& rng) {
  Border_result r;
  const double L = s.union_cage().bbox_diagonal();
  const double delta = 1e-5 * L;
  for (std::size_t i : s.leaf_cages()) {
    const Triangle_cage& ci = s.description().cages[i].rest;
    const auto& gi = s.global_vertices(i);
    for (std::size_t j : s.neighbours(i)) {
      if (j < i) continue;
      const auto& gj = s.global_vertices(j);
      for (const auto& t : ci.triangles) {
        bool shared = true;
        for (int k = 0; k < 3; ++k) shared = shared && std::find(gj.begin(), gj.end(), gi[t[k]]) != gj.end();
        if (!shared) continue;
        const Vec3 a = ci.vertices[t[0]], b = ci.vertices[t[1]], c = ci.vertices[t[2]];
        Vec3 n = cross(sub(b, a), sub(c, a));
        n = mul(1 / norm(n), n);
        Vec3 t1 = mul(1 / norm(sub(b, a)), sub(b, a));
        Vec3 t2 = cross(n, t1);
        for (int probe = 0; probe < 2; ++probe) {
          std::uniform_real_distribution<double> U(0.2, 0.8);
          double u = U(rng), v = U(rng);
          if (u + v > 0.9) {
            u *= 0.5;
            v *= 0.5;
          }
          const Vec3 q = add(a, add(mul(u, sub(b, a)), mul(v, sub(c, a))));
          const Mat3 Ji = one_sided_jacobian(s, i, B, q, n, t1, t2, delta, fh);
          const Mat3 Jj = one_sided_jacobian(s, j, B, q, mul(-1, n), t1, t2, delta, fh);
          Mat3 D;
          // Jj's third column is along -n: flip it back to +n.
          for (int col = 0; col < 2; ++col) D[col] = sub(Ji[col], Jj[col]);
          D[2] = add(Ji[2], Jj[2]);
          r.max_rel_jump = std::max(r.max_rel_jump, max_abs(D) / max_abs(Ji));
          r.max_value_gap = std::max(
              r.max_value_gap,
              norm(sub(s.evaluate(q, i, B, Sine_smoothing(), fh), s.evaluate(q, j, B, Sine_smoothing(), fh))) / L);
          ++r.probes;
        }
      }
    }
  }
  return r;
}

inline std::string tmp(const std::string& name) { return std::string(CMGEOM_TEST_TMP_DIR) + "/cage_system_" + name; }

}  // namespace

#endif  // CMGEOM_TEST_CAGE_SYSTEM_UTIL_H
