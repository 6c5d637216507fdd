// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Chart-constrained edge collapses on a mesh with per-corner texture coordinates (thesis §3.5):
// Chart_constraints (test(): the three topological rules of §3.5, the UV placement of the kept
// vertex by the closed form of §3.5, no UV fold, and the bijectivity of the projections onto the
// tangent plane, §3.2/§3.5), Chart_constraint_filter (CGAL's PlacementFilter) and
// Chart_constraint_visitor (rewrites the corner UVs after a collapse and hands the Collapse_record
// to a texture resampler, §3.6). The filter and visitor run under CMGeom's engine and CGAL's.
// Key choices where the thesis is silent: a vertex "lies on more than two charts" when it has more
// than two chart-boundary edges (a chart corner) or faces in more than two UV wedges, and chart
// corners never move (the chart count is kept); charts only shrink inside their original UV
// region; a folding UV placement first falls back to the UVs of v1, of v0 and the midpoint.
// Complexity: O(deg(v0) + deg(v1)) per test and UV update.
//
// Manual: doc/Textured_simplification/README.md, "What happens at each collapse".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_CHART_CONSTRAINTS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_CHART_CONSTRAINTS_H

#include <CMGeom/config.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Textured_simplification/edge_collapse.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>

#include <CGAL/boost/graph/helpers.h>
#include <CGAL/boost/graph/iterator.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <type_traits>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

using UV2 = std::array<double, 2>;

/// One triangle of the star of a collapsed edge, before the collapse.
struct Star_triangle {
  std::array<internal::Vec3, 3> p;  ///< positions, in face order
  std::array<UV2, 3> uv;            ///< corner UVs, in face order
  int moving_corner = -1;           ///< corner at v0 or v1 (-1: the face holds both: removed)
  int wedge = 0;                    ///< 0 or 1: the chart side of the edge it belongs to
  bool removed = false;             ///< one of the (one or two) faces incident to the edge
  bool unchanged = false;           ///< half-edge collapse: a face of the kept vertex in another
                                    ///< wedge; neither its positions nor its UVs change
};

/// Everything the texture resampling of §3.6 needs about one accepted collapse.
struct Collapse_record {
  std::vector<Star_triangle> star;      ///< every face incident to v0 or v1, before the collapse
  internal::Vec3 placement{{0, 0, 0}};  ///< 3D position of the kept vertex
  std::array<UV2, 2> new_uv{};          ///< UV of the kept vertex in wedge 0 / wedge 1
  int wedges = 1;
  internal::Vec3 normal{{0, 0, 1}};  ///< normal of the tangent plane π (unit)
  bool chart_boundary_edge = false;

  /// The new triangle t' made from star triangle `k` (precondition: !star[k].removed).
  std::array<internal::Vec3, 3> new_positions(std::size_t k) const {
    auto p = star[k].p;
    p[star[k].moving_corner] = placement;
    return p;
  }
  std::array<UV2, 3> new_uvs(std::size_t k) const {
    auto t = star[k].uv;
    if (!star[k].unchanged) t[star[k].moving_corner] = new_uv[star[k].wedge];
    return t;
  }
};

/// Options of the chart constraints.
struct Chart_constraint_options {
  /// Tangent-plane bijectivity test of §3.5 (needed for the texture resampling of §3.6).
  bool bijectivity = true;
  /// Baseline mode: chart-boundary vertices never move (seams frozen, as other simplifiers do);
  /// only interior edges of charts are collapsed.
  bool freeze_chart_boundaries = false;
  /// Extension of §3.5 (rule 1 forbids it): an edge from a chart-interior vertex to a
  /// chart-boundary vertex may be collapsed as a half-edge collapse onto the boundary vertex (its
  /// position and UVs are kept, so no chart boundary changes). Without it a chart keeps at least
  /// the interior vertices whose neighbours are all on its boundary. Needs an engine that uses the
  /// placement returned by the filter (CMGeom's does; CGAL 5.5.1's ignores it: keep this off there).
  bool boundary_half_edge_collapses = true;
};

/// Counters of refused collapses, by reason.
struct Chart_constraint_statistics {
  std::size_t accepted = 0, topology = 0, uv_fold = 0, projection_overlap = 0, degenerate = 0;
};

