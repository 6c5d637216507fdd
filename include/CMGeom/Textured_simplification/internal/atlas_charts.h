// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Internal steps of rebuild_atlas() (rebuild_atlas.h): charts grown over a simplified mesh,
// each parameterised by LSCM (CGAL Surface_mesh_parameterization) and checked bijective, then
// packed into one texture. Face and vertex indices are those of a garbage-free Surface_mesh.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_ATLAS_CHARTS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_ATLAS_CHARTS_H

#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>
#include <CGAL/convex_hull_2.h>
#include <CGAL/min_quadrilateral_2.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <queue>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

using Atlas_uv = std::array<double, 2>;

/// One chart of a rebuilt atlas: its faces and, per face, the UV of each corner (in the order of
/// halfedges_around_face from halfedge(f)); UVs in 3D length units until packed, then in [0,1]².
struct Atlas_chart {
  std::vector<std::uint32_t> faces;
  std::vector<std::array<Atlas_uv, 3>> uvs;
  double area_3d = 0;
};

/// Grows charts over the faces listed in `subset` (all faces when empty) so that every chart is
/// a topological disk with a simple boundary (a face joins a chart through one edge with its
/// third vertex new to the chart, or through two edges) and every face normal stays within the
/// cone of half-angle acos(cos_max) around the chart's area-weighted mean normal. Faces are taken
/// flattest first (a priority queue on the angle to the mean normal); seeds in face order.
/// Returns the faces of each chart.
inline std::vector<std::vector<std::uint32_t>> grow_charts(const Surface_mesh& m, const std::vector<Vector_3>& normal,
                                                           const std::vector<double>& area,
                                                           const std::vector<std::uint32_t>& subset, double cos_max) {
  using F = Surface_mesh::Face_index;
  const std::size_t nf = m.number_of_faces();
  constexpr std::int32_t unavailable = -2, free_face = -1;
  std::vector<std::int32_t> chart(nf, subset.empty() ? free_face : unavailable);
  for (std::uint32_t f : subset) chart[f] = free_face;
  std::vector<std::int32_t> vertex_stamp(m.number_of_vertices(), -1);
  std::vector<std::vector<std::uint32_t>> charts;
  std::vector<std::uint32_t> order;
  if (subset.empty()) {
    order.resize(nf);
    std::iota(order.begin(), order.end(), 0u);
  } else {
    order = subset;
  }
  using Entry = std::pair<double, std::uint32_t>;  // (1 - cos to the mean normal, face)
  for (std::uint32_t seed : order) {
    if (chart[seed] != free_face) continue;
    const std::int32_t id = std::int32_t(charts.size());
    charts.emplace_back();
    auto& faces_of = charts.back();
    Vector_3 sum(0, 0, 0);
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    auto accept = [&](std::uint32_t f) {
      chart[f] = id;
      faces_of.push_back(f);
      sum = sum + area[f] * normal[f];
      for (auto h : CGAL::halfedges_around_face(m.halfedge(F(f)), m)) vertex_stamp[std::size_t(m.target(h))] = id;
    };
    auto axis = [&] {
      const double l = std::sqrt(sum.squared_length());
      return l > 0 ? sum / l : normal[faces_of.front()];
    };
    auto push_neighbours = [&](std::uint32_t f) {
      const Vector_3 a = axis();
      for (auto h : CGAL::halfedges_around_face(m.halfedge(F(f)), m)) {
        const auto o = m.opposite(h);
        if (m.is_border(o)) continue;
        const std::uint32_t g = std::uint32_t(m.face(o));
        if (chart[g] == free_face) queue.push({1.0 - a * normal[g], g});
      }
    };
    accept(seed);
    push_neighbours(seed);
    while (!queue.empty()) {
      const std::uint32_t f = queue.top().second;
      queue.pop();
      if (chart[f] != free_face) continue;
      if (axis() * normal[f] < cos_max) continue;
      // disk test: edges shared with the chart, and the vertex opposite a single shared edge
      int shared = 0;
      Surface_mesh::Halfedge_index lone;
      for (auto h : CGAL::halfedges_around_face(m.halfedge(F(f)), m)) {
        const auto o = m.opposite(h);
        if (!m.is_border(o) && chart[std::size_t(m.face(o))] == id) {
          ++shared;
          lone = h;
        }
      }
      if (shared == 3 || shared == 0) continue;
      if (shared == 1 && vertex_stamp[std::size_t(m.target(m.next(lone)))] == id) continue;
      accept(f);
      push_neighbours(f);
    }
  }
  return charts;
}

