// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// rebuild_atlas(), Atlas_options, Atlas_source: a new texture atlas for a simplified mesh, baked
// from the original. This is what lets the textured simplification reach any face count: the
// input's charts no longer constrain the collapses (it extends the thesis, whose charts never
// merge, §3.5 and §3.7). Charts are grown over the simplified surface within a normal cone and
// parameterised by LSCM (checked one to one, else grown again narrower), shelf-packed at one texel
// density, then baked: each texel takes the colour of the nearest point of the original among the
// faces turned the same way (so a thin part shows the side one sees), and the gutters are dilated.
// Tangent-space normal maps are carried through object space. Output: per-corner UVs in [0,1]²,
// one material with the baked diffuse (and normal) image.
//
// Manual: doc/Textured_simplification/README.md, "Any target: a new atlas (the default)".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_REBUILD_ATLAS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_REBUILD_ATLAS_H

#include <CMGeom/Compact_model/internal/Vec3.h>
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Textured_simplification/Index_texture.h>
#include <CMGeom/Textured_simplification/internal/atlas_charts.h>
#include <CMGeom/internal/huge_pages.h>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>

#include <boost/property_map/property_map.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

struct Atlas_options {
  /// Size of the output textures in texels; 0: the input's texel density (its first used texture's
  /// size times the UV range its UVs span, for UVs that repeat the texture), 64 to 8192 a side.
  int texture_width = 0, texture_height = 0;
  /// Padding texels around each chart (then filled by dilation).
  int gutter_texels = 2;
  /// Half-angle of the normal cone of a chart, in degrees (0, 90).
  double chart_cone_degrees = 60.0;
};

struct Atlas_result {
  std::size_t charts = 0;
  int texture_width = 0, texture_height = 0;
  double texels_per_unit = 0;        ///< texel density of the packing (texels per length unit)
  double coverage = 0;               ///< fraction of the texels covered by triangles
  std::size_t texels_baked = 0;      ///< texels inside the charts (looked up on the original, or painted)
  std::size_t texels_painted = 0;    ///< of which a painter gave (internal::Atlas_painter), not looked up
  std::size_t texels_unmatched = 0;  ///< of which had no facing original point within reach
  double seconds_charts = 0;         ///< making, parameterising and packing the charts
  double seconds_paint = 0;          ///< the painter's work (0 without one)
  double seconds_bake = 0;           ///< the lookups, the gutters' fill and the images
};

namespace internal {

inline Vector_3 unit_or_zero(const Vector_3& v) {
  const double l = std::sqrt(v.squared_length());
  return l > 0 ? v / l : Vector_3(0, 0, 0);
}

/// Orthonormal tangent frame (T, B, N) of a triangle with corner positions p and UVs t: T and B
/// follow the UV gradients (orthonormalised against the face normal N, B's handedness kept).
inline std::array<Vector_3, 3> tangent_frame(const std::array<Point_3, 3>& p, const std::array<Atlas_uv, 3>& t) {
  const Vector_3 e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Vector_3 n = unit_or_zero(CGAL::cross_product(e1, e2));
  const double du1 = t[1][0] - t[0][0], dv1 = t[1][1] - t[0][1], du2 = t[2][0] - t[0][0], dv2 = t[2][1] - t[0][1];
  const double det = du1 * dv2 - du2 * dv1;
  Vector_3 tu = det != 0 ? (e1 * dv2 - e2 * dv1) / det : e1;
  Vector_3 tv = det != 0 ? (e2 * du1 - e1 * du2) / det : CGAL::cross_product(n, e1);
  Vector_3 T = unit_or_zero(tu - n * (n * tu));
  if (T == Vector_3(0, 0, 0)) T = unit_or_zero(e1);
  const double hand = (CGAL::cross_product(n, T) * tv) < 0 ? -1.0 : 1.0;
  return {{T, hand * CGAL::cross_product(n, T), n}};
}

/// The original surface as an AABB tree (CGAL) of plain-double triangles, with the query the
/// baking needs: the closest point among the faces whose normal makes an angle below 90° with a
/// given direction (the simplified face's normal), within a given distance. Of faces at the same
/// distance, the one of smallest index: the answer does not depend on the order faces are tried in,
/// so the tree's search and nearest_among() (over the candidates gather() gives for a group of
/// nearby points) find the same point.
class Facing_closest_point {
public:
  using SC = CGAL::Simple_cartesian<double>;
  using Triangles = std::vector<SC::Triangle_3>;
  using Primitive = CGAL::AABB_triangle_primitive<SC, Triangles::const_iterator>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<SC, Primitive>>;

  struct Hit {
    std::size_t face = std::size_t(-1);
    std::array<double, 3> point{{0, 0, 0}};
    double squared_distance = std::numeric_limits<double>::infinity();
    bool found() const { return face != std::size_t(-1); }
  };

  /// Faces whose `usable` entry is 0 are never returned.
  Facing_closest_point(Triangles triangles, std::vector<Vector_3> normals, std::vector<char> usable)
      : tris_(std::move(triangles)),
        normals_(std::move(normals)),
        usable_(std::move(usable)),
        tree_(tris_.cbegin(), tris_.cend()) {
    tree_.build();
  }

  /// Face `f` tested alone (a hint: tightens the bound before a search); a zero `n` accepts
  /// faces of any orientation.
  void test(std::size_t f, const double* p, const Vector_3& n, Hit& best) const {
    if (accepts(f, n)) consider(f, p, best);
  }

