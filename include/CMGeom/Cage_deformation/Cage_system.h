// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Cage_system: the *Cages deformation of thesis §5.3. Leaf cages with disjoint interiors share
// border faces; each has its own coordinates T_i (mean value, Green or harmonic), and the
// piecewise deformation is made C¹ across borders by the join transformation J_i (§5.3.2) and
// the smooth one S_i = d_i T_i + (1 − d_i) J_i (§5.3.3); upper-level cages own vertices of lower
// ones (§5.3.4). The structure (welded vertices, borders, join cages, hierarchy order) is built by
// internal::Cage_system_topology; this class adds the coordinates, writes S_i(p) as one sparse
// row over the deformed leaf vertices (bind(), Cage_system_binding) and evaluates the frames.
// The grid factory make_grid_cage_system() (Grid_cage_system.h) and the description are included.
// Formulas, storage and the choices where the thesis leaves room: "*Cages" in
// doc/Cage_deformation/README.md.
//
// Complexity: construction O(Σ m_i log) plus one coordinate setup per join cage (harmonic: a
// solve each); binding O(N (m_i + Σ_[u] m_[u])) per point in C_i; deform O(nnz) per frame.
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_H

#include <CMGeom/Cage_deformation/Any_cage_coordinates.h>
#include <CMGeom/Cage_deformation/Cage_binding.h>
#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Cage_deformation/Grid_cage_system.h>
#include <CMGeom/Cage_deformation/internal/Cage_system_topology.h>
#include <CMGeom/Error.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// Default smoothing function f of §5.3.2: ½ sin(π(x − ½)) + ½ on [0, 1] (f(0) = f'(0) = 0,
/// f(1) = 1, f' ≥ 0). Any function object double(double) with these properties can replace it.
struct Sine_smoothing {
  double operator()(double x) const {
    if (x <= 0) return 0;
    if (x >= 1) return 1;
    return 0.5 * std::sin(3.14159265358979323846 * (x - 0.5)) + 0.5;
  }
};

/// Default f_h of §5.3.3: ½ sin(π(x/h − ½)) + ½ below h, 1 from h on. Any function object
/// double(double x, double h) with f_h(0) = f_h'(0) = f_h'(h) = 0, f_h = 1 on [h, 1], f_h' ≥ 0.
struct Sine_h_smoothing {
  double operator()(double x, double h) const {
    if (x >= h) return 1;
    if (x <= 0) return 0;
    return 0.5 * std::sin(3.14159265358979323846 * (x / h - 0.5)) + 0.5;
  }
};

/// f_h that is 1 everywhere: S_i = T_i, the piecewise deformation of §5.3.1 (C⁰ for MVC and HC,
/// discontinuous for Green), for comparisons with *Cages (thesis Fig. 5.2(a, b)).
struct Piecewise_smoothing {
  double operator()(double, double) const { return 1.0; }
};

namespace internal {
/// Winding number of a closed triangle cage around x (solid angles, Van Oosterom-Strackee).
inline double winding_number(const Triangle_cage& c, const Vec3& x) {
  double w = 0;
  for (const auto& t : c.triangles) {
    const Vec3 a = sub(c.vertices[t[0]], x), b = sub(c.vertices[t[1]], x), d = sub(c.vertices[t[2]], x);
    const double la = norm(a), lb = norm(b), ld = norm(d);
    const double num = dot(a, cross(b, d));
    const double den = la * lb * ld + dot(a, b) * ld + dot(b, d) * la + dot(d, a) * lb;
    w += 2 * std::atan2(num, den);
  }
  return w / (4 * 3.14159265358979323846);
}
}  // namespace internal

template <class Weight>
class Cage_system_binding;

class Cage_system {
public:
  /// One sparse entry of a point's row: S(p) = Σ weight · basis[column].
  struct Entry {
    std::uint32_t column;
    double weight;
  };
  /// What binding one point gives.
  struct Point_row {
    std::size_t cage = 0;  ///< index of the leaf cage (in description order)
    double d = 1;          ///< d_i(p), the influence of T_i (1: T_i only)
    Coordinate_status status = Coordinate_status::regular;
    bool inside = true;  ///< inside some leaf cage (winding number ≥ ½)
    std::vector<Entry> entries;
  };

