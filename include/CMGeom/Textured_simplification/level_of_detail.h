// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// simplify_to_levels(): a level-of-detail chain from ONE simplification run. The collapses of
// simplify_mesh() run down to the smallest target and the mesh is copied each time the face count
// reaches a level's target, so every level is the same collapse sequence stopped earlier; each copy
// gets the final fit of its vertices to the input's points that simplify_mesh() gives the mesh it
// ends with (`memory.fit`), made on the copy alone, on another core while the run goes on from the
// unfitted mesh (Surface_memory::fitted_positions_later()), so a level is vertex for vertex the mesh
// simplify_mesh() returns for that target (on the whole, and where only the first level ran in
// parts; a level after a run cut again goes on from the levels before it). A large input is cut
// into parts simplified on all cores down to the first collapsed level, as
// simplify_mesh() cuts it (`parts_min_faces`), and so is every level large enough on the way
// down to the next (`later_parts_min_faces`: the quadrics and the memory's points carried into
// the parts; not a shared texture's chain, which runs on as one run once its first parts are put
// back together); the rest runs on the whole. Levels
// may also be asked by error bound (`max_errors`: each level's Hausdorff distance to the input
// guaranteed within its bound by Hausdorff_bound, one run per bound). Texture: an atlas per level (default), painted
// from the input followed down the collapses onto that level and baked where no input face lands (a chain any of whose
// runs is cut into parts: baked from the input alone, as simplify_textured_mesh() bakes the atlas of an input it cuts,
// since the collapse history follows one whole mesh), or one shared texture, the coarsest level's atlas, which every
// finer level addresses (the thesis' future work of levels sharing one texture, §7.1). A finer level is mapped into
// that atlas through the collapse history (Collapse_history): each of its vertices and faces is followed down the
// collapses to the coarse face its part of the surface became, then placed on the nearest face
// around it; so parts that fold onto one place of the coarsest level (a label over a bottle) keep
// apart. (A shared texture's chain whose first run begins in parts starts the history once they
// are put back together, each input point on the nearest face of that mesh, still close to the
// input: Collapse_history::add_input_nearest(); from there the history is exact.) The parts of the input that this
// projection squashes (steep against the coarse face they became) or hides, those that read colours other than their
// own from the atlas, and those under a finer level's face that reads colours other than a bake's from it
// (`overflow_colour_tolerance`), get charts of their own in a strip added under the
// atlas, which the finer levels' faces standing for them address (`overflow_charts`,
// internal/atlas_layers.h). Each level's
// geometric error is measured unless `measure_error` is false.
//
// Manual: doc/Textured_simplification/README.md, "Levels of detail from one run, and one texture for all of them".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_LEVEL_OF_DETAIL_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_LEVEL_OF_DETAIL_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>
#include <CMGeom/Textured_simplification/Hausdorff_bound.h>
#include <CMGeom/Textured_simplification/Removed_faces_visitor.h>
#include <CMGeom/Textured_simplification/Surface_memory.h>
#include <CMGeom/Textured_simplification/rebuild_atlas.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/internal/atlas_layers.h>
#include <CMGeom/Textured_simplification/internal/collapse_history.h>

#include <CGAL/boost/graph/copy_face_graph.h>

#include <boost/range/irange.hpp>

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <iterator>
#include <limits>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