  /// The area of face `f`.
  double area(std::size_t f) const { return std::sqrt(tris_[f].squared_area()); }

  /// A candidate of gather(): a face, the distance from the gathering point to it, and its box.
  struct Candidate {
    double distance;
    std::uint32_t face;
    CGAL::Bbox_3 box;
  };

  /// The faces facing `n` (any for a zero `n`) within sqrt(radius2) of `q`, nearest first (ties
  /// by index), into `out`; false, with `out` incomplete, when there are more than `most`.
  bool gather(const double* q, const Vector_3& n, double radius2, std::size_t most, std::vector<Candidate>& out) const {
    out.clear();
    Gather_traits traits{this, q, n, radius2, most, &out};
    tree_.traversal(0, traits);
    if (out.size() > most) return false;
    std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
      return a.distance < b.distance || (a.distance == b.distance && a.face < b.face);
    });
    return true;
  }

  /// The closest point to `p` among `candidates` (gather()'s, at a point q, facing its `n`), nearer than
  /// sqrt(best.squared_distance) (best is kept if none); `pq` is |p - q|. When the candidates hold
  /// every facing face within sqrt(best.squared_distance) + pq of q, this is search()'s answer:
  /// a face at distance D from q is at least D - pq from p, so the scan stops at the first
  /// candidate farther than that from q.
  void nearest_among(const double* p, const std::vector<Candidate>& candidates, double pq, Hit& best) const {
    for (const Candidate& c : candidates) {
      const double lower = c.distance - pq;
      // (a relative margin: the distances to q and to p are rounded separately)
      if (lower > 0 && lower * lower > best.squared_distance * (1 + 1e-9)) break;
      // (a face whose box is farther than the best cannot be nearer; the margin keeps the ties)
      if (box_distance(p, c.box) > best.squared_distance * (1 + 1e-9)) continue;
      consider(c.face, p, best);  // (gather() kept only faces it accepts)
    }
  }

  /// The closest facing point nearer than sqrt(best.squared_distance) (best is kept if none).
  void search(const double* p, const Vector_3& n, Hit& best) const {
    Traits traits{this, p, n, &best};
    tree_.traversal_with_priority(0, traits);
  }

private:
  struct Traits {
    using Priority = double;
    const Facing_closest_point* self;
    const double* p;
    Vector_3 n;
    Hit* best;
    bool go_further() const { return true; }
    template <class Query>
    void intersection(const Query&, const Primitive& prim) const {
      self->test(std::size_t(prim.id() - self->tris_.cbegin()), p, n, *best);
    }
    double box_distance(const CGAL::Bbox_3& b) const { return Facing_closest_point::box_distance(p, b); }
    // (<=: a face as near as the best one may still win the tie)
    template <class Query, class Node>
    bool do_intersect(const Query&, const Node& node) const {
      return box_distance(node.bbox()) <= best->squared_distance;
    }
    template <class Query, class Node>
    std::pair<bool, double> do_intersect_with_priority(const Query&, const Node& node) const {
      const double d = box_distance(node.bbox());
      return {d <= best->squared_distance, -d};
    }
  };

  /// Whether face `f` may answer a query along `n`: usable, and facing `n` (any for a zero `n`).
  bool accepts(std::size_t f, const Vector_3& n) const {
    return usable_[f] && (n == CGAL::NULL_VECTOR || normals_[f] * n > 0);
  }
  /// The point of face `f` closest to `p`.
  CM::internal::Vec3 closest_point(std::size_t f, const double* p) const {
    using CM::internal::Vec3;
    const auto& t = tris_[f];
    auto v = [](const SC::Point_3& x) { return Vec3(x.x(), x.y(), x.z()); };
    return CM::internal::closest_on_triangle(Vec3(p[0], p[1], p[2]), v(t[0]), v(t[1]), v(t[2]));
  }
  /// Face `f` (accepted) as the answer for `p` if it is nearer than `best` (ties: the lower index).
  void consider(std::size_t f, const double* p, Hit& best) const {
    const CM::internal::Vec3 q = closest_point(f, p);
    const double d = CM::internal::squared_length(q - CM::internal::Vec3(p[0], p[1], p[2]));
    if (d < best.squared_distance || (d == best.squared_distance && f < best.face)) best = {f, {{q.x, q.y, q.z}}, d};
  }

  static double box_distance(const double* p, const CGAL::Bbox_3& b) {
    return CM::internal::squared_distance_to_box(CM::internal::Vec3(p[0], p[1], p[2]), b);
  }

  struct Gather_traits {
    const Facing_closest_point* self;
    const double* q;
    Vector_3 n;
    double radius2;
    std::size_t most;
    std::vector<Candidate>* out;
    bool go_further() const { return out->size() <= most; }
    template <class Query>
    void intersection(const Query&, const Primitive& prim) const {
      const std::size_t f = std::size_t(prim.id() - self->tris_.cbegin());
      if (!self->accepts(f, n)) return;
      const double d = CM::internal::squared_length(self->closest_point(f, q) - CM::internal::Vec3(q[0], q[1], q[2]));
      if (d <= radius2) out->push_back({std::sqrt(d), std::uint32_t(f), self->tris_[f].bbox()});
    }
    template <class Query, class Node>
    bool do_intersect(const Query&, const Node& node) const {
      return box_distance(q, node.bbox()) <= radius2;
    }
  };

  Triangles tris_;
  std::vector<Vector_3> normals_;
  std::vector<char> usable_;
  Tree tree_;
};

}  // namespace internal

