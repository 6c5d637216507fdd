// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The collapse history and the painting of atlases from the input, shared by
// simplify_textured_mesh() (its new atlas) and simplify_to_levels() (each level's atlas, or the one
// shared by every level). The input's vertices and face centroids are points that follow the
// collapses (Collapse_history, the thesis' point gathering of §4.3 with every point kept); after
// the run each lies on the face of the simplified mesh its part of the surface became. Mapped
// through that history into the simplified mesh's new atlas, the input's faces paint the atlas with
// their own colours (paint_atlas_from_original); rebuild_atlas() then looks up only the texels no
// input face reached. Not part of the documented interface.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_COLLAPSE_HISTORY_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_COLLAPSE_HISTORY_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Textured_simplification/Surface_memory.h>
#include <CMGeom/Textured_simplification/rebuild_atlas.h>
#include <CMGeom/internal/huge_pages.h>

#include <CGAL/boost/graph/copy_face_graph.h>

#include <boost/range/irange.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

/// Gives each copied vertex (`v2v`: pairs of a vertex of the original and its copy in `to`) the
/// position `positions` holds for the original (indexed by its vertex index); nothing when
/// `positions` is empty.
inline void set_copied_points(Surface_mesh& to,
                              const std::vector<std::pair<Surface_mesh::Vertex_index, Surface_mesh::Vertex_index>>& v2v,
                              const std::vector<Point_3>& positions) {
  if (!positions.empty())
    for (const auto& [v, w] : v2v) to.point(w) = positions[std::size_t(v)];
}

/// Gives each copied face (`f2f`: pairs of a face of `from` and its copy in `to`) the material
/// ("f:material", Textured_mesh's) it has in `from`, when `from` has that map (copy_face_graph()
/// copies no map of the mesh's own).
inline void copy_face_materials(const Surface_mesh& from, Surface_mesh& to,
                                const std::vector<std::pair<Surface_mesh::Face_index, Surface_mesh::Face_index>>& f2f) {
  const auto material = from.property_map<Surface_mesh::Face_index, int>("f:material");
  if (!material.second) return;
  auto copied = to.add_property_map<Surface_mesh::Face_index, int>("f:material", 0).first;
  for (const auto& [f, g] : f2f) copied[g] = material.first[f];
}

/// Copies the live part of `from` (a mesh that may hold garbage) into a new garbage-free mesh, its
/// faces' materials included; `v2v` receives the pairs of set_copied_points() (a level of a chain
/// then gets its fitted positions: Level_fitter).
inline Surface_mesh compact_copy(const Surface_mesh& from,
                                 std::vector<std::pair<Surface_mesh::Vertex_index, Surface_mesh::Vertex_index>>& v2v) {
  Surface_mesh to;
  v2v.clear();
  std::vector<std::pair<Surface_mesh::Face_index, Surface_mesh::Face_index>> f2f;
  CGAL::copy_face_graph(from, to,
                        CGAL::parameters::vertex_to_vertex_output_iterator(std::back_inserter(v2v))
                            .face_to_face_output_iterator(std::back_inserter(f2f)));
  copy_face_materials(from, to, f2f);
  return to;
}

/// The final fit simplify_mesh() would make on the mesh being simplified, to be computed later:
/// takes what the fit reads now and returns a callable that gives the fitted positions (by vertex
/// index of that mesh) on any thread, while the run goes on (Surface_memory::fitted_positions_later());
/// the mesh and the run are not changed. An empty callable: the run fits nothing.
using Level_fitter = std::function<std::function<std::vector<Point_3>()>(const Surface_mesh&)>;

/// A level's fit made beside the collapses (Level_fitter): the pairs of the run's vertices and the
/// level's copy of each, and, once computed, the fitted positions by the run's vertex index.
struct Pending_level_fit {
  std::size_t level = 0;  // (index of the snapshot)
  std::vector<std::pair<Surface_mesh::Vertex_index, Surface_mesh::Vertex_index>> v2v;
  std::vector<Point_3> positions;
};

/// Forwards every engine call to the caller's visitor; the snapshot visitors below derive from it
/// and add to OnCollapsed.
template <class Visitor>
struct Forwarding_visitor {
  Visitor visitor;
  template <class TM>
  void OnStarted(TM& tm) const {
    visitor.OnStarted(tm);
  }
  template <class TM>
  void OnFinished(TM& tm) const {
    visitor.OnFinished(tm);
  }
  template <class P>
  void OnStopConditionReached(const P& p) const {
    visitor.OnStopConditionReached(p);
  }
  template <class P, class C>
  void OnCollected(const P& p, const C& c) const {
    visitor.OnCollected(p, c);
  }
  template <class P, class C, class S>
  void OnSelected(const P& p, const C& c, S i, S n) const {
    visitor.OnSelected(p, c, i, n);
  }
  template <class P, class Pl>
  void OnCollapsing(const P& p, const Pl& pl) const {
    visitor.OnCollapsing(p, pl);
  }
  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    visitor.OnCollapsed(p, v);
  }
  template <class P>
  void OnNonCollapsable(const P& p) const {
    visitor.OnNonCollapsable(p);
  }
  template <class TM, class H>
  void OnFlipped(const TM& tm, const H& h) const {
    visitor.OnFlipped(tm, h);
  }
  template <class TM, class Faces>
  void OnFacesRemoved(const TM& tm, const Faces& fs) const {
    visitor.OnFacesRemoved(tm, fs);
  }
};

/// A copy of the mesh being simplified and, when the collapse history is followed (shared
/// texture), the points that stand for its vertices and faces and where the earlier points lie on it.
struct Level_snapshot {
  Surface_mesh mesh;  ///< garbage-free
  /// Per vertex / face of `mesh`: the index of the point that follows it down the collapses (nil: none).
  std::vector<std::uint32_t> vertex_point, face_point;
  /// Per point added before this snapshot: the face of `mesh` it lies on (nil: none).
  std::vector<std::uint32_t> face_of_point;
};