/// Options of simplify_to_levels().
struct Level_of_detail_options {
  /// Face targets of the levels, strictly decreasing (a target >= the input's face count is the
  /// input itself).
  std::vector<std::size_t> target_faces;
  /// Instead of face targets: error bounds, strictly increasing, >= 0, as fractions of the input's
  /// bounding-box diagonal. Each level's Hausdorff distance to the input, both ways, is guaranteed
  /// at most its bound: the chain runs once per bound, each run going on from the last with the
  /// larger bound, every collapse checked by Hausdorff_bound as simplify_mesh() checks them for
  /// `max_error`, and a level is the mesh left when no collapse within its bound is (0, or a bound
  /// no collapse meets: the input itself). The levels are not fitted (the bound holds for the
  /// collapsed positions) and not pruned (prune_components is refused with bounds). Each level's
  /// error is then measured (Metrics::approximation_error with `error_samples`). Ignored when empty.
  std::vector<double> max_errors;
  /// The tests of the bound (Hausdorff_bound_options), with max_errors.
  Hausdorff_bound_options error_bound;
  /// Cost and placement (plain Garland-Heckbert by default, as simplify_mesh).
  Quadric_options quadric = Quadric_options{false};
  bool surface_memory = true;
  /// The memoryful cost's points and, in `memory.fit`, the fit of each level's vertices to them,
  /// as simplify_mesh()'s Mesh_simplification_options::memory (rounds = 0: every level as the
  /// collapses leave it). With `surface_memory` only.
  Surface_memory_options memory;
  bool flips = false;
  /// Whole connected components may be removed when cheaper than the next collapse (simplify_mesh()'s
  /// `prune_components`), never below the smallest level's target (in the error-bound mode, whose
  /// snapshots are measured with what is removed: never below one face). A level that still has a
  /// component the coarsest one lost is mapped into a shared atlas by its nearest coarse faces and
  /// gets overflow charts where those show the wrong colours.
  bool prune_components = false;
  /// Textured input: one atlas for every level (see the file comment) instead of one per level.
  bool shared_texture = false;
  /// The atlas (per-level atlases, or the shared one).
  Atlas_options atlas;
  /// Shared texture: a corner past its chart's border is extended over it by at most this
  /// fraction of the coarse face it is projected on (barycentric coordinates >= -this).
  double max_extrapolation = internal::default_max_extrapolation;
  /// Shared texture: parts of the input that the coarsest level's atlas squashes (steep against
  /// the coarse face they became) or hides (folded under another part) get charts of their own, in
  /// a strip added under the atlas, which the finer levels address (internal/atlas_layers.h);
  /// false: the finer levels show them as the atlas has them.
  bool overflow_charts = true;
  /// Shared texture with overflow charts: the colours each finer level's face shows from the
  /// coarsest level's atlas are also checked against what a bake would give it (sampled at fixed
  /// points of the face, internal::Shown_colour_error); the input under a face that is off by
  /// more than this (root mean square, colour values in [0, 1]) gets charts of its own too, and a
  /// face takes its overflow chart only where that shows colours nearer to the bake's. The input
  /// level's own faces are checked the same way against the input's texture on them
  /// (internal::mark_input_shown_wrong()). 0 switches the check off (the geometric tests alone
  /// decide). The default, a fifth of the colour range,
  /// sits in the middle of the values (0.1 to 0.3) that gave image errors within 5 % of each
  /// other on the shared textured models.
  double overflow_colour_tolerance = 0.2;
  /// Untextured input with face targets: when the input has at least this many faces and the first
  /// collapsed level at most half of them, the collapses down to that level run in parts on all
  /// cores first, as simplify_mesh() runs them (internal::simplify_in_parts(), with these two
  /// settings and its other parts settings at their defaults), then on the whole down to that
  /// level, the parts' points kept by the memoryful cost. Where simplify_mesh() itself cuts (the
  /// target at most a quarter of the faces) the first collapsed level is the mesh it returns for
  /// that target. The same holds level by level: when a level has at least this many faces and the
  /// next at most half of them, the collapses down to the next level run in parts again, going on
  /// from the quadrics and points the run so far left (on a 1M-face input with levels 1, 0.25,
  /// 0.05, 0.01: parts down to 25 %, again down to 5 % and again down to 1 %, the later cuts with
  /// `later_parts_min_faces` and `later_part_faces`). 0: never. A textured chain with an atlas per
  /// level is cut as an untextured one (when any of its runs would be cut, the first or a later
  /// one), and its levels' atlases are then baked from the input
  /// without the collapse history (which follows one whole mesh): on DamagedHelmet subdivided
  /// three times (989k faces) the chain of levels 1, 0.25, 0.05, 0.01 took 18.3 s on the whole and
  /// 9.2 s in parts, `simplify` to 1 % alone 5.4-5.8 s (doc/Textured_simplification/README.md,
  /// "Levels of detail from one run"). A shared-texture chain, which needs the history down to its
  /// coarsest level, runs its first collapses in parts when they would be cut (the history then
  /// starts on the mesh they leave, each input point on the nearest face) and the rest as one run
  /// on the whole: on that mesh 20.3-22.9 s -> 16.0-16.8 s. The error-bound mode and an input whose
  /// faces use several materials (which the parts would not keep) run on the whole.
  std::size_t parts_min_faces = Mesh_simplification_options().parts_min_faces;
  /// Faces of a part at least (simplify_mesh()'s `part_faces`).
  std::size_t part_faces = Mesh_simplification_options().part_faces;
  /// When the input was large enough to be cut (`parts_min_faces`), a level on the way down is cut
  /// again, on the way down to the next level (at most half of it), once it has at least
  /// `later_parts_min_faces` faces, into parts of at least `later_part_faces` faces (instead of
  /// the two settings above). A level carries every point of the input on fewer faces: a part of
  /// 16,384 faces of the 25 % level holds the points of 65,536 input faces, as a part of the
  /// input's own cut does. With these defaults a 1M-face input's 5 % level (53,736 faces) is cut
  /// in 2 and its 25 % level in 16 (instead of 4), igea's 25 % level (67,172 faces) in 4 (it was
  /// simplified on one core before): the chains of igea and its 1M-face subdivision (levels 1,
  /// 0.25, 0.05, 0.01) 12 and 15 % faster, each coarsest level as close to the input as
  /// `simplify_mesh()`'s run to that target alone (doc/Textured_simplification/README.md). 0: a
  /// level is cut only when it has `parts_min_faces` faces.
  std::size_t later_parts_min_faces = 32768;
  /// See `later_parts_min_faces`.
  std::size_t later_part_faces = 16384;
  /// Measure every level's error against the input (Metrics::approximation_error, the input's side
  /// prepared once: Metrics::Error_reference), beside the collapses and the texture work.
  bool measure_error = true;
  /// Samples per direction of that measure; 0: 2 x the input's face count.
  std::size_t error_samples = 0;
};

/// One level of the chain.
struct Level_of_detail {
  Textured_mesh mesh;
  std::size_t target_faces = 0;
  bool is_input = false;  ///< the input itself (target >= its face count)
  double hausdorff = -1;  ///< symmetric Hausdorff / bounding-box diagonal (-1: not measured)
  double rms = -1;        ///< RMS distance / diagonal (-1: not measured)
  Atlas_result atlas;     ///< its atlas (per-level mode), or the shared one (coarsest level)
};

struct Level_of_detail_result {
  std::vector<Level_of_detail> levels;
  double seconds_collapse = 0;  ///< the collapse run, snapshots included
  /// Parts simplified at once before the first collapsed level (0: the whole at once; see
  /// Level_of_detail_options::parts_min_faces), and the faces when they were put back together.
  std::size_t parts = 0, faces_after_parts = 0;
  /// Runs of the collapses that began in parts: the one down to the first collapsed level, and
  /// each one down to a coarser level whose finer neighbour is itself large enough to be cut
  /// (Level_of_detail_options::parts_min_faces). 0: the chain ran on the whole.
  std::size_t runs_in_parts = 0;
  double seconds_texture = 0;  ///< atlas extraction, baking, mapping through the shared atlas
  /// The error measures: what is left of them once the texture work is done (they run beside
  /// the collapses and the texture work; the error-bound mode measures inside the collapse run).
  double seconds_error = 0;
  /// Shared texture: the fraction of the original's texels in the atlas that another part of the
  /// original took (parts that fold onto one place of the coarsest level, e.g. a label over a
  /// bottle on a 45-face bottle); those parts show the other part's colours at every level.
  double shared_texture_hidden = 0;
  /// Shared texture: the share of the input's area given overflow charts (parts the atlas squashes
  /// or hides get charts of their own, in a strip under the atlas, which the finer levels address;
  /// internal/atlas_layers.h), and the height that strip adds to the atlas, as a fraction of its own.
  double shared_texture_relocated = 0, shared_texture_overflow = 0;
  double seconds = 0;
};