namespace internal {
/// What an Atlas_painter gives rebuild_atlas(): texels of the atlas it painted itself, which are
/// then not looked up on the original (level_of_detail.h paints the original into its atlases).
struct Atlas_paint {
  Image colours;            ///< W x H with the atlas' colour channels, rows running down
  std::vector<char> given;  ///< W x H, row y from the bottom (as the UVs' v): the texels painted
  /// Optional, with normal maps: the given texels' normals in object space, 3 floats per texel in
  /// the order of `given` (Atlas_source::normal_at()); the baking expresses them in the new faces'
  /// tangent frames. Left empty, the normals of the given texels are looked up.
  std::vector<float> normals;
  /// Optional: per texel, the original's face that painted it + 1 (0: none); the lookups of the
  /// texels left start from the face of the given texel before them (a tight first bound).
  std::vector<std::uint32_t> faces;
};
/// Called by rebuild_atlas() once the simplified mesh has its new UVs, before the baking, with
/// `colours` and `given` sized and blank.
using Atlas_painter = std::function<void(const Textured_mesh& simplified, Atlas_paint& paint)>;
}  // namespace internal

class Atlas_source;
inline Atlas_result rebuild_atlas(const Atlas_source& src, Textured_mesh& simplified, const Atlas_options& options,
                                  const internal::Atlas_painter* painter = nullptr);