  /// Builds the structure and the coordinates (harmonic ones are solved here). Throws
  /// Invalid_input when the leaf cages overlap (a face shared with the same orientation or by
  /// more than two cages), when shared vertices get different deformed positions, or when an
  /// owned vertex lies where its parent's coordinates are undefined, or when a border h names a
  /// cage that shares no face with its cage. Messages start with the description's `source` (the
  /// file it was read from) when it has one.
  explicit Cage_system(const Cage_system_description& d) : desc_(d) {
    try {
      build();
    } catch (const Invalid_input& e) {
      if (d.source.empty()) throw;
      throw Invalid_input(d.source + ": " + e.what());
    }
  }

  const Cage_system_description& description() const { return desc_; }
  std::size_t number_of_cages() const { return desc_.cages.size(); }
  const std::vector<std::size_t>& leaf_cages() const { return topo_.leaves; }
  bool is_leaf(std::size_t cage) const { return topo_.is_leaf[cage] != 0; }
  /// Welded vertices of the leaf cages (rest positions) and, per leaf cage, local -> global.
  const std::vector<Vec3>& leaf_vertices() const { return topo_.vertices; }
  const std::vector<std::uint32_t>& global_vertices(std::size_t cage) const { return topo_.global_of[cage]; }
  /// Adj(C_i): the leaf cages sharing a face with C_i.
  std::vector<std::size_t> neighbours(std::size_t cage) const {
    std::vector<std::size_t> r;
    for (const auto& b : topo_.borders[cage]) r.push_back(b.other);
    return r;
  }
  /// Number of shared triangles of B_ij (0 if not adjacent).
  std::size_t border_size(std::size_t i, std::size_t j) const {
    for (const auto& b : topo_.borders[i])
      if (b.other == j) return b.triangles;
    return 0;
  }
  /// Global ids of the vertices of ∂C_i.
  std::vector<std::uint32_t> boundary_vertices(std::size_t cage) const {
    std::set<std::uint32_t> s;
    for (const auto& b : topo_.borders[cage])
      for (std::uint32_t l : b.local) s.insert(topo_.global_of[cage][l]);
    return {s.begin(), s.end()};
  }
  /// Leaf cages having global vertex v as a vertex.
  const std::vector<std::size_t>& incident_cages(std::uint32_t v) const { return topo_.incident[v]; }
  /// The partition of boundary vertices (§5.3.2): class k has vertices (global ids), the cages
  /// whose union is its join cage, and the join cage itself.
  std::size_t number_of_join_cages() const { return topo_.classes.size(); }
  const std::vector<std::uint32_t>& join_class(std::size_t k) const { return topo_.classes[k].vertices; }
  const std::vector<std::size_t>& join_class_cages(std::size_t k) const { return topo_.classes[k].cages; }
  const Triangle_cage& join_cage(std::size_t k) const { return topo_.classes[k].cage; }
  /// Classes of ∂C_i.
  const std::vector<std::size_t>& join_classes_of(std::size_t cage) const { return topo_.classes_of[cage]; }
  /// Columns of the global basis.
  std::size_t number_of_coordinates() const { return K_; }
  /// The surface of the union of all leaf cages (shared faces removed); a single cage with the
  /// same surface vertices, for comparisons with single-cage methods (thesis Fig. 5.6).
  Triangle_cage union_cage() const {
    std::vector<std::size_t> all(topo_.leaves.begin(), topo_.leaves.end());
    std::vector<std::uint32_t> local;
    return topo_.merged_cage(desc_, all, local);
  }