template <class TriangleMesh, class VertexPointMap, class UVMap>
class Chart_constraints {
public:
  using GT = boost::graph_traits<TriangleMesh>;
  using vertex_descriptor = typename GT::vertex_descriptor;
  using halfedge_descriptor = typename GT::halfedge_descriptor;
  using face_descriptor = typename GT::face_descriptor;
  using Vec3 = internal::Vec3;

  Chart_constraints(TriangleMesh& tm, VertexPointMap vpm, UVMap uv,
                    const Chart_constraint_options& options = Chart_constraint_options())
      : tm_(tm), vpm_(vpm), uv_(uv), options_(options) {}

  /// §3.5: may `h` (v0 -> v1) be collapsed with its kept vertex at `x`? On success the record of
  /// the collapse (record()) is filled, and the collapse must follow before the next test().
  bool test(halfedge_descriptor h, const Vec3& x) {
    ok_ = false;
    rec_.star.clear();
    const halfedge_descriptor o = opposite(h, tm_);
    const vertex_descriptor v0 = source(h, tm_), v1 = target(h, tm_);
    const bool cb = is_chart_boundary_edge(edge(h, tm_), tm_, uv_);
    const std::size_t n0 = number_of_chart_boundary_edges(v0, tm_, uv_);
    const std::size_t n1 = number_of_chart_boundary_edges(v1, tm_, uv_);
    // the three topological rules of §3.5 (see the header comment for "more than two charts")
    if (cb) {
      if (n0 != 2 || n1 != 2 || options_.freeze_chart_boundaries) return refuse(stats_.topology);
    } else if (n0 != 0 && n1 != 0) {
      return refuse(stats_.topology);
    } else if ((n0 != 0 || n1 != 0) && !options_.boundary_half_edge_collapses) {
      return refuse(stats_.topology);
    }
    // half-edge collapse onto the chart-boundary endpoint (interior edge, one end on a boundary)
    const bool half_edge = !cb && (n0 != 0 || n1 != 0);
    const vertex_descriptor v_fixed = n0 != 0 ? v0 : v1;
    // star faces, with their wedge (chart side) label
    const face_descriptor fL = is_border(h, tm_) ? GT::null_face() : face(h, tm_);
    const face_descriptor fR = is_border(o, tm_) ? GT::null_face() : face(o, tm_);
    faces_.clear();
    labels_.clear();
    auto add_faces_around = [&](vertex_descriptor v) {
      for (halfedge_descriptor g : CGAL::halfedges_around_target(v, tm_)) {
        if (is_border(g, tm_)) continue;
        const face_descriptor f = face(g, tm_);
        bool known = false;
        for (face_descriptor k : faces_) known |= k == f;
        if (!known) {
          faces_.push_back(f);
          labels_.push_back(-1);
        }
      }
    };
    add_faces_around(v0);
    add_faces_around(v1);
    auto label_of = [&](face_descriptor f) -> int& {
      for (std::size_t i = 0; i < faces_.size(); ++i)
        if (faces_[i] == f) return labels_[i];
      return labels_[0];  // unreachable: f is in the star
    };
    // flood each side around v0 and around v1 across edges that are not chart boundaries
    bool conflict = false;
    auto flood = [&](face_descriptor seed, int label) {
      if (seed == GT::null_face()) return;
      if (label_of(seed) != -1) {
        conflict = true;
        return;
      }
      label_of(seed) = label;
      for (vertex_descriptor v : {v0, v1}) {
        bool changed = true;
        while (changed) {
          changed = false;
          for (halfedge_descriptor g : CGAL::halfedges_around_target(v, tm_)) {
            // g ends at v: the edge of g separates face(g) and face(opposite(g))
            if (is_border(g, tm_) || is_border(opposite(g, tm_), tm_)) continue;
            if (is_chart_boundary_edge(edge(g, tm_), tm_, uv_)) continue;
            int& a = label_of(face(g, tm_));
            int& b = label_of(face(opposite(g, tm_), tm_));
            if (a == label && b != label) {
              if (b != -1) {
                conflict = true;
                return;
              }
              b = label;
              changed = true;
            } else if (b == label && a != label) {
              if (a != -1) {
                conflict = true;
                return;
              }
              a = label;
              changed = true;
            }
          }
        }
      }
    };
    const bool seam = cb && fL != GT::null_face() && fR != GT::null_face();
    flood(fL != GT::null_face() ? fL : fR, 0);
    if (seam) flood(fR, 1);
    if (conflict) return refuse(stats_.topology);  // the two sides are one UV wedge
    for (int& l : labels_) {
      if (l >= 0) continue;
      if (!half_edge) return refuse(stats_.topology);  // more than two UV wedges around v0 or v1
      l = 2;                                           // a face of the fixed vertex in another wedge: unchanged
    }

    // record the star
    rec_.wedges = seam ? 2 : 1;
    rec_.placement = half_edge ? internal::to_vec3(get(vpm_, v_fixed)) : x;
    rec_.chart_boundary_edge = cb;
    Vec3 nsum{{0, 0, 0}};
    verts_.clear();
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      Star_triangle t;
      std::array<vertex_descriptor, 3> vs;
      halfedge_descriptor g = halfedge(faces_[i], tm_);
      int moving = 0;
      for (int c = 0; c < 3; ++c, g = next(g, tm_)) {
        const vertex_descriptor w = target(g, tm_);
        vs[c] = w;
        t.p[c] = internal::to_vec3(get(vpm_, w));
        const auto q = get(uv_, g);
        t.uv[c] = {{CGAL::to_double(q.x()), CGAL::to_double(q.y())}};
        if (w == v0 || w == v1) {
          ++moving;
          t.moving_corner = c;
        }
      }
      t.removed = moving == 2;
      if (t.removed) t.moving_corner = -1;
      t.wedge = labels_[i] == 2 ? 0 : labels_[i];
      t.unchanged = labels_[i] == 2;
      nsum = internal::add(nsum, internal::cross(internal::sub(t.p[1], t.p[0]), internal::sub(t.p[2], t.p[0])));
      rec_.star.push_back(t);
      verts_.push_back(vs);
    }
    const double nn = internal::norm(nsum);
    if (!(nn > 0)) return refuse(stats_.degenerate);
    rec_.normal = internal::scale(nsum, 1.0 / nn);