/// What the baking reads from the original mesh, extracted once: its triangles with their UVs,
/// materials and chart ids, the texture size of the new atlas, and — after prepare() — the chart
/// map of the original layout and the closest-point tree. simplify_textured_mesh() extracts it
/// before the collapses and prepares it while they run (a second core builds the tree and the
/// chart map). The original's materials are referred to, not copied: they must outlive it.
class Atlas_source {
public:
  /// Throws Invalid_input when `original` has no UVs or no decoded image, or for option values
  /// out of range.
  Atlas_source(const Textured_mesh& original, const Atlas_options& options) : mats_(&original.materials()) {
    namespace I = internal;
    const Surface_mesh& om = original.mesh();
    if (!original.has_uvs()) throw Invalid_input("rebuild_atlas: the original mesh has no texture coordinates");
    if (!(options.chart_cone_degrees > 0 && options.chart_cone_degrees < 90))
      throw Invalid_input("rebuild_atlas: chart_cone_degrees must be in (0, 90), got " +
                          std::to_string(options.chart_cone_degrees));
    if (options.gutter_texels < 1 || options.gutter_texels > 64)
      throw Invalid_input("rebuild_atlas: gutter_texels must be in [1, 64], got " +
                          std::to_string(options.gutter_texels));
    if (om.has_garbage()) throw Invalid_input("rebuild_atlas: the original mesh must be garbage-free");
    const auto& mats = *mats_;
    // materials in use, and the images the new atlas needs
    used_.assign(mats.size(), 0);
    for (auto f : om.faces()) {
      const int m = original.material(f);
      if (m >= 0 && std::size_t(m) < mats.size()) used_[std::size_t(m)] = 1;
    }
    const bool derived_size = options.texture_width <= 0;
    W_ = options.texture_width;
    H_ = options.texture_height;
    bool any_image = false;
    for (std::size_t i = 0; i < mats.size(); ++i) {
      if (!used_[i]) continue;
      const Image& d = mats[i].diffuse_image;
      const Image& n = mats[i].normal_image;
      if (!d.empty()) colour_channels_ = (std::max)(colour_channels_, d.channels());
      any_normal_ |= !n.empty();
      const Image& ref = !d.empty() ? d : n;
      if (!ref.empty() && !any_image && W_ <= 0) {
        W_ = ref.width();
        H_ = ref.height();
      }
      any_image |= !ref.empty();
    }
    for (std::size_t i = 0; i < used_.size(); ++i)
      if (used_[i] && used_count_++ == 0) first_used_ = i;
    if (!any_image)
      throw Invalid_input("rebuild_atlas: '" + original.source() + "' has no decoded texture to bake from");
    int W = W_, H = H_;
    if (derived_size) {
      // the input texture's texel density over the UV range the input uses: UVs that repeat the
      // texture (tiling) get as many texels as the tiles they cover, up to 8192 a side, 64 at least
      double u0 = 0, v0 = 0, u1 = 1, v1 = 1;
      for (auto h : om.halfedges()) {
        if (om.is_border(h)) continue;
        const Point_2 t = original.uv(h);
        u0 = (std::min)(u0, t.x());
        u1 = (std::max)(u1, t.x());
        v0 = (std::min)(v0, t.y());
        v1 = (std::max)(v1, t.y());
      }
      const double w = double(W) * (u1 - u0), h = double(H) * (v1 - v0);
      const double shrink = (std::max)(w, h) > 8192 ? 8192 / (std::max)(w, h) : 1.0;
      W = (std::max)(64, int(std::lround(w * shrink)));
      H = (std::max)(64, int(std::lround(h * shrink)));
    } else if (H <= 0) {
      H = W;
    }
    if (W < 8 || H < 8 || W > 16384 || H > 16384)
      throw Invalid_input("rebuild_atlas: texture size " + std::to_string(W) + " x " + std::to_string(H) +
                          " out of [8, 16384]");
    W_ = W;
    H_ = H;
    // the triangles, with tangent frames when a normal map is carried, and their chart ids
    source_.resize(om.number_of_faces());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, source_.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i < r.end(); ++i) {
                          const Surface_mesh::Face_index f(static_cast<Surface_mesh::size_type>(i));
                          Source& s = source_[i];
                          for (int k = 0; k < 3; ++k) {
                            const auto h = I::corner_halfedge(om, f, k);
                            s.p[std::size_t(k)] = om.point(om.target(h));
                            const Point_2 t = original.uv(h);
                            s.uv[std::size_t(k)] = {{t.x(), t.y()}};
                          }
                          s.material = original.material(f);
                          if (any_normal_)
                            s.frame = I::tangent_frame(s.p, s.uv);
                          else
                            s.frame[2] = I::unit_or_zero(CGAL::cross_product(s.p[1] - s.p[0], s.p[2] - s.p[0]));
                        }
                      });
    // a plain array, not a dynamic property of the mesh: adding one would change the mesh while
    // simplify_mesh reads it on another core (simplify_textured_mesh takes the source meanwhile)
    std::vector<int> chart_of(om.num_faces(), -1);
    charts_ = compute_chart_ids(om, original.uv_map(),
                                boost::make_iterator_property_map(chart_of.begin(), get(boost::face_index, om)));
    for (auto f : om.faces()) source_[std::size_t(f)].chart = std::uint32_t(chart_of[std::size_t(f)] + 1);
    const auto bb = CGAL::Polygon_mesh_processing::bbox(om);
    diag_ = std::sqrt(CGAL::square(bb.xmax() - bb.xmin()) + CGAL::square(bb.ymax() - bb.ymin()) +
                      CGAL::square(bb.zmax() - bb.zmin()));
  }

  /// Builds the chart map and the closest-point tree (reads only this object: may run while the
  /// original mesh changes).
  void prepare() {
    namespace I = internal;
    const auto& mats = *mats_;
    // the original layout's chart map (texels of each chart grown by two rings), so that a lookup
    // never blends texels of another chart or of the gutters (sample_original, as the
    // chart-keeping path does)
    {
      std::vector<std::array<UV2, 3>> uv_tris(source_.size());
      std::vector<int> ids(source_.size());
      for (std::size_t f = 0; f < source_.size(); ++f) {
        for (int k = 0; k < 3; ++k)
          uv_tris[f][std::size_t(k)] = {{source_[f].uv[std::size_t(k)][0], source_[f].uv[std::size_t(k)][1]}};
        ids[f] = int(source_[f].chart) - 1;
      }
      int rw = 0, rh = 0;
      for (std::size_t i = 0; i < mats.size() && rw == 0; ++i)
        if (used_[i] && !mats[i].diffuse_image.empty()) {
          rw = mats[i].diffuse_image.width();
          rh = mats[i].diffuse_image.height();
        }
      if (rw == 0) {
        rw = W_;
        rh = H_;
      }
      region_ = Chart_map(make_texture_domain(uv_tris, rw, rh, 8192), uv_tris, ids);
    }
    I::Facing_closest_point::Triangles tris;
    std::vector<Vector_3> fn;
    tris.reserve(source_.size());
    fn.reserve(source_.size());
    for (const Source& s : source_) {
      auto pt = [](const Point_3& q) { return I::Facing_closest_point::SC::Point_3(q.x(), q.y(), q.z()); };
      tris.emplace_back(pt(s.p[0]), pt(s.p[1]), pt(s.p[2]));
      fn.push_back(s.frame[2]);
    }
    // faces of charts too small to cover a texel centre of the chart map have no texels to show
    // (tested face by face: where charts share texels the map holds only one of them)
    std::vector<char> chart_has_texels, usable(source_.size(), 1);
    for (std::size_t f = 0; f < source_.size(); ++f) {
      const std::uint32_t c = source_[f].chart;
      if (c >= chart_has_texels.size()) chart_has_texels.resize(std::size_t(c) + 1, 0);
      if (chart_has_texels[c]) continue;
      std::array<UV2, 3> t;
      for (int k = 0; k < 3; ++k)
        t[std::size_t(k)] =
            region_.domain().to_texel({{source_[f].uv[std::size_t(k)][0], source_[f].uv[std::size_t(k)][1]}});
      rasterize_triangle(t, region_.width(), region_.height(), [&](int, int) { chart_has_texels[c] = 1; });
    }
    bool any = false;
    for (std::size_t f = 0; f < source_.size(); ++f) {
      const std::uint32_t c = source_[f].chart;
      usable[f] = c < chart_has_texels.size() && chart_has_texels[c];
      any |= usable[f] != 0;
    }
    if (!any) std::fill(usable.begin(), usable.end(), 1);
    finder_ = std::make_unique<I::Facing_closest_point>(std::move(tris), std::move(fn), std::move(usable));
  }

  bool prepared() const { return finder_ != nullptr; }
  /// Number of charts of the original layout.
  std::size_t charts() const { return charts_; }
  /// Number of faces of the original (the faces colour_at() and normal_at() take).
  std::size_t number_of_faces() const { return source_.size(); }
  /// Number of colour channels of the baked atlas (1 to 4).
  int colour_channels() const { return colour_channels_; }

  /// The colour the baking gives a point of the original's face `face` (face order of the
  /// original) at barycentric coordinates (w0, w1, w2) (clamped onto the face): the material's
  /// texture there (bilinear, taps kept in the face's chart; grey spread to RGB), times the
  /// material's colour when several materials are merged into one atlas, or the material's colour
  /// for an untextured material. Writes colour_channels() values. Needs prepared().
  void colour_at(std::size_t face, double w0, double w1, double w2, float* out) const {
    CGAL_precondition(prepared() && face < source_.size());
    const Source& s = source_[face];
    w1 = (std::min)((std::max)(w1, 0.0), 1.0);
    w2 = (std::min)((std::max)(w2, 0.0), 1.0 - w1);
    w0 = 1 - w1 - w2;
    const double u = w0 * s.uv[0][0] + w1 * s.uv[1][0] + w2 * s.uv[2][0];
    const double v = w0 * s.uv[0][1] + w1 * s.uv[1][1] + w2 * s.uv[2][1];
    const auto& mats = *mats_;
    float c[4] = {1, 1, 1, 1};
    const Material* mat =
        s.material >= 0 && std::size_t(s.material) < mats.size() ? &mats[std::size_t(s.material)] : nullptr;
    if (mat && !mat->diffuse_image.empty()) {
      const UV2 a = region_.domain().to_texel({{u, v}});
      sample_original(region_, mat->diffuse_image, float(a[0]), float(a[1]), c, s.chart);
      if (mat->diffuse_image.channels() < 3)  // grey (and alpha): spread to RGB
        c[3] = mat->diffuse_image.channels() == 2 ? c[1] : 1.f, c[1] = c[2] = c[0];
      if (used_count_ > 1)
        for (int k = 0; k < 3; ++k) c[k] *= float(mat->diffuse_color[std::size_t(k)]);
    } else if (mat) {
      for (int k = 0; k < 3; ++k) c[k] = float(mat->diffuse_color[std::size_t(k)]);
    }
    for (int k = 0; k < colour_channels_; ++k) out[k] = c[k];
  }

  /// Whether a used material has a normal map (the atlas then has one too).
  bool has_normal_maps() const { return any_normal_; }

  /// The normal, in object space, that the baking gives a point of the original's face `face` at
  /// barycentric coordinates (w0, w1, w2) (clamped onto the face): the material's normal map there
  /// in the face's tangent frame, or the face's normal without a normal map. Needs prepared().
  Vector_3 normal_at(std::size_t face, double w0, double w1, double w2) const {
    CGAL_precondition(prepared() && face < source_.size());
    const Source& s = source_[face];
    const auto& mats = *mats_;
    const Material* mat =
        s.material >= 0 && std::size_t(s.material) < mats.size() ? &mats[std::size_t(s.material)] : nullptr;
    if (!mat || mat->normal_image.empty()) return s.frame[2];
    w1 = (std::min)((std::max)(w1, 0.0), 1.0);
    w2 = (std::min)((std::max)(w2, 0.0), 1.0 - w1);
    w0 = 1 - w1 - w2;
    const double u = w0 * s.uv[0][0] + w1 * s.uv[1][0] + w2 * s.uv[2][0];
    const double v = w0 * s.uv[0][1] + w1 * s.uv[1][1] + w2 * s.uv[2][1];
    const UV2 tx = region_.domain().to_texel({{u, v}});
    float t[4] = {0.5f, 0.5f, 1.f, 1.f};
    sample_original(region_, mat->normal_image, float(tx[0]), float(tx[1]), t, s.chart);
    return internal::unit_or_zero((2.0 * t[0] - 1.0) * s.frame[0] + (2.0 * t[1] - 1.0) * s.frame[1] +
                                  (2.0 * t[2] - 1.0) * s.frame[2]);
  }

  /// The colour the baking gives point `p` of a surface whose normal there is `n`: colour_at() at
  /// the closest point of the original among its faces facing the same way (of any orientation
  /// when none does; a zero `n` accepts any). Writes colour_channels() values. Needs prepared().
  /// `hint`, a face of the original likely near `p`, is tested first: the search then prunes with
  /// its distance (the same closest point, found sooner; none when `p` lies on it).
  void colour_near(const Point_3& p, const Vector_3& n, float* out, std::size_t hint = std::size_t(-1)) const {
    CGAL_precondition(prepared());
    const double q[3] = {p.x(), p.y(), p.z()};
    internal::Facing_closest_point::Hit hit;
    if (hint < source_.size()) finder_->test(hint, q, n, hit);
    finder_->search(q, n, hit);
    if (!hit.found()) finder_->search(q, CGAL::NULL_VECTOR, hit);
    if (!hit.found()) {
      for (int k = 0; k < colour_channels_; ++k) out[k] = 0.f;
      return;
    }
    const std::array<double, 3> w = hit_coordinates(hit);
    colour_at(hit.face, w[0], w[1], w[2], out);
  }

