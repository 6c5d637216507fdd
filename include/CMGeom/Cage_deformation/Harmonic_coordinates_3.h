// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Harmonic_coordinates_3 and Harmonic_options: harmonic coordinates of Joshi, Meyer, DeRose, Green
// and Sanocki (2007) on a regular grid, a model of CageCoordinates (Cage_coordinates.h). Thesis
// §5.3.1 lists HC with MVC as coordinates usable per cage, and §5.3.2 needs C1 coordinates for
// the join, hence the tricubic lookup. Each coordinate solves Laplace(h_i) = 0 on the grid
// (7-point Laplacian, conjugate gradients coarse to fine, one coordinate per TBB task). Key
// choice: the boundary nodes take the mean value coordinates of their position (default), so the
// discrete solution reproduces every affine map of the cage exactly; `closest_point` keeps the
// discrete maximum principle instead. Lookup: trilinear or tricubic B-spline. Points on the cage
// get status on_boundary, outside it undefined (zeros), near it approximate: never silently wrong.
// Outside the cage, harmonic coordinates do not exist (the Laplace problem lives inside); with
// `outside = mean_value` a point there takes the cage's mean value coordinates instead (status
// extended), a choice of ours the thesis leaves open (§5.3.1 pairs HC with MVC per cage; §5.3.4
// handles coordinates undefined outside by its λ rule): on the cage both are the hat functions
// (and with the default boundary values the grid's boundary nodes hold MVC), so the map stays
// continuous across the cage, and MVC reproduce every affine map there too.
//
// Manual: doc/Cage_deformation/README.md, "Methods and the choices made".
#ifndef CMGEOM_CAGE_DEFORMATION_HARMONIC_COORDINATES_3_H
#define CMGEOM_CAGE_DEFORMATION_HARMONIC_COORDINATES_3_H

#include <CMGeom/Cage_deformation/Cage_coordinates.h>
#include <CMGeom/Cage_deformation/Mean_value_coordinates_3.h>
#include <CMGeom/Cage_deformation/internal/Cage_geometry.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

enum class Harmonic_interpolation { trilinear, tricubic };
enum class Harmonic_boundary_values { mean_value, closest_point };
/// What a point outside the cage gets: status undefined and zero weights (default), or the cage's
/// mean value coordinates with status extended (see the file comment).
enum class Harmonic_outside { undefined, mean_value };

struct Harmonic_options {
  int resolution = 64;  ///< cells along the longest side of the cage's bounding box
  Harmonic_interpolation interpolation = Harmonic_interpolation::tricubic;
  Harmonic_boundary_values boundary_values = Harmonic_boundary_values::mean_value;
  double solver_tolerance = 1e-12;                         ///< relative residual of every CG solve
  int max_iterations = 5000;                               ///< per level and coordinate
  Harmonic_outside outside = Harmonic_outside::undefined;  ///< points outside the cage
};

class Harmonic_coordinates_3 {
public:
  using Deformation_rule = Vertex_deformation_rule;

  explicit Harmonic_coordinates_3(const Triangle_cage& cage, const Harmonic_options& options = Harmonic_options())
      : cage_(std::make_shared<Triangle_cage>(cage)),
        g_(std::make_shared<internal::Cage_geometry>(cage)),
        opt_(options),
        mvc_(cage) {
    CGAL_precondition(options.resolution >= 4);
    solve();
  }

  std::size_t number_of_coordinates() const { return g_->n; }
  const Triangle_cage& cage() const { return *cage_; }
  Deformation_rule deformation_rule() const { return Deformation_rule(g_->n); }
  const Harmonic_options& options() const { return opt_; }
  /// Grid spacing of the finest level.
  double spacing() const { return grid_->h; }
  /// Nodes per axis of the finest level.
  std::array<int, 3> grid_size() const { return {grid_->nx, grid_->ny, grid_->nz}; }
  std::size_t number_of_interior_nodes() const { return grid_->unknowns; }
  /// CG iterations summed over coordinates and levels (for reports).
  std::size_t solver_iterations() const { return iterations_; }
  /// Largest relative residual left by the finest-level solves.
  double solver_residual() const { return residual_; }
  /// Bytes of the stored grid values.
  std::size_t grid_bytes() const { return field_.size() * sizeof(double); }