  // ----------------------------------------------------------------------------- deformation
  /// Deformed positions of the welded leaf vertices from the deformed positions of every cage
  /// (description order; internal cages included), propagated down the hierarchy (§5.3.4).
  std::vector<Vec3> deformed_leaf_vertices(const std::vector<std::vector<Vec3>>& deformed) const {
    CGAL_precondition(deformed.size() == desc_.cages.size());
    std::vector<std::vector<Vec3>> final(desc_.cages.size());
    for (std::size_t c : topo_.order) {
      const Cage_description& cd = desc_.cages[c];
      CGAL_precondition(deformed[c].size() == cd.rest.vertices.size());
      final[c] = deformed[c];
      for (const auto& l : cd.parents) {
        std::vector<Vec3> basis;
        coords_[l.cage].basis(final[l.cage], basis);
        for (std::uint32_t k : l.vertices)
          final[c][k] =
              follow_parent(l.cage, basis, cd.rest.vertices[k], internal::sub(deformed[c][k], cd.rest.vertices[k]));
      }
    }
    std::vector<Vec3> g(topo_.vertices.size());
    std::vector<char> set(topo_.vertices.size(), 0);
    for (std::size_t c : topo_.leaves)
      for (std::size_t k = 0; k < topo_.global_of[c].size(); ++k) {
        const std::uint32_t v = topo_.global_of[c][k];
        // An owned copy wins over a free one, so a shared vertex listed by one cage's parent link
        // follows the parent in every cage.
        if (!set[v] || owned_local(c, k)) {
          g[v] = final[c][k];
          set[v] = 1;
        }
      }
    return g;
  }
  /// The description's own deformed poses.
  std::vector<Vec3> deformed_leaf_vertices() const {
    std::vector<std::vector<Vec3>> d;
    for (const auto& c : desc_.cages) d.push_back(c.deformed);
    return deformed_leaf_vertices(d);
  }

  /// The global basis (number_of_coordinates() vectors) of deformed leaf vertex positions: the
  /// positions themselves, then the extra vectors of cages whose coordinates have some (Green).
  std::vector<Vec3> basis(const std::vector<Vec3>& leaf_positions) const {
    CGAL_precondition(leaf_positions.size() == topo_.vertices.size());
    std::vector<Vec3> B(leaf_positions), local, b;
    B.resize(K_);
    for (std::size_t c : topo_.leaves) {
      const std::size_t n = topo_.global_of[c].size();
      if (coords_[c].number_of_coordinates() == n) continue;
      local.clear();
      for (std::uint32_t v : topo_.global_of[c]) local.push_back(leaf_positions[v]);
      coords_[c].basis(local, b);
      std::copy(b.begin() + std::ptrdiff_t(n), b.end(), B.begin() + std::ptrdiff_t(cage_col_[c]));
    }
    return B;
  }

  /// The leaf cage a point belongs to (largest winding number; lowest index on ties) and
  /// whether it is inside it.
  std::pair<std::size_t, bool> locate(const Vec3& p) const {
    std::size_t best = topo_.leaves[0];
    double bw = -std::numeric_limits<double>::infinity();
    auto test = [&](std::size_t c) {
      const double w = internal::winding_number(desc_.cages[c].rest, p);
      if (w > bw + 1e-12) {
        bw = w;
        best = c;
      }
    };
    for (std::size_t c : topo_.leaves)
      if (topo_.in_box(c, p)) test(c);
    if (bw < 0.5 - 1e-9)
      for (std::size_t c : topo_.leaves)
        if (!topo_.in_box(c, p)) test(c);
    return {best, bw >= 0.5 - 1e-9};
  }