/// The collapse history of points, for painting the atlases. Every vertex and every face centroid of
/// the input and of each finer level is a point attached to a face of the mesh being simplified; a
/// collapse or a flip moves the points of the faces it changes to the nearest face of the new star
/// (Surface_memory's point gathering, the thesis' §4.3, with every point kept). So a point of a
/// finer level ends on the coarse face its own part of the surface became. A global closest-point
/// search cannot tell that where parts of a model fold onto one place of the coarse surface (a label
/// over a bottle, a visor over a helmet): it gives both parts the same texels.
class Collapse_history {
public:
  using Mesh = Surface_mesh;
  using Vertex = Mesh::Vertex_index;
  using Face = Mesh::Face_index;
  using VPM = Mesh::Property_map<Vertex, Point_3>;
  using V3 = CM::internal::Vec3;
  static constexpr std::uint32_t nil = 0xffffffffu;

  /// `work`: the (garbage-free) mesh about to be simplified; its vertices and faces are the
  /// first points, returned with identity maps (`mesh` left empty).
  explicit Collapse_history(const Mesh& work)
      : memory_(work, work.points(), std::vector<std::tuple<Face, V3, double>>(), every_point_counts()) {}

  /// The points of `work`'s own vertices and faces (the input's, before the first collapse).
  Level_snapshot add_input(const Mesh& work) {
    Level_snapshot s;
    std::vector<std::pair<Vertex, Vertex>> v2v;
    std::vector<std::pair<Face, Face>> f2f;
    for (Vertex v : work.vertices()) v2v.emplace_back(v, v);
    for (Face f : work.faces()) f2f.emplace_back(f, f);
    add_points(work, v2v, f2f, work.number_of_vertices(), work.number_of_faces(), s);
    return s;
  }

  /// The points of `input`'s vertices and faces, numbered as add_input(input) numbers them, for a
  /// history started on `work`, a simplification of `input` made without one (the input cut into
  /// parts, simplified and put back together: level_of_detail.h): each point starts on the face of
  /// `work` nearest to it (the points of a vertex in no face: none), where add_input() knows its
  /// face; the history follows it exactly from there on. `work` must be garbage-free.
  /// O((V + F) log F') for `input`'s V vertices and F faces and `work`'s F' faces, on all cores.
  Level_snapshot add_input_nearest(const Mesh& input, const Mesh& work) {
    if (work.has_garbage()) throw std::invalid_argument("Collapse_history::add_input_nearest: garbage in `work`");
    const Metrics::internal::Triangle_tree tree(Metrics::internal::make_flat_mesh(work, work.points(), "chain mesh"));
    const std::vector<Face> face_of(work.faces().begin(), work.faces().end());  // (the tree's triangle k)
    // the points, in add_input()'s order: the vertices in a face, then the faces' centroids
    std::vector<V3> queries;
    Level_snapshot s;
    s.vertex_point.assign(input.number_of_vertices(), nil);
    s.face_point.assign(input.number_of_faces(), nil);
    std::vector<std::pair<std::uint32_t*, std::size_t>> slot;  // (where each point's number goes)
    for (Vertex v : input.vertices()) {
      if (input.is_isolated(v)) continue;  // (no surface to follow)
      queries.push_back(vec(input.point(v)));
      slot.emplace_back(&s.vertex_point[std::size_t(v)], queries.size() - 1);
    }
    for (Face f : input.faces()) {
      queries.push_back(centroid(input, f));
      slot.emplace_back(&s.face_point[std::size_t(f)], queries.size() - 1);
    }
    std::vector<std::uint32_t> nearest(queries.size());
    using KP = Metrics::internal::Triangle_tree::K::Point_3;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        // (consecutive points are mostly close: each search starts from the last one's)
                        std::pair<KP, std::size_t> last{KP(), 0};
                        bool first = true;
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const KP q(queries[i].x, queries[i].y, queries[i].z);
                          last = first ? tree.closest_point_and_triangle(q)
                                       : tree.closest_point_and_triangle(q, last.first, last.second);
                          first = false;
                          nearest[i] = std::uint32_t(last.second);
                        }
                      });
    for (const auto& [out, i] : slot) *out = memory_.add_point(face_of[nearest[i]], queries[i]);
    return s;
  }

  /// A garbage-free copy of `work` with the faces of it every point added so far lies on; then the
  /// copy's vertices and faces become points too. `work` must not have been compacted
  /// (collect_garbage() renumbers the faces the points are attached to): snapshots are taken
  /// inside the run, the last one when it finishes.
  /// `v2v` as compact_copy()'s (the copy's points are `work`'s, as are those of the points added:
  /// the run follows them).
  Level_snapshot take(const Mesh& work, std::vector<std::pair<Vertex, Vertex>>& v2v) {
    Level_snapshot s;
    v2v.clear();
    std::vector<std::pair<Face, Face>> f2f;
    CGAL::copy_face_graph(work, s.mesh,
                          CGAL::parameters::vertex_to_vertex_output_iterator(std::back_inserter(v2v))
                              .face_to_face_output_iterator(std::back_inserter(f2f)));
    copy_face_materials(work, s.mesh, f2f);
    std::vector<std::uint32_t> copy_face(work.number_of_faces() + work.number_of_removed_faces(), nil);
    for (const auto& [from, to] : f2f) copy_face[std::size_t(from)] = std::uint32_t(to);
    const std::vector<Face> on = memory_.faces_of_points();
    s.face_of_point.resize(on.size(), nil);
    for (std::size_t i = 0; i < on.size(); ++i)
      if (on[i] != Mesh::null_face() && std::size_t(on[i]) < copy_face.size())
        s.face_of_point[i] = copy_face[std::size_t(on[i])];
    if (follow_levels_) add_points(work, v2v, f2f, s.mesh.number_of_vertices(), s.mesh.number_of_faces(), s);
    return s;
  }

  /// Per point added so far: the face of the mesh being simplified it lies on (null_face(): none),
  /// before any collect_garbage().
  std::vector<Face> faces_of_points() const { return memory_.faces_of_points(); }

  /// Whether take() makes the copy's vertices and faces points too (default; one shared texture
  /// maps every level through the history, an atlas per level only the input).
  void follow_levels(bool yes) { follow_levels_ = yes; }

  void before_collapse(const Mesh& tm, Mesh::Halfedge_index h) { memory_.before_collapse(tm, h); }
  void after_collapse(const Mesh& tm, Vertex v) { memory_.after_collapse(tm, v); }
  void after_flip(const Mesh& tm, Mesh::Halfedge_index h) { memory_.after_flip(tm, h); }
  /// The points of faces a pruned component took are dropped (nil in later snapshots).
  void drop_faces(const std::vector<Face>& fs) { memory_.drop_faces(fs); }

