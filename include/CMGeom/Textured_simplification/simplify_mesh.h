// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// simplify_mesh(): geometric simplification of a Surface_mesh in one call (a face count, a ratio, a cost
// bound or a guaranteed error bound), as `cmgeom simplify --no-texture` and the new-atlas path of
// simplify_textured_mesh() run it: the quadrics of Area_weighted_quadric_policies, completed by the
// memoryful cost of Surface_memory (unless switched off), on CMGeom's engine (edge_collapse.h), edge
// flips on request; the error bound is Hausdorff_bound.h's. With the memoryful cost and no error
// bound (nor endpoint placement), the vertices are then fitted to the input's points (Surface_memory::fit_vertices(),
// `options.memory.fit`): a least-squares move of every vertex that lowers the RMS distance.
//
// Key choice: large inputs (at least `parts_min_faces` faces, asked for at most a quarter of them
// by default) are simplified on all cores. They are cut into 2^k parts (internal/Mesh_parts.h),
// each simplified on its own core with the input's quadrics and its cut vertices locked, down to
// its share of the target plus a few faces per cut vertex; then the whole is rebuilt and the
// remaining collapses (those of the strips along the cuts, mostly) run on it. Before that, the
// parts are put back together pairwise, the last cut first: each pair is simplified along its
// common cut, with the cuts it still has locked, the pairs of a level at once, so that the stage on
// the whole is left with the strips of the first two levels' cuts only (it shares the target
// between the four regions they bound by cost). The parts depend on the mesh alone, so
// the result is the same on any number of cores.
//
// Manual: doc/Textured_simplification/README.md, "One call, and large meshes on all cores: `simplify_mesh()`".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_SIMPLIFY_MESH_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_SIMPLIFY_MESH_H

#include <CMGeom/config.h>
#include <CMGeom/Error.h>
#include <CMGeom/internal/release_freed_memory.h>
#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>
#include <CMGeom/Textured_simplification/Endpoint_placement.h>
#include <CMGeom/Textured_simplification/Hausdorff_bound.h>
#include <CMGeom/Textured_simplification/Removed_faces_visitor.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/Surface_memory.h>
#include <CMGeom/Textured_simplification/edge_collapse.h>
#include <CMGeom/Textured_simplification/internal/Mesh_parts.h>
#include <CMGeom/Textured_simplification/parameters.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/helpers.h>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

/// The collapse engine of simplify_mesh().
enum class Simplification_engine {
  cmgeom,  ///< CMGeom's edge_collapse (edge_collapse.h): memoryful cost, flips, parts
  cgal     ///< CGAL's Surface_mesh_simplification::edge_collapse, with No_normal_flip_filter
};

/// Why a simplification stopped.
enum class Stop_reason {
  target,       ///< the face target was reached (or there was nothing to do)
  chart_limit,  ///< no collapse left that keeps the charts (simplify_textured_mesh, keep_charts)
  no_collapse,  ///< no valid collapse left at all (topology: e.g. a tetrahedron)
  max_cost,     ///< the cheapest collapse left costs more than `max_cost`
  max_error     ///< no collapse left that keeps the Hausdorff bound `max_error`
};

inline const char* to_string(Stop_reason r) {
  return r == Stop_reason::target        ? "target"
         : r == Stop_reason::chart_limit ? "chart_limit"
         : r == Stop_reason::max_cost    ? "max_cost"
         : r == Stop_reason::max_error   ? "max_error"
                                         : "no_collapse";
}

/// Options of simplify_mesh().
struct Mesh_simplification_options {
  /// The target of simplify_mesh(mesh, options): a face count (`target_faces`) or a fraction of
  /// the input's faces (`target_ratio`, see target_faces_for_ratio()), not both, and/or a cost
  /// bound (`max_cost`): the collapses stop when the cheapest one left costs more than it
  /// (whichever of the count and the bound comes first).
  std::optional<std::size_t> target_faces;
  std::optional<double> target_ratio;
  /// In the engine's cost units, the cost being the one collapses are ranked by: the quadric
  /// error at the placement (plain quadrics: sum over the input faces merged into the edge's
  /// endpoints of area x squared distance to their planes, plus the border term), raised by the
  /// memoryful cost where that one is higher. Finite and >= 0.
  std::optional<double> max_cost;
  /// A guaranteed bound on the Hausdorff distance between the output and the input, both ways,
  /// as a fraction of the input's bounding-box diagonal (Hausdorff_bound.h): collapses and flips
  /// that would break it are refused, and without a face target the collapses go on until none
  /// is left within it. Finite and > 0. Never simplified in parts.
  std::optional<double> max_error;
  Hausdorff_bound_options error_bound;
  /// The collapse engine. `cgal` runs the quadrics alone: `surface_memory` and `flips` must then
  /// be false, and there are no parts.
  Simplification_engine engine = Simplification_engine::cmgeom;
  /// The cost and placement policy (Area_weighted_quadric_policies): plain Garland-Heckbert
  /// quadrics by default, as `cmgeom simplify`, simplify_textured_mesh() and simplify_to_levels()
  /// (with the memoryful cost, the lowest RMS and Hausdorff error measured; manual,
  /// Textured_simplification, "Which policy is the default"); `quadric.weighted = true` for the
  /// thesis' weighting (§3.4.2), the default of the policy class itself.
  Quadric_options quadric = Quadric_options{false};
  /// The memoryful cost (Surface_memory.h) on top of the quadrics, and after the collapses the fit
  /// of the vertices to the input's points (`memory.fit`; not with max_error, whose bound holds for
  /// the collapsed positions, nor with endpoint_placement, whose vertices are the input's).
  bool surface_memory = true;
  Surface_memory_options memory;
  /// Edge flips between collapses (parameters::edge_flips).
  bool flips = false;
  /// Whole connected components may be removed, cheapest first, when removing one costs less than
  /// the next collapse or no collapse is left, never below the face target and never the
  /// component of largest area (parameters::prune_components: the price is the component's
  /// area-weighted squared distance to its centroid, in the quadric's unit). Gives the faces that
  /// small parts (screws, debris, the loose pieces of a game asset) would hold at their smallest
  /// to the rest; off by default (it changes the number of components). Needs a face target
  /// (count or ratio); not with max_error (its bound would not cover what is removed) nor with the
  /// `cgal` engine (Invalid_input / std::invalid_argument).
  bool prune_components = false;
  /// Placements at an endpoint (Endpoint_placement) instead of the quadric's minimiser.
  bool endpoint_placement = false;
  /// Inputs with at least this many faces are simplified in parts first (0: never; see the file
  /// comment).
  std::size_t parts_min_faces = 262144;
  /// Each part has at least this many faces (at most 16 parts). With 65,536, what a part's
  /// simplification works on (mesh, queue, quadrics, points: about 12 MB) fits twice in a 32 MB
  /// last-level cache, which two cores share (doc/Textured_simplification/README.md).
  std::size_t part_faces = 65536;
  /// Each part stops at this many times its share of the target (>= 1), plus
  /// `parts_tail_per_cut_vertex` faces per cut vertex it holds; parts are used only when the
  /// input has at least four times parts_stop_factor x target faces (below that, rebuilding the
  /// whole costs more than the parts save).
  double parts_stop_factor = 1.0;
  /// The faces a part keeps beyond its share of the target for each of its cut (locked) vertices
  /// (>= 0): the room the second stage needs to simplify the strips along the cuts, which the
  /// parts leave at the input's resolution. With 3, the outputs of igea and its 1M-face
  /// subdivision at 10, 2 and 1 % are as close to the input as with parts stopping at four times
  /// their share (the rule before), while at 10 % the parts do 87 % of the collapses instead of
  /// none (doc/Textured_simplification/README.md, "large meshes on all cores").
  double parts_tail_per_cut_vertex = 3.0;
  /// The cuts of the first `parts_whole_levels` levels of halving (1, 3, 7, ... cuts) are left to
  /// the stage on the whole, which shares the target between the 2^parts_whole_levels regions they
  /// bound by cost; the finer cuts are taken up before, pairwise, the last cut first: each pair of
  /// sibling parts is put back together into their group, simplified along the cut between them as
  /// a part with the cuts it still has locked, the groups of a level at once (>= 1; 4 or more: all
  /// parts put back together at once). With 1 the shares of the two halves are fixed by their
  /// face counts, which costs accuracy where the detail is uneven (the twice-subdivided ogre to 1 %:
  /// RMS +29 % against 2; doc/Textured_simplification/README.md, "large meshes on all cores").
  int parts_whole_levels = 2;
  /// Called once, right before the input mesh is first changed (on a simplification in parts,
  /// after the parts are simplified): a caller may read the input on another core until then, and
  /// waits here for that reading to end. An exception it throws leaves the input unchanged.
  std::function<void()> before_changing_input;
  /// On a simplification in parts, frees the input mesh as soon as its parts are cut (it is
  /// rebuilt from them): the input is no longer held while the parts are simplified and merged
  /// (on the 1M-face igea to 1 %, the whole `cmgeom simplify` peaks at 246 MB with it, 284 MB
  /// without; doc/Textured_simplification/README.md), but an exception thrown while the parts
  /// are simplified (out of memory) leaves `mesh` empty instead of unchanged. Off by default;
  /// `cmgeom simplify` sets it, the input being its file. before_changing_input is then called
  /// right before the input is freed.
  bool release_input_in_parts = false;
};