private:
  /// The barycentric coordinates (clamped onto the face) of a closest point the finder returned,
  /// in its face of the original.
  std::array<double, 3> hit_coordinates(const internal::Facing_closest_point::Hit& hit) const {
    const Source& s = source_[hit.face];
    const Vector_3 e1 = s.p[1] - s.p[0], e2 = s.p[2] - s.p[0];
    const Vector_3 e = Point_3(hit.point[0], hit.point[1], hit.point[2]) - s.p[0];
    const double d11 = e1 * e1, d12 = e1 * e2, d22 = e2 * e2, d1 = e * e1, d2 = e * e2;
    const double den = d11 * d22 - d12 * d12;
    double w1 = den > 0 ? (d22 * d1 - d12 * d2) / den : 0, w2 = den > 0 ? (d11 * d2 - d12 * d1) / den : 0;
    w1 = (std::min)((std::max)(w1, 0.0), 1.0);
    w2 = (std::min)((std::max)(w2, 0.0), 1.0 - w1);
    return {{1 - w1 - w2, w1, w2}};
  }

  friend Atlas_result rebuild_atlas(const Atlas_source&, Textured_mesh&, const Atlas_options&,
                                    const internal::Atlas_painter*);
  struct Source {
    std::array<Point_3, 3> p;
    std::array<internal::Atlas_uv, 3> uv;
    std::array<Vector_3, 3> frame;  // tangent frame (normal maps only; frame[2] always the normal)
    int material = -1;
    std::uint32_t chart = 0;  // chart id + 1 in the original layout
  };
  const std::vector<Material>* mats_;
  std::vector<char> used_;
  std::size_t used_count_ = 0, first_used_ = 0;
  int W_ = 0, H_ = 0, colour_channels_ = 3;
  bool any_normal_ = false;
  double diag_ = 0;
  std::size_t charts_ = 0;
  std::vector<Source> source_;
  Chart_map region_;
  std::unique_ptr<internal::Facing_closest_point> finder_;
};