  /// The row of S_i at p for leaf cage `cage` (§5.3.3). `f`, `fh`: the smoothing functions.
  template <class F = Sine_smoothing, class Fh = Sine_h_smoothing>
  Point_row row(const Vec3& p, std::size_t cage, const F& f = F(), const Fh& fh = Fh()) const {
    Point_row r;
    r.cage = cage;
    std::vector<double> w(coords_[cage].number_of_coordinates());
    r.status = coords_[cage].evaluate(p, w.data());
    r.d = distance(p, cage, fh);
    std::vector<std::pair<std::size_t, double>> alpha;  // (class, f(W̄))
    std::vector<std::vector<double>> wbar;
    if (r.d < 1) {
      double sum = 0;
      for (std::size_t k : topo_.classes_of[cage]) {
        const internal::Join_class& cl = topo_.classes[k];
        std::vector<double> x(join_coords_[k].number_of_coordinates());
        join_coords_[k].evaluate(p, x.data());
        double W = 0;
        if (!cl.local.empty()) {
          for (std::uint32_t l : cl.local) W += x[l];
        } else {  // interior vertices: Π_j (1 − w̄_Xj) over the cages outside the join cage
          W = 1;
          for (const auto& g : cl.bubble) {
            double s = 0;
            for (std::uint32_t l : g) s += x[l];
            W *= 1 - s;
          }
        }
        const double g = f(std::min(1.0, std::max(0.0, W)));
        if (g > 0) {
          alpha.push_back({k, g});
          wbar.push_back(std::move(x));
          sum += g;
        }
      }
      if (!(sum > 0)) {
        r.d = 1;  // every f(W̄) vanishes: T_i alone, its common limit (see the README)
        alpha.clear();
      } else {
        for (auto& a : alpha) a.second /= sum;
      }
    }
    // Every term is a combination of the same welded vertices: gather the coefficients per column.
    const std::size_t n = topo_.global_of[cage].size();
    for (std::size_t k = 0; k < w.size(); ++k) {
      const std::size_t col = k < n ? topo_.global_of[cage][k] : cage_col_[cage] + (k - n);
      if (r.d * w[k] != 0) r.entries.push_back({std::uint32_t(col), r.d * w[k]});
    }
    for (std::size_t a = 0; a < alpha.size(); ++a) {
      const internal::Join_class& cl = topo_.classes[alpha[a].first];
      const double s = (1 - r.d) * alpha[a].second;
      for (std::size_t k = 0; k < wbar[a].size(); ++k)
        if (s * wbar[a][k] != 0) r.entries.push_back({cl.global[k], s * wbar[a][k]});
    }
    std::sort(r.entries.begin(), r.entries.end(), [](const Entry& x, const Entry& y) { return x.column < y.column; });
    std::size_t m = 0;
    for (std::size_t e = 0; e < r.entries.size(); ++e) {
      if (m > 0 && r.entries[m - 1].column == r.entries[e].column)
        r.entries[m - 1].weight += r.entries[e].weight;
      else
        r.entries[m++] = r.entries[e];
    }
    r.entries.resize(m);
    return r;
  }
  template <class F = Sine_smoothing, class Fh = Sine_h_smoothing>
  Point_row row(const Vec3& p, const F& f = F(), const Fh& fh = Fh()) const {
    const auto [c, inside] = locate(p);
    Point_row r = row(p, c, f, fh);
    r.inside = inside;
    if (!inside && r.status < Coordinate_status::extended) r.status = Coordinate_status::extended;
    return r;
  }

  /// d_i(p) = f_{h_i}(Π_j (1 − w_ij(p))), 1 for a cage without neighbours (§5.3.3). Borders
  /// given their own h_ij (Cage_description::border_h) leave the product and get their own
  /// factor: d_i = f_{h_i}(Π_{j plain} (1 − w_ij)) · Π_{j own} f_{h_ij}(1 − w_ij). Without such
  /// borders this is the thesis' formula; every factor is C¹, 1 away from its borders, and 0
  /// with a zero gradient on them, so d_i keeps the properties the C¹ argument needs.
  template <class Fh = Sine_h_smoothing>
  double distance(const Vec3& p, std::size_t cage, const Fh& fh = Fh()) const {
    if (topo_.borders[cage].empty()) return 1;
    std::vector<double> w(mvc_[cage].number_of_coordinates());
    mvc_[cage].evaluate(p, w.data());
    double x = 1, own = 1;
    auto clamp = [](double y) { return std::min(1.0, std::max(0.0, y)); };
    for (const auto& b : topo_.borders[cage]) {
      double wij = 0;
      for (std::uint32_t l : b.local) wij += w[l];
      if (b.h > 0)
        own *= fh(clamp(1 - wij), b.h);
      else
        x *= 1 - wij;
    }
    return own * fh(clamp(x), desc_.cages[cage].h);
  }
  /// h of the border of `cage` with `other`: its own value, or the cage's h_i.
  double border_h(std::size_t cage, std::size_t other) const {
    for (const auto& b : topo_.borders[cage])
      if (b.other == other && b.h > 0) return b.h;
    return desc_.cages[cage].h;
  }

  /// S(p) for the given global basis (direct evaluation, for tests and single points).
  template <class F = Sine_smoothing, class Fh = Sine_h_smoothing>
  Vec3 evaluate(const Vec3& p, std::size_t cage, const std::vector<Vec3>& B, const F& f = F(),
                const Fh& fh = Fh()) const {
    Vec3 x{0, 0, 0};
    for (const Entry& e : row(p, cage, f, fh).entries) x = internal::add(x, internal::mul(e.weight, B[e.column]));
    return x;
  }