/// What simplify_mesh() did.
struct Mesh_simplification_result {
  std::size_t faces_in = 0, faces_out = 0;
  std::size_t target_faces = 0;  ///< the face target (a ratio's count); 0 without one
  /// With max_error: the largest distance the bound's tests accepted, as a fraction of the input's
  /// diagonal (<= max_error; a bound on the output's Hausdorff distance to the input).
  double error_bound = 0;
  Stop_reason stopped_by = Stop_reason::target;
  std::size_t parts = 0;              ///< parts simplified at once (0: the whole at once)
  std::size_t faces_after_parts = 0;  ///< faces when the parts were put back together
  double seconds_parts = 0;           ///< the parts: cutting, simplifying, putting back
  std::size_t fit_moves = 0;          ///< vertex moves of the final fit (Surface_memory::fit_vertices)
  double seconds_fit = 0;             ///< the final fit
  double seconds = 0;                 ///< all of it
};

namespace internal {

/// The placement of a part: none between two locked vertices (the edge never enters the queue),
/// the locked vertex's point next to one, else the base placement's.
template <class BasePlacement>
struct Locked_vertex_placement {
  BasePlacement base;
  const std::vector<std::uint8_t>* locked;
  template <class Profile>
  auto operator()(const Profile& p) const -> CMGeom::internal::optional<typename Profile::Point> {
    using Placement = CMGeom::internal::optional<typename Profile::Point>;
    const bool a = (*locked)[std::size_t(p.v0())] != 0, b = (*locked)[std::size_t(p.v1())] != 0;
    if (a && b) return Placement();
    if (a) return Placement(p.p0());
    if (b) return Placement(p.p1());
    return base(p);
  }
};

/// Refuses a collapse onto a locked vertex that would join it to another locked vertex it has no
/// edge to: edges between locked vertices stay those of the input, so that two parts cannot make
/// the same new edge (the whole would have it twice).
/// A part may also hold two locked copies of one input vertex, when its faces around that vertex
/// make two runs (a fan that crosses the cut twice, as on the open, non-manifold ogre): the copies
/// become one vertex when the parts are put back together, so no vertex may become a neighbour of
/// both (the whole would have two edges between the same two vertices) and no copy a neighbour of
/// another. `twin` (null when the part has none) marks the locked vertices whose input vertex has
/// another locked copy in the part.
template <class Point>
struct Locked_vertex_filter {
  const Mesh_part<Point>* part;
  const std::vector<std::uint8_t>* twin;
  template <class Profile, class Placement>
  Placement operator()(const Profile& p, const Placement& placement) const {
    const auto& tm = p.surface_mesh();
    const std::vector<std::uint8_t>& locked = part->locked;
    // (the kept vertex is the locked one, if any: see Locked_vertex_placement)
    const bool a = locked[std::size_t(p.v0())] != 0, b = locked[std::size_t(p.v1())] != 0;
    const auto kept = b ? p.v1() : p.v0(), gone = b ? p.v0() : p.v1();
    if (!a && !b) return twin ? twins_apart(tm, kept, gone, placement) : placement;
    for (auto w : CGAL::vertices_around_target(gone, tm)) {
      if (w == kept || !locked[std::size_t(w)]) continue;
      bool adjacent = false;
      for (auto x : CGAL::vertices_around_target(kept, tm))
        if (x == w) {
          adjacent = true;
          break;
        }
      if (!adjacent) return Placement();
    }
    return twin ? twins_apart(tm, kept, gone, placement) : placement;
  }

private:
  // the twin rule above, for a collapse of `gone` onto `kept` the rest of the filter accepts
  template <class Mesh, class Vertex, class Placement>
  Placement twins_apart(const Mesh& tm, Vertex kept, Vertex gone, const Placement& placement) const {
    const std::vector<std::uint32_t>& to_input = part->to_input;
    std::vector<Vertex> around_kept;
    for (auto x : CGAL::vertices_around_target(kept, tm))
      if (x != gone) around_kept.push_back(x);
    auto next_to_kept = [&](Vertex w) {
      return std::find(around_kept.begin(), around_kept.end(), w) != around_kept.end();
    };
    // the input vertices of the twins around the kept vertex once the collapse is done
    std::vector<std::uint32_t> keys;
    for (Vertex x : around_kept)
      if ((*twin)[std::size_t(x)]) keys.push_back(to_input[std::size_t(x)]);
    std::vector<Vertex> joined;  // the gone vertex's neighbours that become the kept one's
    for (auto w : CGAL::vertices_around_target(gone, tm))
      if (w != kept && !next_to_kept(w)) {
        joined.push_back(w);
        if ((*twin)[std::size_t(w)]) keys.push_back(to_input[std::size_t(w)]);
      }
    const bool kept_twin = (*twin)[std::size_t(kept)] != 0;
    const std::uint32_t own = kept_twin ? to_input[std::size_t(kept)] : no_index;
    std::sort(keys.begin(), keys.end());
    if (std::adjacent_find(keys.begin(), keys.end()) != keys.end()) return Placement();
    if (kept_twin && std::binary_search(keys.begin(), keys.end(), own)) return Placement();
    // a twin kept vertex must not become the neighbour of a vertex next to its other copy
    if (kept_twin)
      for (Vertex w : joined)
        for (auto x : CGAL::vertices_around_target(w, tm))
          if (x != kept && (*twin)[std::size_t(x)] && to_input[std::size_t(x)] == own) return Placement();
    return placement;
  }
};

/// The faces the collapses of the parts' stage remove, counted on every thread, as
/// CMGeom::internal::Progress_reporter counts (CMGeom/Progress.h), but in faces rather than a
/// fraction: any thread adds to the count, and the thread that made the object (the caller of the
/// algorithm, which takes part in the parts' collapses) calls `report` with the count so far at its
/// first collapse after every `step` more faces, and at the stage's end with the exact count. So a
/// progress display moves during the parts' stage, and its callback stays on the caller's thread.
/// Nothing is counted without a `report`. One object may serve several stages (a chain's runs,
/// level_of_detail.h): the counts go on from the stages before.
struct Parts_progress {
  static constexpr std::size_t step = 2048;  // (about 1024 collapses, as Removed_faces_visitor reports)
  std::function<void(std::size_t removed)> report;
  std::atomic<std::size_t> removed{0};
  std::size_t before = 0;  // faces removed by the stages that ended (exact counts)
  std::thread::id caller = std::this_thread::get_id();
  std::size_t next = step;  // (the caller's thread only)
  void collapsed(std::size_t faces) {
    if (!report) return;
    const std::size_t now = removed.fetch_add(faces, std::memory_order_relaxed) + faces;
    // (`next` belongs to the caller's thread: the id test comes first)
    if (std::this_thread::get_id() != caller || now < next) return;
    next = now + step;
    report(now);
  }
};

/// Whether Visitor has OnPartsProgress(std::size_t) (Removed_faces_visitor has): the faces the
/// parts' stage of simplify_mesh() and simplify_to_levels() has removed so far, which CGAL's
/// visitor concept has no call for.
template <class Visitor, class = void>
struct has_parts_progress : std::false_type {};
template <class Visitor>
struct has_parts_progress<Visitor, std::void_t<decltype(std::declval<const Visitor&>().OnPartsProgress(std::size_t()))>>
    : std::true_type {};

/// A Parts_progress that reports to `visitor`'s OnPartsProgress(), when it has one (the visitor
/// must outlive the stage).
template <class Visitor>
void report_parts_progress_to(const Visitor& visitor, Parts_progress& progress) {
  if constexpr (has_parts_progress<Visitor>::value)
    progress.report = [&visitor](std::size_t removed) { visitor.OnPartsProgress(removed); };
}

/// The collapse may keep either endpoint: the kept one inherits the lock, the input vertex and
/// the twin mark (Locked_vertex_filter). Counts the faces removed in `progress`, when given.
template <class Point>
struct Locked_vertex_visitor : Edge_collapse_visitor_base {
  Mesh_part<Point>* part;
  std::vector<std::uint8_t>* twin;  // null when the part has none
  Parts_progress* progress;         // null: not counted
  template <class Profile, class V>
  void OnCollapsed(const Profile& p, const V& kept) const {
    if (progress) progress->collapsed(std::size_t(p.left_face_exists()) + std::size_t(p.right_face_exists()));
    const std::size_t a = std::size_t(p.v0()), b = std::size_t(p.v1()), k = std::size_t(kept);
    if (!part->locked[a] && !part->locked[b]) return;
    const std::size_t from = part->locked[a] ? a : b;
    part->locked[k] = 1;
    part->to_input[k] = part->to_input[from];
    part->run[k] = part->run[from];
    part->run_cut[k] = part->run_cut[from];
    if (twin) (*twin)[k] = (*twin)[from];
  }
};

/// The twin marks of a part's locked vertices (Locked_vertex_filter); empty when no input vertex
/// has two locked copies in it.
template <class Point>
std::vector<std::uint8_t> locked_twins(const Mesh_part<Point>& part) {
  std::vector<std::uint32_t> keys;
  for (auto u : part.mesh.vertices())
    if (part.locked[std::size_t(u)]) keys.push_back(part.to_input[std::size_t(u)]);
  std::sort(keys.begin(), keys.end());
  std::vector<std::uint32_t> twice;
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (keys[i] == keys[i - 1] && (twice.empty() || twice.back() != keys[i])) twice.push_back(keys[i]);
  if (twice.empty()) return {};
  std::vector<std::uint8_t> twin(part.locked.size(), 0);
  for (auto u : part.mesh.vertices())
    if (part.locked[std::size_t(u)] && std::binary_search(twice.begin(), twice.end(), part.to_input[std::size_t(u)]))
      twin[std::size_t(u)] = 1;
  return twin;
}

/// Number of halvings of an input of `faces` faces into parts of at least `part_faces` (0: none,
/// or an input below `parts_min_faces`), whatever the target.
inline int halvings_into_parts(std::size_t faces, const Mesh_simplification_options& o) {
  if (o.parts_min_faces == 0 || faces < o.parts_min_faces || o.part_faces == 0) return 0;
  int levels = 0;
  while (levels < max_part_levels && (faces >> (levels + 1)) >= o.part_faces) ++levels;
  return levels;
}

/// Number of halvings of the input into parts (0: none), see the file comment.
inline int part_levels(std::size_t faces, std::size_t target, const Mesh_simplification_options& o) {
  if (4.0 * o.parts_stop_factor * double(target) > double(faces)) return 0;
  return halvings_into_parts(faces, o);
}

/// Number of halvings simplify_mesh() makes of an input of `faces` faces under `o` (0: it runs as
/// one piece): parts are used for a face target (or ratio) alone, on CMGeom's engine.
inline int run_part_levels(std::size_t faces, const Mesh_simplification_options& o) {
  std::optional<std::size_t> target = o.target_faces;
  if (o.target_ratio) target = target_faces_for_ratio(faces, *o.target_ratio);
  if (!target || o.max_cost || o.max_error || o.engine == Simplification_engine::cgal) return 0;
  return part_levels(faces, *target, o);
}

/// Calls fn with the policy's own placement, or with Endpoint_placement over it.
template <class Policy, class Fn>
void collapse_with_placement(const Policy& policy, bool endpoint, Fn fn) {
  if (endpoint)
    fn(Endpoint_placement<Policy>{policy});
  else
    fn(policy);
}

/// The first stage (see the file comment): on return `mesh` is the parts put back together,
/// `policy` holds their quadrics for the next initialize(), `memory` their points (if asked).
/// `progress` (optional) counts the faces the stage removes and reports them (Parts_progress).
/// With `resume`, `mesh` is the result of collapses already made (removed elements allowed) and
/// the stage goes on from them: each part takes its vertices' quadrics and weights from `policy`
/// and its faces' points from `memory` (when set), instead of computing them from its faces and
/// vertices (level_of_detail.h runs a chain's levels so, one stage per level). With `source`, the
/// parts are cut from `*source`, which is left as it is, and put back together into `mesh`, which
/// must be empty (a chain keeps its input as its first level and copies nothing of it).
template <class Point, class Memory>
void simplify_in_parts(CGAL::Surface_mesh<Point>& mesh, std::size_t target, int levels,
                       const Mesh_simplification_options& options,
                       Area_weighted_quadric_policies<CGAL::Surface_mesh<Point>>& policy, std::optional<Memory>& memory,
                       Parts_progress* progress = nullptr, bool resume = false,
                       const CGAL::Surface_mesh<Point>* source = nullptr) {
  using Mesh = CGAL::Surface_mesh<Point>;
  using Policy = Area_weighted_quadric_policies<Mesh>;
  using V = typename Mesh::Vertex_index;
  using Quadric = typename Policy::Quadric;
  using size_type = typename Mesh::size_type;
  if (source && (resume || !mesh.is_empty()))
    throw std::invalid_argument("simplify_in_parts: a separate source needs an empty mesh and no resume");
  const Mesh& in = source ? *source : mesh;  // (read until the parts are cut)
  const std::size_t faces_in = in.number_of_faces(), vertices_in = in.number_of_vertices();
  const std::size_t vertex_slots = in.num_vertices();  // removed ones included
  // No quadric of the whole input is made (`policy` has no records until the merge): each part
  // computes its own from its faces, and only the vertices on a part's border take theirs from
  // their star in the input (see below).
  std::vector<std::uint32_t> label;
  std::vector<std::vector<std::uint32_t>> faces_of = split_faces(in, levels, label);
  const std::size_t n = faces_of.size();
  std::vector<Mesh_part<Point>> parts(n);
  {
    // the parts first; the tables that cut them are dropped before anything else is allocated
    std::vector<std::uint32_t> corner_vertex(in.num_halfedges(), no_index), side_edge(in.num_halfedges(), no_index);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
      parts[k] = make_part(in, std::uint32_t(k), faces_of[k], label, corner_vertex, side_edge,
                           levels > options.parts_whole_levels ? levels : 0);
    });
  }
  std::vector<std::uint32_t>().swap(label);
  // resumed: the points of the run so far go to the parts (face i of part k is the mesh's face
  // faces_of[k][i]); a point on no face is dropped, as the merge below drops it
  using Point_list = std::vector<std::tuple<typename Mesh::Face_index, CM::internal::Vec3, double>>;
  std::vector<Point_list> resumed_points(resume && memory ? n : 0);
  if (resume && memory) {
    using Face = typename Mesh::Face_index;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> part_face(in.num_faces(), {no_index, no_index});
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t i = 0; i < faces_of[k].size(); ++i)
        part_face[faces_of[k][i]] = {std::uint32_t(k), std::uint32_t(i)};
    memory->for_each_point([&](Face f, const CM::internal::Vec3& p, double area) {
      if (f == Mesh::null_face()) return;
      const auto [k, i] = part_face[std::size_t(f)];
      if (k != no_index) resumed_points[k].emplace_back(Face(size_type(i)), p, area);
    });
    memory.reset();
  }
  std::vector<std::vector<std::uint32_t>>().swap(faces_of);
  CMGeom::internal::release_freed_memory();  // the worker threads' arenas keep what make_part freed
  // then the parts' quadrics, the input's numbers: a vertex inside a part has its whole star
  // there, with its faces in the input's order (make_part keeps it), so the part's initialize()
  // sums the same terms in the same order; a vertex on a part's border (on a cut, or on the
  // input's border, whose edges a part numbers in its own order) takes the sum over its star in
  // the input, taken first, so that the input can be freed before the parts' quadrics are made
  using Vertex_data = std::pair<typename Mesh::Vertex_index, std::pair<Quadric, double>>;
  std::vector<std::vector<Vertex_data>> border_data(n);
  if (!resume)
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
      const Mesh& pm = parts[k].mesh;
      for (auto u : pm.vertices())
        if (CGAL::is_border(u, pm))
          border_data[k].emplace_back(
              u, policy.star_vertex_data(in, in.points(), V(size_type(parts[k].to_input[std::size_t(u)]))));
    });
  if (options.release_input_in_parts) {
    if (options.before_changing_input) options.before_changing_input();
    mesh.clear_without_removing_property_maps();
  }
  std::vector<std::optional<Policy>> part_policy(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    const Mesh& pm = parts[k].mesh;
    Policy& pp = part_policy[k].emplace(parts[k].mesh, options.quadric);
    if (resume) {  // (every vertex, inner or not, as the run so far left it)
      for (auto u : pm.vertices()) {
        const V w(size_type(parts[k].to_input[std::size_t(u)]));
        pp.set_vertex_data(u, policy.quadric(w), policy.weight(w));
      }
      pp.keep_vertex_data_once();
      return;
    }
    pp.initialize(pm, pm.points());
    for (const auto& [u, data] : border_data[k]) pp.set_vertex_data(u, data.first, data.second);
    std::vector<Vertex_data>().swap(border_data[k]);
    pp.keep_vertex_data_once();
  });
  // the cut vertices' input quadrics are needed again at the merge: their quadric on the whole
  // is the input's plus what each part added
  std::unordered_map<std::uint32_t, std::pair<Quadric, double>> cut_data;  // by input vertex
  for (std::size_t k = 0; k < n; ++k)
    for (auto u : parts[k].mesh.vertices())
      if (parts[k].locked[std::size_t(u)])
        cut_data.emplace(parts[k].to_input[std::size_t(u)],
                         std::make_pair(part_policy[k]->quadric(u), part_policy[k]->weight(u)));
  std::vector<std::optional<Memory>> part_memory(n);
  // a part's (or group's) memory: the caps, as shares of the input's
  auto memory_options = [&](std::size_t part_vertices) {
    Surface_memory_options mo = options.memory;
    mo.parallel_pricing = false;  // (the cores are busy with the parts)
    for (std::size_t* cap : {&mo.max_points, &mo.pricing_points})
      if (*cap > 0)
        *cap = (std::max)(std::size_t(1),
                          std::size_t(std::ceil(double(*cap) * double(part_vertices) / double(vertices_in))));
    return mo;
  };
  // simplifies a part (or group) down to its share of the target plus the room for the cut strips
  // (parts_tail_per_cut_vertex faces per locked vertex), but at least two faces per locked
  // vertex: a part emptied down to its locked border would be a flat fan the second stage cannot
  // repair (measured on the tests' torus cut into 16 parts: at 2 % Hausdorff 4.6x that of the
  // whole at once without this floor, 1.35x with it)
  auto simplify_part = [&](Mesh_part<Point>& part, Policy& pp, Memory* pmem) {
    Mesh& pm = part.mesh;
    // (over the live vertices: a collapse onto a locked vertex that keeps the other slot moves the
    // mark there, Locked_vertex_visitor, and leaves it on the removed one; a part simplified a
    // second time would otherwise count them)
    std::size_t locked = 0;
    for (auto u : pm.vertices()) locked += part.locked[std::size_t(u)];
    const std::size_t stop =
        (std::max)(2 * locked, std::size_t(std::ceil(options.parts_stop_factor * double(target) *
                                                     double(part.input_faces) / double(faces_in))) +
                                   std::size_t(std::ceil(options.parts_tail_per_cut_vertex * double(locked))));
    if (pm.number_of_faces() <= stop) return;
    std::vector<std::uint8_t> twin = locked_twins(part);
    std::vector<std::uint8_t>* twins = twin.empty() ? nullptr : &twin;
    collapse_with_placement(pp, options.endpoint_placement, [&](const auto& placement) {
      using Base = std::decay_t<decltype(placement)>;
      edge_collapse(pm, Face_count_stop_predicate<Mesh>(pm, stop),
                    CMGeom::parameters::surface_memory(
                        pmem, CGAL::parameters::get_cost(pp)
                                  .get_placement(Locked_vertex_placement<Base>{placement, &part.locked})
                                  .filter(Locked_vertex_filter<Point>{&part, twins})
                                  .visitor(Locked_vertex_visitor<Point>{{}, &part, twins, progress})));
    });
  };
  // The quadrics and points of the parts first .. first + count - 1, put back together as `merged`,
  // on its vertices and faces: a cut vertex's quadric is its input quadric plus what each part
  // added to it. Each part's policy and memory are freed once taken.
  auto gather = [&](std::size_t first, std::size_t count, const Merged_parts<Point>& merged, std::vector<Quadric>& q,
                    std::vector<double>& w, Point_list& points) {
    const std::size_t nv = merged.points.size();
    q.assign(nv, Quadric());
    w.assign(nv, 1.0);
    {  // (reserved whole: on the 1M-face mesh the points are half a million, growing by doubling
       // would leave up to 20 MB unused at the memory's peak)
      std::size_t total = 0;
      for (std::size_t k = first; k < first + count; ++k)
        if (part_memory[k]) total += part_memory[k]->number_of_points();
      points.reserve(total);
    }
    for (std::size_t i = 0; i < nv; ++i)
      if (merged.input_vertex[i] != no_index) {
        const auto& [input_q, input_w] = cut_data.at(merged.input_vertex[i]);
        q[i] = input_q;
        w[i] = input_w;
      }
    for (std::size_t s = 0; s < count; ++s) {
      const std::size_t k = first + s;
      for (auto u : parts[k].mesh.vertices()) {
        const std::size_t i = merged.vertex[s][std::size_t(u)];
        const Quadric& pq = part_policy[k]->quadric(u);
        if (parts[k].locked[std::size_t(u)]) {
          const Quadric& input = cut_data.at(merged.input_vertex[i]).first;
          q[i] = Quadric::combine(q[i], 1.0, Quadric::combine(pq, 1.0, input, -1.0), 1.0);
        } else {
          q[i] = pq;
          w[i] = part_policy[k]->weight(u);
        }
      }
      part_policy[k].reset();
      if (!part_memory[k]) continue;
      part_memory[k]->for_each_point([&](auto f, const CM::internal::Vec3& p, double area) {
        if (f == Mesh::null_face() || merged.face[s][std::size_t(f)] == no_index) return;
        points.emplace_back(typename Mesh::Face_index(size_type(merged.face[s][std::size_t(f)])), p, area);
      });
      part_memory[k].reset();
    }
  };
  // Gives `pp` the gathered quadrics for the next initialize(); in weighted mode a vertex glued
  // from cut copies and no longer locked (`locked`, or none) gets its weight from its new star.
  auto set_quadrics = [&](const Policy& pp, const Mesh& m, const std::vector<Quadric>& q, const std::vector<double>& w,
                          const Merged_parts<Point>& merged, const std::vector<std::uint8_t>* locked) {
    for (std::size_t i = 0; i < q.size(); ++i) pp.set_vertex_data(V(size_type(i)), q[i], w[i]);
    if (options.quadric.weighted)
      for (std::size_t i = 0; i < q.size(); ++i)
        if (merged.input_vertex[i] != no_index && !(locked && (*locked)[i]))
          pp.recompute_weight(m, m.points(), V(size_type(i)));
    pp.keep_vertex_data_once();
  };
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t k) {
    Memory* pmem = nullptr;
    if (options.surface_memory && !resumed_points.empty()) {
      pmem = &part_memory[k].emplace(parts[k].mesh, parts[k].mesh.points(), resumed_points[k],
                                     memory_options(parts[k].input_vertices));
      Point_list().swap(resumed_points[k]);
    } else if (options.surface_memory) {
      pmem = &part_memory[k].emplace(parts[k].mesh, parts[k].mesh.points(), memory_options(parts[k].input_vertices));
    }
    simplify_part(parts[k], *part_policy[k], pmem);
  });
  // then level by level down to parts_whole_levels, each pair of sibling parts put back together
  // into their group (the cut between them unlocked) and the group simplified as a part, the pairs
  // of a level at once: what is left for the whole is the strips of the first levels' cuts
  for (int level = levels - 1; level >= options.parts_whole_levels; --level) {
    const std::size_t m = std::size_t(1) << level, per = parts.size() / m;
    std::vector<Mesh_part<Point>> groups(m);
    std::vector<std::optional<Policy>> group_policy(m);
    std::vector<std::optional<Memory>> group_memory(m);
    tbb::parallel_for(std::size_t(0), m, [&](std::size_t j) {
      Mesh_part<Point>& g = groups[j];
      std::vector<const Mesh_part<Point>*> list;  // the parts it is made of
      for (std::size_t k = per * j; k < per * (j + 1); ++k) list.push_back(&parts[k]);
      const Merged_parts<Point> merged = merge_part_group(list, level);
      const std::size_t nv = merged.points.size();
      build_triangle_mesh(g.mesh, merged.points, merged.corners, merged.sides, merged.edges);
      g.to_input = merged.input_vertex;
      g.locked.assign(nv, 0);
      g.run.assign(nv, {});
      g.run_cut.assign(nv, 0);
      for (std::size_t s = 0; s < per; ++s) {  // a cut vertex stays locked if its run is cut here
        const Mesh_part<Point>& part = *list[s];
        g.input_faces += part.input_faces;
        g.input_vertices += part.input_vertices;
        for (auto u : part.mesh.vertices())
          if (part.locked[std::size_t(u)]) {
            const std::size_t i = merged.vertex[s][std::size_t(u)];
            g.run[i] = part.run[std::size_t(u)];
            g.run_cut[i] = part.run_cut[std::size_t(u)];
            g.locked[i] = std::uint8_t((part.run_cut[std::size_t(u)] >> level) & 1u);
          }
      }
      std::vector<Quadric> q;
      std::vector<double> w;
      Point_list points;
      gather(per * j, per, merged, q, w, points);
      for (std::size_t k = per * j; k < per * (j + 1); ++k) parts[k] = Mesh_part<Point>();  // freed
      Policy& gp = group_policy[j].emplace(g.mesh, options.quadric);
      set_quadrics(gp, g.mesh, q, w, merged, &g.locked);
      Memory* gmem = nullptr;
      if (options.surface_memory)
        gmem = &group_memory[j].emplace(g.mesh, g.mesh.points(), points, memory_options(g.input_vertices));
      Point_list().swap(points);
      simplify_part(g, gp, gmem);
    });
    // (a vector swap moves no element: the policies and memories keep their meshes)
    parts.swap(groups);
    part_policy.swap(group_policy);
    part_memory.swap(group_memory);
  }

  Merged_parts<Point> merged = merge_parts(parts, vertex_slots);
  std::vector<Quadric> q;
  std::vector<double> w;
  Point_list points;
  // The whole is checked before it replaces the input (nothing is lost on a failure), on one
  // core while the other gathers its quadrics and points.
  tbb::parallel_invoke([&] { gather(0, parts.size(), merged, q, w, points); },
                       [&] {
                         Mesh check;
                         build_triangle_mesh(check, merged.points, merged.corners, merged.sides, merged.edges);
                         if (!CGAL::is_valid_polygon_mesh(check) || !CGAL::is_triangle_mesh(check))
                           throw std::logic_error("simplify_mesh: the simplified parts do not make a valid mesh");
                       });
  if (options.before_changing_input && !options.release_input_in_parts) options.before_changing_input();
  parts.clear();
  mesh.clear_without_removing_property_maps();
  build_triangle_mesh(mesh, merged.points, merged.corners, merged.sides, merged.edges);
  set_quadrics(policy, mesh, q, w, merged, nullptr);  // (nothing is locked in the whole)
  if (options.surface_memory) memory.emplace(mesh, mesh.points(), points, options.memory);
  Point_list().swap(points);
  // (every input face was in one part: the faces gone are those the collapses removed)
  if (progress) {
    progress->before += faces_in - mesh.number_of_faces();
    if (progress->report) progress->report(progress->before);
  }
}

}  // namespace internal