private:
  /// The memory's options: every point counts for when it starts moving the points of a whole
  /// star (as it prices collapses), i.e. from the first collapse.
  static Surface_memory_options every_point_counts() {
    Surface_memory_options o;
    o.pricing_points = 0;
    return o;
  }

  bool follow_levels_ = true;
  static V3 vec(const Point_3& p) { return V3(p.x(), p.y(), p.z()); }
  static V3 centroid(const Mesh& m, Face f) {
    V3 c(0, 0, 0);
    for (Vertex v : CGAL::vertices_around_face(m.halfedge(f), m)) c = c + vec(m.point(v));
    return (1. / 3.) * c;
  }

  void add_points(const Mesh& work, const std::vector<std::pair<Vertex, Vertex>>& v2v,
                  const std::vector<std::pair<Face, Face>>& f2f, std::size_t nv, std::size_t nf, Level_snapshot& s) {
    s.vertex_point.assign(nv, nil);
    s.face_point.assign(nf, nil);
    for (const auto& [from, to] : v2v)
      for (auto h : CGAL::halfedges_around_target(from, work))
        if (!work.is_border(h)) {  // an isolated vertex has no surface to follow
          s.vertex_point[std::size_t(to)] = memory_.add_point(work.face(h), vec(work.point(from)));
          break;
        }
    for (const auto& [from, to] : f2f) s.face_point[std::size_t(to)] = memory_.add_point(from, centroid(work, from));
  }

  Surface_memory<Mesh, VPM> memory_;
};

/// Forwards every call, and keeps the collapse history (when there is one) up to date.
template <class Visitor>
struct History_visitor : Forwarding_visitor<Visitor> {
  Collapse_history* history;
  const Level_fitter* fitter = nullptr;  // the snapshots' fit (none: the run's positions)
  History_visitor(const Visitor& v, Collapse_history* h, const Level_fitter* f = nullptr)
      : Forwarding_visitor<Visitor>{v}, history(h), fitter(f) {}
  template <class P, class Pl>
  void OnCollapsing(const P& p, const Pl& pl) const {
    this->visitor.OnCollapsing(p, pl);
    if (history) history->before_collapse(p.surface_mesh(), p.v0_v1());
  }
  template <class TM, class H>
  void OnFlipped(const TM& tm, const H& h) const {
    this->visitor.OnFlipped(tm, h);
    if (history) history->after_flip(tm, h);
  }
  /// (the faces of a pruned component: removed already, their indices still name them)
  template <class TM, class Faces>
  void OnFacesRemoved(const TM& tm, const Faces& fs) const {
    this->visitor.OnFacesRemoved(tm, fs);
    if (history) history->drop_faces(fs);
  }
  /// For the OnCollapsed of the visitors below, before they look at the mesh.
  template <class P, class V>
  void collapsed(const P& p, const V& v) const {
    this->visitor.OnCollapsed(p, v);
    if (history) history->after_collapse(p.surface_mesh(), v);
  }
  /// A copy of `mesh` with its vertices fitted (when there is a fitter), with the history's points
  /// when there is one.
  Level_snapshot snapshot(const Surface_mesh& mesh) const {
    std::function<std::vector<Point_3>()> later;
    std::vector<std::pair<Surface_mesh::Vertex_index, Surface_mesh::Vertex_index>> v2v;
    Level_snapshot s = snapshot_to_fit(mesh, later, v2v);
    if (later) set_copied_points(s.mesh, v2v, later());
    return s;
  }
  /// The same copy with the run's positions, and in `later` its fit to be made (empty: none; the
  /// positions it gives go to the copy's vertices through `v2v`, set_copied_points()).
  Level_snapshot snapshot_to_fit(
      const Surface_mesh& mesh, std::function<std::vector<Point_3>()>& later,
      std::vector<std::pair<Surface_mesh::Vertex_index, Surface_mesh::Vertex_index>>& v2v) const {
    later = fitter && *fitter ? (*fitter)(mesh) : std::function<std::vector<Point_3>()>();
    return history ? history->take(mesh, v2v) : Level_snapshot{compact_copy(mesh, v2v), {}, {}, {}};
  }
};

/// How far past its chart's border a corner mapped through the history may be extended, as a
/// fraction of the face it is projected on (map_by_history()'s `max_extrapolation`; the default of
/// Level_of_detail_options and the value simplify_textured_mesh() uses).
inline constexpr double default_max_extrapolation = 0.5;

/// The face property in which Following_visitor keeps each face's index before compaction.
inline constexpr const char* before_compaction_property = "f:cmgeom_before_compaction";