  /// Binds every point (TBB-parallel; results do not depend on the thread count). `progress`
  /// (optional, CMGeom/Progress.h) is called from the calling thread with the fraction of the
  /// points bound, at most about 256 times; it must be cheap.
  template <class Weight = double, class PointRange, class F = Sine_smoothing, class Fh = Sine_h_smoothing>
  Cage_system_binding<Weight> bind(const PointRange& points, const F& f = F(), const Fh& fh = Fh(),
                                   const Progress_callback& progress = Progress_callback()) const;

private:
  // The whole construction, in the order of its checks (the constructor adds the source to error
  // messages): the structure (internal::Cage_system_topology) and the coordinates built on it.
  void build() {
    const std::size_t C = desc_.cages.size();
    topo_.find_leaves(desc_);
    coords_.resize(C);
    for (std::size_t i = 0; i < C; ++i)
      coords_[i] = make_cage_coordinates(desc_.cages[i].coordinates, desc_.cages[i].rest, desc_.cages[i].harmonic);
    mvc_.resize(C);
    for (std::size_t c : topo_.leaves) mvc_[c] = Any_cage_coordinates(Mean_value_coordinates_3(desc_.cages[c].rest));
    topo_.weld_leaves(desc_);
    topo_.build_borders(desc_);
    topo_.build_classes(desc_);
    for (const internal::Join_class& cl : topo_.classes)
      join_coords_.push_back(make_cage_coordinates(desc_.join_coordinates, cl.cage, desc_.join_harmonic));
    topo_.topological_order(desc_);
    check_ownership();
    // Column layout: one column per welded leaf vertex (every coordinate type puts the deformed
    // vertices first in its basis), then the extra columns of a cage (Green: s_j n'_j per face).
    std::size_t K = topo_.vertices.size();
    cage_col_.assign(C, 0);
    for (std::size_t i : topo_.leaves) {
      cage_col_[i] = K;
      K += coords_[i].number_of_coordinates() - desc_.cages[i].rest.vertices.size();
    }
    K_ = K;
  }

  bool owned_local(std::size_t c, std::size_t k) const { return topo_.owned[c][k] != 0; }

  void check_ownership() {
    // A welded leaf vertex has at most one parent; every owned rest vertex must have defined
    // coordinates in its parent.
    std::vector<std::size_t> parent_of(topo_.vertices.size(), internal::Cage_system_topology::npos);
    for (std::size_t c = 0; c < desc_.cages.size(); ++c)
      for (const auto& l : desc_.cages[c].parents)
        for (std::uint32_t k : l.vertices) {
          std::vector<double> w(coords_[l.cage].number_of_coordinates());
          if (coords_[l.cage].evaluate(desc_.cages[c].rest.vertices[k], w.data()) == Coordinate_status::undefined)
            throw Invalid_input("cage " + std::to_string(c) + " vertex " + std::to_string(k) +
                                " lies outside its parent cage " + std::to_string(l.cage) +
                                ", whose coordinates are undefined there");
          if (!topo_.is_leaf[c]) continue;
          std::size_t& p = parent_of[topo_.global_of[c][k]];
          if (p != internal::Cage_system_topology::npos && p != l.cage)
            throw Invalid_input("leaf vertex " + std::to_string(topo_.global_of[c][k]) +
                                " is owned by two parent cages (" + std::to_string(p) + " and " +
                                std::to_string(l.cage) + ")");
          p = l.cage;
        }
  }

  static Vec3 apply(const std::vector<Vec3>& basis, const std::vector<double>& w) {
    Vec3 x{0, 0, 0};
    for (std::size_t k = 0; k < w.size(); ++k) x = internal::add(x, internal::mul(w[k], basis[k]));
    return x;
  }

  Vec3 follow_parent(std::size_t parent, const std::vector<Vec3>& basis, const Vec3& r, const Vec3& t) const {
    std::vector<double> w(coords_[parent].number_of_coordinates());
    if (coords_[parent].evaluate(internal::add(r, t), w.data()) != Coordinate_status::undefined) return apply(basis, w);
    // λ rule of §5.3.4 for coordinates not defined outside the cage.
    coords_[parent].evaluate(r, w.data());
    const Vec3 Tr = apply(basis, w);
    double lambda = 1;
    for (int k = 0; k < 60; ++k) {
      lambda *= 2;
      if (coords_[parent].evaluate(internal::add(r, internal::mul(1 / lambda, t)), w.data()) !=
          Coordinate_status::undefined)
        return internal::add(Tr, internal::mul(lambda, internal::sub(apply(basis, w), Tr)));
    }
    return internal::add(Tr, t);
  }