  template <class Point, class OutputIterator>
  Coordinate_status operator()(const Point& query, OutputIterator out) const {
    const Vec3 x = internal::to_vec3(query);
    const std::size_t K = g_->n;
    Scratch& s = scratch();
    s.acc.assign(K, 0.0);
    // On the cage the coordinates are the boundary data: the hat functions, which mean value
    // coordinates return exactly there.
    const double tol = 1e-8 * g_->L;
    for (std::size_t t = 0; t < g_->m; ++t)
      if (std::abs(g_->signed_distance(t, x)) <= tol && g_->distance_to_triangle(t, x) <= tol) return mvc_(x, out);
    if (g_->winding_number(x) < 0.5) {
      if (opt_.outside == Harmonic_outside::mean_value) {
        mvc_(x, out);
        return Coordinate_status::extended;
      }
      for (std::size_t i = 0; i < K; ++i) *out++ = 0.0;
      return Coordinate_status::undefined;
    }
    Coordinate_status st = Coordinate_status::regular;
    bool done = false;
    if (opt_.interpolation == Harmonic_interpolation::tricubic) {
      const int c = cubic(x, s.acc);
      done = c >= 0;
      if (c == 1) st = Coordinate_status::approximate;
    }
    if (!done) {
      if (opt_.interpolation == Harmonic_interpolation::tricubic) st = Coordinate_status::approximate;
      if (!linear(x, s.acc, st)) {
        for (std::size_t i = 0; i < K; ++i) *out++ = 0.0;
        return Coordinate_status::undefined;
      }
    }
    for (std::size_t i = 0; i < K; ++i) *out++ = s.acc[i];
    return st;
  }

private:
  enum : std::int8_t { exterior = 0, boundary = 1, interior = 2 };

  struct Grid {
    Vec3 origin{0, 0, 0};
    double h = 1;
    int nx = 0, ny = 0, nz = 0;
    std::vector<std::int8_t> label;
    std::vector<std::int32_t> valid;  // node -> index among valid (boundary + interior) nodes, -1
    std::vector<std::int32_t> valid_node;
    std::size_t first_ghost = std::size_t(-1);  // valid indices from here on are ghost nodes
    std::size_t unknowns = 0;
    std::vector<std::int32_t> unknown;  // valid index -> unknown index (or -1 for boundary)
    std::vector<std::int32_t> unknown_valid;
    std::vector<std::array<std::int32_t, 6>> nbr;          // per unknown: valid indices of neighbours
    std::vector<std::array<std::int32_t, 6>> nbr_unknown;  // same as unknown indices, -1 if boundary
    std::size_t node(int i, int j, int k) const { return (std::size_t(k) * ny + std::size_t(j)) * nx + std::size_t(i); }
  };

  struct Scratch {
    std::vector<double> acc;
  };
  static Scratch& scratch() {
    thread_local Scratch s;
    return s;
  }

