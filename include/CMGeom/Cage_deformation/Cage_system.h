// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Cage_system: the *Cages deformation of thesis §5.3. Leaf cages with disjoint interiors share
// border faces; each has its own coordinates T_i (mean value, Green or harmonic, §5.3.3), and the
// piecewise deformation is made C¹ across borders by
//   J_i(p) = Σ_[u] f(W̄_[u](p)) T̄_[u](p) / Σ_[u] f(W̄_[u](p)),   W̄_[u] = Σ_{v∈[u]} w̄(v, p)   (§5.3.2)
//   S_i(p) = d_i(p) T_i(p) + (1 − d_i(p)) J_i(p),   d_i = f_{h_i}(Π_j (1 − w_ij(p)))           (§5.3.3)
// where [u] runs over the classes of boundary vertices of C_i with the same join cage (the union
// of their incident cages, shared faces removed) and w̄ are C¹ coordinates of that join cage.
// Upper-level (internal) cages own vertices of lower-level cages (§5.3.4); changes propagate
// downwards only.
//
// Structure (built once): global leaf vertices (leaf cage vertices welded by identical rest
// position), borders B_ij = faces shared with opposite orientation, boundary vertices, incident
// cages per vertex, the partition into classes, one join cage (and its coordinates) per class.
// Binding: every point is located in one leaf cage (largest winding number), and S_i(p) is
// written as one sparse row over a global basis: the welded leaf vertices, then the extra vectors
// of Green cages (s_j n'_j per face). T_i, every T̄_[u] and hence S_i are combinations of the same
// deformed vertices, so the coefficients of d_i T_i and of (1 − d_i) f(W̄_[u]) / Σ f · T̄_[u] are
// summed per vertex: a row holds at most the vertices of C_i's join cages. S is linear in the
// deformed vertex positions, so each frame is one sparse matrix-vector product (Cage_binding),
// and join data are stored only where d_i < 1 (memory falls with h, Table 5.1). The rows are
// kept in Cage_binding's grouped storage: the points of one cage with the same join terms share
// one column pattern, so a weight costs 8 bytes (no column index) and each group is a small
// dense product.
//
// Choices where the thesis leaves room (documented in doc/Cage_deformation/README.md):
//   * h per border (§5.5 lets h be chosen per border, per cage or for the whole model, but gives
//     no formula for the first): a border with its own h_ij leaves the product of d_i
//     and contributes its own factor f_{h_ij}(1 − w_ij) (see distance()); a system without
//     per-border values is exactly the thesis' d_i.
//   * w_i in d_i are the *mean value* coordinates of C_i whatever T_i is: Green coordinates are
//     not barycentric (Σ_{v∈VB_ij} φ_v ≠ 1 on B_ij) and the grid harmonic coordinates are only
//     approximate near the cage; MVC make d_i vanish exactly on every border.
//   * Adjacency means sharing at least one face (a triangle of both cages, opposite orientation);
//     shared faces must be triangulated identically in both cages. Cages touching at an edge or a
//     vertex only are not neighbours, but they are incident cages of that vertex for join cages.
//   * A boundary vertex u strictly inside its join cage X (a lattice vertex surrounded by 8
//     cells) is no vertex of X's surface, so the thesis' W̄ = Σ w̄(v, p) would be 0 for its class;
//     then every f(W̄) vanishes on whole faces of some cages (the centre cell of a 3x3x3 grid) and
//     J is undefined there. For such a class we use W̄_[u] = Π_j (1 − Σ_{v∈VB_Xj} w̄(v, p)) over
//     the cages C_j outside X that share faces B_Xj with it: the construction of d_i applied to
//     X. It is C¹ inside X, positive inside, and vanishes on every border of X with an outside
//     cage, which is what the C¹ argument of §5.3.2 needs. If all f(W̄) still vanish at a point
//     (not met in grids), T_i is used there (d_i := 1).
//   * Points outside every leaf cage are given to the cage of largest winding number (status
//     `extended`, or that of T_i); MVC and Green are defined there, harmonic ones are not.
//   * Multi-level: a child vertex with rest position r, user displacement t (deformed − rest in
//     the child's own description) and parent P moves to T_P(r + t) (its coordinates are those
//     of the moved vertex in P's rest pose, recomputed per frame: only cage vertices are
//     recomputed, never mesh vertices). When r + t is outside P and P's coordinates are undefined
//     there (harmonic), the λ rule is used: v″ = T_P(r) + λ (T_P(r + t/λ) − T_P(r)), with the
//     smallest λ = 2^k making r + t/λ defined.
//
// Complexity: construction O(Σ m_i log) plus one coordinate setup per join cage (harmonic: a
// solve each); binding O(N (m_i + Σ_[u] m_[u])) per point in C_i (join terms only where d_i < 1);
// deform O(nnz) per frame.
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_H