    if (half_edge) {
      // the kept UV is the fixed vertex's in the wedge of the edge's faces
      const halfedge_descriptor hf = fL != GT::null_face() ? h : o;  // in a face of the edge
      const UV2 u = target(hf, tm_) == v_fixed ? to_uv(get(uv_, hf)) : to_uv(get(uv_, prev(hf, tm_)));
      if (!place_uv(0, false, u, u, &u)) return refuse(stats_.uv_fold);
      // the engine tested fold-overs at the policy's placement; this is another one
      if (internal::collapse_flips_a_face(tm_, vpm_, h, rec_.placement)) return refuse(stats_.degenerate);
    }
    // UV placement, one wedge at a time
    for (int w = 0; w < (half_edge ? 0 : rec_.wedges); ++w) {
      const face_descriptor fw = w == 0 ? (fL != GT::null_face() ? fL : fR) : fR;
      wedge_face_[w] = fw;
      const halfedge_descriptor hw = (fw == fL) ? h : o;  // halfedge of e in face fw
      // corners of v0 / v1 in fw: target(hw) and target(prev(hw))... hw goes a -> b
      UV2 ua = to_uv(get(uv_, prev(hw, tm_))), ub = to_uv(get(uv_, hw));
      // chart-boundary edge: the boundary neighbours p (before x = source(hw)) and q (after
      // y = target(hw)) along the chart boundary, with their UVs in this wedge
      if (cb) {
        if (!boundary_neighbour_uv(source(hw, tm_), edge(h, tm_), w, bp_[w]) ||
            !boundary_neighbour_uv(target(hw, tm_), edge(h, tm_), w, bq_[w]))
          return refuse(stats_.topology);
      }
      if (!place_uv(w, cb, ua, ub)) return refuse(stats_.uv_fold);
    }
    if (options_.bijectivity && !projections_are_bijective(v0, v1)) return refuse(stats_.projection_overlap);
    ok_ = true;
    pending_ = h;
    ++stats_.accepted;
    return true;
  }

  /// Rewrites the corner UVs of the faces around the kept vertex (call right after the collapse
  /// of the edge last accepted by test()).
  void apply(vertex_descriptor v_kept) {
    if (!ok_) return;
    ok_ = false;
    for (std::size_t i = 0; i < faces_.size(); ++i) {
      const Star_triangle& t = rec_.star[i];
      if (t.removed) continue;
      const face_descriptor f = faces_[i];
      halfedge_descriptor g = halfedge(f, tm_);
      for (int c = 0; c < 3; ++c, g = next(g, tm_)) {
        const vertex_descriptor w = target(g, tm_);
        UV2 u = t.unchanged ? t.uv[t.moving_corner] : rec_.new_uv[t.wedge];
        if (w != v_kept) {
          // the corner of an unmoved vertex keeps its old UV in this face
          for (int k = 0; k < 3; ++k)
            if (k != t.moving_corner && verts_[i][k] == w) u = t.uv[k];
        }
        put(uv_, g, typename boost::property_traits<UVMap>::value_type(u[0], u[1]));
      }
    }
  }

  /// Region test for concave boundary corners: `f(sliver, face)` says whether the chart of
  /// `face` may grow by the UV triangle `sliver` (default: never, charts only shrink).
  void set_growth_test(std::function<bool(const std::array<UV2, 3>&, face_descriptor)> f) { may_grow_ = std::move(f); }

  const Collapse_record& record() const { return rec_; }
  const Chart_constraint_statistics& statistics() const { return stats_; }
  TriangleMesh& mesh() const { return tm_; }