/// A History_visitor for a run that takes no snapshot (simplify_textured_mesh()). When the run
/// finishes, before simplify_mesh() compacts the mesh, it stores the face each point lies on in
/// `on` and each live face's own index in the face property before_compaction_property, which
/// renumbered_faces() reads once the mesh is compacted.
template <class Visitor>
struct Following_visitor : History_visitor<Visitor> {
  std::vector<Surface_mesh::Face_index>* on;
  Following_visitor(const Visitor& v, Collapse_history* h, std::vector<Surface_mesh::Face_index>* on_faces)
      : History_visitor<Visitor>(v, h), on(on_faces) {}
  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    this->collapsed(p, v);
  }
  void OnFinished(Surface_mesh& mesh) const {
    this->visitor.OnFinished(mesh);
    *on = this->history->faces_of_points();
    auto before = mesh.add_property_map<Surface_mesh::Face_index, std::uint32_t>(before_compaction_property, 0).first;
    for (auto f : mesh.faces()) before[f] = std::uint32_t(f);
  }
};

/// With Following_visitor: the face of the compacted `mesh` each point lies on (nil: none); removes
/// the property the visitor added.
inline std::vector<std::uint32_t> renumbered_faces(Surface_mesh& mesh,
                                                   const std::vector<Surface_mesh::Face_index>& on) {
  using Face = Surface_mesh::Face_index;
  std::vector<std::uint32_t> out(on.size(), Collapse_history::nil);
  auto before = mesh.property_map<Face, std::uint32_t>(before_compaction_property);
  if (!before.second) return out;
  std::size_t slots = 0;
  for (Face f : mesh.faces()) slots = (std::max)(slots, std::size_t(before.first[f]) + 1);
  for (Face f : on)
    if (f != Surface_mesh::null_face()) slots = (std::max)(slots, std::size_t(f) + 1);
  std::vector<std::uint32_t> renumbered(slots, Collapse_history::nil);
  for (Face f : mesh.faces()) renumbered[before.first[f]] = std::uint32_t(f);
  mesh.remove_property_map(before.first);
  for (std::size_t i = 0; i < on.size(); ++i)
    if (on[i] != Surface_mesh::null_face()) out[i] = renumbered[std::size_t(on[i])];
  return out;
}

/// The texture coordinates of point p under the affine map of triangle t (corner coordinates uv),
/// from p's projection on t's plane, barycentric coordinates clamped to >= -extend.
inline Point_2 extended_uv(const std::array<CM::internal::Vec3, 3>& t, const std::array<Point_2, 3>& uv,
                           const CM::internal::Vec3& p, double extend) {
  using CM::internal::dot;
  const auto e1 = t[1] - t[0], e2 = t[2] - t[0], e = p - t[0];
  const double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), d1 = dot(e, e1), d2 = dot(e, e2);
  const double den = d11 * d22 - d12 * d12;
  std::array<double, 3> w{{1.0 / 3, 1.0 / 3, 1.0 / 3}};
  if (den > 0 && std::isfinite(den)) {
    const double w1 = (d22 * d1 - d12 * d2) / den, w2 = (d11 * d2 - d12 * d1) / den;
    w = {{1 - w1 - w2, w1, w2}};
    double sum = 0;
    for (double& x : w) {
      x = (std::max)(x, -extend);
      sum += x;
    }
    for (double& x : w) x /= sum;
  }
  return Point_2(w[0] * uv[0].x() + w[1] * uv[1].x() + w[2] * uv[2].x(),
                 w[0] * uv[0].y() + w[1] * uv[1].y() + w[2] * uv[2].y());
}

/// `t` moved onto the texture ([0, 1]²): a corner extended past a chart at the atlas' edge would
/// read, with a repeating sampler, the other side of the atlas.
inline Point_2 on_texture(const Point_2& t) {
  return Point_2(std::clamp(t.x(), 0.0, 1.0), std::clamp(t.y(), 0.0, 1.0));
}