#include <CMGeom/Cage_deformation/Any_cage_coordinates.h>
#include <CMGeom/Cage_deformation/Cage_binding.h>
#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Error.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
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
    bool inside = true;    ///< inside some leaf cage (winding number ≥ ½)
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
  const std::vector<std::size_t>& leaf_cages() const { return leaves_; }
  bool is_leaf(std::size_t cage) const { return is_leaf_[cage] != 0; }
  /// Welded vertices of the leaf cages (rest positions) and, per leaf cage, local -> global.
  const std::vector<Vec3>& leaf_vertices() const { return gv_; }
  const std::vector<std::uint32_t>& global_vertices(std::size_t cage) const { return g_of_[cage]; }
  /// Adj(C_i): the leaf cages sharing a face with C_i.
  std::vector<std::size_t> neighbours(std::size_t cage) const {
    std::vector<std::size_t> r;
    for (const auto& b : borders_[cage]) r.push_back(b.other);
    return r;
  }
  /// Number of shared triangles of B_ij (0 if not adjacent).
  std::size_t border_size(std::size_t i, std::size_t j) const {
    for (const auto& b : borders_[i])
      if (b.other == j) return b.triangles;
    return 0;
  }
  /// Global ids of the vertices of ∂C_i.
  std::vector<std::uint32_t> boundary_vertices(std::size_t cage) const {
    std::set<std::uint32_t> s;
    for (const auto& b : borders_[cage])
      for (std::uint32_t l : b.local) s.insert(g_of_[cage][l]);
    return {s.begin(), s.end()};
  }
  /// Leaf cages having global vertex v as a vertex.
  const std::vector<std::size_t>& incident_cages(std::uint32_t v) const { return incident_[v]; }
  /// The partition of boundary vertices (§5.3.2): class k has vertices (global ids), the cages
  /// whose union is its join cage, and the join cage itself.
  std::size_t number_of_join_cages() const { return classes_.size(); }
  const std::vector<std::uint32_t>& join_class(std::size_t k) const { return classes_[k].vertices; }
  const std::vector<std::size_t>& join_class_cages(std::size_t k) const { return classes_[k].cages; }
  const Triangle_cage& join_cage(std::size_t k) const { return classes_[k].cage; }
  /// Classes of ∂C_i.
  const std::vector<std::size_t>& join_classes_of(std::size_t cage) const { return classes_of_[cage]; }
  /// Columns of the global basis.
  std::size_t number_of_coordinates() const { return K_; }
  /// The surface of the union of all leaf cages (shared faces removed); a single cage with the
  /// same surface vertices, for comparisons with single-cage methods (thesis Fig. 5.6).
  Triangle_cage union_cage() const {
    std::vector<std::size_t> all(leaves_.begin(), leaves_.end());
    std::vector<std::uint32_t> local;
    return merged_cage(all, local);
  }

  // ----------------------------------------------------------------------------- deformation
  /// Deformed positions of the welded leaf vertices from the deformed positions of every cage
  /// (description order; internal cages included), propagated down the hierarchy (§5.3.4).
  std::vector<Vec3> deformed_leaf_vertices(const std::vector<std::vector<Vec3>>& deformed) const {
    CGAL_precondition(deformed.size() == desc_.cages.size());
    std::vector<std::vector<Vec3>> final(desc_.cages.size());
    for (std::size_t c : order_) {
      const Cage_description& cd = desc_.cages[c];
      CGAL_precondition(deformed[c].size() == cd.rest.vertices.size());
      final[c] = deformed[c];
      for (const auto& l : cd.parents) {
        std::vector<Vec3> basis;
        coords_[l.cage].basis(final[l.cage], basis);
        for (std::uint32_t k : l.vertices)
          final[c][k] = follow_parent(l.cage, basis, cd.rest.vertices[k],
                                      internal::sub(deformed[c][k], cd.rest.vertices[k]));
      }
    }
    std::vector<Vec3> g(gv_.size());
    std::vector<char> set(gv_.size(), 0);
    for (std::size_t c : leaves_)
      for (std::size_t k = 0; k < g_of_[c].size(); ++k) {
        const std::uint32_t v = g_of_[c][k];
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
    CGAL_precondition(leaf_positions.size() == gv_.size());
    std::vector<Vec3> B(leaf_positions), local, b;
    B.resize(K_);
    for (std::size_t c : leaves_) {
      const std::size_t n = g_of_[c].size();
      if (coords_[c].number_of_coordinates() == n) continue;
      local.clear();
      for (std::uint32_t v : g_of_[c]) local.push_back(leaf_positions[v]);
      coords_[c].basis(local, b);
      std::copy(b.begin() + std::ptrdiff_t(n), b.end(), B.begin() + std::ptrdiff_t(cage_col_[c]));
    }
    return B;
  }

  /// The leaf cage a point belongs to (largest winding number; lowest index on ties) and
  /// whether it is inside it.
  std::pair<std::size_t, bool> locate(const Vec3& p) const {
    std::size_t best = leaves_[0];
    double bw = -std::numeric_limits<double>::infinity();
    auto test = [&](std::size_t c) {
      const double w = internal::winding_number(desc_.cages[c].rest, p);
      if (w > bw + 1e-12) {
        bw = w;
        best = c;
      }
    };
    for (std::size_t c : leaves_)
      if (in_box(c, p)) test(c);
    if (bw < 0.5 - 1e-9)
      for (std::size_t c : leaves_)
        if (!in_box(c, p)) test(c);
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
      for (std::size_t k : classes_of_[cage]) {
        const Join_class& cl = classes_[k];
        std::vector<double> x(cl.coords.number_of_coordinates());
        cl.coords.evaluate(p, x.data());
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
        r.d = 1;  // every f(W̄) vanishes: see the header (T_i is the common limit)
        alpha.clear();
      } else {
        for (auto& a : alpha) a.second /= sum;
      }
    }
    // Every term is a combination of the same welded vertices: gather the coefficients per column.
    const std::size_t n = g_of_[cage].size();
    for (std::size_t k = 0; k < w.size(); ++k) {
      const std::size_t col = k < n ? g_of_[cage][k] : cage_col_[cage] + (k - n);
      if (r.d * w[k] != 0) r.entries.push_back({std::uint32_t(col), r.d * w[k]});
    }
    for (std::size_t a = 0; a < alpha.size(); ++a) {
      const Join_class& cl = classes_[alpha[a].first];
      const double s = (1 - r.d) * alpha[a].second;
      for (std::size_t k = 0; k < wbar[a].size(); ++k)
        if (s * wbar[a][k] != 0) r.entries.push_back({cl.global[k], s * wbar[a][k]});
    }
    std::sort(r.entries.begin(), r.entries.end(),
              [](const Entry& x, const Entry& y) { return x.column < y.column; });
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
    if (borders_[cage].empty()) return 1;
    std::vector<double> w(mvc_[cage].number_of_coordinates());
    mvc_[cage].evaluate(p, w.data());
    double x = 1, own = 1;
    auto clamp = [](double y) { return std::min(1.0, std::max(0.0, y)); };
    for (const auto& b : borders_[cage]) {
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
    for (const auto& b : borders_[cage])
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
  static constexpr std::size_t npos = std::size_t(-1);
  // The whole construction (the constructor adds the source to error messages).
  void build() {
    const std::size_t C = desc_.cages.size();
    if (C == 0) throw Invalid_input("a cage system needs at least one cage");
    is_leaf_.assign(C, 1);
    for (const auto& c : desc_.cages)
      for (const auto& l : c.parents) is_leaf_[l.cage] = 0;
    for (std::size_t i = 0; i < C; ++i)
      if (is_leaf_[i]) leaves_.push_back(i);
    leaf_slot_.assign(C, npos);
    for (std::size_t s = 0; s < leaves_.size(); ++s) leaf_slot_[leaves_[s]] = s;
    coords_.resize(C);
    for (std::size_t i = 0; i < C; ++i)
      coords_[i] = make_cage_coordinates(desc_.cages[i].coordinates, desc_.cages[i].rest, desc_.cages[i].harmonic);
    weld_leaves();
    build_borders();
    build_classes();
    topological_order();
    check_ownership();
    // Column layout: one column per welded leaf vertex (every coordinate type puts the deformed
    // vertices first in its basis), then the extra columns of a cage (Green: s_j n'_j per face).
    std::size_t K = gv_.size();
    cage_col_.assign(C, 0);
    for (std::size_t i : leaves_) {
      cage_col_[i] = K;
      K += coords_[i].number_of_coordinates() - desc_.cages[i].rest.vertices.size();
    }
    K_ = K;
  }

  struct Border {
    std::size_t other = 0, triangles = 0;
    std::vector<std::uint32_t> local;  // VB_ij, local indices in this cage
    double h = 0;                      // own h_ij, 0: none (h_i applies)
  };
  struct Join_class {
    std::vector<std::size_t> cages;      // incident cage set (sorted)
    std::vector<std::uint32_t> vertices; // [u], global ids
    Triangle_cage cage;                  // join cage
    std::vector<std::uint32_t> global;   // join cage local -> global
    std::vector<std::uint32_t> local;    // vertices of [u] on the join cage (local ids)
    // When no vertex of [u] lies on the join cage (a vertex surrounded by its cages): per cage
    // outside the join cage sharing faces with it, the local ids of those faces' vertices.
    std::vector<std::vector<std::uint32_t>> bubble;
    Any_cage_coordinates coords;
  };

  bool in_box(std::size_t c, const Vec3& p) const {
    for (int a = 0; a < 3; ++a)
      if (p[a] < box_[c][0][a] || p[a] > box_[c][1][a]) return false;
    return true;
  }
  bool owned_local(std::size_t c, std::size_t k) const { return owned_[c][k] != 0; }

  void weld_leaves() {
    std::map<Vec3, std::uint32_t> id;
    const std::size_t C = desc_.cages.size();
    g_of_.assign(C, {});
    box_.assign(C, {});
    mvc_.resize(C);
    owned_.assign(C, {});
    double L = 0;
    for (std::size_t c : leaves_) L = std::max(L, desc_.cages[c].rest.bbox_diagonal());
    for (std::size_t c = 0; c < C; ++c) {
      const auto& cd = desc_.cages[c];
      owned_[c].assign(cd.rest.vertices.size(), 0);
      for (const auto& l : cd.parents)
        for (std::uint32_t k : l.vertices) owned_[c][k] = 1;
    }
    std::vector<std::pair<std::size_t, std::size_t>> first;  // global -> (cage, local)
    for (std::size_t c : leaves_) {
      const auto& cd = desc_.cages[c];
      mvc_[c] = Any_cage_coordinates(Mean_value_coordinates_3(cd.rest));
      Vec3 lo = cd.rest.vertices[0], hi = lo;
      for (std::size_t k = 0; k < cd.rest.vertices.size(); ++k) {
        const Vec3& p = cd.rest.vertices[k];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
        auto [it, fresh] = id.emplace(p, std::uint32_t(gv_.size()));
        if (fresh) {
          gv_.push_back(p);
          incident_.emplace_back();
          first.push_back({c, k});
        } else if (!owned_[c][k] && !owned_[first[it->second].first][first[it->second].second]) {
          const auto [c0, k0] = first[it->second];
          if (internal::norm(internal::sub(desc_.cages[c0].deformed[k0], cd.deformed[k])) > 1e-9 * L)
            throw Invalid_input("cages " + std::to_string(c0) + " and " + std::to_string(c) +
                                " share rest vertex " + std::to_string(it->second) +
                                " but give it different deformed positions");
        }
        g_of_[c].push_back(it->second);
        if (incident_[it->second].empty() || incident_[it->second].back() != c)
          incident_[it->second].push_back(c);
      }
      const double eps = 1e-9 * std::max(L, 1e-300);
      for (int a = 0; a < 3; ++a) {
        lo[a] -= eps;
        hi[a] += eps;
      }
      box_[c] = {lo, hi};
    }
  }

  static std::array<std::uint32_t, 3> sorted(std::array<std::uint32_t, 3> t) {
    std::sort(t.begin(), t.end());
    return t;
  }
  // +1 / -1: orientation of t relative to its sorted order.
  static int parity(const std::array<std::uint32_t, 3>& t) {
    const auto s = sorted(t);
    for (int r = 0; r < 3; ++r)
      if (t[r] == s[0] && t[(r + 1) % 3] == s[1]) return 1;
    return -1;
  }

  void build_borders() {
    const std::size_t C = desc_.cages.size();
    borders_.assign(C, {});
    std::map<std::array<std::uint32_t, 3>, std::vector<std::pair<std::size_t, int>>> faces;
    for (std::size_t c : leaves_)
      for (const auto& t : desc_.cages[c].rest.triangles) {
        const std::array<std::uint32_t, 3> g{g_of_[c][t[0]], g_of_[c][t[1]], g_of_[c][t[2]]};
        faces[sorted(g)].push_back({c, parity(g)});
      }
    std::map<std::pair<std::size_t, std::size_t>, std::set<std::uint32_t>> vb;
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> count;
    for (const auto& [key, users] : faces) {
      if (users.size() == 1) continue;
      if (users.size() > 2 || users[0].second == users[1].second || users[0].first == users[1].first)
        throw Invalid_input("leaf cages " + std::to_string(users[0].first) + " and " +
                            std::to_string(users[1].first) +
                            " overlap (a face is used twice with the same orientation or by more "
                            "than two cages)");
      for (int s = 0; s < 2; ++s) {
        const auto pr = std::make_pair(users[s].first, users[1 - s].first);
        vb[pr].insert(key.begin(), key.end());
        ++count[pr];
      }
    }
    for (const auto& [pr, verts] : vb) {
      Border b;
      b.other = pr.second;
      b.triangles = count[pr];
      for (std::uint32_t v : verts) {
        const auto& gl = g_of_[pr.first];
        b.local.push_back(std::uint32_t(std::find(gl.begin(), gl.end(), v) - gl.begin()));
      }
      borders_[pr.first].push_back(std::move(b));
    }
    for (std::size_t c = 0; c < desc_.cages.size(); ++c)
      for (const Cage_border_h& bh : desc_.cages[c].border_h) {
        const std::string who = "cage " + std::to_string(c) + ": border h for cage " + std::to_string(bh.cage);
        if (!(bh.h > 0 && bh.h <= 1)) throw Invalid_input(who + ": h must be in (0, 1]");
        if (!is_leaf_[c]) throw Invalid_input(who + ": only leaf cages have borders");
        auto it = std::find_if(borders_[c].begin(), borders_[c].end(),
                               [&](const Border& b) { return b.other == bh.cage; });
        if (it == borders_[c].end()) throw Invalid_input(who + ", which shares no face with it");
        if (it->h > 0) throw Invalid_input(who + " is given twice");
        it->h = bh.h;
      }
  }

  // Union of the given leaf cages, faces shared by two of them removed; `global` gets local ->
  // global ids.
  Triangle_cage merged_cage(const std::vector<std::size_t>& cages, std::vector<std::uint32_t>& global) const {
    std::map<std::array<std::uint32_t, 3>, std::vector<std::array<std::uint32_t, 3>>> faces;
    for (std::size_t c : cages)
      for (const auto& t : desc_.cages[c].rest.triangles) {
        const std::array<std::uint32_t, 3> g{g_of_[c][t[0]], g_of_[c][t[1]], g_of_[c][t[2]]};
        faces[sorted(g)].push_back(g);
      }
    std::map<std::uint32_t, std::uint32_t> local;
    Triangle_cage out;
    global.clear();
    for (const auto& [key, ts] : faces) {
      if (ts.size() != 1) continue;
      std::array<std::uint32_t, 3> t;
      for (int k = 0; k < 3; ++k) {
        auto [it, fresh] = local.emplace(ts[0][k], std::uint32_t(global.size()));
        if (fresh) {
          global.push_back(ts[0][k]);
          out.vertices.push_back(gv_[ts[0][k]]);
        }
        t[k] = it->second;
      }
      out.triangles.push_back(t);
    }
    return out;
  }

  void build_classes() {
    const std::size_t C = desc_.cages.size();
    classes_of_.assign(C, {});
    std::map<std::vector<std::size_t>, std::size_t> by_set;
    std::vector<char> boundary(gv_.size(), 0);
    for (std::size_t c : leaves_)
      for (const auto& b : borders_[c])
        for (std::uint32_t l : b.local) boundary[g_of_[c][l]] = 1;
    for (std::uint32_t v = 0; v < gv_.size(); ++v) {
      if (!boundary[v]) continue;
      auto [it, fresh] = by_set.emplace(incident_[v], classes_.size());
      if (fresh) {
        classes_.emplace_back();
        classes_.back().cages = incident_[v];
      }
      classes_[it->second].vertices.push_back(v);
    }
    for (std::size_t k = 0; k < classes_.size(); ++k) {
      Join_class& cl = classes_[k];
      cl.cage = merged_cage(cl.cages, cl.global);
      for (std::uint32_t v : cl.vertices) {
        auto it = std::find(cl.global.begin(), cl.global.end(), v);
        if (it != cl.global.end()) cl.local.push_back(std::uint32_t(it - cl.global.begin()));
      }
      if (cl.local.empty()) {
        std::set<std::array<std::uint32_t, 3>> surface;
        for (const auto& t : cl.cage.triangles) surface.insert(sorted({cl.global[t[0]], cl.global[t[1]], cl.global[t[2]]}));
        for (std::size_t j : leaves_) {
          if (std::binary_search(cl.cages.begin(), cl.cages.end(), j)) continue;
          std::set<std::uint32_t> group;
          for (const auto& t : desc_.cages[j].rest.triangles) {
            const auto key = sorted({g_of_[j][t[0]], g_of_[j][t[1]], g_of_[j][t[2]]});
            if (!surface.count(key)) continue;
            for (std::uint32_t g : key)
              group.insert(std::uint32_t(std::find(cl.global.begin(), cl.global.end(), g) - cl.global.begin()));
          }
          if (!group.empty()) cl.bubble.emplace_back(group.begin(), group.end());
        }
      }
      cl.coords = make_cage_coordinates(desc_.join_coordinates, cl.cage, desc_.join_harmonic);
      for (std::size_t c : cl.cages) classes_of_[c].push_back(k);
    }
  }

  void topological_order() {
    // Parents before children (the links were checked acyclic by the reader; re-checked here
    // for hand-made descriptions).
    const std::size_t C = desc_.cages.size();
    std::vector<int> indeg(C, 0);
    std::vector<std::vector<std::size_t>> children(C);
    for (std::size_t c = 0; c < C; ++c)
      for (const auto& l : desc_.cages[c].parents) {
        if (l.cage >= C || l.cage == c) throw Invalid_input("cage " + std::to_string(c) + ": bad parent link");
        children[l.cage].push_back(c);
        ++indeg[c];
      }
    std::vector<std::size_t> q;
    for (std::size_t c = 0; c < C; ++c)
      if (!indeg[c]) q.push_back(c);
    for (std::size_t i = 0; i < q.size(); ++i)
      for (std::size_t ch : children[q[i]])
        if (--indeg[ch] == 0) q.push_back(ch);
    if (q.size() != C) throw Invalid_input("the parent links of the cage system form a cycle");
    order_ = q;
  }

  void check_ownership() {
    // A welded leaf vertex has at most one parent; every owned rest vertex must have defined
    // coordinates in its parent.
    std::vector<std::size_t> parent_of(gv_.size(), npos);
    for (std::size_t c = 0; c < desc_.cages.size(); ++c)
      for (const auto& l : desc_.cages[c].parents)
        for (std::uint32_t k : l.vertices) {
          std::vector<double> w(coords_[l.cage].number_of_coordinates());
          if (coords_[l.cage].evaluate(desc_.cages[c].rest.vertices[k], w.data()) ==
              Coordinate_status::undefined)
            throw Invalid_input("cage " + std::to_string(c) + " vertex " + std::to_string(k) +
                                " lies outside its parent cage " + std::to_string(l.cage) +
                                ", whose coordinates are undefined there");
          if (!is_leaf_[c]) continue;
          std::size_t& p = parent_of[g_of_[c][k]];
          if (p != npos && p != l.cage)
            throw Invalid_input("leaf vertex " + std::to_string(g_of_[c][k]) +
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
    if (coords_[parent].evaluate(internal::add(r, t), w.data()) != Coordinate_status::undefined)
      return apply(basis, w);
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
  std::vector<char> is_leaf_;
  std::vector<std::size_t> leaves_, leaf_slot_, order_, cage_col_;
  std::vector<Any_cage_coordinates> coords_;
  std::vector<Any_cage_coordinates> mvc_;  // w_i of d_i (leaf cages)
  std::vector<std::array<Vec3, 2>> box_;
  std::vector<Vec3> gv_;
  std::vector<std::vector<std::uint32_t>> g_of_;
  std::vector<std::vector<char>> owned_;
  std::vector<std::vector<std::size_t>> incident_;
  std::vector<std::vector<Border>> borders_;
  std::vector<Join_class> classes_;
  std::vector<std::vector<std::size_t>> classes_of_;
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
  out.b_ = Cage_binding<Weight>::from_sparse_rows(K_, std::move(row_start), std::move(columns),
                                                  std::move(values), std::move(status),
                                                  Weight_storage::grouped);
  progress.finish();
  return out;
}

/// A lattice of nx × ny × nz box cages around [lo, hi] (thesis §5.3 on any model, no authored
/// cages): shared faces are split along the diagonal through their lowest-numbered lattice
/// vertex, identically in both cells, so neighbours share triangles. Deformed = rest.
inline Cage_system_description make_grid_cage_system(const Vec3& lo, const Vec3& hi, int nx, int ny, int nz,
                                                     Coordinate_type type = Coordinate_type::mean_value,
                                                     double h = 1.0) {
  if (nx < 1 || ny < 1 || nz < 1 || nx * ny * nz > 4096)
    throw Invalid_input("grid cage system: cell counts must be >= 1 and at most 4096 cells in all");
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] > lo[a]) || !std::isfinite(lo[a]) || !std::isfinite(hi[a]))
      throw Invalid_input("grid cage system: the box must have a positive, finite size along each axis");
  const int n[3] = {nx, ny, nz};
  auto id = [&](int i, int j, int k) { return std::uint32_t((k * (ny + 1) + j) * (nx + 1) + i); };
  auto pos = [&](int i, int j, int k) {
    const int q[3] = {i, j, k};
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = q[a] == n[a] ? hi[a] : lo[a] + (hi[a] - lo[a]) * q[a] / n[a];
    return p;
  };
  Cage_system_description d;
  d.source = "grid";
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        Cage_description c;
        c.name = "cell_" + std::to_string(i) + "_" + std::to_string(j) + "_" + std::to_string(k);
        c.rest_source = "grid";
        std::vector<std::uint32_t> gid;
        for (int c3 = 0; c3 < 8; ++c3) {
          const int di = c3 & 1, dj = (c3 >> 1) & 1, dk = (c3 >> 2) & 1;
          c.rest.vertices.push_back(pos(i + di, j + dj, k + dk));
          gid.push_back(id(i + di, j + dj, k + dk));
        }
        // Outward quads (local corner bits x = 1, y = 2, z = 4), counter-clockwise from outside.
        const std::array<std::array<std::uint32_t, 4>, 6> quads{{{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                                                  {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}};
        for (const auto& q : quads) {
          int s = 0;  // start the fan at the corner with the smallest lattice id
          for (int r = 1; r < 4; ++r)
            if (gid[q[r]] < gid[q[s]]) s = r;
          const std::uint32_t a = q[s], b = q[(s + 1) % 4], cc = q[(s + 2) % 4], e = q[(s + 3) % 4];
          c.rest.triangles.push_back({a, b, cc});
          c.rest.triangles.push_back({a, cc, e});
        }
        validate_cage(c.rest, c.name, Cage_orientation::require_outward);
        c.deformed = c.rest.vertices;
        c.coordinates = type;
        c.h = h;
        d.cages.push_back(std::move(c));
      }
  return d;
}

/// The grid of box cages around the bounding box of `points` (a range of CGAL points or
/// 3-arrays), enlarged on every side by `margin` times its diagonal (a flat model still gets
/// cages of positive thickness).
template <class PointRange>
Cage_system_description make_grid_cage_system(const PointRange& points, int nx, int ny, int nz,
                                              double margin = 0.05,
                                              Coordinate_type type = Coordinate_type::mean_value,
                                              double h = 1.0) {
  if (std::begin(points) == std::end(points)) throw Invalid_input("grid cage system: no points");
  if (!(margin >= 0 && margin <= 10)) throw Invalid_input("grid cage system: the margin must be in [0, 10]");
  Vec3 lo = internal::to_vec3(*std::begin(points)), hi = lo;
  for (const auto& q : points) {
    const Vec3 p = internal::to_vec3(q);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  }
  double diag = internal::norm(internal::sub(hi, lo));
  if (!(diag > 0) || !std::isfinite(diag)) throw Invalid_input("grid cage system: the points have no extent");
  const double e = std::max(margin * diag, 1e-6 * diag);
  for (int a = 0; a < 3; ++a) {
    lo[a] -= e;
    hi[a] += e;
  }
  return make_grid_cage_system(lo, hi, nx, ny, nz, type, h);
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_H