/// Replaces the UVs and materials of `simplified` (a garbage-free triangle mesh) by a new atlas
/// baked from the original `src` was made from (prepared: prepare()); see the file comment.
inline Atlas_result rebuild_atlas(const Atlas_source& src, Textured_mesh& simplified, const Atlas_options& options,
                                  const internal::Atlas_painter* painter) {
  using Clock = std::chrono::steady_clock;
  namespace I = internal;
  Surface_mesh& sm = simplified.mesh();
  if (sm.has_garbage() || !CGAL::is_triangle_mesh(sm) || sm.number_of_faces() == 0)
    throw Invalid_input("rebuild_atlas: the simplified mesh must be a garbage-free, non-empty triangle mesh");
  CGAL_precondition(src.prepared());
  const auto& mats = *src.mats_;
  const auto& source = src.source_;
  const auto* finder = src.finder_.get();
  const int W = src.W_, H = src.H_, colour_channels = src.colour_channels_;
  const bool any_normal = src.any_normal_;
  const double diag = src.diag_;
  Atlas_result res;
  res.texture_width = W;
  res.texture_height = H;

  // 1-2. charts of the simplified mesh, parameterised and packed
  const auto t0 = Clock::now();
  const std::size_t nf = sm.number_of_faces();
  std::vector<Vector_3> normal(nf);
  std::vector<double> area(nf);
  std::vector<std::array<Point_3, 3>> corner_point(nf);
  for (auto f : sm.faces()) {
    const std::size_t i = std::size_t(f);
    for (int k = 0; k < 3; ++k) corner_point[i][std::size_t(k)] = sm.point(sm.target(I::corner_halfedge(sm, f, k)));
    const Vector_3 c =
        CGAL::cross_product(corner_point[i][1] - corner_point[i][0], corner_point[i][2] - corner_point[i][0]);
    area[i] = 0.5 * std::sqrt(c.squared_length());
    normal[i] = I::unit_or_zero(c);
  }
  std::vector<I::Atlas_chart> charts = I::make_charts(sm, normal, area, options.chart_cone_degrees);
  res.texels_per_unit = I::pack_charts(charts, W, H, options.gutter_texels);
  res.charts = charts.size();
  std::vector<std::array<I::Atlas_uv, 3>> face_uv(nf);
  for (const auto& c : charts)
    for (std::size_t i = 0; i < c.faces.size(); ++i) face_uv[c.faces[i]] = c.uvs[i];
  res.seconds_charts = std::chrono::duration<double>(Clock::now() - t0).count();
  for (auto f : sm.faces())
    for (int k = 0; k < 3; ++k) {
      const auto& t = face_uv[std::size_t(f)][std::size_t(k)];
      simplified.set_uv(I::corner_halfedge(sm, f, k), Point_2(t[0], t[1]));
    }

  // 3. baking (of the texels a painter did not give)
  internal::Atlas_paint paint;
  if (painter) {
    const auto tp = Clock::now();
    paint.colours = Image(W, H, colour_channels);
    CMGeom::internal::assign_on_huge_pages(paint.given, std::size_t(W) * std::size_t(H), char(0));
    (*painter)(simplified, paint);
    if (paint.given.size() != std::size_t(W) * std::size_t(H)) paint.given.clear();
    if (paint.given.empty() || !any_normal || paint.normals.size() != 3 * paint.given.size()) paint.normals.clear();
    if (paint.faces.size() != paint.given.size()) paint.faces.clear();
    res.seconds_paint = std::chrono::duration<double>(Clock::now() - tp).count();
  }
  const Image& given_colours = paint.colours;
  const std::vector<char>& given = paint.given;
  const std::vector<float>& given_normals = paint.normals;
  const std::vector<std::uint32_t>& given_faces = paint.faces;
  const bool normals_given = !given_normals.empty();
  auto give = [&](std::size_t i, float* c) {
    const int x = int(i % std::size_t(W)), y = int(i / std::size_t(W));
    for (int ch = 0; ch < colour_channels; ++ch) c[ch] = given_colours.value(x, H - 1 - y, ch);
  };
  const auto t1 = Clock::now();
  const double reach = 0.1 * diag, reach2 = CGAL::square(reach);  // farther, a facing point is no match
  const std::size_t n = std::size_t(W) * std::size_t(H);
  constexpr std::uint32_t far = 0xffffffffu;
  std::vector<std::uint32_t> dist = CMGeom::internal::filled_on_huge_pages(n, far), dist_normal;
  std::vector<float> colour = CMGeom::internal::filled_on_huge_pages(n * std::size_t(colour_channels), 0.f);
  std::vector<float> normal_acc;
  if (any_normal) CMGeom::internal::assign_on_huge_pages(normal_acc, n * 3, 0.f);
  std::vector<std::size_t> baked_per_face(nf, 0), fixed_per_face(nf, 0), painted_per_face(nf, 0);
  // The texels a painter did not give are looked up a tile of tile x tile texels at a time (per
  // face): the facing faces that can be nearest to any of the tile's points are gathered once
  // around the tile's centre q (within min(d(q) + r, reach) + r, d being the distance to the
  // nearest facing face, r the tile's radius about q; d is 1-Lipschitz), then each texel scans
  // them nearest to q first. Neighbouring texels share most of their tree search otherwise: on the
  // damaged helmet at 1 %, 55 triangle tests and 212 tree nodes per texel. The answer is the tree
  // search's (Facing_closest_point: ties go to the lowest face index). A tile is searched texel by
  // texel instead where the faces around it are small beside it (more than
  // `most_expected_per_texel` per texel expected in the gathering disc: on DamagedHelmet
  // subdivided three times, 1M faces, the tiles were 1.3x slower than the tree there), or where
  // the gathering finds more than `most_per_texel` per texel.
  constexpr int tile_shift = 3;
  constexpr double most_expected_per_texel = 2;
  constexpr std::size_t most_per_texel = 16;
  struct Lookup {
    std::size_t i;
    std::uint64_t tile;
    double p[3];
    bool given;
  };
  // (a face at a time: the coarsest levels have few faces of many texels each)
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 1), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<Lookup> lookups;
    std::vector<I::Facing_closest_point::Candidate> candidates;
    std::vector<double> pq;  // |p - q| of each texel of a tile
    for (std::size_t fi = range.begin(); fi < range.end(); ++fi) {
      const auto& P = corner_point[fi];
      const auto& T = face_uv[fi];
      std::array<UV2, 3> tex;
      for (int k = 0; k < 3; ++k) tex[std::size_t(k)] = {{T[std::size_t(k)][0] * W, T[std::size_t(k)][1] * H}};
      const double det = I::signed_area_2(tex[0], tex[1], tex[2]);
      if (det == 0) continue;
      std::array<Vector_3, 3> new_frame;
      if (any_normal) new_frame = I::tangent_frame(P, T);
      const Vector_3 nf_dir = normal[fi];
      std::size_t hint = std::size_t(-1);
      lookups.clear();
      rasterize_triangle(tex, W, H, [&](int x, int y) {
        const auto [b0, b1, b2] = texel_centre_barycentric(tex, det, x, y);
        const std::size_t i = std::size_t(y) * std::size_t(W) + std::size_t(x);
        const bool is_given = !given.empty() && given[i];
        ++baked_per_face[fi];
        dist[i] = 0;
        if (is_given && (!any_normal || normals_given)) {  // no lookup needed
          give(i, &colour[i * std::size_t(colour_channels)]);
          if (!given_faces.empty() && given_faces[i] != 0 && given_faces[i] <= source.size())
            hint = std::size_t(given_faces[i] - 1);
          ++painted_per_face[fi];
          if (any_normal) {
            const Vector_3 nobj(given_normals[3 * i], given_normals[3 * i + 1], given_normals[3 * i + 2]);
            normal_acc[i * 3 + 0] = float(0.5 * (nobj * new_frame[0]) + 0.5);
            normal_acc[i * 3 + 1] = float(0.5 * (nobj * new_frame[1]) + 0.5);
            normal_acc[i * 3 + 2] = float(0.5 * (nobj * new_frame[2]) + 0.5);
          }
          return;
        }
        const Point_3 p =
            CGAL::ORIGIN + (b0 * (P[0] - CGAL::ORIGIN) + b1 * (P[1] - CGAL::ORIGIN) + b2 * (P[2] - CGAL::ORIGIN));
        const std::uint64_t tile = (std::uint64_t(y >> tile_shift) << 32) | std::uint64_t(x >> tile_shift);
        lookups.push_back({i, tile, {p.x(), p.y(), p.z()}, is_given});
      });
      if (lookups.empty()) continue;
      // (rows of texels come in order: sorting by tile keeps each tile's texels in that order)
      std::stable_sort(lookups.begin(), lookups.end(),
                       [](const Lookup& a, const Lookup& b) { return a.tile < b.tile; });
      auto look_up = [&](const Lookup& t, I::Facing_closest_point::Hit& hit) {
        const std::size_t i = t.i;
        if (!hit.found()) {  // nothing faces this way within reach: the closest point whatever its side
          hit.squared_distance = std::numeric_limits<double>::infinity();
          finder->search(t.p, CGAL::NULL_VECTOR, hit);
          ++fixed_per_face[fi];
        }
        hint = hit.face;
        const std::array<double, 3> w = src.hit_coordinates(hit);
        const double w0 = w[0], w1 = w[1], w2 = w[2];
        if (t.given)
          give(i, &colour[i * std::size_t(colour_channels)]);
        else
          src.colour_at(hit.face, w0, w1, w2, &colour[i * std::size_t(colour_channels)]);
        if (any_normal) {
          const Vector_3 nobj = src.normal_at(hit.face, w0, w1, w2);
          const double a = nobj * new_frame[0], b = nobj * new_frame[1], z = nobj * new_frame[2];
          normal_acc[i * 3 + 0] = float(0.5 * a + 0.5);
          normal_acc[i * 3 + 1] = float(0.5 * b + 0.5);
          normal_acc[i * 3 + 2] = float(0.5 * z + 0.5);
        }
      };
      for (std::size_t first = 0; first < lookups.size();) {
        std::size_t last = first + 1;
        while (last < lookups.size() && lookups[last].tile == lookups[first].tile) ++last;
        const std::size_t count = last - first;
        // the tile's centre and radius
        double q[3] = {0, 0, 0};
        for (std::size_t k = first; k < last; ++k)
          for (int c = 0; c < 3; ++c) q[c] += lookups[k].p[c];
        for (int c = 0; c < 3; ++c) q[c] /= double(count);
        pq.assign(count, 0.0);
        double r = 0;
        for (std::size_t k = first; k < last; ++k) {
          const double* p = lookups[k].p;
          pq[k - first] = std::sqrt(CGAL::square(p[0] - q[0]) + CGAL::square(p[1] - q[1]) + CGAL::square(p[2] - q[2]));
          r = (std::max)(r, pq[k - first]);
        }
        bool gathered = false;
        if (count > 1) {
          I::Facing_closest_point::Hit at_q;
          at_q.squared_distance = reach2;
          if (hint != std::size_t(-1)) finder->test(hint, q, nf_dir, at_q);
          finder->search(q, nf_dir, at_q);
          const double d = at_q.found() ? (std::min)(std::sqrt(at_q.squared_distance) + r, reach) : reach;
          // (a relative margin for the rounding of the distances)
          const double radius = (d + r) * (1 + 1e-9) + 1e-12 * diag;
          // the faces expected within the radius (a disc of the surface, tiled by faces the size
          // of the nearest one): where they are small beside the tile, the tree per texel is faster
          bool worth = true;
          if (at_q.found()) {
            const double disc = CGAL_PI * (std::max)(0.0, radius * radius - at_q.squared_distance);
            worth = disc < most_expected_per_texel * double(count) * finder->area(at_q.face);
          }
          if (worth) gathered = finder->gather(q, nf_dir, radius * radius, most_per_texel * count, candidates);
        }
        for (std::size_t k = first; k < last; ++k) {
          I::Facing_closest_point::Hit hit;
          hit.squared_distance = reach2;
          if (gathered) {
            finder->nearest_among(lookups[k].p, candidates, pq[k - first], hit);
          } else {
            if (hint != std::size_t(-1)) finder->test(hint, lookups[k].p, nf_dir, hit);
            finder->search(lookups[k].p, nf_dir, hit);
          }
          look_up(lookups[k], hit);
        }
        first = last;
      }
    }
  });
  for (std::size_t i = 0; i < nf; ++i) {
    res.texels_baked += baked_per_face[i];
    res.texels_unmatched += fixed_per_face[i];
    res.texels_painted += painted_per_face[i];
  }

  res.coverage = double(res.texels_baked) / double(n);
  // (the gutters' normals are grown from the charts', given colours or not)
  if (any_normal) dist_normal = CMGeom::internal::copy_on_huge_pages(dist);
  if (!given.empty())  // given texels outside the charts (gutters) are given too
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
        if (given[i] && dist[i] == far) {
          give(i, &colour[i * std::size_t(colour_channels)]);
          dist[i] = 0;
        }
    });
  // the two maps' gutters are filled at once (each fill is one pass over the texture)
  Image diffuse, normal_map;
  tbb::task_group fill;
  if (any_normal) fill.run([&] { normal_map = internal::dilate_into_image(W, H, 3, dist_normal, normal_acc); });
  diffuse = internal::dilate_into_image(W, H, colour_channels, dist, colour);
  fill.wait();
  res.seconds_bake = std::chrono::duration<double>(Clock::now() - t1).count();

  // the one material
  Material out;
  if (src.used_count_ == 1) {
    out.name = mats[src.first_used_].name;
    out.diffuse_color = mats[src.first_used_].diffuse_color;
  } else {
    out.name = "atlas";
    out.diffuse_color = {{1, 1, 1}};
  }
  if (out.name.empty()) out.name = "atlas";
  out.diffuse_image = std::move(diffuse);
  out.normal_image = std::move(normal_map);
  simplified.materials().clear();
  simplified.materials().push_back(std::move(out));
  for (auto f : sm.faces()) simplified.material_map()[f] = 0;
  simplified.set_has_uvs(true);
  return res;
}

/// Replaces the UVs and materials of `simplified` (a garbage-free triangle mesh) by a new atlas
/// baked from `original` (UVs and decoded textures, IO::load_textures); see the file comment.
/// Throws Invalid_input when `original` has no UVs or no decoded image, or for option values
/// out of range.
inline Atlas_result rebuild_atlas(const Textured_mesh& original, Textured_mesh& simplified,
                                  const Atlas_options& options = {}) {
  Atlas_source src(original, options);
  src.prepare();
  return rebuild_atlas(src, simplified, options);
}

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_REBUILD_ATLAS_H
