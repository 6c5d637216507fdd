// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Local deformations of a Compact Model's base (thesis §6.3): Local_deformation_solver,
// local_deformations(), Local_deformation_options. For every base vertex v with deformed position
// v', the affine map T_v(x) = M (x - v) + v' that best maps the 1-ring neighbours to their deformed
// positions in the least-squares sense. Key choices: M = V U^-1 (the thesis prints U^-1 V, which is
// not the minimiser); a regulariser for flat rings, which maps the rest normal to the deformed
// normal scaled by the ring's stretch and vanishes where the ring leaves its tangent plane, so
// every affine deformation is reproduced there and similarities everywhere; an unchanged
// neighbourhood gets the exact identity. The rest part is computed once; a pose costs O(E), in
// parallel and deterministic.
//
// Manual: doc/Deformable_compact_model/README.md, "Choices where the thesis is open (and why)".
#ifndef CMGEOM_DEFORMABLE_COMPACT_MODEL_LOCAL_DEFORMATIONS_H
#define CMGEOM_DEFORMABLE_COMPACT_MODEL_LOCAL_DEFORMATIONS_H

#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Error.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace DCM {

using CM::Vec3;
using CM::Vertex_affine_map;

struct Local_deformation_options {
  /// Rings with n^T U n below flatness * trace(U) are regularised (see the file comment).
  double flatness = 0.01;
  bool parallel = true;  ///< TBB over base vertices (results do not depend on it)
};

/// Rest-state data of the local deformations of one Compact Model's base: 1-rings, the
/// oriented incident faces, and the regularised inverse U*^-1 of every vertex.
class Local_deformation_solver {
public:
  explicit Local_deformation_solver(const CM::Compact_model& m,
                                    const Local_deformation_options& opt = Local_deformation_options())
      : rest_(m.vertices), opt_(opt) {
    if (!(opt.flatness >= 0. && opt.flatness <= 1.))
      throw Invalid_input("local deformations: flatness must be in [0, 1], got " + std::to_string(opt.flatness));
    const std::size_t V = rest_.size();
    // Neighbours and oriented (next, previous) corners of every vertex, as CSR arrays.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> nb;  // (vertex, neighbour)
    std::vector<std::array<std::uint32_t, 3>> fans;           // (vertex, next, previous)
    nb.reserve(6 * m.faces.size());
    fans.reserve(3 * m.faces.size());
    for (const auto& f : m.faces)
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = f[c].vertex, a = f[(c + 1) % 3].vertex, b = f[(c + 2) % 3].vertex;
        if (v >= V || a >= V || b >= V) throw Invalid_input("local deformations: face vertex index out of range");
        nb.emplace_back(v, a);
        nb.emplace_back(v, b);
        fans.push_back({v, a, b});
      }
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    std::sort(fans.begin(), fans.end());
    ring_start_.assign(V + 1, 0);
    for (const auto& p : nb) ++ring_start_[p.first + 1];
    for (std::size_t i = 0; i < V; ++i) ring_start_[i + 1] += ring_start_[i];
    ring_.reserve(nb.size());
    for (const auto& p : nb) ring_.push_back(p.second);
    fan_start_.assign(V + 1, 0);
    for (const auto& f : fans) ++fan_start_[f[0] + 1];
    for (std::size_t i = 0; i < V; ++i) fan_start_[i + 1] += fan_start_[i];
    fan_.reserve(2 * fans.size());
    for (const auto& f : fans) {
      fan_.push_back(f[1]);
      fan_.push_back(f[2]);
    }
    rest_normal_.resize(V);
    mu_.assign(V, 0.);
    inverse_.resize(V);
    degenerate_.assign(V, 0);
    for_vertices([&](std::size_t v) { prepare(v); });
  }

  std::size_t number_of_vertices() const { return rest_.size(); }
  const std::vector<Vec3>& rest_positions() const { return rest_; }
  /// Neighbours of base vertex v (ascending).
  std::pair<const std::uint32_t*, const std::uint32_t*> ring(std::size_t v) const {
    return {ring_.data() + ring_start_[v], ring_.data() + ring_start_[v + 1]};
  }
  /// Regularisation weight mu of vertex v (0: the thesis' plain least-squares map).
  double regularisation(std::size_t v) const { return mu_[v]; }
  /// Whether vertex v's ring is degenerate even with the regulariser (its map is a translation).
  bool is_degenerate(std::size_t v) const { return degenerate_[v] != 0; }
  std::size_t number_of_regularised_vertices() const {
    return std::size_t(std::count_if(mu_.begin(), mu_.end(), [](double x) { return x > 0.; }));
  }
  std::size_t number_of_degenerate_vertices() const {
    return std::size_t(std::count(degenerate_.begin(), degenerate_.end(), 1));
  }
  /// Memory held by the precomputation, in bytes.
  std::size_t bytes() const {
    return rest_.size() * sizeof(Vec3) * 2 + (ring_.size() + fan_.size()) * sizeof(std::uint32_t) +
           (ring_start_.size() + fan_start_.size()) * sizeof(std::size_t) + mu_.size() * sizeof(double) +
           inverse_.size() * sizeof(Mat3) + degenerate_.size();
  }

  /// The maps T_v of every base vertex for one pose (`deformed`: one position per base vertex).
  void compute(const std::vector<Vec3>& deformed, std::vector<Vertex_affine_map>& maps) const {
    const std::size_t V = rest_.size();
    if (deformed.size() != V)
      throw Invalid_input("local deformations: " + std::to_string(deformed.size()) + " deformed positions for " +
                          std::to_string(V) + " base vertices");
    for (std::size_t i = 0; i < V; ++i)
      if (!std::isfinite(deformed[i].x + deformed[i].y + deformed[i].z))
        throw Invalid_input("local deformations: deformed position " + std::to_string(i) + " is not finite");
    maps.resize(V);
    for_vertices([&](std::size_t v) { maps[v] = map_of(v, deformed); });
  }
  std::vector<Vertex_affine_map> compute(const std::vector<Vec3>& deformed) const {
    std::vector<Vertex_affine_map> maps;
    compute(deformed, maps);
    return maps;
  }

