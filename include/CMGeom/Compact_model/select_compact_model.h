// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// build_selected_compact_model(): the Compact Model of the lowest measured error among a few
// build configurations (Fit_configuration: how the base vertices are placed, the thesis'
// independent fits or the joint refit, quadric or cubic local surfaces). A CMGeom addition, and
// the `cmgeom cm build` default (`--fit auto`): the thesis (chapter 4) gives one method, and
// measured over the shared models no single configuration is best everywhere (the joint refit
// lowers the median Hausdorff error but raises it on a fifth of the cases; optimal placement
// helps the joint refit on CAD parts and hurts the thesis' fits). Each candidate is built, rounded
// to float as the CM file stores it, reconstructed at `Selection_options::level` (regular, closest
// point, as `cm reconstruct` does by default) and measured against the input (Metro-style
// symmetric Hausdorff distance); the lowest Hausdorff distance wins, the lower RMS breaking ties.
// So the result is, at that level and on those samples, never farther from the input than the
// thesis' own build, at the price of one build and one measure per candidate.
//
// Manual: doc/Compact_model/README.md, "Choosing the fits by measurement".
#ifndef CMGEOM_COMPACT_MODEL_SELECT_COMPACT_MODEL_H
#define CMGEOM_COMPACT_MODEL_SELECT_COMPACT_MODEL_H

#include <CMGeom/Compact_model/build_compact_model.h>
#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Compact_model/reconstruction_to_mesh.h>
#include <CMGeom/Error.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Progress.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <tbb/task_group.h>