  // Labels nodes and fills the boundary values of one level; returns the valid-node values
  // (K per valid node) with the boundary ones set and the interior ones zero.
  void build_level(int R, Grid& G, std::vector<double>& values) const {
    const internal::Cage_geometry& g = *g_;
    Vec3 lo = g.v[0], hi = g.v[0];
    for (const Vec3& p : g.v)
      for (int c = 0; c < 3; ++c) {
        lo[c] = std::min(lo[c], p[c]);
        hi[c] = std::max(hi[c], p[c]);
      }
    const double ext = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    G.h = ext / R;
    const int margin = 3;
    int dims[3];
    for (int c = 0; c < 3; ++c) {
      G.origin[c] = lo[c] - margin * G.h;
      dims[c] = int(std::ceil((hi[c] - lo[c]) / G.h)) + 2 * margin + 1;
    }
    G.nx = dims[0];
    G.ny = dims[1];
    G.nz = dims[2];
    const std::size_t N = std::size_t(G.nx) * G.ny * G.nz;
    G.label.assign(N, interior);
    // Boundary: nodes within h/2 of a triangle, with the closest triangle and barycentrics.
    std::vector<double> dist(N, 1e300);
    std::vector<std::int32_t> ctri(N, -1);
    std::vector<std::array<double, 3>> cbary(N);
    const double reach = 0.5 * G.h * (1 + 1e-9);
    for (std::size_t t = 0; t < g.m; ++t) {
      int b0[3], b1[3];
      for (int c = 0; c < 3; ++c) {
        double mn = 1e300, mx = -1e300;
        for (int k = 0; k < 3; ++k) {
          mn = std::min(mn, g.v[g.tri[t][k]][c]);
          mx = std::max(mx, g.v[g.tri[t][k]][c]);
        }
        b0[c] = std::max(0, int(std::floor((mn - reach - G.origin[c]) / G.h)));
        b1[c] = std::min(dims[c] - 1, int(std::ceil((mx + reach - G.origin[c]) / G.h)));
      }
      for (int k = b0[2]; k <= b1[2]; ++k)
        for (int j = b0[1]; j <= b1[1]; ++j)
          for (int i = b0[0]; i <= b1[0]; ++i) {
            const Vec3 p{G.origin[0] + i * G.h, G.origin[1] + j * G.h, G.origin[2] + k * G.h};
            if (std::abs(g.signed_distance(t, p)) > reach) continue;
            std::array<double, 3> b;
            const double d = g.distance_to_triangle(t, p, &b);
            const std::size_t q = G.node(i, j, k);
            if (d <= reach && d < dist[q]) {
              dist[q] = d;
              ctri[q] = std::int32_t(t);
              cbary[q] = b;
              G.label[q] = boundary;
            }
          }
    }
    // Exterior: flood fill from a margin corner through non-boundary nodes.
    std::vector<std::size_t> stack{0};
    G.label[0] = exterior;
    while (!stack.empty()) {
      const std::size_t q = stack.back();
      stack.pop_back();
      const int i = int(q % G.nx), j = int((q / G.nx) % G.ny), k = int(q / (std::size_t(G.nx) * G.ny));
      const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
      for (const auto& c : nb) {
        if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= G.nx || c[1] >= G.ny || c[2] >= G.nz) continue;
        const std::size_t r = G.node(c[0], c[1], c[2]);
        if (G.label[r] != interior) continue;
        G.label[r] = exterior;
        stack.push_back(r);
      }
    }
    // Index valid nodes and unknowns.
    G.valid.assign(N, -1);
    G.valid_node.clear();
    G.unknown.clear();
    G.unknown_valid.clear();
    for (std::size_t q = 0; q < N; ++q) {
      if (G.label[q] == exterior) continue;
      G.valid[q] = std::int32_t(G.valid_node.size());
      G.valid_node.push_back(std::int32_t(q));
      if (G.label[q] == interior) {
        G.unknown.push_back(std::int32_t(G.unknown_valid.size()));
        G.unknown_valid.push_back(G.valid[q]);
      } else {
        G.unknown.push_back(-1);
      }
    }
    G.unknowns = G.unknown_valid.size();
    G.nbr.resize(G.unknowns);
    const std::ptrdiff_t off[6] = {-1, 1, -G.nx, G.nx, -std::ptrdiff_t(G.nx) * G.ny, std::ptrdiff_t(G.nx) * G.ny};
    for (std::size_t u = 0; u < G.unknowns; ++u) {
      const std::size_t q = std::size_t(G.valid_node[G.unknown_valid[u]]);
      for (int d = 0; d < 6; ++d) G.nbr[u][d] = G.valid[std::size_t(std::ptrdiff_t(q) + off[d])];
    }
    G.nbr_unknown.resize(G.unknowns);
    for (std::size_t u = 0; u < G.unknowns; ++u) {
      for (int d = 0; d < 6; ++d) G.nbr_unknown[u][d] = G.unknown[std::size_t(G.nbr[u][d])];
    }
    // Boundary values.
    const std::size_t K = g.n;
    values.assign(G.valid_node.size() * K, 0.0);
    std::vector<std::size_t> bnodes;
    for (std::size_t v = 0; v < G.valid_node.size(); ++v)
      if (G.label[std::size_t(G.valid_node[v])] == boundary) bnodes.push_back(v);
    if (opt_.boundary_values == Harmonic_boundary_values::mean_value) {
      Mean_value_coordinates_3 mvc(*cage_);
      tbb::parallel_for(std::size_t(0), bnodes.size(), [&](std::size_t b) {
        const std::size_t v = bnodes[b];
        const std::size_t q = std::size_t(G.valid_node[v]);
        const int i = int(q % G.nx), j = int((q / G.nx) % G.ny), k = int(q / (std::size_t(G.nx) * G.ny));
        const Vec3 p{G.origin[0] + i * G.h, G.origin[1] + j * G.h, G.origin[2] + k * G.h};
        mvc(p, values.begin() + std::ptrdiff_t(v * K));
      });
    } else {
      for (std::size_t v : bnodes) {
        const std::size_t q = std::size_t(G.valid_node[v]);
        for (int c = 0; c < 3; ++c) values[v * K + g.tri[std::size_t(ctri[q])][c]] += cbary[q][c];
      }
    }
  }

  // Conjugate gradients on the interior unknowns of coordinate i (7-point Laplacian scaled so
  // that the diagonal is 6). `values` holds the boundary data and the start on entry.
  std::pair<int, double> cg(const Grid& G, std::vector<double>& values, std::size_t i) const {
    const std::size_t K = g_->n, U = G.unknowns;
    if (U == 0) return {0, 0.0};
    std::vector<double> x(U), r(U), p(U), Ap(U);
    auto val = [&](std::int32_t v) { return values[std::size_t(v) * K + i]; };
    double bnorm = 0;
    for (std::size_t u = 0; u < U; ++u) {
      x[u] = val(G.unknown_valid[u]);
      double b = 0, ax = 6 * x[u];
      for (int d = 0; d < 6; ++d) {
        const std::int32_t nb = G.nbr[u][d];
        const std::int32_t nu = G.unknown[std::size_t(nb)];
        if (nu < 0)
          b += val(nb);
        else
          ax -= val(nb);
      }
      bnorm += b * b;
      r[u] = b - ax;
    }
    bnorm = std::sqrt(bnorm);
    if (bnorm == 0) bnorm = 1;
    p = r;
    double rr = 0;
    for (double v : r) rr += v * v;
    int it = 0;
    const double stop = opt_.solver_tolerance * bnorm;
    while (std::sqrt(rr) > stop && it < opt_.max_iterations) {
      double pAp = 0;
      for (std::size_t u = 0; u < U; ++u) {
        double a = 6 * p[u];
        const auto& nb = G.nbr_unknown[u];
        for (int d = 0; d < 6; ++d)
          if (nb[d] >= 0) a -= p[std::size_t(nb[d])];
        Ap[u] = a;
        pAp += p[u] * a;
      }
      const double alpha = rr / pAp;
      double rr2 = 0;
      for (std::size_t u = 0; u < U; ++u) {
        x[u] += alpha * p[u];
        r[u] -= alpha * Ap[u];
        rr2 += r[u] * r[u];
      }
      const double beta = rr2 / rr;
      rr = rr2;
      for (std::size_t u = 0; u < U; ++u) p[u] = r[u] + beta * p[u];
      ++it;
    }
    for (std::size_t u = 0; u < U; ++u) values[std::size_t(G.unknown_valid[u]) * K + i] = x[u];
    return {it, std::sqrt(rr) / bnorm};
  }

  // Starting values of `fine` interior unknowns: trilinear lookup in the coarser level.
  void prolong(const Grid& C, const std::vector<double>& cv, const Grid& F, std::vector<double>& fv) const {
    const std::size_t K = g_->n;
    tbb::parallel_for(std::size_t(0), F.unknowns, [&](std::size_t u) {
      const std::size_t v = std::size_t(F.unknown_valid[u]);
      const std::size_t q = std::size_t(F.valid_node[v]);
      const int i = int(q % F.nx), j = int((q / F.nx) % F.ny), k = int(q / (std::size_t(F.nx) * F.ny));
      const Vec3 p{F.origin[0] + i * F.h, F.origin[1] + j * F.h, F.origin[2] + k * F.h};
      double w[8];
      std::int32_t idx[8];
      if (!stencil(C, p, w, idx)) return;
      double ws = 0;
      for (int c = 0; c < 8; ++c)
        if (idx[c] >= 0) ws += w[c];
      if (ws <= 0) return;
      for (int c = 0; c < 8; ++c)
        if (idx[c] >= 0)
          for (std::size_t a = 0; a < K; ++a) fv[v * K + a] += w[c] / ws * cv[std::size_t(idx[c]) * K + a];
    });
  }

  // Trilinear stencil of p in grid G: weights and valid indices (-1 for exterior nodes).
  static bool stencil(const Grid& G, const Vec3& p, double w[8], std::int32_t idx[8]) {
    int c0[3];
    double f[3];
    const int dims[3] = {G.nx, G.ny, G.nz};
    for (int c = 0; c < 3; ++c) {
      const double t = (p[c] - G.origin[c]) / G.h;
      c0[c] = int(std::floor(t));
      if (c0[c] < 0 || c0[c] + 1 >= dims[c]) return false;
      f[c] = t - c0[c];
    }
    for (int c = 0; c < 8; ++c) {
      const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
      w[c] = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]) * (dk ? f[2] : 1 - f[2]);
      idx[c] = G.valid[G.node(c0[0] + di, c0[1] + dj, c0[2] + dk)];
    }
    return true;
  }

  bool linear(const Vec3& x, std::vector<double>& acc, Coordinate_status& st) const {
    const Grid& G = *grid_;
    const std::size_t K = g_->n;
    double w[8];
    std::int32_t idx[8];
    if (!stencil(G, x, w, idx)) return false;
    double ws = 0;
    bool missing = false;
    for (int c = 0; c < 8; ++c) {
      if (idx[c] >= 0)
        ws += w[c];
      else if (w[c] > 0)
        missing = true;
      if (idx[c] >= 0 && std::size_t(idx[c]) >= G.first_ghost && w[c] > 0) missing = true;
    }
    if (ws <= 1e-12) return false;
    if (missing) st = Coordinate_status::approximate;
    for (int c = 0; c < 8; ++c) {
      if (idx[c] < 0 || w[c] == 0) continue;
      const double* f = field_.data() + std::size_t(idx[c]) * K;
      const double a = w[c] / ws;
      for (std::size_t i = 0; i < K; ++i) acc[i] += a * f[i];
    }
    return true;
  }

  // Uniform cubic B-spline over the 4x4x4 nodes around x: -1 if one of them has no value (acc
  // untouched), 1 if ghost nodes were used, 0 otherwise.
  int cubic(const Vec3& x, std::vector<double>& acc) const {
    const Grid& G = *grid_;
    const std::size_t K = g_->n;
    int c0[3];
    double bw[3][4];
    const int dims[3] = {G.nx, G.ny, G.nz};
    for (int c = 0; c < 3; ++c) {
      const double t = (x[c] - G.origin[c]) / G.h;
      c0[c] = int(std::floor(t));
      if (c0[c] - 1 < 0 || c0[c] + 2 >= dims[c]) return -1;
      const double u = t - c0[c], u2 = u * u, u3 = u2 * u;
      bw[c][0] = (1 - 3 * u + 3 * u2 - u3) / 6;
      bw[c][1] = (4 - 6 * u2 + 3 * u3) / 6;
      bw[c][2] = (1 + 3 * u + 3 * u2 - 3 * u3) / 6;
      bw[c][3] = u3 / 6;
    }
    std::int32_t idx[64];
    int ghost = 0;
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const std::int32_t v = G.valid[G.node(c0[0] - 1 + i, c0[1] - 1 + j, c0[2] - 1 + k)];
          if (v < 0) return -1;
          if (std::size_t(v) >= G.first_ghost) ghost = 1;
          idx[(k * 4 + j) * 4 + i] = v;
        }
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const double a = bw[0][i] * bw[1][j] * bw[2][k];
          const double* f = field_.data() + std::size_t(idx[(k * 4 + j) * 4 + i]) * K;
          for (std::size_t c = 0; c < K; ++c) acc[c] += a * f[c];
        }
    return ghost;
  }

  void solve() {
    const std::size_t K = g_->n;
    std::vector<int> res;
    for (int R = opt_.resolution; R >= 8; R /= 2) res.push_back(R);
    if (res.empty()) res.push_back(opt_.resolution);
    std::reverse(res.begin(), res.end());
    std::shared_ptr<Grid> prev;
    std::vector<double> prev_values;
    iterations_ = 0;
    for (std::size_t l = 0; l < res.size(); ++l) {
      auto G = std::make_shared<Grid>();
      std::vector<double> values;
      build_level(res[l], *G, values);
      if (prev) prolong(*prev, prev_values, *G, values);
      std::vector<std::pair<int, double>> stats(K);
      tbb::parallel_for(std::size_t(0), K, [&](std::size_t i) { stats[i] = cg(*G, values, i); });
      residual_ = 0;
      for (const auto& s : stats) {
        iterations_ += std::size_t(s.first);
        residual_ = std::max(residual_, s.second);
      }
      prev = G;
      prev_values.swap(values);
    }
    if (opt_.boundary_values == Harmonic_boundary_values::mean_value) add_ghosts(*prev, prev_values);
    grid_ = prev;
    field_.swap(prev_values);
  }

  // Ghost nodes: the exterior nodes within 3 nodes (Chebyshev distance) of the domain get the
  // mean value coordinates of their position. Every node value then reproduces linear functions,
  // so lookups whose stencil leaves the domain (points within a cell or two of the cage) keep
  // the exact affine reproduction instead of being renormalised; they are still flagged
  // `approximate`, since they mix harmonic and mean value data.
  void add_ghosts(Grid& G, std::vector<double>& values) const {
    const std::size_t N = G.label.size(), K = g_->n;
    std::vector<unsigned char> mark(N);
    for (std::size_t q = 0; q < N; ++q) mark[q] = G.label[q] != exterior;
    for (int pass = 0; pass < 3; ++pass) {
      std::vector<unsigned char> next = mark;
      for (int k = 0; k < G.nz; ++k)
        for (int j = 0; j < G.ny; ++j)
          for (int i = 0; i < G.nx; ++i) {
            if (!mark[G.node(i, j, k)]) continue;
            for (int dk = -1; dk <= 1; ++dk)
              for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                  const int a = i + di, b = j + dj, c = k + dk;
                  if (a < 0 || b < 0 || c < 0 || a >= G.nx || b >= G.ny || c >= G.nz) continue;
                  next[G.node(a, b, c)] = 1;
                }
          }
      mark.swap(next);
    }
    G.first_ghost = G.valid_node.size();
    for (std::size_t q = 0; q < N; ++q)
      if (mark[q] && G.label[q] == exterior) {
        G.valid[q] = std::int32_t(G.valid_node.size());
        G.valid_node.push_back(std::int32_t(q));
      }
    values.resize(G.valid_node.size() * K);
    Mean_value_coordinates_3 mvc(*cage_);
    tbb::parallel_for(G.first_ghost, G.valid_node.size(), [&](std::size_t v) {
      const std::size_t q = std::size_t(G.valid_node[v]);
      const int i = int(q % G.nx), j = int((q / G.nx) % G.ny), k = int(q / (std::size_t(G.nx) * G.ny));
      const Vec3 p{G.origin[0] + i * G.h, G.origin[1] + j * G.h, G.origin[2] + k * G.h};
      mvc(p, values.begin() + std::ptrdiff_t(v * K));
    });
  }

  std::shared_ptr<const Triangle_cage> cage_;
  std::shared_ptr<const internal::Cage_geometry> g_;
  Harmonic_options opt_;
  Mean_value_coordinates_3 mvc_;  // exact values on the cage itself
  std::shared_ptr<const Grid> grid_;
  std::vector<double> field_;  // K values per valid node of the finest grid
  std::size_t iterations_ = 0;
  double residual_ = 0;
};

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_HARMONIC_COORDINATES_3_H
