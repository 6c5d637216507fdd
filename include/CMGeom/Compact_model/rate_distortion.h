// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// build_compact_model_for(): a Compact Model chosen for an error bound or a size bound (Rate_target,
// Rate_choice), i.e. the base size, the quantization of the compact file (cm_compact_io.h) and the
// reconstruction level. A CMGeom addition: the thesis fixes the base size by hand (chapter 4,
// Tables 4.1-4.3). The error is the Metro-style symmetric Hausdorff distance between the input and
// the reconstruction of the decoded version 3 file, as a fraction of the bounding-box diagonal.
// Key choice: the error of a CM is not monotone in its base size, so candidate bases (a grid of
// ratio sqrt 2) are searched upwards from small ones instead of bisected; when no candidate meets
// the target the closest one is returned with `met` false. Each candidate costs one build, one
// reconstruction and one error measure per level (about 5-8 candidates), the measures against one
// prepared Metrics::Error_reference of the input; a level within an error bound is measured again
// at Metrics' default density (as `cmgeom error` measures), and meets the bound only if it still
// does.
//
// Manual: doc/Compact_model/README.md, "The compact file (version 3) and rate–distortion".
#ifndef CMGEOM_COMPACT_MODEL_RATE_DISTORTION_H
#define CMGEOM_COMPACT_MODEL_RATE_DISTORTION_H

#include <CMGeom/Compact_model/build_compact_model.h>
#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/reconstruct.h>
#include <CMGeom/Compact_model/reconstruction_to_mesh.h>
#include <CMGeom/Error.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Progress.h>

#include <CGAL/Polygon_mesh_processing/bbox.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <vector>