namespace internal {

/// Removes the vertices in no face (an input may hold them; no collapse touches them, and they are
/// no part of a simplified surface); the mesh is left with them marked removed, before its
/// collect_garbage().
template <class Point>
void remove_isolated_vertices(CGAL::Surface_mesh<Point>& mesh) {
  for (auto v : mesh.vertices())
    if (mesh.is_isolated(v)) mesh.remove_vertex(v);
}

/// The diagonal of the bounding box of the mesh's vertices (0 for an empty mesh).
template <class Mesh>
double bbox_diagonal(const Mesh& mesh) {
  if (mesh.is_empty()) return 0.;
  const CGAL::Bbox_3 b = CGAL::Polygon_mesh_processing::bbox(mesh);
  return std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
                   CGAL::square(b.zmax() - b.zmin()));
}

/// The checks of the error-bound options that simplify_mesh() and simplify_textured_mesh() share
/// (`who` names the caller in the messages): std::invalid_argument for a `max_error` that is not
/// finite and > 0, or a depth limit out of [0, 16].
inline void check_max_error(const std::optional<double>& max_error, const Hausdorff_bound_options& bound,
                            const std::string& who) {
  if (max_error && !(*max_error > 0.0 && std::isfinite(*max_error)))
    throw std::invalid_argument(who + ": max_error must be finite and > 0, got " + std::to_string(*max_error));
  check_bound_options(bound, who + ": error_bound.max_depth");
}