/// Gives `fine` texture coordinates in the atlas of `coarse` (see the file comment), each face
/// material 0 (the atlas' images are the caller's to give: they are large, and a mapping made only
/// to be measured or painted from needs none). `vertex_point` and `face_point` are the points of the fine mesh's
/// vertices and faces, `coarse_face_of_point` the coarse face each point lies on (Level_snapshot).
/// A fine face goes into the chart of the coarse face its centroid's point lies on; a corner takes
/// the coordinates of its point's place on its coarse face when that face is in the chart, else of
/// its projection on the nearest face of the chart around that place, extended past the chart's
/// border by at most `max_extrapolation` of the face (barycentric coordinates >= -it). When given,
/// `chart_of_face` receives the chart of each fine face and `depth_of_face` the distance from its
/// centroid to its coarse face.
inline void map_by_history(const Textured_mesh& coarse, Textured_mesh& fine,
                           const std::vector<std::uint32_t>& vertex_point, const std::vector<std::uint32_t>& face_point,
                           const std::vector<std::uint32_t>& coarse_face_of_point, double max_extrapolation,
                           double border_texels, int atlas_width, int atlas_height,
                           std::vector<int>* chart_of_face = nullptr, std::vector<double>* depth_of_face = nullptr) {
  using Face = Surface_mesh::Face_index;
  using Vertex = Surface_mesh::Vertex_index;
  using V3 = CM::internal::Vec3;
  constexpr std::size_t none = std::size_t(-1);
  const Surface_mesh& cm = coarse.mesh();
  Surface_mesh& fm = fine.mesh();
  const double texels_u = (std::max)(1, atlas_width), texels_v = (std::max)(1, atlas_height);
  // the coarse faces (garbage-free: indices 0..nc-1): triangles, UVs, charts
  auto chart_map = get(CGAL::dynamic_face_property_t<int>(), cm);
  compute_chart_ids(cm, coarse.uv_map(), chart_map);
  const std::size_t nc = cm.number_of_faces();
  std::vector<std::array<V3, 3>> tri(nc);
  std::vector<std::array<Point_2, 3>> uvs(nc);
  std::vector<int> chart(nc);
  for (Face f : cm.faces()) {
    const std::size_t i = std::size_t(f);
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(cm.halfedge(f), cm)) {
      const Point_3& p = cm.point(cm.target(h));
      tri[i][std::size_t(k)] = V3(p.x(), p.y(), p.z());
      uvs[i][std::size_t(k)] = coarse.uv(h);
      ++k;
    }
    chart[i] = get(chart_map, f);
  }
  // each coarse face's neighbourhood: the faces around its corners, and the faces around theirs
  std::vector<V3> normal(nc);
  std::vector<std::vector<std::size_t>> ring(nc);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nc), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      normal[i] = CM::internal::normalized(CM::internal::cross(tri[i][1] - tri[i][0], tri[i][2] - tri[i][0]));
      std::vector<std::size_t>& g = ring[i];
      g.push_back(i);
      for (int depth = 0; depth < 2; ++depth) {
        const std::size_t end = g.size();
        for (std::size_t j = 0; j < end; ++j)
          for (Vertex c : CGAL::vertices_around_face(cm.halfedge(Face(Surface_mesh::size_type(g[j]))), cm))
            for (Face a : CGAL::faces_around_target(cm.halfedge(c), cm))
              if (a != Surface_mesh::null_face() && std::find(g.begin(), g.end(), std::size_t(a)) == g.end())
                g.push_back(std::size_t(a));
      }
    }
  });
  // and its bounding sphere (centroid, farthest corner): a face whose sphere is farther from a
  // point than the best distance so far cannot be nearer (the searches below skip it)
  std::vector<V3> centre(nc);
  std::vector<double> radius(nc);
  for (std::size_t i = 0; i < nc; ++i) {
    const CM::internal::Centroid_sphere sphere = CM::internal::centroid_sphere(tri[i][0], tri[i][1], tri[i][2]);
    centre[i] = sphere.centre;
    radius[i] = sphere.radius;
  }
  auto vec = [](const Point_3& p) { return V3(p.x(), p.y(), p.z()); };
  auto distance2 = [&](std::size_t f, const V3& p) {
    return CM::internal::squared_length(p - CM::internal::closest_on_triangle(p, tri[f][0], tri[f][1], tri[f][2]));
  };
  // whether face f is surely not nearer to p than sqrt(d2): the distance from p to its sphere is
  // at least that (with a margin for round-off, so that a skipped face could not have won)
  auto beyond = [&](std::size_t f, const V3& p, double d2) {
    const double out = CM::internal::length(p - centre[f]) - radius[f];
    return out > 0 && out * out > d2 * (1 + 1e-9);
  };
  // the face a point's collapse history put it on, then the nearest face around it turned the way
  // of the normal n (the history finds the part of the coarse surface, the local search the place)
  auto home_of = [&](const std::vector<std::uint32_t>& points, std::size_t i, const V3& p, const V3& n) {
    if (i >= points.size() || points[i] >= coarse_face_of_point.size()) return none;
    const std::uint32_t f = coarse_face_of_point[points[i]];
    if (f >= nc) return none;
    std::size_t best = none, best_any = f;
    double d_best = std::numeric_limits<double>::infinity(), d_any = d_best;
    for (std::size_t g : ring[f]) {
      if (beyond(g, p, d_best)) continue;  // (d_any <= d_best: nearer to neither)
      const double d = distance2(g, p);
      if (d < d_any) {
        d_any = d;
        best_any = g;
      }
      if (d < d_best && CM::internal::dot(normal[g], n) > 0) {
        d_best = d;
        best = g;
      }
    }
    return best != none ? best : best_any;
  };
  // the face of `faces` (a non-empty range of coarse face indices) nearest to p, the first of equals
  auto nearest_among = [&](const auto& faces, const V3& p) {
    std::size_t best = *std::begin(faces);
    double d_best = std::numeric_limits<double>::infinity();
    for (std::size_t f : faces) {
      if (beyond(f, p, d_best)) continue;
      const double d = distance2(f, p);
      if (d < d_best) {
        d_best = d;
        best = f;
      }
    }
    return best;
  };
  // texture coordinates of p's projection on coarse face f's plane, barycentric coordinates
  // clamped to >= -extend and renormalised
  auto uv_on = [&](std::size_t f, const V3& p, double extend) { return extended_uv(tri[f], uvs[f], p, extend); };

  // the fine mesh's vertex normals (area-weighted)
  const std::size_t nf = fm.number_of_faces();
  std::vector<V3> vertex_normal(fm.number_of_vertices(), V3(0, 0, 0));
  for (Face f : fm.faces()) {
    const auto h = fm.halfedge(f);
    const V3 a = vec(fm.point(fm.source(h))), b = vec(fm.point(fm.target(h))), c = vec(fm.point(fm.target(fm.next(h))));
    const V3 n = CM::internal::cross(b - a, c - a);
    for (Vertex v : CGAL::vertices_around_face(h, fm))
      vertex_normal[std::size_t(v)] = vertex_normal[std::size_t(v)] + n;
  }
  // each fine face's coarse face, chart and depth
  std::vector<std::size_t> face_home(nf);
  std::vector<int> face_chart(nf, 0);
  std::vector<double> face_depth(nf, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const auto g = fm.halfedge(Face(Surface_mesh::size_type(i)));
      const V3 a = vec(fm.point(fm.source(g))), b = vec(fm.point(fm.target(g))),
               d = vec(fm.point(fm.target(fm.next(g))));
      const V3 c = (1. / 3.) * (a + b + d);
      std::size_t h = home_of(face_point, i, c, CM::internal::cross(b - a, d - a));
      if (h == none) h = nearest_among(boost::irange(std::size_t(0), nc), c);  // a point the history lost
      face_home[i] = h;
      face_chart[i] = chart[h];
      face_depth[i] = std::sqrt(distance2(h, c));
    }
  });

  // one texture coordinate per (vertex, chart) used; the coarse faces of the fine faces around the
  // vertex in that chart are where its search starts
  struct Key_hash {
    std::size_t operator()(const std::pair<std::uint32_t, int>& k) const {
      return std::size_t(k.first) * 0x9E3779B97F4A7C15ull ^ std::size_t(k.second);
    }
  };
  std::unordered_map<std::pair<std::uint32_t, int>, std::size_t, Key_hash> slot;
  std::vector<std::pair<std::uint32_t, int>> keys;
  std::vector<std::vector<std::size_t>> seeds;
  for (Face f : fm.faces())
    for (auto h : CGAL::halfedges_around_face(fm.halfedge(f), fm)) {
      const std::pair<std::uint32_t, int> k{std::uint32_t(fm.target(h)), face_chart[std::size_t(f)]};
      const auto [it, added] = slot.emplace(k, keys.size());
      if (added) {
        keys.push_back(k);
        seeds.emplace_back();
      }
      auto& s = seeds[it->second];
      if (std::find(s.begin(), s.end(), face_home[std::size_t(f)]) == s.end()) s.push_back(face_home[std::size_t(f)]);
    }
  std::vector<Point_2> uv_of(keys.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, keys.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::size_t> around;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Vertex v(keys[i].first);
      const int k = keys[i].second;
      const V3 p = vec(fm.point(v));
      const std::size_t own = home_of(vertex_point, std::size_t(v), p, vertex_normal[std::size_t(v)]);
      if (own != none && chart[own] == k) {  // its place on its face: inside the face, no extension
        // past the face's border (over a convex edge, a projection on the face's plane squashes the
        // surface onto it) by at most `border_texels`, into the chart's neighbour or its gutter
        const Point_2 in = uv_on(own, p, 0.0), out = uv_on(own, p, max_extrapolation);
        const double dx = (out.x() - in.x()) * texels_u, dy = (out.y() - in.y()) * texels_v;
        const double d = std::sqrt(dx * dx + dy * dy);
        const double t = d > border_texels ? border_texels / d : 1.0;
        uv_of[i] = Point_2(in.x() + t * (out.x() - in.x()), in.y() + t * (out.y() - in.y()));
        continue;
      }
      // across a seam of the coarse atlas: the nearest face of the chart among the seeds and
      // the faces around their corners
      around.clear();
      for (std::size_t s : seeds[i]) {
        around.push_back(s);
        for (Vertex c : CGAL::vertices_around_face(cm.halfedge(Face(Surface_mesh::size_type(s))), cm))
          for (Face g : CGAL::faces_around_target(cm.halfedge(c), cm))
            if (g != Surface_mesh::null_face() && chart[std::size_t(g)] == k) around.push_back(std::size_t(g));
      }
      uv_of[i] = uv_on(nearest_among(around, p), p, max_extrapolation);
    }
  });
  for (Point_2& t : uv_of) t = on_texture(t);
  for (Face f : fm.faces())
    for (auto h : CGAL::halfedges_around_face(fm.halfedge(f), fm))
      fine.set_uv(h, uv_of[slot.at({std::uint32_t(fm.target(h)), face_chart[std::size_t(f)]})]);
  for (Face f : fm.faces()) fine.material_map()[f] = 0;
  fine.set_has_uvs(true);
  if (chart_of_face) *chart_of_face = std::move(face_chart);
  if (depth_of_face) *depth_of_face = std::move(face_depth);
}