/// The halfedge of face `f` whose target is corner `k` (0, 1, 2 from halfedge(f)).
inline Surface_mesh::Halfedge_index corner_halfedge(const Surface_mesh& m, Surface_mesh::Face_index f, int k) {
  auto h = m.halfedge(f);
  for (int i = 0; i < k; ++i) h = m.next(h);
  return h;
}

inline double signed_area_2(const Atlas_uv& a, const Atlas_uv& b, const Atlas_uv& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/// True when the closed segments pq and rs cross at a point that is not a shared endpoint.
inline bool segments_cross(const Atlas_uv& p, const Atlas_uv& q, const Atlas_uv& r, const Atlas_uv& s) {
  auto orient = [](const Atlas_uv& a, const Atlas_uv& b, const Atlas_uv& c) {
    const double v = signed_area_2(a, b, c);
    return v > 0 ? 1 : (v < 0 ? -1 : 0);
  };
  const int o1 = orient(p, q, r), o2 = orient(p, q, s), o3 = orient(r, s, p), o4 = orient(r, s, q);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  auto on = [](const Atlas_uv& a, const Atlas_uv& b, const Atlas_uv& c) {  // c on segment ab, not an end
    return c != a && c != b && (std::min)(a[0], b[0]) <= c[0] && c[0] <= (std::max)(a[0], b[0]) &&
           (std::min)(a[1], b[1]) <= c[1] && c[1] <= (std::max)(a[1], b[1]);
  };
  return (o1 == 0 && on(p, q, r)) || (o2 == 0 && on(p, q, s)) || (o3 == 0 && on(r, s, p)) || (o4 == 0 && on(r, s, q));
}

/// How much larger than the diagonal of its faces' bounding box a chart's parameterisation may be
/// (the diagonal of its UV bounding box, in the same units): an isometric map of a chart within the
/// normal cone is about as large (a cylinder's quarter unrolled: 1.1 times); LSCM's conformal map,
/// scaled to the chart's area, grows where it shrinks elsewhere, a few times at most.
inline constexpr double max_chart_stretch = 8.0;

/// The diagonal of the bounding box of the faces `faces` of `m`.
inline double bbox_diagonal(const Surface_mesh& m, const std::vector<std::uint32_t>& faces) {
  CGAL::Bbox_3 box;
  for (std::uint32_t f : faces)
    for (auto v : CGAL::vertices_around_face(m.halfedge(Surface_mesh::Face_index(f)), m)) box += m.point(v).bbox();
  return std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                   CGAL::square(box.zmax() - box.zmin()));
}