private:
  template <class P>
  static UV2 to_uv(const P& p) {
    return {{CGAL::to_double(p.x()), CGAL::to_double(p.y())}};
  }
  static double cross2(const UV2& a, const UV2& b, const UV2& c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  }
  bool refuse(std::size_t& counter) {
    ++counter;
    return false;
  }

  /// UV, in wedge w, of the other end of the chart-boundary edge at `x` that is not `e`.
  bool boundary_neighbour_uv(vertex_descriptor x, typename GT::edge_descriptor e, int w, UV2& out) const {
    for (halfedge_descriptor g : CGAL::halfedges_around_target(x, tm_)) {
      if (edge(g, tm_) == e || !is_chart_boundary_edge(edge(g, tm_), tm_, uv_)) continue;
      // g: p -> x. The corner of p in face(g) is prev(g); in face(opposite(g)) it is opposite(g).
      const halfedge_descriptor og = opposite(g, tm_);
      if (!is_border(g, tm_) && wedge_label(face(g, tm_)) == w) {
        out = to_uv(get(uv_, prev(g, tm_)));
        return true;
      }
      if (!is_border(og, tm_) && wedge_label(face(og, tm_)) == w) {
        out = to_uv(get(uv_, og));
        return true;
      }
    }
    return false;
  }
  int wedge_label(face_descriptor f) const {
    for (std::size_t i = 0; i < faces_.size(); ++i)
      if (faces_[i] == f) return labels_[i];
    return -1;
  }

  /// §3.5 placement for wedge w; ua/ub: UVs of v0/v1 in the wedge's face on the edge.
  bool place_uv(int w, bool on_boundary, const UV2& ua, const UV2& ub, const UV2* forced = nullptr) {
    // orientation and area of the old texture triangles of the wedge
    double area_u = 0;
    int sign = 0;
    for (const Star_triangle& t : rec_.star) {
      if (t.wedge != w || t.unchanged) continue;
      const double a = cross2(t.uv[0], t.uv[1], t.uv[2]);
      const int s = a > 0 ? 1 : (a < 0 ? -1 : 0);
      if (s == 0) return false;
      if (sign == 0) sign = s;
      if (s != sign) return false;
      area_u += 0.5 * std::abs(a);
    }
    if (!(area_u > 0)) return false;
    // relative 3D areas a_j of the new triangles of the wedge
    double total3 = 0;
    areas_.clear();
    for (std::size_t k = 0; k < rec_.star.size(); ++k) {
      const Star_triangle& t = rec_.star[k];
      if (t.wedge != w || t.removed || t.unchanged) continue;
      const auto p = rec_.new_positions(k);
      const double a = 0.5 * internal::norm(internal::cross(internal::sub(p[1], p[0]), internal::sub(p[2], p[0])));
      areas_.push_back(a);
      total3 += a;
    }
    if (areas_.empty() || !(total3 > 0)) return false;
    if (forced) {
      if (!uv_fan_is_valid(w, sign, area_u, *forced)) return false;
      rec_.new_uv[w] = *forced;
      return true;
    }
    // ā_j(x) = s·½ cross(b2 − b1, x − b1) / A_U = g_j·x + c_j; residual (ā_j/a_j − 1).
    // Rows k_j = g_j/a_j, right-hand side β_j = 1 − c_j/a_j (least squares).
    double m00 = 0, m01 = 0, m11 = 0, r0 = 0, r1 = 0;  // normal equations (free)
    rows_.clear();
    std::size_t j = 0;
    for (const Star_triangle& t : rec_.star) {
      if (t.wedge != w || t.removed || t.unchanged) continue;
      const double aj = areas_[j++] / total3;
      if (!(aj > 0)) return false;
      const UV2& b1 = t.uv[(t.moving_corner + 1) % 3];
      const UV2& b2 = t.uv[(t.moving_corner + 2) % 3];
      // triangle (x, b1, b2) in face order: area = ½ cross(b1 − x, b2 − x) = ½ cross(b2 − b1, x − b1)
      const double dx = b2[0] - b1[0], dy = b2[1] - b1[1];
      const double s = 0.5 * double(sign) / area_u / aj;
      const double gx = -dy * s, gy = dx * s;
      const double c = (dy * b1[0] - dx * b1[1]) * s;
      const double beta = 1.0 - c;
      rows_.push_back({{gx, gy, beta}});
      m00 += gx * gx;
      m01 += gx * gy;
      m11 += gy * gy;
      r0 += gx * beta;
      r1 += gy * beta;
    }
    UV2 candidates[5];
    int nc = 0;
    if (on_boundary) {
      // x = ua + t (ub − ua), t in [0, 1]
      const double Dx = ub[0] - ua[0], Dy = ub[1] - ua[1];
      double num = 0, den = 0;
      for (const auto& r : rows_) {
        const double kd = r[0] * Dx + r[1] * Dy;
        num += kd * (r[2] - (r[0] * ua[0] + r[1] * ua[1]));
        den += kd * kd;
      }
      double t = den > 0 ? num / den : 0.5;
      t = t < 0 ? 0 : (t > 1 ? 1 : t);
      // The chart may only shrink: moving x (t > 0) or y (t < 1) along ē cuts the boundary corner
      // at that vertex, which stays inside the old chart only if the corner is convex. So charts
      // never leave their original UV region, and the index texture never writes over another
      // chart's texels (the thesis asks for empty texture near concave boundaries instead).
      // a concave corner may still be cut when the caller's region test accepts the sliver
      // (p, x, y) / (x, y, q) the chart would grow by (e.g. it stays within the chart's own texels)
      const bool x_convex =
          double(sign) * cross2(bp_[w], ua, ub) >= 0 || (may_grow_ && may_grow_({{bp_[w], ua, ub}}, wedge_face_[w]));
      const bool y_convex =
          double(sign) * cross2(ua, ub, bq_[w]) >= 0 || (may_grow_ && may_grow_({{ua, ub, bq_[w]}}, wedge_face_[w]));
      if (x_convex && y_convex) candidates[nc++] = {{ua[0] + t * Dx, ua[1] + t * Dy}};
      if (x_convex) candidates[nc++] = ub;  // x moves onto y
      if (y_convex) candidates[nc++] = ua;
      if (x_convex && y_convex) candidates[nc++] = {{0.5 * (ua[0] + ub[0]), 0.5 * (ua[1] + ub[1])}};
    } else {
      const double det = m00 * m11 - m01 * m01;
      if (std::abs(det) > 1e-12 * (m00 * m11 + m01 * m01) && det != 0)
        candidates[nc++] = {{(r0 * m11 - r1 * m01) / det, (m00 * r1 - m01 * r0) / det}};
    }
    if (!on_boundary) {
      candidates[nc++] = ub;
      candidates[nc++] = ua;
      candidates[nc++] = {{0.5 * (ua[0] + ub[0]), 0.5 * (ua[1] + ub[1])}};
    }
    for (int i = 0; i < nc; ++i) {
      if (!std::isfinite(candidates[i][0]) || !std::isfinite(candidates[i][1])) continue;
      if (uv_fan_is_valid(w, sign, area_u, candidates[i])) {
        rec_.new_uv[w] = candidates[i];
        return true;
      }
    }
    return false;
  }

  /// No new texture triangle of wedge w folds or degenerates (with the wedge's old orientation,
  /// a fan of positively oriented triangles over the old wedge's link cannot overlap itself).
  bool uv_fan_is_valid(int w, int sign, double area_u, const UV2& x) const {
    double sum = 0;
    for (const Star_triangle& t : rec_.star) {
      if (t.wedge != w || t.removed || t.unchanged) continue;
      auto uv = t.uv;
      uv[t.moving_corner] = x;
      const double a = 0.5 * cross2(uv[0], uv[1], uv[2]) * double(sign);
      if (!(a > 1e-12 * area_u)) return false;
      sum += a;
    }
    // interior wedge: the fan tiles the old region exactly (same link polygon)
    return rec_.wedges == 2 || rec_.chart_boundary_edge || std::abs(sum - area_u) <= 1e-9 * area_u + 1e-300;
  }

  /// §3.5: the orthogonal projections onto π of the old and of the new triangles do not overlap.
  bool projections_are_bijective(vertex_descriptor v0, vertex_descriptor v1) const {
    const Vec3& n = rec_.normal;
    // frame of π
    Vec3 a = std::abs(n[0]) < 0.9 ? Vec3{{1, 0, 0}} : Vec3{{0, 1, 0}};
    Vec3 e1 = internal::cross(n, a);
    e1 = internal::scale(e1, 1.0 / internal::norm(e1));
    const Vec3 e2 = internal::cross(n, e1);
    auto proj = [&](const Vec3& p) { return UV2{{internal::dot(p, e1), internal::dot(p, e2)}}; };
    double scale2 = 0;
    for (const Star_triangle& t : rec_.star)
      for (int c = 0; c < 3; ++c) {
        const Vec3 d = internal::sub(t.p[c], rec_.placement);
        scale2 = (std::max)(scale2, internal::dot(d, d));
      }
    const double eps = 1e-12 * scale2;
    double angle0 = 0, angle1 = 0, angle_new = 0;
    auto angle_at = [](const UV2& o, const UV2& b, const UV2& c) {
      const double x1 = b[0] - o[0], y1 = b[1] - o[1], x2 = c[0] - o[0], y2 = c[1] - o[1];
      return std::atan2(x1 * y2 - y1 * x2, x1 * x2 + y1 * y2);
    };
    for (std::size_t k = 0; k < rec_.star.size(); ++k) {
      const Star_triangle& t = rec_.star[k];
      const UV2 q[3] = {proj(t.p[0]), proj(t.p[1]), proj(t.p[2])};
      if (!(cross2(q[0], q[1], q[2]) > eps)) return false;
      for (int c = 0; c < 3; ++c) {
        const double ang = angle_at(q[c], q[(c + 1) % 3], q[(c + 2) % 3]);
        if (verts_[k][c] == v0) angle0 += ang;
        if (verts_[k][c] == v1) angle1 += ang;
      }
      if (t.removed) continue;
      const auto np = rec_.new_positions(k);
      const UV2 r[3] = {proj(np[0]), proj(np[1]), proj(np[2])};
      if (!(cross2(r[0], r[1], r[2]) > eps)) return false;
      const int c = t.moving_corner;
      angle_new += angle_at(r[c], r[(c + 1) % 3], r[(c + 2) % 3]);
    }
    const double two_pi = 6.283185307179586;
    auto closed = [&](vertex_descriptor v) { return !CGAL::is_border(v, tm_); };
    if (closed(v0) && std::abs(angle0 - two_pi) > 0.5) return false;
    if (closed(v1) && std::abs(angle1 - two_pi) > 0.5) return false;
    if (closed(v0) && closed(v1) && std::abs(angle_new - two_pi) > 0.5) return false;
    return true;
  }

  TriangleMesh& tm_;
  VertexPointMap vpm_;
  UVMap uv_;
  Chart_constraint_options options_;
  Chart_constraint_statistics stats_;
  Collapse_record rec_;
  std::vector<face_descriptor> faces_;
  std::vector<int> labels_;
  std::vector<std::array<vertex_descriptor, 3>> verts_;
  UV2 bp_[2], bq_[2];
  face_descriptor wedge_face_[2];
  std::function<bool(const std::array<UV2, 3>&, face_descriptor)> may_grow_;
  std::vector<double> areas_;
  std::vector<std::array<double, 3>> rows_;
  halfedge_descriptor pending_;
  bool ok_ = false;
};