/// Per face of a mesh painted into an atlas (paint_atlas_from_original()): the texels of its chart
/// its rasterisation covers, and those it won (nearest to the coarse surface among the faces there).
struct Face_texels {
  std::vector<std::uint32_t> covered, won;
};

/// A texel of a W x H grid: its index y * W + x and its coordinates.
struct Grid_texel {
  std::size_t at;
  int x, y;
};

/// Grows a texel labelling over the 4-neighbour grid of a W x H image, one ring at a time, at most
/// `rings` rings: a texel `is_open` next to a labelled one (`is_labelled`, or labelled in an
/// earlier ring) gets `take(texel, neighbour)` (two Grid_texel), which returns whether it took it.
/// The rings are grown serially and in texel order, so the result does not depend on the thread
/// count; the first front (the labelled texels next to an open one) is found on all cores, a band
/// of rows each, and joined in row order. `is_labelled` and `is_open` are called concurrently then
/// (they only read); the work is the image's texels once, then the rings'.
template <class Labelled, class Open, class Take>
void grow_rings(int W, int H, int rings, const Labelled& is_labelled, const Open& is_open, const Take& take) {
  if (W <= 0 || H <= 0 || rings <= 0) return;
  const std::size_t w = std::size_t(W);
  auto for_neighbours = [&](const Grid_texel& t, auto&& fn) {  // (left, right, below, above)
    if (t.x > 0) fn(Grid_texel{t.at - 1, t.x - 1, t.y});
    if (t.x + 1 < W) fn(Grid_texel{t.at + 1, t.x + 1, t.y});
    if (t.y > 0) fn(Grid_texel{t.at - w, t.x, t.y - 1});
    if (t.y + 1 < H) fn(Grid_texel{t.at + w, t.x, t.y + 1});
  };
  const int band = 64;  // rows per task of the first front
  const int bands = (H + band - 1) / band;
  std::vector<std::vector<Grid_texel>> fronts(static_cast<std::size_t>(bands));
  tbb::parallel_for(0, bands, [&](int b) {
    std::vector<Grid_texel>& out = fronts[std::size_t(b)];
    for (int y = b * band; y < (std::min)(H, (b + 1) * band); ++y)
      for (int x = 0; x < W; ++x) {
        const Grid_texel t{std::size_t(y) * w + std::size_t(x), x, y};
        if (!is_labelled(t.at)) continue;
        bool border = false;
        for_neighbours(t, [&](const Grid_texel& n) { border = border || is_open(n.at); });
        if (border) out.push_back(t);
      }
  });
  std::vector<Grid_texel> front, next;
  std::size_t total = 0;
  for (const auto& f : fronts) total += f.size();
  front.reserve(total);
  for (auto& f : fronts) {
    front.insert(front.end(), f.begin(), f.end());
    std::vector<Grid_texel>().swap(f);
  }
  for (int ring = 0; ring < rings && !front.empty(); ++ring) {
    next.clear();
    for (const Grid_texel& t : front)
      for_neighbours(t, [&](const Grid_texel& n) {
        if (is_open(n.at) && take(n, t)) next.push_back(n);
      });
    front.swap(next);
  }
}