/// The diagonal of the bounding box of a chart's texture coordinates.
inline double uv_extent(const Atlas_chart& chart) {
  double lo[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  double hi[2] = {-lo[0], -lo[1]};
  for (const auto& t : chart.uvs)
    for (const auto& p : t)
      for (int k = 0; k < 2; ++k) {
        lo[k] = (std::min)(lo[k], p[std::size_t(k)]);
        hi[k] = (std::max)(hi[k], p[std::size_t(k)]);
      }
  return std::sqrt(CGAL::square(hi[0] - lo[0]) + CGAL::square(hi[1] - lo[1]));
}

/// LSCM parameterisation of one chart (a disk: see grow_charts), written into `chart.uvs` in
/// 3D length units (the map scaled to the chart's surface area). Returns false when the result is
/// not bijective: a triangle of zero or opposite orientation, or a self-crossing boundary (with
/// every triangle positively oriented and a simple boundary, the map is one to one); and when it
/// is more than max_chart_stretch times the chart's bounding box (a blown-up sliver, see below).
inline bool parameterize_chart(const Surface_mesh& m, Atlas_chart& chart) {
  using V = Surface_mesh::Vertex_index;
  using F = Surface_mesh::Face_index;
  const std::size_t n = chart.faces.size();
  chart.uvs.assign(n, {});
  chart.area_3d = 0;
  for (std::uint32_t f : chart.faces)
    chart.area_3d += std::sqrt(CGAL::squared_area(m.point(m.target(corner_halfedge(m, F(f), 0))),
                                                  m.point(m.target(corner_halfedge(m, F(f), 1))),
                                                  m.point(m.target(corner_halfedge(m, F(f), 2)))));
  if (n == 1) {  // a lone triangle: its isometric layout
    const F f(chart.faces[0]);
    const Point_3 a = m.point(m.target(corner_halfedge(m, f, 0))), b = m.point(m.target(corner_halfedge(m, f, 1))),
                  c = m.point(m.target(corner_halfedge(m, f, 2)));
    const Vector_3 ab = b - a, ac = c - a;
    const double lab = std::sqrt(ab.squared_length());
    if (!(lab > 0)) return false;
    const double x = (ac * ab) / lab;
    const double y = std::sqrt((std::max)(0.0, ac.squared_length() - x * x));
    if (!(y > 0)) return false;
    chart.uvs[0] = {{{{0, 0}}, {{lab, 0}}, {{x, y}}}};
    return true;
  }
  // the chart as a mesh of its own
  Surface_mesh sub;
  std::vector<V> local(m.number_of_vertices(), Surface_mesh::null_vertex());
  std::vector<std::array<V, 3>> corners(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const V v = m.target(corner_halfedge(m, F(chart.faces[i]), k));
      if (local[std::size_t(v)] == Surface_mesh::null_vertex()) local[std::size_t(v)] = sub.add_vertex(m.point(v));
      corners[i][std::size_t(k)] = local[std::size_t(v)];
    }
    if (sub.add_face(corners[i][0], corners[i][1], corners[i][2]) == Surface_mesh::null_face()) return false;
  }
  Surface_mesh::Halfedge_index border;
  std::size_t borders = 0;
  for (auto h : sub.halfedges())
    if (sub.is_border(h)) {
      border = h;
      ++borders;
      break;
    }
  if (borders == 0) return false;
  auto uvmap = sub.add_property_map<V, Point_2>("v:lscm_uv", Point_2(0, 0)).first;
  namespace SMP = CGAL::Surface_mesh_parameterization;
  if (SMP::parameterize(sub, SMP::LSCM_parameterizer_3<Surface_mesh>(), border, uvmap) != SMP::OK) return false;
  double uv_area = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) {
      const Point_2 p = uvmap[corners[i][std::size_t(k)]];
      if (!std::isfinite(p.x()) || !std::isfinite(p.y())) return false;
      chart.uvs[i][std::size_t(k)] = {{p.x(), p.y()}};
    }
    uv_area += 0.5 * signed_area_2(chart.uvs[i][0], chart.uvs[i][1], chart.uvs[i][2]);
  }
  if (uv_area < 0) {  // LSCM may return the mirror image
    for (auto& t : chart.uvs)
      for (auto& p : t) p[0] = -p[0];
    uv_area = -uv_area;
  }
  if (!(uv_area > 0)) return false;
  const double s = std::sqrt(chart.area_3d / uv_area);
  double min_area = std::numeric_limits<double>::infinity();
  for (auto& t : chart.uvs) {
    for (auto& p : t) p = {{p[0] * s, p[1] * s}};
    min_area = (std::min)(min_area, signed_area_2(t[0], t[1], t[2]));
  }
  // every triangle positively oriented (relative to the chart's size, against round-off slivers)
  if (!(min_area > 1e-12 * chart.area_3d)) return false;
  // no part of the chart blown up: LSCM can map a near-degenerate sliver (an edge of 1e-7 beside two
  // of 0.014) to a needle whose tiny area the scaling to the chart's 3D area cannot see, thousands of
  // times the chart's size; the packing then shrank every chart of the atlas to fit it (a 10 % level
  // of a 1M-face mesh: 2,296 texels in its charts instead of about a million). A map this much
  // larger than the chart's bounding box is refused, so the chart is cut smaller.
  if (!(uv_extent(chart) <= max_chart_stretch * bbox_diagonal(m, chart.faces))) return false;
  // the boundary: edges of chart faces whose other face is not in the chart
  std::vector<std::uint32_t> sorted = chart.faces;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::pair<Atlas_uv, Atlas_uv>> segs;
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const auto h = m.next(corner_halfedge(m, F(chart.faces[i]), k));  // corner k -> corner k + 1
      const auto o = m.opposite(h);
      if (!m.is_border(o) && std::binary_search(sorted.begin(), sorted.end(), std::uint32_t(m.face(o)))) continue;
      segs.push_back({chart.uvs[i][std::size_t(k)], chart.uvs[i][std::size_t((k + 1) % 3)]});
    }
  // self-crossing test, segments sorted by their lowest u
  std::sort(segs.begin(), segs.end(), [](const auto& a, const auto& b) {
    return (std::min)(a.first[0], a.second[0]) < (std::min)(b.first[0], b.second[0]);
  });
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const double hi = (std::max)(segs[i].first[0], segs[i].second[0]);
    for (std::size_t j = i + 1; j < segs.size(); ++j) {
      if ((std::min)(segs[j].first[0], segs[j].second[0]) > hi) break;
      if (segments_cross(segs[i].first, segs[i].second, segs[j].first, segs[j].second)) return false;
    }
  }
  return true;
}