namespace CMGeom {
namespace CM {

/// What build_compact_model_for() aims at (see the file comment); at least one bound is set.
struct Rate_target {
  double max_error = 0.;       ///< symmetric Hausdorff bound, fraction of the bounding-box diagonal; 0 = none
  std::size_t max_bytes = 0;   ///< size bound of the version 3 file; 0 = none
  int max_level = 3;           ///< highest reconstruction level considered, in [1, 6]
  /// Error samples per direction of the search; 0 = 2 x the input's faces. A level within
  /// `max_error` is then measured again at Metrics' default density (as `cmgeom error`), and meets
  /// the bound only if that measure does too.
  std::size_t samples = 0;
  Progress_callback progress;  ///< fraction of the candidates measured (upper bound 1)
};

/// What build_compact_model_for() chose and measured.
struct Rate_choice {
  std::size_t base_faces = 0;       ///< target faces passed to build_compact_model
  int level = 0;                    ///< reconstruction level the error was measured at
  Compact_encoding encoding;        ///< write the model with this to get `bytes`
  std::size_t bytes = 0;            ///< size of the version 3 file
  double hausdorff = 0., rms = 0.;  ///< at `level`, fractions of the diagonal
  int candidates = 0;               ///< models built and measured
  bool met = false;                 ///< the target holds
};

namespace internal {

struct Rate_candidate {
  Compact_model model;
  Compact_encoding encoding;
  std::size_t bytes = 0;
  bool measured = false;
  int level = 0;
  double hausdorff = std::numeric_limits<double>::infinity(), rms = 0.;
};

}  // namespace internal

/// Builds the Compact Model of `input` for `target` (see the file comment); `choice` receives
/// what was chosen, and the model its reconstruction level (Compact_model::reconstruction_level,
/// stored in its file, counted in `choice.bytes`). Write the result with write_compact_cm(path, model,
/// choice.encoding). Throws Invalid_input for an invalid target or input.
template <class Traits = Quadric_surface_traits>
Compact_model build_compact_model_for(const CMGeom::Surface_mesh& input, const Rate_target& target, Rate_choice& choice,
                                      const Build_options& options = Build_options(), const Traits& traits = Traits()) {
  if (!(target.max_error >= 0.) || !std::isfinite(target.max_error) ||
      (target.max_error == 0. && target.max_bytes == 0))
    throw Invalid_input("build_compact_model_for: set max_error (> 0, a fraction of the diagonal) or max_bytes");
  if (target.max_level < 1 || target.max_level > 6)
    throw Invalid_input("build_compact_model_for: max_level must be in [1, 6]");
  if (input.number_of_faces() < 32) throw Invalid_input("build_compact_model_for: the input needs at least 32 faces");
  const CGAL::Bbox_3 box = CGAL::Polygon_mesh_processing::bbox(input);
  const double diagonal = std::sqrt((box.xmax() - box.xmin()) * (box.xmax() - box.xmin()) +
                                    (box.ymax() - box.ymin()) * (box.ymax() - box.ymin()) +
                                    (box.zmax() - box.zmin()) * (box.zmax() - box.zmin()));
  if (!(diagonal > 0.) || !std::isfinite(diagonal))
    throw Invalid_input("build_compact_model_for: the input has an empty or invalid bounding box");

  std::vector<std::size_t> grid;
  for (double f = 16.; f <= double(input.number_of_faces()) / 2.; f *= std::sqrt(2.)) grid.push_back(std::size_t(f));
  if (grid.empty()) grid.push_back(16);
  std::map<std::size_t, internal::Rate_candidate> cache;
  CMGeom::internal::Progress_reporter progress(target.progress);
  int measured = 0;
  const int expected = int(grid.size()) / 2 + 4;
  Metrics::Error_options eo;
  eo.samples = target.samples ? target.samples : 2 * input.number_of_faces();
  eo.vertex_field = false;
  // the input's side of every measure (its tree and samples), prepared once: the same numbers as
  // approximation_error() (the number of samples is fixed)
  const Metrics::Error_reference reference(input, eo);
  std::optional<Metrics::Error_reference> dense;  // (the check of a bound met, made when first needed)

  auto encoding_for = [&](double tolerance_fraction) {
    Compact_encoding e;
    e.tolerance = tolerance_fraction * diagonal;
    return e;
  };
  const double fixed_tolerance = target.max_error > 0. ? target.max_error / 10. : 1e-3;
  auto built = [&](std::size_t i) -> internal::Rate_candidate& {
    auto it = cache.find(i);
    if (it != cache.end()) return it->second;
    internal::Rate_candidate c;
    c.model = build_compact_model(input, grid[i], options, traits);
    // (the file stores the chosen level in one byte, whatever its value: counted from the start)
    c.model.reconstruction_level = 0;
    c.encoding = encoding_for(fixed_tolerance);
    c.bytes = compact_cm_bytes(c.model, c.encoding).size();
    return cache.emplace(i, std::move(c)).first->second;
  };
  auto measure = [&](internal::Rate_candidate& c) {
    if (c.measured) return;
    const Compact_model q = quantized_model(c.model, c.encoding);
    Reconstruction_options ro;
    for (int level = 1; level <= target.max_level; ++level) {
      // (with an error bound, the lowest level within it is kept: the finer ones are never chosen)
      if (target.max_error > 0. && c.hausdorff <= target.max_error) break;
      const CMGeom::Surface_mesh mesh = to_surface_mesh(reconstruct_regular(q, level, ro, traits));
      // A level is kept only when its error is below the one kept so far: a lower bound of it on
      // every 16th sample (a subset of the full measure's; the margin covers the round-off by
      // which a closest point depends on where its search starts) spares the full measure of one
      // that cannot be. The choice is the one every full measure gives.
      if (std::isfinite(c.hausdorff) && reference.hausdorff_lower_bound(mesh, 16) > c.hausdorff * (1. + 1e-9) + 1e-15)
        continue;
      const Metrics::Approximation_error e = reference.error(mesh);
      double h = e.hausdorff, rms = e.rms;  // fractions of the input's diagonal
      // A level within the error bound is measured again at Metrics' default density, the one
      // `cmgeom error` uses (10 x the larger face count per direction, every vertex and edge):
      // the search's sparser samples can miss the farthest point (spot at 0.01: 0.00983 sparse,
      // 0.01018 dense), and a model chosen for a bound must meet it as a user measures it.
      if (target.max_error > 0. && h <= target.max_error) {
        if (!dense) {
          Metrics::Error_options d;
          d.vertex_field = false;
          dense.emplace(input, d);
        }
        const Metrics::Approximation_error de = dense->error(mesh);
        if (de.hausdorff > h) h = de.hausdorff;
        rms = de.rms;
      }
      // max_error: the lowest level within the bound; otherwise the lowest error
      const bool better = target.max_error > 0. ? (c.hausdorff > target.max_error && h < c.hausdorff) : h < c.hausdorff;
      if (better) {
        c.level = level;
        c.hausdorff = h;
        c.rms = rms;
      }
    }
    c.measured = true;
    progress.report(std::min(1., double(++measured) / expected));
  };
  auto fits = [&](std::size_t i) { return target.max_bytes == 0 || built(i).bytes <= target.max_bytes; };
  auto meets = [&](std::size_t i) {
    internal::Rate_candidate& c = built(i);
    measure(c);
    return c.hausdorff <= target.max_error;
  };

  // The largest grid base that fits the size bound (all of them without one).
  std::size_t hi = grid.size() - 1;
  if (target.max_bytes > 0) {
    if (!fits(0)) {
      hi = 0;
    } else if (!fits(hi)) {
      std::size_t lo = 0;  // fits(lo) and !fits(hi)
      while (hi - lo > 1) {
        const std::size_t mid = (lo + hi) / 2;
        (fits(mid) ? lo : hi) = mid;
      }
      hi = lo;
    }
  }
  std::size_t chosen = hi;
  if (target.max_error > 0.) {
    // The smallest base in [0, hi] that meets the error bound: bases of ratio 2 upwards until one
    // meets it (the error is not monotone in the base size, so no bisection from the top), then
    // bisection between it and the one below.
    std::size_t lo = 0, up = 0;
    bool found = meets(0);
    while (!found && up < hi) {
      lo = up;
      up = std::min(hi, up + 2);
      found = meets(up);
    }
    if (found) {
      while (up - lo > 1) {  // meets(up), and !meets(lo) unless up = lo = 0
        const std::size_t mid = (lo + up) / 2;
        (meets(mid) ? up : lo) = mid;
      }
      chosen = up;
    } else {
      // none meets it: the lowest error measured
      double best = std::numeric_limits<double>::infinity();
      for (auto& kv : cache)
        if (kv.second.measured && kv.second.hausdorff < best) {
          best = kv.second.hausdorff;
          chosen = kv.first;
        }
    }
  } else {
    // The lowest error among the largest fitting base and the two below it.
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < 3 && k <= hi; ++k) {
      internal::Rate_candidate& c = built(hi - k);
      measure(c);
      if (c.hausdorff < best) {
        best = c.hausdorff;
        chosen = hi - k;
      }
    }
    // A finer quantization when the error allows it and the file still fits.
    internal::Rate_candidate& c = built(chosen);
    const Compact_encoding finer = encoding_for(std::max(1e-5, c.hausdorff / 10.));
    if (finer.tolerance < c.encoding.tolerance) {
      const std::size_t bytes = compact_cm_bytes(c.model, finer).size();
      if (bytes <= target.max_bytes) {
        c.encoding = finer;
        c.bytes = bytes;
        c.measured = false;
        c.hausdorff = std::numeric_limits<double>::infinity();
        measure(c);
      }
    }
  }
  internal::Rate_candidate& c = built(chosen);
  measure(c);
  choice.base_faces = grid[chosen];
  choice.level = c.level;
  c.model.reconstruction_level = c.level;
  choice.encoding = c.encoding;
  choice.bytes = c.bytes;
  choice.hausdorff = c.hausdorff;
  choice.rms = c.rms;
  choice.candidates = int(cache.size());
  choice.met = (target.max_bytes == 0 || c.bytes <= target.max_bytes) &&
               (target.max_error == 0. || c.hausdorff <= target.max_error);
  progress.report(1.);
  return std::move(c.model);
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_RATE_DISTORTION_H