/// Paints the atlas `paint.colours` of `coarse` (the shared one made for the coarsest level, or a
/// level's own) from the original itself: every original
/// face, at the texture coordinates map_by_history() gave it (`original_mapped`, the original's
/// faces in order), is rasterised into the atlas and each texel it covers takes the original's
/// colour at that point of the face (Atlas_source::colour_at). A texel keeps the colour of the
/// original face nearest to the coarse surface among those covering it, and is written only by
/// faces of the chart it belongs to: a chart's own texels and the gutter texels nearer to it than
/// to any other chart, up to `gutter_texels` away (farther texels by any). So a corner extended
/// past its chart's border reads that chart's colours, not a neighbouring chart's. The painted
/// colours then grow over the unpainted texels of their chart (up to `gutter_texels` rings).
/// `paint.given` receives the texels painted, `paint.faces` the original face each came from and,
/// with normal maps, `paint.normals` the original's normals there in object space (rebuild_atlas()
/// bakes the other texels from the coarse surface: this runs as its Atlas_painter). So the finest
/// level reads the original's colours
/// almost exactly, and a coarser level, whose points map to the same atlas points as the original
/// points they stand for, reads those colours too. Rows are painted in parallel bands. Returns
/// the fraction of the texels the original's faces cover that went to another face (hidden:
/// parts of the original that fold onto the same place of the coarse surface). When given,
/// `texels_of_face` receives, per original face, the texels of its chart it covers and those it won.
inline double paint_atlas_from_original(const Atlas_source& source, const Textured_mesh& coarse,
                                        const Textured_mesh& original_mapped, const std::vector<int>& chart_of_face,
                                        const std::vector<double>& depth_of_face, int gutter_texels, Atlas_paint& paint,
                                        Face_texels* texels_of_face = nullptr) {
  Image& image = paint.colours;
  image.unshare();  // (written below on all cores)
  using Face = Surface_mesh::Face_index;
  const int W = image.width(), H = image.height(), C = image.channels();
  if (W <= 0 || H <= 0 || C != source.colour_channels()) return 0.0;
  // the chart of every texel of the coarse atlas (-1: none)
  const Surface_mesh& cm = coarse.mesh();
  auto chart_map = get(CGAL::dynamic_face_property_t<int>(), cm);
  compute_chart_ids(cm, coarse.uv_map(), chart_map);
  std::vector<int> owner = CMGeom::internal::filled_on_huge_pages(std::size_t(W) * std::size_t(H), -1);
  auto texel_triangle = [&](const Textured_mesh& tm, Face f) {
    std::array<UV2, 3> t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(tm.mesh().halfedge(f), tm.mesh())) {
      const Point_2 p = tm.uv(h);
      t[std::size_t(k++)] = {{p.x() * W, p.y() * H}};
    }
    return t;
  };
  for (Face f : cm.faces()) {
    const int c = get(chart_map, f);
    rasterize_triangle(texel_triangle(coarse, f), W, H,
                       [&](int x, int y) { owner[std::size_t(y) * std::size_t(W) + std::size_t(x)] = c; });
  }
  // the gutters go to the nearest chart, one ring of texels at a time (4-neighbours)
  grow_rings(
      W, H, gutter_texels, [&](std::size_t at) { return owner[at] != -1; },
      [&](std::size_t at) { return owner[at] == -1; },
      [&](const Grid_texel& to, const Grid_texel& from) {
        owner[to.at] = owner[from.at];
        return true;
      });
  const Surface_mesh& om = original_mapped.mesh();
  const std::size_t nf = om.number_of_faces();
  std::vector<std::array<UV2, 3>> tri(nf);
  std::vector<std::pair<int, int>> rows(nf);
  for (Face f : om.faces()) {
    const std::size_t i = std::size_t(f);
    tri[i] = texel_triangle(original_mapped, f);
    double lo = tri[i][0][1], hi = lo;
    for (const auto& p : tri[i]) {
      lo = (std::min)(lo, p[1]);
      hi = (std::max)(hi, p[1]);
    }
    rows[i] = {int(std::floor(lo)) - 1, int(std::ceil(hi)) + 1};
  }
  const int band = 16;
  std::atomic<std::size_t> covered{0}, won{0};
  std::vector<char> painted = CMGeom::internal::filled_on_huge_pages(std::size_t(W) * std::size_t(H), char(0));
  std::vector<float> normals;
  if (source.has_normal_maps())
    CMGeom::internal::assign_on_huge_pages(normals, 3 * std::size_t(W) * std::size_t(H), 0.f);
  std::vector<std::uint32_t> faces = CMGeom::internal::filled_on_huge_pages(std::size_t(W) * std::size_t(H), 0u);
  tbb::parallel_for(0, (H + band - 1) / band, [&](int b) {
    const int y0 = b * band, y1 = (std::min)(H, y0 + band);
    const std::size_t texels = std::size_t(y1 - y0) * std::size_t(W);
    std::vector<double> best(texels, std::numeric_limits<double>::infinity());
    std::vector<std::size_t> winner(texels, std::size_t(-1));
    std::size_t band_covered = 0;
    for (std::size_t i = 0; i < nf; ++i) {
      if (rows[i].second < y0 || rows[i].first >= y1) continue;
      const int k = chart_of_face[i];
      const double depth = depth_of_face[i];
      rasterize_triangle(tri[i], W, H, y0, y1, [&](int x, int y) {
        const std::size_t at = std::size_t(y) * std::size_t(W) + std::size_t(x);
        if (owner[at] != -1 && owner[at] != k) return;
        ++band_covered;
        const std::size_t j = std::size_t(y - y0) * std::size_t(W) + std::size_t(x);
        if (depth >= best[j]) return;
        best[j] = depth;
        winner[j] = i;
      });
    }
    std::size_t band_won = 0;
    float c[4];
    for (std::size_t j = 0; j < texels; ++j) {
      const std::size_t i = winner[j];
      if (i == std::size_t(-1)) continue;
      ++band_won;
      painted[std::size_t(y0) * std::size_t(W) + j] = 1;
      faces[std::size_t(y0) * std::size_t(W) + j] = std::uint32_t(i + 1);
      const auto& t = tri[i];
      const int x = int(j % std::size_t(W)), y = y0 + int(j / std::size_t(W));
      const auto [b0, b1, b2] = texel_centre_barycentric(t, signed_area_2(t[0], t[1], t[2]), x, y);
      source.colour_at(i, b0, b1, b2, c);
      for (int ch = 0; ch < C; ++ch) image.set_value(x, H - 1 - y, ch, c[ch]);  // image rows run down
      if (!normals.empty()) {
        const Vector_3 n = source.normal_at(i, b0, b1, b2);
        const std::size_t at = 3 * (std::size_t(y0) * std::size_t(W) + j);
        normals[at] = float(n.x());
        normals[at + 1] = float(n.y());
        normals[at + 2] = float(n.z());
      }
    }
    covered += band_covered;
    won += band_won;
  });
  if (texels_of_face) {  // each face's covered texels and those it won, before the growth below
    texels_of_face->covered.assign(nf, 0);
    texels_of_face->won.assign(nf, 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        std::uint32_t c = 0, w = 0;
        const int k = chart_of_face[i];
        rasterize_triangle(tri[i], W, H, [&](int x, int y) {
          const std::size_t at = std::size_t(y) * std::size_t(W) + std::size_t(x);
          if (owner[at] != -1 && owner[at] != k) return;
          ++c;
          w += faces[at] == std::uint32_t(i + 1);
        });
        texels_of_face->covered[i] = c;
        texels_of_face->won[i] = w;
      }
    });
  }
  // the original's colours grow over the texels of their chart that no original face covered
  // (squashed strips over convex edges, the gutters), where the coarse bake may have found
  // another part of the original (the bottle under a label): up to `gutter_texels` rings
  grow_rings(
      W, H, gutter_texels, [&](std::size_t at) { return painted[at] != 0; },
      [&](std::size_t at) { return !painted[at] && owner[at] != -1; },
      [&](const Grid_texel& to, const Grid_texel& from) {
        if (owner[to.at] != owner[from.at]) return false;
        image.copy_pixel(to.x, H - 1 - to.y, from.x, H - 1 - from.y, C);
        if (!normals.empty())
          for (int k = 0; k < 3; ++k) normals[3 * to.at + std::size_t(k)] = normals[3 * from.at + std::size_t(k)];
        faces[to.at] = faces[from.at];
        painted[to.at] = 1;
        return true;
      });
  paint.given = std::move(painted);
  paint.normals = std::move(normals);
  paint.faces = std::move(faces);
  return covered > 0 ? 1.0 - double(won) / double(covered) : 0.0;
}