/// Charts of the faces of `m` (all faces when `subset` is empty), each parameterised without
/// folds or overlaps: a chart whose LSCM map is not bijective is grown again over its own faces
/// with a narrower cone (half the angle, twice at most), then split into lone triangles.
inline std::vector<Atlas_chart> make_charts(const Surface_mesh& m, const std::vector<Vector_3>& normal,
                                            const std::vector<double>& area, double cone_degrees,
                                            const std::vector<std::uint32_t>& subset = {}) {
  std::vector<Atlas_chart> done;
  struct Pending {
    std::vector<std::uint32_t> faces;
    double degrees;
  };
  std::vector<Pending> work{{subset, cone_degrees}};
  bool first = true;
  while (!work.empty()) {
    std::vector<Atlas_chart> candidates;
    std::vector<double> degrees_of;
    for (const Pending& p : work) {
      if (!first && p.degrees < cone_degrees / 4.5) {  // last resort: lone triangles
        for (std::uint32_t f : p.faces) {
          candidates.push_back({{f}, {}, 0});
          degrees_of.push_back(0);
        }
        continue;
      }
      const double c = std::cos(p.degrees * 3.14159265358979323846 / 180.0);
      for (auto& faces : grow_charts(m, normal, area, p.faces, c)) {
        candidates.push_back({std::move(faces), {}, 0});
        degrees_of.push_back(p.degrees);
      }
    }
    first = false;
    std::vector<char> ok(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i < r.end(); ++i)
                          ok[i] = parameterize_chart(m, candidates[i]) ? 1 : 0;
                      });
    work.clear();
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      if (ok[i]) {
        done.push_back(std::move(candidates[i]));
      } else if (candidates[i].faces.size() == 1) {
        // a degenerate lone triangle: a tiny right triangle keeps it addressable
        Atlas_chart& c = candidates[i];
        const double e = 1e-9 + std::sqrt((std::max)(c.area_3d, 0.0));
        c.uvs.assign(1, {{{{0, 0}}, {{e, 0}}, {{0, e}}}});
        done.push_back(std::move(c));
      } else {
        work.push_back({std::move(candidates[i].faces), degrees_of[i] / 2});
      }
    }
  }
  return done;
}