  Cage_system_description desc_;
  internal::Cage_system_topology topo_;
  std::vector<Any_cage_coordinates> coords_;       // T_i of every cage
  std::vector<Any_cage_coordinates> mvc_;          // w_i of d_i (leaf cages)
  std::vector<Any_cage_coordinates> join_coords_;  // per join class: coordinates of its join cage
  std::vector<std::size_t> cage_col_;              // first extra column of each leaf cage
  std::size_t K_ = 0;
};

/// The binding of N points to a Cage_system: one sparse row of S per point, the leaf cage of
/// each point and its influence value d_i(p) (the influence map of §5.3.3, Fig. 5.2-5.3).
template <class Weight = double>
class Cage_system_binding {
public:
  const Cage_binding<Weight>& weights() const { return b_; }
  const std::vector<std::uint32_t>& cage_of_point() const { return cage_; }
  const std::vector<float>& influence() const { return d_; }
  std::size_t number_of_points() const { return cage_.size(); }
  std::size_t outside() const { return outside_; }
  /// Points whose row holds join terms (d_i < 1).
  std::size_t joined_points() const { return joined_; }
  std::size_t weights_bytes() const { return b_.weights_bytes(); }
  /// Deformed positions from the global basis (Cage_system::basis()).
  void deform(const std::vector<Vec3>& basis, std::vector<Vec3>& out) const { b_.deform(basis, out); }

private:
  friend class Cage_system;
  Cage_binding<Weight> b_;
  std::vector<std::uint32_t> cage_;
  std::vector<float> d_;
  std::size_t outside_ = 0, joined_ = 0;
};

template <class Weight, class PointRange, class F, class Fh>
Cage_system_binding<Weight> Cage_system::bind(const PointRange& points, const F& f, const Fh& fh,
                                              const Progress_callback& progress_callback) const {
  const std::size_t N = std::size_t(std::distance(std::begin(points), std::end(points)));
  auto first = std::begin(points);
  // The rows' share of the time; the rest groups them (Cage_binding::from_sparse_rows).
  CMGeom::internal::Progress_reporter progress(progress_callback);
  progress.phase(0., 0.95, N);
  constexpr std::size_t block = 256;
  const std::size_t nb = (N + block - 1) / block;
  std::vector<std::vector<Weight>> vals(nb);
  std::vector<std::vector<std::uint32_t>> cols(nb);
  std::vector<std::vector<std::size_t>> counts(nb);
  Cage_system_binding<Weight> out;
  out.cage_.resize(N);
  out.d_.resize(N);
  std::vector<Coordinate_status> status(N);
  std::vector<char> inside(N);
  tbb::parallel_for(std::size_t(0), nb, [&](std::size_t bi) {
    for (std::size_t v = bi * block; v < std::min(N, (bi + 1) * block); ++v) {
      const Point_row r = row(internal::to_vec3(*(first + std::ptrdiff_t(v))), f, fh);
      out.cage_[v] = std::uint32_t(r.cage);
      out.d_[v] = float(r.d);
      status[v] = r.status;
      inside[v] = r.inside;
      for (const Entry& e : r.entries) {
        vals[bi].push_back(Weight(e.weight));
        cols[bi].push_back(e.column);
      }
      counts[bi].push_back(r.entries.size());
    }
    progress.add(std::min(N, (bi + 1) * block) - bi * block);
  });
  std::vector<std::size_t> row_start{0};
  std::vector<std::uint32_t> columns;
  std::vector<Weight> values;
  for (std::size_t bi = 0; bi < nb; ++bi) {
    for (std::size_t c : counts[bi]) row_start.push_back(row_start.back() + c);
    values.insert(values.end(), vals[bi].begin(), vals[bi].end());
    columns.insert(columns.end(), cols[bi].begin(), cols[bi].end());
  }
  for (std::size_t v = 0; v < N; ++v) {
    out.outside_ += !inside[v];
    out.joined_ += out.d_[v] < 1;
  }
  out.b_ = Cage_binding<Weight>::from_sparse_rows(K_, std::move(row_start), std::move(columns), std::move(values),
                                                  std::move(status), Weight_storage::grouped);
  progress.finish();
  return out;
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_H