private:
  using Mat3 = std::array<std::array<double, 3>, 3>;

  template <class Body>
  void for_vertices(const Body& body) const {
    CM::internal::for_range(rest_.size(), opt_.parallel, body);
  }

  // Area-weighted unit normal of the faces around v (zero vector if they have no area).
  Vec3 fan_normal(std::size_t v, const std::vector<Vec3>& P) const {
    Vec3 n(0, 0, 0);
    for (std::size_t k = fan_start_[v]; k < fan_start_[v + 1]; ++k)
      n += CM::internal::cross(P[fan_[2 * k]] - P[v], P[fan_[2 * k + 1]] - P[v]);
    const double l = CM::internal::length(n);
    return l > 0. ? (1. / l) * n : Vec3(0, 0, 0);
  }

  void prepare(std::size_t v) {
    Mat3 U{};
    for (std::size_t k = ring_start_[v]; k < ring_start_[v + 1]; ++k) {
      const Vec3 a = rest_[ring_[k]] - rest_[v];
      const double ac[3] = {a.x, a.y, a.z};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) U[i][j] += ac[i] * ac[j];
    }
    const Vec3 n = fan_normal(v, rest_);
    rest_normal_[v] = n;
    const double nc[3] = {n.x, n.y, n.z};
    double nUn = 0.;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) nUn += nc[i] * U[i][j] * nc[j];
    const double tr = U[0][0] + U[1][1] + U[2][2];
    mu_[v] = std::max(0., opt_.flatness * tr - nUn);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) U[i][j] += mu_[v] * nc[i] * nc[j];
    // Inverse by the adjugate; "degenerate" when det is negligible against (trace/3)^3.
    Mat3 A{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
        A[i][j] = U[i1][j1] * U[i2][j2] - U[i1][j2] * U[i2][j1];  // cofactor (j, i) = adjugate (i, j)
      }
    const double det = U[0][0] * A[0][0] + U[0][1] * A[1][0] + U[0][2] * A[2][0];
    const double t3 = (tr / 3.) * (tr / 3.) * (tr / 3.);
    if (!(tr > 0.) || !(std::abs(det) > 1e-12 * t3) || !std::isfinite(det)) {
      degenerate_[v] = 1;
      return;
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) inverse_[v][i][j] = A[i][j] / det;
  }

  Vertex_affine_map map_of(std::size_t v, const std::vector<Vec3>& P) const {
    Vertex_affine_map T;
    T.rest = rest_[v];
    T.deformed = P[v];
    bool same = P[v] == rest_[v];
    for (std::size_t k = ring_start_[v]; same && k < ring_start_[v + 1]; ++k) same = P[ring_[k]] == rest_[ring_[k]];
    T.identity = same;
    if (same || degenerate_[v]) return T;  // M = I (exact identity, or translation)
    Mat3 W{};                              // V* = sum b a^T + mu s n' n^T
    double aa = 0., bb = 0.;
    for (std::size_t k = ring_start_[v]; k < ring_start_[v + 1]; ++k) {
      const Vec3 a = rest_[ring_[k]] - rest_[v], b = P[ring_[k]] - P[v];
      const double ac[3] = {a.x, a.y, a.z}, bc[3] = {b.x, b.y, b.z};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) W[i][j] += bc[i] * ac[j];
      aa += CM::internal::squared_length(a);
      bb += CM::internal::squared_length(b);
    }
    if (mu_[v] > 0.) {
      const Vec3 nd = std::sqrt(bb / aa) * fan_normal(v, P);
      const Vec3& n = rest_normal_[v];
      const double dc[3] = {nd.x, nd.y, nd.z}, nc[3] = {n.x, n.y, n.z};
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) W[i][j] += mu_[v] * dc[i] * nc[j];
    }
    const Mat3& Ui = inverse_[v];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) T.M[i][j] = W[i][0] * Ui[0][j] + W[i][1] * Ui[1][j] + W[i][2] * Ui[2][j];
    return T;
  }

  std::vector<Vec3> rest_;
  Local_deformation_options opt_;
  std::vector<std::size_t> ring_start_, fan_start_;
  std::vector<std::uint32_t> ring_, fan_;  // fan_: (next, previous) pairs, oriented like the faces
  std::vector<Vec3> rest_normal_;
  std::vector<double> mu_;
  std::vector<Mat3> inverse_;
  std::vector<std::uint8_t> degenerate_;
};

/// One-shot form: the maps T_v of `m`'s base for the deformed base positions `deformed` (§6.3).
inline std::vector<Vertex_affine_map> local_deformations(
    const CM::Compact_model& m, const std::vector<Vec3>& deformed,
    const Local_deformation_options& opt = Local_deformation_options()) {
  return Local_deformation_solver(m, opt).compute(deformed);
}

}  // namespace DCM
}  // namespace CMGeom

#endif  // CMGEOM_DEFORMABLE_COMPACT_MODEL_LOCAL_DEFORMATIONS_H