/// The length `max_error` is a fraction of: the diagonal of `mesh`'s bounding box (0 without a
/// `max_error`). Throws Invalid_input for a mesh with faces whose vertices all lie at one point.
template <class Mesh>
double max_error_diagonal(const Mesh& mesh, const std::optional<double>& max_error, const std::string& who) {
  const double diagonal = max_error ? bbox_diagonal(mesh) : 0.;
  if (max_error && !(diagonal > 0.) && mesh.number_of_faces() > 0)
    throw Invalid_input(who + ": max_error on a mesh whose vertices all lie at one point");
  return diagonal;
}

/// The first two vertices (in vertex order) joined by two edges, or none. A valid
/// CGAL::Surface_mesh may hold such a pair (e.g. after quads are split along diagonals that meet an
/// existing edge).
template <class Mesh>
std::optional<std::pair<std::size_t, std::size_t>> doubled_edge(const Mesh& mesh) {
  std::vector<std::size_t> around;
  for (auto v : vertices(mesh)) {
    if (halfedge(v, mesh) == boost::graph_traits<Mesh>::null_halfedge()) continue;  // (an isolated vertex)
    around.clear();
    for (auto h : CGAL::halfedges_around_target(v, mesh)) around.push_back(std::size_t(source(h, mesh)));
    std::sort(around.begin(), around.end());
    const auto twice = std::adjacent_find(around.begin(), around.end());
    if (twice != around.end()) return std::make_pair(std::size_t(v), *twice);
  }
  return std::nullopt;
}