/// PlacementFilter calling Chart_constraints::test() (CGAL's concept).
template <class CC>
struct Chart_constraint_filter {
  CC* cc = nullptr;
  Chart_constraint_filter() = default;
  explicit Chart_constraint_filter(CC& c) : cc(&c) {}
  template <class Profile, class Placement>
  Placement operator()(const Profile& p, const Placement& pl) const {
    if (!pl) return pl;
    if (!cc->test(p.v0_v1(), internal::to_vec3(*pl))) return Placement();
    const auto& x = cc->record().placement;  // differs from *pl for half-edge collapses
    using Point = std::decay_t<decltype(*pl)>;
    return Placement(Point(x[0], x[1], x[2]));
  }
};

/// Does nothing with a collapse record.
struct No_resampling {
  void operator()(const Collapse_record&) const {}
};

/// EdgeCollapseSimplificationVisitor: after each collapse, hands the record to `resample`
/// (which sees the old UVs in the record), then rewrites the corner UVs; forwards every call to
/// `inner` (e.g. a progress visitor).
template <class CC, class Resampler = No_resampling, class Inner = Edge_collapse_visitor_base>
struct Chart_constraint_visitor : Edge_collapse_visitor_base {
  CC* cc = nullptr;
  Resampler* resample = nullptr;
  Inner inner;
  Chart_constraint_visitor() = default;
  Chart_constraint_visitor(CC& c, Resampler* r, Inner in = Inner()) : cc(&c), resample(r), inner(in) {}
  template <class TM>
  void OnStarted(TM& tm) {
    inner.OnStarted(tm);
  }
  template <class TM>
  void OnFinished(TM& tm) {
    inner.OnFinished(tm);
  }
  template <class Profile>
  void OnStopConditionReached(const Profile& p) {
    inner.OnStopConditionReached(p);
  }
  template <class Profile, class OFT>
  void OnCollected(const Profile& p, const OFT& c) {
    inner.OnCollected(p, c);
  }
  template <class Profile, class OFT, class S>
  void OnSelected(const Profile& p, const OFT& c, S a, S b) {
    inner.OnSelected(p, c, a, b);
  }
  template <class Profile, class OP>
  void OnCollapsing(const Profile& p, const OP& pl) {
    inner.OnCollapsing(p, pl);
  }
  template <class Profile>
  void OnNonCollapsable(const Profile& p) {
    inner.OnNonCollapsable(p);
  }
  template <class Profile, class V>
  void OnCollapsed(const Profile& p, const V& v) {
    if (resample) (*resample)(cc->record());
    cc->apply(v);
    inner.OnCollapsed(p, v);
  }
};

template <class TriangleMesh, class VertexPointMap, class UVMap>
Chart_constraint_filter<Chart_constraints<TriangleMesh, VertexPointMap, UVMap>> make_chart_constraint_filter(
    Chart_constraints<TriangleMesh, VertexPointMap, UVMap>& cc) {
  return Chart_constraint_filter<Chart_constraints<TriangleMesh, VertexPointMap, UVMap>>(cc);
}

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_CHART_CONSTRAINTS_H