namespace internal {

/// A tbb::task_group that its destructor waits for, without throwing: the tasks of a run left by an
/// exception finish before what they read goes (their own exceptions are then dropped).
struct Waited_task_group {
  tbb::task_group group;
  Waited_task_group() = default;
  Waited_task_group(const Waited_task_group&) = delete;
  Waited_task_group& operator=(const Waited_task_group&) = delete;
  ~Waited_task_group() {
    try {
      group.wait();
    } catch (...) {  // (only when wait() was not called: an exception is leaving already)
    }
  }
};

/// The levels' errors, measured beside the work that follows their snapshots (the serial collapses
/// leave cores idle): the first task prepares the input's side once (Metrics::Error_reference),
/// then measures the levels one after another as their copies come; a level that comes while no
/// task runs starts one. No thread ever waits for another here; wait() gives the results.
class Background_level_errors {
public:
  Background_level_errors(const Surface_mesh& input, const Metrics::Error_options& options) {
    running_ = true;
    tasks_.group.run([this, &input, options] {
      reference_.emplace(input, options);
      drain();
    });
  }
  Background_level_errors(const Background_level_errors&) = delete;
  Background_level_errors& operator=(const Background_level_errors&) = delete;

  /// Queues level `level` (its geometry, copied now).
  void add(std::size_t level, const Surface_mesh& mesh) {
    Item item{level, Metrics::internal::make_flat_mesh(mesh, mesh.points(), "level")};
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(item));
    if (!running_) {
      running_ = true;
      tasks_.group.run([this] { drain(); });
    }
  }

  /// Waits for every queued level; (level, error) pairs, by level. Rethrows a measure's exception.
  std::vector<std::pair<std::size_t, Metrics::Approximation_error>> wait() {
    tasks_.group.wait();
    std::sort(results_.begin(), results_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    return std::move(results_);
  }

private:
  struct Item {
    std::size_t level;
    Metrics::internal::Flat_mesh mesh;
  };
  void drain() {
    while (true) {
      Item item;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (queue_.empty()) {
          running_ = false;
          return;
        }
        item = std::move(queue_.front());
        queue_.erase(queue_.begin());
      }
      Metrics::Approximation_error e = reference_->error_flat(item.mesh);
      std::lock_guard<std::mutex> lock(mutex_);
      results_.emplace_back(item.level, std::move(e));
    }
  }

  std::mutex mutex_;
  std::optional<Metrics::Error_reference> reference_;  // (written by the first task, before any measure)
  std::vector<Item> queue_;
  bool running_ = false;
  std::vector<std::pair<std::size_t, Metrics::Approximation_error>> results_;
  Waited_task_group tasks_;  // (last: destroyed first, it waits for the tasks that use the others)
};

/// What the two snapshot visitors below share: a copy is taken once its collapse is complete, at
/// the engine's next call (OnSelected of the next edge, before the stop predicate is asked, or
/// OnFinished), after the policy has merged the kept vertex's quadric and the flips around it are
/// made, so a level is the mesh a run stopped there leaves (and its fit, that run's final fit).
/// Derived::take_pending(mesh) takes the copies a collapse called for; Derived::finished(mesh) runs
/// at the end.
template <class Derived, class Visitor>
struct Completed_snapshot_visitor : History_visitor<Visitor> {
  using History_visitor<Visitor>::History_visitor;
  template <class P, class C, class S>
  void OnSelected(const P& p, const C& c, S i, S n) const {
    static_cast<const Derived&>(*this).take_pending(p.surface_mesh());
    this->visitor.OnSelected(p, c, i, n);
  }
  template <class TM>
  void OnFinished(TM& tm) const {
    static_cast<const Derived&>(*this).take_pending(tm);
    this->visitor.OnFinished(tm);
    static_cast<const Derived&>(*this).finished(tm);
  }
};

/// Visitor that copies the mesh each time the face count reaches the next level's target (see
/// Completed_snapshot_visitor), and forwards every call to the caller's visitor.
template <class Visitor>
struct Snapshot_visitor : Completed_snapshot_visitor<Snapshot_visitor<Visitor>, Visitor> {
  struct State {
    const std::vector<std::size_t>* targets;  // the collapsed levels' targets, decreasing
    std::size_t next = 0;
    std::vector<Level_snapshot> snapshots;
    std::size_t last = 0;                       // the run's last level (its stop; a chain may be taken in several runs)
    bool pending = false;                       // a collapse reached the next target: copy at the next call
    Background_level_errors* errors = nullptr;  // measures each copy, when set
    // the levels' fits, made beside the collapses (each then measured, when asked); finished()
    // waits for them and gives their positions to the copies
    std::vector<std::shared_ptr<Pending_level_fit>> fits;
    bool complete_when_finished = true;  // false: the caller calls complete_fits() (a run of several)
    // true: the fits of the levels the run ends with wait for launch_deferred_fits() (the next run
    // begins in parts, which take both cores; its collapses on the whole that follow take one)
    bool defer_fits_at_end = false;
    std::vector<std::function<void()>> deferred;
    Waited_task_group fit_tasks;
    /// Starts the fits held back by defer_fits_at_end.
    void launch_deferred_fits() {
      for (auto& task : deferred) fit_tasks.group.run(std::move(task));
      deferred.clear();
    }
    /// Waits for the levels' fits and gives their positions to the copies.
    void complete_fits() {
      launch_deferred_fits();
      fit_tasks.group.wait();
      for (const auto& fit : fits) set_copied_points(snapshots[fit->level].mesh, fit->v2v, fit->positions);
      fits.clear();
    }
  };
  State* state;
  Snapshot_visitor(State* s, const Visitor& v, Collapse_history* h, const Level_fitter* f = nullptr)
      : Completed_snapshot_visitor<Snapshot_visitor<Visitor>, Visitor>(v, h, f), state(s) {}

  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    this->collapsed(p, v);
    note_count(p.surface_mesh());
  }
  /// (a pruned component: the face count falls as after collapses)
  template <class TM, class Faces>
  void OnFacesRemoved(const TM& tm, const Faces& fs) const {
    History_visitor<Visitor>::OnFacesRemoved(tm, fs);
    note_count(tm);
  }
  /// A copy is due once the face count reaches the next target (the last target is the run's
  /// stop: the mesh left at the end is that level).
  void note_count(const Surface_mesh& mesh) const {
    state->pending = state->next < state->last && mesh.number_of_faces() <= (*state->targets)[state->next];
  }
  void take_pending(const Surface_mesh& mesh) const {
    if (!state->pending) return;
    state->pending = false;
    while (state->next < state->last && mesh.number_of_faces() <= (*state->targets)[state->next]) take(mesh);
  }
  /// The copy now; its fit (and then its error) on another core while the collapses go on: the
  /// fit reads a copy of what it needs (Surface_memory::fitted_positions_later()). `at_end`: taken
  /// when the run finished (its fit then waits for launch_deferred_fits() with defer_fits_at_end).
  void take(const Surface_mesh& mesh, bool at_end = false) const {
    std::function<std::vector<Point_3>()> later;
    auto fit = std::make_shared<Pending_level_fit>();
    fit->level = state->snapshots.size();
    state->snapshots.push_back(this->snapshot_to_fit(mesh, later, fit->v2v));
    const std::size_t level = state->next++;
    Background_level_errors* errors = state->errors;
    if (!later) {  // (nothing to fit: the copy is the level)
      if (errors) errors->add(level, state->snapshots.back().mesh);
      return;
    }
    state->fits.push_back(fit);
    // (the error is measured on a copy of its own: the snapshots may move meanwhile)
    auto copy = errors ? std::make_shared<Surface_mesh>(state->snapshots.back().mesh) : nullptr;
    auto task = [fit, later, errors, level, copy] {
      fit->positions = later();
      if (!errors) return;
      set_copied_points(*copy, fit->v2v, fit->positions);
      errors->add(level, *copy);
    };
    if (at_end && state->defer_fits_at_end)
      state->deferred.emplace_back(std::move(task));
    else
      state->fit_tasks.group.run(std::move(task));
  }
  /// The levels not taken yet (the last, and any the run did not reach) are the mesh the run ends
  /// with: copied now, while the history's points still name its faces; then every level gets its
  /// fitted positions (unless the caller completes them later, State::complete_when_finished).
  void finished(const Surface_mesh& mesh) const {
    while (state->next <= state->last) take(mesh, true);
    if (state->complete_when_finished) state->complete_fits();
  }
};