/// The first vertex (in vertex order) that the border passes more than once, and how many times,
/// or none: a pinch, where fans of faces meet at one vertex (a non-manifold vertex kept as one, as
/// CGAL::IO::read_polygon_mesh leaves those of ogre.obj).
template <class Mesh>
std::optional<std::pair<std::size_t, int>> pinched_vertex(const Mesh& mesh) {
  for (auto v : vertices(mesh)) {
    if (halfedge(v, mesh) == boost::graph_traits<Mesh>::null_halfedge()) continue;  // (an isolated vertex)
    const int borders = border_passes(mesh, v);
    if (borders > 1) return std::make_pair(std::size_t(v), borders);
  }
  return std::nullopt;
}

/// The message of a refusal by `who` of a mesh with a pinch (pinched_vertex()); `alternative`
/// names what the caller may use instead of CGAL's edge_collapse.
inline std::string pinch_refusal(const std::string& who, const std::pair<std::size_t, int>& pinch,
                                 const std::string& alternative) {
  return who + ": the border passes vertex " + std::to_string(pinch.first) + " " + std::to_string(pinch.second) +
         " times (fans of faces meet there), which CGAL's edge_collapse does not handle (use " + alternative +
         ", or split the vertex: CGAL::Polygon_mesh_processing::duplicate_non_manifold_vertices)";
}