/// Packs the charts into a W x H texture with `gutter` texels of padding around each chart:
/// every chart is turned to its smallest-area bounding rectangle (CGAL::min_rectangle_2 of its
/// UV convex hull), then rectangles are placed on shelves, tallest first, at the largest common
/// scale (texels per length unit, by bisection) that fits. Chart UVs become texture UVs in
/// [0,1]². Returns the scale.
inline double pack_charts(std::vector<Atlas_chart>& charts, int W, int H, int gutter) {
  using K = Kernel;
  struct Box {
    double w = 0, h = 0;
  };
  std::vector<Box> box(charts.size());
  // orient each chart
  for (std::size_t c = 0; c < charts.size(); ++c) {
    Atlas_chart& ch = charts[c];
    std::vector<K::Point_2> pts, hull;
    for (const auto& t : ch.uvs)
      for (const auto& p : t) pts.emplace_back(p[0], p[1]);
    CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));
    double cs = 1, sn = 0;
    if (hull.size() >= 3) {
      std::vector<K::Point_2> rect;
      CGAL::min_rectangle_2(hull.begin(), hull.end(), std::back_inserter(rect));
      if (rect.size() == 4) {
        const K::Vector_2 d = rect[1] - rect[0];
        const double l = std::sqrt(d.squared_length());
        if (l > 0) {
          cs = d.x() / l;
          sn = d.y() / l;
        }
      }
    }
    double umin = 1e300, vmin = 1e300, umax = -1e300, vmax = -1e300;
    for (auto& t : ch.uvs)
      for (auto& p : t) {
        const double u = cs * p[0] + sn * p[1], v = -sn * p[0] + cs * p[1];
        p = {{u, v}};
        umin = (std::min)(umin, u);
        vmin = (std::min)(vmin, v);
        umax = (std::max)(umax, u);
        vmax = (std::max)(vmax, v);
      }
    bool turn = (vmax - vmin) > (umax - umin);  // lay charts flat: shelves waste less
    for (auto& t : ch.uvs)
      for (auto& p : t) {
        const double u = p[0] - umin, v = p[1] - vmin;
        p = turn ? Atlas_uv{{vmax - vmin - v, u}} : Atlas_uv{{u, v}};  // a rotation, orientation kept
      }
    box[c] = turn ? Box{vmax - vmin, umax - umin} : Box{umax - umin, vmax - vmin};
  }
  std::vector<std::size_t> order(charts.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return box[a].h > box[b].h; });
  std::vector<std::array<double, 2>> at(charts.size());
  const double pad = 2.0 * gutter + 1.0;  // gutters, plus a texel for the rounding of a chart's extent
  auto place = [&](double s) {
    double x = 0, y = 0, shelf = 0;
    for (std::size_t c : order) {
      const double w = std::ceil(box[c].w * s + pad), h = std::ceil(box[c].h * s + pad);
      if (w > W) return false;
      if (x + w > W) {
        y += shelf;
        x = 0;
        shelf = 0;
      }
      at[c] = {{x, y}};
      x += w;
      shelf = (std::max)(shelf, h);
      if (y + shelf > H) return false;
    }
    return true;
  };
  double area = 0;
  for (const Box& b : box) area += b.w * b.h;
  double hi = area > 0 ? std::sqrt(double(W) * double(H) / area) : 1.0, lo = 0;
  while (place(hi)) hi *= 2;  // make sure `hi` does not fit
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (place(mid))
      lo = mid;
    else
      hi = mid;
  }
  place(lo);
  for (std::size_t c = 0; c < charts.size(); ++c)
    for (auto& t : charts[c].uvs)
      for (auto& p : t) p = {{(at[c][0] + gutter + 0.5 + p[0] * lo) / W, (at[c][1] + gutter + 0.5 + p[1] * lo) / H}};
  return lo;
}

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_ATLAS_CHARTS_H