/// Copies the mesh a run ends with (the error-bound mode: a level is where no collapse is left
/// within its bound), and forwards every call to the caller's visitor.
template <class Visitor>
struct Final_snapshot_visitor : Completed_snapshot_visitor<Final_snapshot_visitor<Visitor>, Visitor> {
  std::optional<Level_snapshot>* out;
  Final_snapshot_visitor(std::optional<Level_snapshot>* o, const Visitor& v, Collapse_history* h,
                         const Level_fitter* f = nullptr)
      : Completed_snapshot_visitor<Final_snapshot_visitor<Visitor>, Visitor>(v, h, f), out(o) {}
  template <class P, class V>
  void OnCollapsed(const P& p, const V& v) const {
    this->collapsed(p, v);
  }
  void take_pending(const Surface_mesh&) const {}
  void finished(const Surface_mesh& mesh) const { out->emplace(this->snapshot(mesh)); }
};

/// simplify_mesh()'s options for a run of the chain's cost to `target` faces (the parts stage).
inline Mesh_simplification_options chain_simplification_options(const Level_of_detail_options& options,
                                                                std::size_t target) {
  Mesh_simplification_options o;
  o.target_faces = target;
  o.quadric = options.quadric;
  o.surface_memory = options.surface_memory;
  o.memory = options.memory;
  o.flips = options.flips;
  o.prune_components = options.prune_components;
  o.parts_min_faces = options.parts_min_faces;
  o.part_faces = options.part_faces;
  return o;
}