/// Throws CMGeom::Invalid_input when two edges join the same two vertices (doubled_edge()): CGAL
/// 5.5's edge_collapse loops or fails an assertion on them; or when the border passes a vertex
/// more than once (pinched_vertex()): Euler::collapse_edge, which assumes a 2-manifold, can then
/// leave a fan of faces behind at the vertex's old place. CMGeom's engine never collapses either.
template <class Mesh>
void check_for_cgal_engine(const Mesh& mesh) {
  if (const auto e = doubled_edge(mesh))
    throw Invalid_input("simplify_mesh: vertices " + std::to_string(e->first) + " and " + std::to_string(e->second) +
                        " are joined by two edges, which CGAL's edge_collapse does not handle (use CMGeom's engine)");
  if (const auto v = pinched_vertex(mesh)) throw Invalid_input(pinch_refusal("simplify_mesh", *v, "CMGeom's engine"));
}

/// The stop of simplify_mesh(): a face count and/or a cost bound, remembering which one fired.
template <class Mesh>
struct Target_stop {
  std::optional<Face_count_stop_predicate<Mesh>> count;
  std::optional<double> max_cost;
  Stop_reason* fired;
  template <class FT, class Profile>
  bool operator()(const FT& cost, const Profile& p, std::size_t initial, std::size_t current) const {
    if (count && (*count)(cost, p, initial, current)) {
      *fired = Stop_reason::target;
      return true;
    }
    if (max_cost && CGAL::to_double(cost) > *max_cost) {
      *fired = Stop_reason::max_cost;
      return true;
    }
    return false;
  }
};

}  // namespace internal