/// Paints the atlas of `level` (`paint`, as an Atlas_painter is handed it) from the input followed
/// down the collapses: `mapped` (the input's mesh, its faces in the input's order) gets texture
/// coordinates in that atlas through the history (map_by_history(); `input_points`: the points of
/// the input's vertices and faces, `on_level`: the face of `level` each point ended on), then its
/// faces paint their own colours (paint_atlas_from_original()). Returns the share of the input's
/// texels another part of the input took (parts folding onto one place of `level`).
/// When given, `texels_of_face` receives each input face's texels (paint_atlas_from_original()).
inline double paint_input_onto(const Atlas_source& source, const Level_snapshot& input_points,
                               const Textured_mesh& level, Textured_mesh& mapped,
                               const std::vector<std::uint32_t>& on_level, double max_extrapolation, int gutter_texels,
                               Atlas_paint& paint, Face_texels* texels_of_face = nullptr) {
  std::vector<int> chart_of_face;
  std::vector<double> depth_of_face;
  map_by_history(level, mapped, input_points.vertex_point, input_points.face_point, on_level, max_extrapolation,
                 0.75 * gutter_texels, paint.colours.width(), paint.colours.height(), &chart_of_face, &depth_of_face);
  return paint_atlas_from_original(source, level, mapped, chart_of_face, depth_of_face, gutter_texels, paint,
                                   texels_of_face);
}

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_COLLAPSE_HISTORY_H