inline double seconds_since_lod(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Whether the faces of `input` use more than one material.
inline bool faces_have_several_materials(const Textured_mesh& input) {
  const auto faces = input.mesh().faces();
  if (faces.empty()) return false;
  const int first = input.material(*faces.begin());
  return std::any_of(faces.begin(), faces.end(),
                     [&](Surface_mesh::Face_index f) { return input.material(f) != first; });
}

/// A copy of `mesh` with its element order (the collapse order depends on it) and without its
/// "h:uv" map: the chain's collapses carry no texture coordinates.
inline Surface_mesh copy_without_uvs(const Surface_mesh& mesh) {
  Surface_mesh copy = mesh;
  auto uv = copy.property_map<Surface_mesh::Halfedge_index, Point_2>("h:uv");
  if (uv.second) copy.remove_property_map(uv.first);
  return copy;
}

/// The collapses of a chain on `work`: simplify_mesh()'s engine, cost and memory, without its final
/// fit and without compacting `work`, in runs that each go on from where the last one stopped
/// (quadrics and the memory's points carried over). With `source`, `work` starts empty and the
/// first run takes `*source` (left as it is): it cuts its parts from it when it begins in parts,
/// and copies it into `work` (without its "h:uv" map) when not.
class Chain_collapses {
public:
  using Mesh = Surface_mesh;
  using VPM = Mesh::Property_map<Mesh::Vertex_index, Point_3>;
  using Bound = Hausdorff_bound<Mesh, VPM>;

  Chain_collapses(Surface_mesh& work, const Level_of_detail_options& options, const Surface_mesh* source = nullptr)
      : work_(work),
        options_(options),
        policy_(work, options.quadric),  // (it keeps no map of the mesh: `work` may be assigned later)
        source_(source),
        input_faces_(source ? source->number_of_faces() : work.number_of_faces()) {
    check_fit_options(options.memory.fit);
    if (source && !work.is_empty()) throw std::invalid_argument("Chain_collapses: a source needs an empty work mesh");
  }
  /// The runs that follow refuse the collapses (and flips) that `bound` does not allow and keep it
  /// up to date (Hausdorff_bound.h; it must follow the work mesh from its first collapse on);
  /// nullptr: none.
  void set_error_bound(Bound* bound) { bound_ = bound; }
  Chain_collapses(const Chain_collapses&) = delete;
  Chain_collapses& operator=(const Chain_collapses&) = delete;

  /// Whether a run to `target` faces from `faces` faces starts with collapses in parts (see
  /// run()): the input is large enough for simplify_mesh() to cut it, and the run removes at
  /// least half of it (simplify_mesh() cuts when its target is at most a quarter of the faces,
  /// part_levels(); a chain, whose coarser levels then come on one core, gains from the parts down
  /// to half).
  int part_levels(std::size_t faces, std::size_t target) const {
    return levels_into_parts(faces, target, parts_options(faces, target));
  }
  /// Whether a chain of the levels `targets` (face counts, decreasing) of an input of `faces`
  /// faces, run without the collapse history, cuts any of its runs into parts (part_levels() of
  /// each level and the next, the input's first), before any chain is made.
  static bool cuts_into_parts(const Level_of_detail_options& options, std::size_t faces,
                              const std::vector<std::size_t>& targets) {
    std::size_t from = faces;
    for (std::size_t target : targets) {
      if (levels_into_parts(from, target, parts_options(options, faces, from, target)) > 0) return true;
      from = target;
    }
    return false;
  }

  /// simplify_mesh()'s options for a run from `faces` faces down to `target` in parts: a level on
  /// the way down (fewer faces than the input) of an input large enough to be cut is cut with the
  /// later parts settings (Level_of_detail_options::later_parts_min_faces), the input itself with
  /// the first ones.
  Mesh_simplification_options parts_options(std::size_t faces, std::size_t target) const {
    return parts_options(options_, input_faces_, faces, target);
  }
  /// The same for a chain under `options` of an input of `input_faces` faces.
  static Mesh_simplification_options parts_options(const Level_of_detail_options& options, std::size_t input_faces,
                                                   std::size_t faces, std::size_t target) {
    Mesh_simplification_options o = chain_simplification_options(options, target);
    if (faces < input_faces && options.later_parts_min_faces > 0 && halvings_into_parts(input_faces, o) > 0) {
      o.parts_min_faces = options.later_parts_min_faces;
      o.part_faces = options.later_part_faces;
    }
    return o;
  }

  /// Collapses until `stop`, with the visitor `make_visitor(fitter)` builds around the run's
  /// Level_fitter (empty without the memoryful cost or without fit rounds), which is valid until
  /// the run's end (the visitor's OnFinished included). With `parts_target` > 0 the collapses down
  /// to that many faces run in parts first when part_levels() says so
  /// (internal::simplify_in_parts(); the visitor sees only the collapses on the whole that follow,
  /// `progress` the faces the parts remove); returns the number of parts (0: none) and the faces
  /// they left. `after_parts`, when set, is called once the parts are done (at once without them),
  /// before the collapses on the whole.
  template <class Stop, class MakeVisitor>
  std::pair<std::size_t, std::size_t> run(const Stop& stop, std::size_t prune_min_faces,
                                          const MakeVisitor& make_visitor, std::size_t parts_target = 0,
                                          Parts_progress* progress = nullptr,
                                          const std::function<void()>& after_parts = {}) {
    const std::size_t faces = source_ ? source_->number_of_faces() : work_.number_of_faces();
    const int levels = part_levels(faces, parts_target);
    if (source_ && levels == 0) work_ = copy_without_uvs(*source_);
    if (levels > 0)
      simplify_in_parts(work_, parts_target, levels, parts_options(faces, parts_target), policy_, memory_, progress,
                        runs_ > 0, source_);
    source_ = nullptr;
    if (after_parts) after_parts();
    const std::size_t faces_after_parts = levels > 0 ? work_.number_of_faces() : 0;
    if (runs_ == 0 && levels == 0 && options_.surface_memory) memory_.emplace(work_, work_.points(), options_.memory);
    // (a later run without parts keeps the quadrics the last run left)
    if (runs_ > 0 && levels == 0) policy_.keep_vertex_data_once();
    ++runs_;
    Surface_memory<Mesh, VPM>* m = memory_ ? &*memory_ : nullptr;
    Level_fitter fitter;
    if (m && options_.memory.fit.rounds > 0)
      fitter = [this, m](const Mesh& mesh) {
        // (a level the fit leaves as it is, Surface_fit_options::min_points_per_face: nothing to do later)
        if (!m->fit_applies(mesh, options_.memory.fit)) return std::function<std::vector<Point_3>()>();
        return m->fitted_positions_later(mesh, options_.memory.fit,
                                         [this](Mesh::Vertex_index v) { return policy_.quadric(v); });
      };
    collapse_with_placement(policy_, false, [&](const auto& placement) {
      edge_collapse(
          work_, stop,
          CMGeom::parameters::prune_components(
              options_.prune_components ? prune_min_faces : 0,
              CMGeom::parameters::surface_memory(
                  m, CMGeom::parameters::edge_flips(
                         options_.flips, CGAL::parameters::get_cost(policy_)
                                             .get_placement(placement)
                                             .filter(Hausdorff_bound_filter<Bound>{bound_})
                                             .visitor(Hausdorff_bound_visitor<Bound, decltype(make_visitor(&fitter))>(
                                                 bound_, make_visitor(&fitter)))))));
    });
    return {levels > 0 ? std::size_t(1) << levels : 0, faces_after_parts};
  }

private:
  // part_levels() under the parts settings `o`
  static int levels_into_parts(std::size_t faces, std::size_t target, const Mesh_simplification_options& o) {
    if (target == 0 || 2 * target > faces) return 0;
    return halvings_into_parts(faces, o);
  }

  Surface_mesh& work_;
  const Level_of_detail_options& options_;
  Area_weighted_quadric_policies<Mesh> policy_;
  Bound* bound_ = nullptr;  // (set_error_bound())
  std::optional<Surface_memory<Mesh, VPM>> memory_;
  const Surface_mesh* source_;  // (until the first run has taken it)
  std::size_t input_faces_;     // (the faces of the chain's input)
  int runs_ = 0;
};

/// simplify_to_levels() of `input`; with `owned` (the input itself, given to the chain) the levels
/// that are the input get it moved in at the end instead of a copy, unless they address a shared
/// texture (then they are the input with new UVs, and the input is read until the end).
template <class Visitor>
Level_of_detail_result simplify_to_levels(const Textured_mesh& input, Textured_mesh* owned,
                                          const Level_of_detail_options& options, Visitor visitor) {
  using Clock = std::chrono::steady_clock;
  const auto t_start = Clock::now();
  const bool by_error = !options.max_errors.empty();
  std::vector<std::size_t> targets = options.target_faces;
  if (by_error) {
    const auto& b = options.max_errors;
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (!(b[i] >= 0) || !std::isfinite(b[i]))
        throw Invalid_input("simplify_to_levels: an error bound is negative or not finite");
      if (i > 0 && b[i] <= b[i - 1])
        throw Invalid_input("simplify_to_levels: the error bounds must be strictly increasing");
    }
    if (options.prune_components)
      throw Invalid_input("simplify_to_levels: prune_components cannot be combined with max_errors");
  } else {
    if (targets.empty()) throw Invalid_input("simplify_to_levels: no level asked for");
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (targets[i] == 0) throw Invalid_input("simplify_to_levels: a level's target is 0 faces");
      if (i > 0 && targets[i] >= targets[i - 1])
        throw Invalid_input("simplify_to_levels: the levels' targets must be strictly decreasing");
    }
  }
  if (!(options.overflow_colour_tolerance >= 0 && std::isfinite(options.overflow_colour_tolerance)))
    throw Invalid_input("simplify_to_levels: overflow_colour_tolerance must be finite and >= 0");
  if (!CGAL::is_triangle_mesh(input.mesh())) throw Invalid_input("simplify_to_levels: not a triangle mesh");
  if (input.mesh().has_garbage()) throw Invalid_input("simplify_to_levels: the input must be garbage-free");
  bool has_image = false;
  for (const Material& m : input.materials()) has_image |= !m.diffuse_image.empty() || !m.normal_image.empty();
  const bool textured = input.has_uvs() && has_image;

  Level_of_detail_result res;
  const std::size_t faces_in = input.mesh().number_of_faces();
  // (the parts' stage rebuilds the mesh from its parts without the faces' materials: an input whose
  // faces use several materials runs on the whole, so that its levels keep each face's material)
  Level_of_detail_options chain_options = options;
  if (internal::faces_have_several_materials(input)) chain_options.parts_min_faces = 0;
  Metrics::Error_options eo;
  eo.samples = options.error_samples > 0 ? options.error_samples : 2 * faces_in;
  eo.vertex_field = false;

  // the collapsed levels' meshes (error-bound mode: the mesh each bounded run ends with)
  std::vector<internal::Level_snapshot> meshes;
  // textured: the collapse history of the input's points (and, for one shared texture, the levels')
  std::optional<internal::Collapse_history> history;
  internal::Level_snapshot input_points;
  std::vector<std::pair<double, double>> measured;  // (hausdorff, rms) of the collapsed levels
  // the history follows `work` from its next collapse on: a copy of the input, from before its
  // first collapse (`is_input`), or the mesh a shared texture's first parts left (the input's
  // points put on its nearest faces)
  auto follow_history = [&](Surface_mesh& work, bool is_input) {
    history.emplace(work);
    history->follow_levels(options.shared_texture);
    input_points = is_input ? history->add_input(work) : history->add_input_nearest(input.mesh(), work);
  };
  const auto t_collapse = Clock::now();
  if (by_error) {
    // One run per bound, each going on from the last with a larger one: every collapse (and flip)
    // is checked by Hausdorff_bound, as simplify_mesh() checks them for `max_error`, and a level is
    // the mesh left when no collapse within its bound is: its Hausdorff distance to the input, both
    // ways, is guaranteed at most the bound. No fit (the bound holds for the collapsed positions)
    // and no pruning (a bound does not cover what a pruned component removes), as there.
    Surface_mesh work = internal::copy_without_uvs(input.mesh());
    if (textured) follow_history(work, true);
    const Metrics::Error_reference reference(input.mesh(), eo);
    const double diagonal = internal::bbox_diagonal(work);
    Level_of_detail_options bound_options = chain_options;
    bound_options.memory.fit.rounds = 0;
    internal::Chain_collapses chain(work, bound_options);  // (its runs, given no parts target, are not cut)
    std::optional<internal::Chain_collapses::Bound> bound;
    targets.clear();
    meshes.reserve(options.max_errors.size());
    for (double e : options.max_errors) {
      if (e == 0 || !(diagonal > 0)) {  // the input itself
        targets.push_back(faces_in);
        continue;
      }
      if (!bound)
        bound.emplace(work, work.points(), e * diagonal, options.error_bound);
      else
        bound->raise_max_error(e * diagonal);
      chain.set_error_bound(&*bound);
      std::optional<internal::Level_snapshot> level;
      chain.run(Face_count_stop_predicate<Surface_mesh>(work, 1), 0, [&](const internal::Level_fitter* fitter) {
        return internal::Final_snapshot_visitor<Visitor>{&level, visitor, history ? &*history : nullptr, fitter};
      });
      if (!level || level->mesh.number_of_faces() >= faces_in) {  // no collapse within the bound
        targets.push_back(faces_in);
        continue;
      }
      targets.push_back(level->mesh.number_of_faces());
      const Metrics::Approximation_error m = reference.error(level->mesh);
      measured.emplace_back(m.hausdorff, m.rms);
      meshes.push_back(std::move(*level));
    }
  }
  // the levels that are the input itself, then the collapsed ones
  std::vector<std::size_t> collapsed;
  for (std::size_t t : targets)
    if (t < faces_in) collapsed.push_back(t);
  const std::size_t kept = targets.size() - collapsed.size();

  // the atlas source, taken and prepared beside the collapses
  Atlas_options ao = options.atlas;
  if (options.shared_texture) ao.gutter_texels = std::max(ao.gutter_texels, 8);
  std::optional<Atlas_source> source;
  tbb::task_group prepare;
  if (textured && !collapsed.empty()) {
    const auto t0 = Clock::now();
    source.emplace(input, ao);
    res.seconds_texture += internal::seconds_since_lod(t0);
    prepare.run([&source] { source->prepare(); });
  }

  // the levels' errors, measured beside the collapses and the texture work
  std::optional<internal::Background_level_errors> errors;
  if (!by_error && options.measure_error && !collapsed.empty()) errors.emplace(input.mesh(), eo);

  try {
    if (!collapsed.empty() && !by_error) {
      // The collapse history (which paints each level's atlas from the input, and maps the finer
      // levels into a shared one) follows one whole mesh. A textured chain with an atlas per level
      // any of whose runs would begin in parts (the first, or one from a level large enough down
      // to the next) does without it, as simplify_textured_mesh() does for an input it cuts: its
      // collapses run as an untextured chain's (in parts on all cores where they would), and each
      // level's atlas is baked from the input by closest point.
      // A shared texture follows every level down to the coarsest, so its chain runs as one run;
      // when that run would begin in parts (an input large enough, cut down to its first level),
      // the parts run without the history and the history starts once they are put back together,
      // each input point on the nearest face (Collapse_history::add_input_nearest()).
      const bool history_after_parts =
          textured && options.shared_texture &&
          internal::Chain_collapses::cuts_into_parts(chain_options, faces_in, {collapsed.front()});
      const bool follow =
          textured && !history_after_parts &&
          (options.shared_texture || !internal::Chain_collapses::cuts_into_parts(chain_options, faces_in, collapsed));
      // a copy with the input's element order (copy_without_uvs(): the chain's levels are then
      // those of simplify_mesh() run on the input to each level's target); without the history,
      // the chain's first run takes the input itself, and copies nothing of it when it begins in parts
      Surface_mesh work;
      if (follow) {
        work = internal::copy_without_uvs(input.mesh());
        follow_history(work, true);
      }
      // (with the history: simplify_mesh()'s run to the smallest target, whole, one run: the
      // history needs the whole mesh at every collapse; without: the collapses down to a level
      // run in parts on all cores first when that pays, Chain_collapses::part_levels(), a run of
      // the whole then takes that level and those after it down to the next level whose
      // collapses run in parts)
      // (the last level of a run, and any the run never reached, are taken when it finishes)
      internal::Chain_collapses chain(work, chain_options, follow ? nullptr : &input.mesh());
      internal::Parts_progress progress;
      internal::report_parts_progress_to(visitor, progress);
      // (the levels of a run are fitted beside the runs that follow: each run's state is kept
      // until all are done)
      using Run_state = typename internal::Snapshot_visitor<Visitor>::State;
      std::list<Run_state> runs;
      for (std::size_t first = 0; first < collapsed.size();) {
        std::size_t last = first;  // the run's last level
        if (!history && !history_after_parts)
          while (last + 1 < collapsed.size() && chain.part_levels(collapsed[last], collapsed[last + 1]) == 0) ++last;
        else
          last = collapsed.size() - 1;
        Run_state& state = runs.emplace_back();
        // (room for every level the run can take: a Level_snapshot moves by copying its mesh, whose
        // move constructor is not noexcept, so a vector that grew would copy each level taken)
        state.snapshots.reserve(collapsed.size() - first);
        state.targets = &collapsed;
        state.next = first;
        state.last = last;
        state.complete_when_finished = false;
        // (the fits of the levels a run ends with start when the next run's parts are done: they
        // would take a core from those parts, and the collapses on the whole after them use one;
        // each fit's result does not depend on when it runs)
        state.defer_fits_at_end = last + 1 < collapsed.size();
        if (errors) state.errors = &*errors;
        const auto [parts, faces_after_parts] = chain.run(
            Face_count_stop_predicate<Surface_mesh>(work, collapsed[last]), collapsed.back(),
            [&](const internal::Level_fitter* fitter) {
              return internal::Snapshot_visitor<Visitor>{&state, visitor, history ? &*history : nullptr, fitter};
            },
            history ? 0 : collapsed[first], &progress,
            [&] {
              for (Run_state& earlier : runs) earlier.launch_deferred_fits();
              if (history_after_parts) follow_history(work, false);  // (the parts put back together)
            });
        if (first == 0) std::tie(res.parts, res.faces_after_parts) = std::tie(parts, faces_after_parts);
        res.runs_in_parts += parts > 0;
        first = last + 1;
      }
      meshes.reserve(collapsed.size());
      for (Run_state& state : runs) {
        state.complete_fits();
        for (auto& snapshot : state.snapshots) meshes.push_back(std::move(snapshot));
      }
    }
  } catch (...) {
    prepare.wait();
    throw;
  }
  res.seconds_collapse = internal::seconds_since_lod(t_collapse);

  res.levels.resize(targets.size());
  const bool give_input = owned != nullptr && !options.shared_texture;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    Level_of_detail& l = res.levels[i];
    l.target_faces = targets[i];
    if (i < kept) {
      if (!give_input) l.mesh = input;  // (else at the end)
      l.is_input = true;
    } else {
      // (an untextured level gets no "h:uv" map unless one is asked for)
      l.mesh = textured ? Textured_mesh(std::move(meshes[i - kept].mesh))
                        : Textured_mesh(std::move(meshes[i - kept].mesh), Textured_mesh::without_uv_map);
    }
  }

  const auto t_texture = Clock::now();
  prepare.wait();
  if (textured && !collapsed.empty()) {
    const double border_texels = 0.75 * ao.gutter_texels;
    // the input, mapped onto a level (whose atlas has its charts) through the collapse history
    // (`on_level`: the face of that level each point ended on), paints that atlas; returns the share
    // of the input's texels hidden (and, when asked, each input face's texels)
    auto paint_input_onto = [&](const Textured_mesh& level, Textured_mesh& mapped,
                                const std::vector<std::uint32_t>& on_level, internal::Atlas_paint& paint,
                                internal::Face_texels* texels = nullptr) {
      return internal::paint_input_onto(*source, input_points, level, mapped, on_level, options.max_extrapolation,
                                        ao.gutter_texels, paint, texels);
    };
    if (options.shared_texture) {
      Level_of_detail& coarsest = res.levels.back();
      // the original, mapped into the coarsest level's atlas once that has its charts, paints it
      // (the texels it paints are not baked); then every finer level is mapped into it
      std::optional<Textured_mesh> original_copy;
      if (kept == 0) original_copy.emplace(input);
      Textured_mesh& original = kept > 0 ? res.levels.front().mesh : *original_copy;
      const std::vector<std::uint32_t>& on_coarsest = meshes.back().face_of_point;
      int atlas_width = 0, atlas_height = 0;
      internal::Face_texels input_texels;
      const internal::Atlas_painter painter = [&](const Textured_mesh& coarse, internal::Atlas_paint& paint) {
        atlas_width = paint.colours.width();
        atlas_height = paint.colours.height();
        res.shared_texture_hidden = paint_input_onto(coarse, original, on_coarsest, paint, &input_texels);
      };
      coarsest.atlas = rebuild_atlas(*source, coarsest.mesh, ao, &painter);
      // every finer level mapped into the atlas through the history
      tbb::parallel_for(kept, res.levels.size() - 1, [&](std::size_t i) {
        const internal::Level_snapshot& points = meshes[i - kept];
        internal::map_by_history(coarsest.mesh, res.levels[i].mesh, points.vertex_point, points.face_point, on_coarsest,
                                 options.max_extrapolation, border_texels, atlas_width, atlas_height);
      });
      // the parts of the input the atlas serves poorly, and those under the finer levels' faces it
      // serves poorly, get charts of their own (atlas_layers.h)
      internal::Atlas_layers layers;
      const bool check_colours =
          options.overflow_charts && options.overflow_colour_tolerance > 0 && coarsest.mesh.materials().size() == 1;
      if (options.overflow_charts) {
        std::vector<char> under_poor(input.mesh().number_of_faces(), 0);
        for (std::size_t i = kept; i + 1 < res.levels.size(); ++i)
          internal::mark_input_under_poorly_served(res.levels[i].mesh, atlas_width, atlas_height,
                                                   coarsest.atlas.texels_per_unit, input_points.face_point,
                                                   meshes[i - kept].face_of_point, under_poor);
        // (the colours checked as well: the atlas as the painter and the bake left it)
        if (check_colours) {
          // the input level itself, and the input under each finer level's faces
          internal::mark_input_shown_wrong(original, coarsest.mesh.materials()[0].diffuse_image, *source,
                                           options.overflow_colour_tolerance, under_poor);
          for (std::size_t i = kept; i + 1 < res.levels.size(); ++i)
            internal::mark_input_under_shown_wrong(res.levels[i].mesh, coarsest.mesh.materials()[0].diffuse_image,
                                                   *source, input_points.face_point, meshes[i - kept].face_of_point,
                                                   options.overflow_colour_tolerance, under_poor);
        }
        layers = internal::add_overflow_charts(*source, coarsest.mesh, original, input_texels,
                                               coarsest.atlas.texels_per_unit, ao, under_poor);
      }
      if (layers.strip_height > 0) {
        atlas_height += layers.strip_height;
        coarsest.atlas.texture_height = atlas_height;
        internal::move_to_layered_atlas(original, layers);
        internal::input_into_overflow(original, layers);
        res.shared_texture_hidden = layers.hidden_share;
        res.shared_texture_relocated = layers.area_share;
        res.shared_texture_overflow = double(layers.strip_height) / double(layers.base_height);
      }
      original.materials() = coarsest.mesh.materials();
      for (std::size_t i = 1; i < kept; ++i) res.levels[i].mesh = original;
      tbb::parallel_for(kept, res.levels.size() - 1, [&](std::size_t i) {
        internal::move_to_layered_atlas(res.levels[i].mesh, layers);
        std::optional<internal::Shown_colour_error> colour_error;
        if (check_colours) colour_error.emplace(coarsest.mesh.materials()[0].diffuse_image, *source);
        internal::level_into_overflow(res.levels[i].mesh, layers, input.mesh(), input_points.face_point,
                                      meshes[i - kept].face_of_point, options.max_extrapolation,
                                      colour_error ? &*colour_error : nullptr);
        res.levels[i].mesh.materials() = coarsest.mesh.materials();
      });
      for (std::size_t i = 0; i + 1 < res.levels.size(); ++i) res.levels[i].atlas = coarsest.atlas;
    } else {
      // each level's atlas is painted from the input mapped onto it through the collapse history
      // (as the shared one), and the texels left are baked
      for (std::size_t i = kept; i < res.levels.size(); ++i) {
        const std::vector<std::uint32_t>& on_level = meshes[i - kept].face_of_point;
        if (on_level.empty()) {  // (no history)
          res.levels[i].atlas = rebuild_atlas(*source, res.levels[i].mesh, ao);
          continue;
        }
        const internal::Atlas_painter painter = [&](const Textured_mesh& level, internal::Atlas_paint& paint) {
          Textured_mesh mapped(input.mesh());
          paint_input_onto(level, mapped, on_level, paint);
        };
        res.levels[i].atlas = rebuild_atlas(*source, res.levels[i].mesh, ao, &painter);
      }
    }
  } else if (!textured) {
    for (auto& l : res.levels)
      if (!l.is_input) {
        l.mesh.set_has_uvs(false);
        l.mesh.materials() = input.materials();
      }
  }
  res.seconds_texture += internal::seconds_since_lod(t_texture);

  if (by_error) {  // measured already, in the run
    for (std::size_t i = 0; i < res.levels.size(); ++i) {
      auto& l = res.levels[i];
      l.hausdorff = l.is_input ? 0 : measured[i - kept].first;
      l.rms = l.is_input ? 0 : measured[i - kept].second;
    }
  } else if (options.measure_error) {
    for (std::size_t i = 0; i < kept; ++i) res.levels[i].hausdorff = res.levels[i].rms = 0;
    if (errors) {  // (what is left of the measures once the texture work is done)
      const auto t_error = Clock::now();
      for (const auto& [i, e] : errors->wait()) {
        res.levels[kept + i].hausdorff = e.hausdorff;
        res.levels[kept + i].rms = e.rms;
      }
      res.seconds_error = internal::seconds_since_lod(t_error);
    }
  }
  if (give_input)  // (nothing reads the input any more)
    for (std::size_t i = 0; i < kept; ++i) {
      if (i + 1 < kept)
        res.levels[i].mesh = input;
      else
        res.levels[i].mesh = std::move(*owned);  // (not in a ?: with `input`: that would copy)
    }
  res.seconds = internal::seconds_since_lod(t_start);
  return res;
}

}  // namespace internal