/// Simplifies `mesh` to the target of `options` (a face count, a ratio of the input's faces, a
/// cost bound and/or a guaranteed error bound; fewer faces than asked only when no valid collapse
/// is left) with the quadrics of `options.quadric` and, unless switched off, the memoryful cost;
/// large inputs with a face target on all cores (see the file comment; never with `max_cost` or
/// `max_error`). Throws std::invalid_argument for invalid options (no target, both a count and a
/// ratio, a ratio out of (0, 1], a negative or non-finite max_cost, a max_error not > 0 or not
/// finite, parts_stop_factor < 1, parts_tail_per_cut_vertex < 0, memory or flips on CGAL's engine),
/// CMGeom::Invalid_input when `mesh` is not a triangle mesh or, with max_error, its vertices all lie at one point,
/// or, on CGAL's engine, two of its edges join the same two vertices.
/// `visitor` sees the collapses on the whole mesh, not those of the parts (a visitor with
/// OnPartsProgress(std::size_t), as Removed_faces_visitor, is told the faces they removed).
/// The mesh is garbage-free on return, without isolated vertices (vertices in no face, which the
/// input may have, are dropped); its property maps stay, with default values after a
/// simplification in parts (the mesh is then rebuilt: every index changes).
/// Manual: doc/Textured_simplification/README.md, "One call, and large meshes on all cores".
/// \tparam Point a CGAL kernel's Point_3
/// \tparam Visitor a model of CGAL's `EdgeCollapseSimplificationVisitor`
template <class Point, class Visitor = Edge_collapse_visitor_base>
Mesh_simplification_result simplify_mesh(CGAL::Surface_mesh<Point>& mesh, const Mesh_simplification_options& options,
                                         Visitor visitor = Visitor()) {
  using Mesh = CGAL::Surface_mesh<Point>;
  using VPM = typename Mesh::template Property_map<typename Mesh::Vertex_index, Point>;
  using Policy = Area_weighted_quadric_policies<Mesh>;
  using Memory = Surface_memory<Mesh, VPM>;
  using Clock = std::chrono::steady_clock;
  if (options.target_faces && options.target_ratio)
    throw std::invalid_argument("simplify_mesh: give a face count or a ratio, not both");
  if (!options.target_faces && !options.target_ratio && !options.max_cost && !options.max_error)
    throw std::invalid_argument("simplify_mesh: no target (target_faces, target_ratio, max_cost or max_error)");
  if (options.target_ratio) target_faces_for_ratio(0, *options.target_ratio);  // checks it
  if (options.max_cost && !(*options.max_cost >= 0.0 && std::isfinite(*options.max_cost)))
    throw std::invalid_argument("simplify_mesh: max_cost must be finite and >= 0, got " +
                                std::to_string(*options.max_cost));
  internal::check_max_error(options.max_error, options.error_bound, "simplify_mesh");
  check_fit_options(options.memory.fit);
  checked_vertex_gap_weight(options.memory.vertex_gap_weight);
  if (!(options.parts_stop_factor >= 1.0)) throw std::invalid_argument("simplify_mesh: parts_stop_factor must be >= 1");
  if (!(options.parts_tail_per_cut_vertex >= 0.0))
    throw std::invalid_argument("simplify_mesh: parts_tail_per_cut_vertex must be >= 0");
  if (options.parts_whole_levels < 1) throw std::invalid_argument("simplify_mesh: parts_whole_levels must be >= 1");
  const bool cgal = options.engine == Simplification_engine::cgal;
  if (options.prune_components && !options.target_faces && !options.target_ratio)
    throw std::invalid_argument("simplify_mesh: prune_components needs a face target (target_faces or target_ratio)");
  if (options.prune_components && options.max_error)
    throw std::invalid_argument("simplify_mesh: prune_components cannot be combined with max_error");
  if (options.prune_components && cgal)
    throw std::invalid_argument("simplify_mesh: prune_components needs CMGeom's engine");
  if (cgal && (options.surface_memory || options.flips))
    throw std::invalid_argument("simplify_mesh: CGAL's engine has no memoryful cost and no flips");
  if (!CGAL::is_triangle_mesh(mesh)) throw Invalid_input("simplify_mesh: not a triangle mesh");
  if (cgal) internal::check_for_cgal_engine(mesh);
  const double diagonal = internal::max_error_diagonal(mesh, options.max_error, "simplify_mesh");
  const auto t0 = Clock::now();
  Mesh_simplification_result res;
  res.faces_in = mesh.number_of_faces();
  std::optional<std::size_t> target = options.target_faces;
  if (options.target_ratio) target = target_faces_for_ratio(res.faces_in, *options.target_ratio);
  res.target_faces = target ? *target : 0;
  if (!target || *target < res.faces_in) {
    Policy policy(mesh, options.quadric);
    std::optional<Memory> memory;
    const int levels = internal::run_part_levels(res.faces_in, options);
    if (levels > 0) {
      internal::Parts_progress progress;
      internal::report_parts_progress_to(visitor, progress);
      internal::simplify_in_parts(mesh, *target, levels, options, policy, memory, &progress);
      res.parts = std::size_t(1) << levels;
      res.faces_after_parts = mesh.number_of_faces();
      res.seconds_parts = std::chrono::duration<double>(Clock::now() - t0).count();
    } else {
      if (options.before_changing_input) options.before_changing_input();
      if (options.surface_memory) memory.emplace(mesh, mesh.points(), options.memory);
    }
    res.stopped_by = Stop_reason::no_collapse;  // unless the stop fires
    internal::Target_stop<Mesh> stop{{}, options.max_cost, &res.stopped_by};
    if (target) stop.count.emplace(mesh, *target);
    Memory* m = memory ? &*memory : nullptr;
    using Bound = Hausdorff_bound<Mesh, VPM>;
    std::optional<Bound> bound;
    if (options.max_error) bound.emplace(mesh, mesh.points(), *options.max_error * diagonal, options.error_bound);
    auto run = [&](const auto& placement, const auto& cgal_filter, const auto& own_filter, const auto& vis) {
      if (cgal)
        CGAL::Surface_mesh_simplification::edge_collapse(
            mesh, stop, CGAL::parameters::get_cost(policy).get_placement(placement).filter(cgal_filter).visitor(vis));
      else
        edge_collapse(
            mesh, stop,
            CMGeom::parameters::prune_components(
                options.prune_components && target ? (std::max)(*target, std::size_t(1)) : 0,
                CMGeom::parameters::surface_memory(
                    m,
                    CMGeom::parameters::edge_flips(
                        options.flips,
                        CGAL::parameters::get_cost(policy).get_placement(placement).filter(own_filter).visitor(vis)))));
    };
    // without a bound the filter and the visitor only forward (one instantiation for both cases)
    Bound* b = bound ? &*bound : nullptr;
    internal::collapse_with_placement(policy, options.endpoint_placement, [&](const auto& placement) {
      run(placement, Hausdorff_bound_filter<Bound, No_normal_flip_filter<>>{b}, Hausdorff_bound_filter<Bound>{b},
          Hausdorff_bound_visitor<Bound, Visitor>(b, visitor));
    });
    if (m && !bound && !options.endpoint_placement && options.memory.fit.rounds > 0) {
      const auto t_fit = Clock::now();
      // what the collapses freed (the engine's queue and per-edge arrays) goes back to the system
      // first, or the fit's arrays (about 60 bytes per point) come on top of it (1M-face igea to
      // 10 % on two threads: peak RSS 236-251 MB instead of 205-222 MB)
      CMGeom::internal::release_freed_memory();
      res.fit_moves = m->fit_vertices(mesh, options.memory.fit, [&](auto v) { return policy.quadric(v); });
      res.seconds_fit = std::chrono::duration<double>(Clock::now() - t_fit).count();
    }
    if (bound) {
      res.error_bound = bound->bound() / diagonal;
      if (res.stopped_by == Stop_reason::no_collapse && bound->refused() > 0) res.stopped_by = Stop_reason::max_error;
    }
  }
  internal::remove_isolated_vertices(mesh);  // (as a run in parts drops them)
  mesh.collect_garbage();
  res.faces_out = mesh.number_of_faces();
  if (target && res.faces_out <= *target) res.stopped_by = Stop_reason::target;
  res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return res;
}