namespace CMGeom {
namespace CM {

/// One way of building a Compact Model (a candidate of build_selected_compact_model()).
struct Fit_configuration {
  std::string name;                ///< shown in reports
  bool optimal_placement = false;  ///< Weighted_quadric_simplifier::optimal_placement (then §4.3's snapping)
  bool joint_fit = false;          ///< Build_options::joint_fit
  bool cubic = false;              ///< Cubic_surface_traits instead of Quadric_surface_traits
  double sharp_angle = 0.;         ///< Build_options::sharp_angle for this build; 0 = the caller's
};

/// The default candidates: the thesis' build (base vertices on input vertices, independent
/// quadric fits: the build of build_compact_model() with the caller's options), the joint refit
/// with quadric surfaces and a sharp-edge threshold of 25 degrees, and the joint refit with cubic
/// surfaces at the caller's threshold, both on bases of optimally placed (then snapped) vertices.
/// Chosen by a survey of eight configurations over the shared classic models (60 cases, level 3;
/// the manual has it): of every set of the thesis' build and two others, these give the lowest
/// median Hausdorff and RMS errors relative to the thesis' build (0.69 and 0.58).
inline std::vector<Fit_configuration> default_fit_candidates() {
  return {
      {"thesis", false, false, false, 0.}, {"joint-25", true, true, false, 25.}, {"joint-cubic", true, true, true, 0.}};
}

/// Builds the Compact Model of `input` in configuration `c`: build_compact_model() with
/// `options` (its `joint_fit` and, when `c.sharp_angle` > 0, its `sharp_angle` replaced by the
/// configuration's), the Weighted_quadric_simplifier placing base vertices as `c` says, and the
/// cubic or quadric traits. `stats` receives the build's statistics.
inline Compact_model build_configured_compact_model(const CMGeom::Surface_mesh& input, std::size_t target_faces,
                                                    const Build_options& options, const Fit_configuration& c,
                                                    Build_statistics* stats = nullptr) {
  Build_options o = options;
  o.joint_fit = c.joint_fit;
  if (c.sharp_angle > 0.) o.sharp_angle = c.sharp_angle;
  Weighted_quadric_simplifier simplify;
  simplify.optimal_placement = c.optimal_placement;
  return c.cubic ? build_compact_model(input, target_faces, o, Cubic_surface_traits(), simplify, stats)
                 : build_compact_model(input, target_faces, o, Quadric_surface_traits(), simplify, stats);
}

/// Options of build_selected_compact_model().
struct Selection_options {
  std::vector<Fit_configuration> candidates = default_fit_candidates();
  int level = 3;               ///< reconstruction level of the measure, in [1, 6]
  std::size_t samples = 0;     ///< samples per direction; 0 = max(2 x the input's faces, 100,000)
  Progress_callback progress;  ///< fraction of the selection done (builds and measures)
};

/// What build_selected_compact_model() built and measured.
struct Selection_result {
  struct Candidate {
    Fit_configuration configuration;
    double hausdorff = 0., rms = 0.;  ///< fractions of the input's bounding-box diagonal
    double seconds = 0.;              ///< its build alone
    Build_statistics statistics;
  };
  std::vector<Candidate> candidates;  ///< in the order of Selection_options::candidates
  std::size_t chosen = 0;             ///< index of the model returned
};

/// Builds the Compact Model of `input` with a base of about `target_faces` faces for every
/// configuration of `selection` (the other build options from `options`; its `joint_fit` and
/// `progress` are replaced) and returns the one of lowest measured error (see the file comment).
/// `result` and `stats` (the chosen build's) receive what was done. Throws Invalid_input for an
/// empty candidate list, a level outside [1, 6], or what build_compact_model() refuses.
inline Compact_model build_selected_compact_model(const CMGeom::Surface_mesh& input, std::size_t target_faces,
                                                  const Build_options& options = Build_options(),
                                                  const Selection_options& selection = Selection_options(),
                                                  Selection_result* result = nullptr,
                                                  Build_statistics* stats = nullptr) {
  if (selection.candidates.empty()) throw Invalid_input("build_selected_compact_model: no candidate configuration");
  for (const Fit_configuration& c : selection.candidates)
    if (!(c.sharp_angle >= 0. && c.sharp_angle < 180.))
      throw Invalid_input("build_selected_compact_model: candidate " + c.name + ": sharp_angle must be in [0, 180)");
  if (selection.level < 1 || selection.level > 6)
    throw Invalid_input("build_selected_compact_model: the level must be in [1, 6]");
  internal::check_build_arguments(input, target_faces, options);

  CMGeom::internal::Progress_reporter progress(selection.progress);
  const std::size_t n = selection.candidates.size();
  Metrics::Error_options eo;
  eo.samples =
      selection.samples ? selection.samples : std::max<std::size_t>(2 * input.number_of_faces(), std::size_t(100000));
  eo.vertex_field = false;

  Selection_result local;
  Selection_result& res = result ? *result : local;
  res.candidates.assign(n, Selection_result::Candidate());
  std::vector<Compact_model> models(n);
  // Every build is a task, and so is the reference side of the measures (the input's tree and
  // samples, prepared once); a candidate's measure runs as soon as its build and the reference are
  // both done, in the task that finished last, so measures run beside the builds still going.
  // Each build is deterministic and mostly sequential (its simplification and the joint refit's
  // factorization use one core). No task waits for another (a waiting thread would run other
  // tasks meanwhile). Progress: the fraction of the builds and measures done, reported from the
  // calling thread only, with the progress of a build that runs there.
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<std::size_t> stages_done{0};
  const double stages = 2. * double(n);
  auto stage_done = [&] {
    const std::size_t k = stages_done.fetch_add(1) + 1;
    if (std::this_thread::get_id() == caller) progress.report(double(k) / stages);
  };
  std::optional<Metrics::Error_reference> reference;
  std::mutex hand_over;            // guards the two below
  bool reference_ready = false;    // `reference` made
  std::vector<std::size_t> built;  // candidates built before it, their measures not started
  auto measure = [&](std::size_t i) {
    Selection_result::Candidate& r = res.candidates[i];
    // (a model stores the kind of every surface: the quadric traits evaluate cubic ones too)
    const Metrics::Approximation_error e =
        reference->error(to_surface_mesh(reconstruct_regular(models[i], selection.level)));
    r.hausdorff = e.hausdorff;
    r.rms = e.rms;
    stage_done();
  };
  tbb::task_group tasks;
  auto build = [&](std::size_t i) {
    Build_options o = options;
    o.progress = nullptr;
    if (progress.active() && std::this_thread::get_id() == caller)
      o.progress = [&](double f) { progress.report((double(stages_done.load()) + (std::min)(f, 1.)) / stages); };
    Selection_result::Candidate& r = res.candidates[i];
    r.configuration = selection.candidates[i];
    const auto t0 = std::chrono::steady_clock::now();
    models[i] = build_configured_compact_model(input, target_faces, o, r.configuration, &r.statistics);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    stage_done();
    {
      std::lock_guard<std::mutex> lock(hand_over);
      if (!reference_ready) {
        built.push_back(i);
        return;
      }
    }
    measure(i);
  };
  auto make_reference = [&] {
    reference.emplace(input, eo);
    std::vector<std::size_t> waiting;
    {
      std::lock_guard<std::mutex> lock(hand_over);
      reference_ready = true;
      waiting.swap(built);
    }
    for (std::size_t i : waiting) tasks.run([&measure, i] { measure(i); });
  };
  // (the costliest configurations first: cubic, then joint refits; the reference last, which the
  // calling thread, taking its own newest task first, then starts at once)
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t(0));
  auto cost_rank = [&](std::size_t i) {
    const Fit_configuration& c = selection.candidates[i];
    return 4 * int(c.cubic) + 2 * int(c.joint_fit) + int(c.optimal_placement);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return cost_rank(a) > cost_rank(b); });
  for (std::size_t i : order) tasks.run([&build, i] { build(i); });
  tasks.run(make_reference);
  tasks.wait();
  double best_h = std::numeric_limits<double>::infinity(), best_rms = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    const Selection_result::Candidate& r = res.candidates[i];
    if (i == 0 || r.hausdorff < best_h || (r.hausdorff == best_h && r.rms < best_rms)) {
      best_h = r.hausdorff;
      best_rms = r.rms;
      res.chosen = i;
    }
  }
  if (stats) *stats = res.candidates[res.chosen].statistics;
  progress.finish();
  return std::move(models[res.chosen]);
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_SELECT_COMPACT_MODEL_H