/// Builds the level-of-detail chain of `input` (see the file comment). `input` is not changed.
/// `visitor` receives the collapse engine's calls (progress; the faces removed by an untextured
/// chain's parts reach it through OnPartsProgress(), as in simplify_mesh()). Throws Invalid_input
/// for targets that are not strictly decreasing or are 0, error bounds that are not strictly
/// increasing or are negative, or a non-triangle mesh.
template <class Visitor = Edge_collapse_visitor_base>
Level_of_detail_result simplify_to_levels(const Textured_mesh& input, const Level_of_detail_options& options,
                                          Visitor visitor = Visitor()) {
  return internal::simplify_to_levels(input, nullptr, options, visitor);
}

/// The same, given the input (`std::move(mesh)`): a level that is the input itself (a target of
/// at least its face count) gets it moved in, where the overload above copies it (on a 1M-face
/// input, about 130 MB less at the end of the chain). With `shared_texture` such a level is a copy
/// with new texture coordinates either way. On an error (an exception) `input` is left as it was.
template <class Visitor = Edge_collapse_visitor_base>
Level_of_detail_result simplify_to_levels(Textured_mesh&& input, const Level_of_detail_options& options,
                                          Visitor visitor = Visitor()) {
  return internal::simplify_to_levels(input, &input, options, visitor);
}

#ifdef CMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED
// Compiled once into CMGeom::Textured_simplification with the default visitor and with
// Removed_faces_visitor.
extern template Level_of_detail_result internal::simplify_to_levels<Edge_collapse_visitor_base>(
    const Textured_mesh&, Textured_mesh*, const Level_of_detail_options&, Edge_collapse_visitor_base);
extern template Level_of_detail_result internal::simplify_to_levels<Removed_faces_visitor>(
    const Textured_mesh&, Textured_mesh*, const Level_of_detail_options&, Removed_faces_visitor);
#endif

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_LEVEL_OF_DETAIL_H