/// simplify_mesh(mesh, options) with `target_faces` as the face target (it replaces the target
/// count or ratio of `options`; a `max_cost` there still applies).
template <class Point, class Visitor = Edge_collapse_visitor_base>
Mesh_simplification_result simplify_mesh(CGAL::Surface_mesh<Point>& mesh, std::size_t target_faces,
                                         const Mesh_simplification_options& options = Mesh_simplification_options(),
                                         Visitor visitor = Visitor()) {
  Mesh_simplification_options o = options;
  o.target_faces = target_faces;
  o.target_ratio.reset();
  return simplify_mesh(mesh, o, visitor);
}

#ifdef CMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED
// Compiled once into CMGeom::Textured_simplification (src/Textured_simplification/
// textured_simplification_instantiations.cpp) for CMGeom's mesh type (CGAL::Surface_mesh of the
// Epick kernel's points): the parts' stage, which no visitor reaches, and simplify_mesh() with
// the default visitor and with Removed_faces_visitor.
namespace internal {
using Precompiled_point = CGAL::Point_3<CGAL::Epick>;
using Precompiled_mesh = CGAL::Surface_mesh<Precompiled_point>;
using Precompiled_memory =
    Surface_memory<Precompiled_mesh, Precompiled_mesh::Property_map<Precompiled_mesh::Vertex_index, Precompiled_point>>;
extern template void simplify_in_parts<Precompiled_point, Precompiled_memory>(
    Precompiled_mesh&, std::size_t, int, const Mesh_simplification_options&,
    Area_weighted_quadric_policies<Precompiled_mesh>&, std::optional<Precompiled_memory>&, Parts_progress*, bool,
    const Precompiled_mesh*);
}  // namespace internal
extern template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Edge_collapse_visitor_base>(
    internal::Precompiled_mesh&, const Mesh_simplification_options&, Edge_collapse_visitor_base);
extern template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Edge_collapse_visitor_base>(
    internal::Precompiled_mesh&, std::size_t, const Mesh_simplification_options&, Edge_collapse_visitor_base);
extern template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Removed_faces_visitor>(
    internal::Precompiled_mesh&, const Mesh_simplification_options&, Removed_faces_visitor);
extern template Mesh_simplification_result simplify_mesh<internal::Precompiled_point, Removed_faces_visitor>(
    internal::Precompiled_mesh&, std::size_t, const Mesh_simplification_options&, Removed_faces_visitor);
#endif

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_SIMPLIFY_MESH_H
