// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Helpers shared by the benchmark programs (header only; no test framework).
#ifndef CMGEOM_BENCH_SUPPORT_H
#define CMGEOM_BENCH_SUPPORT_H

#include <CGAL/Bbox_3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace cmgeom_bench {

/// A path the mesh readers can open: `path` itself, or for a gzipped "name.ext.gz" the file
/// `dir`/`prefix`name.ext decompressed there (kept for the next run: it is written under a
/// temporary name and renamed when complete, so an interrupted run never leaves a truncated copy
/// behind). "" when `dir` cannot be created or gunzip fails.
inline std::string readable_model(const std::string& path, const std::string& dir,
                                  const std::string& prefix = std::string()) {
  namespace fs = std::filesystem;
  if (path.size() <= 3 || path.compare(path.size() - 3, 3, ".gz") != 0) return path;
  std::error_code ec;
  fs::create_directories(dir, ec);
  const std::string out = (fs::path(dir) / (prefix + fs::path(path).stem().string())).string();
  if (fs::exists(out, ec)) return out;
  const std::string part = out + ".part";
  if (std::system(("gunzip -c '" + path + "' > '" + part + "'").c_str()) != 0) {
    fs::remove(part, ec);
    return std::string();
  }
  fs::rename(part, out, ec);
  return ec ? std::string() : out;
}

/// Parses the whole of `text` as a number in [lo, hi] into `out`; false (out unchanged) for an
/// empty string, trailing characters, NaN or a value out of range. For command-line options:
/// std::stod would throw, and std::atof would read "0.1x" as 0.1.
inline bool parse_number(const std::string& text, double lo, double hi, double& out) {
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !(x >= lo && x <= hi)) return false;
  out = x;
  return true;
}

/// Length of the diagonal of `box` (errors are reported as fractions of it).
inline double diagonal(const CGAL::Bbox_3& box) {
  const double dx = box.xmax() - box.xmin(), dy = box.ymax() - box.ymin(), dz = box.zmax() - box.zmin();
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

/// The minimum and the median of repeated measurements of one quantity (seconds unless said
/// otherwise). The minimum is the run least disturbed by other jobs; the median is the typical
/// run. Tables print both, "min / median".
struct Timing {
  double min = 0, median = 0;
  int runs = 0;
  /// Both scaled by `factor` (e.g. 1e3 for milliseconds, or 1 / frames for a per-frame time).
  Timing scaled(double factor) const { return {min * factor, median * factor, runs}; }
};

/// Minimum and median of `samples` (all zero when there are none).
inline Timing summarize(std::vector<double> samples) {
  Timing t;
  t.runs = static_cast<int>(samples.size());
  if (samples.empty()) return t;
  std::sort(samples.begin(), samples.end());
  const std::size_t n = samples.size();
  t.min = samples.front();
  t.median = n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  return t;
}

/// Wall-clock seconds now (steady clock).
inline double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Calls `f` `runs` times (at least once) and returns the minimum and median wall-clock seconds
/// of one call.
template <class F>
Timing time_runs(int runs, F&& f) {
  std::vector<double> t;
  for (int r = 0; r < std::max(runs, 1); ++r) {
    const double t0 = wall_seconds();
    f();
    t.push_back(wall_seconds() - t0);
  }
  return summarize(std::move(t));
}

/// "min / median" of `t` printed with the printf format `format` of one double (e.g. "%.4f").
inline std::string min_median(const Timing& t, const char* format = "%.4f") {
  char a[64], b[64];
  std::snprintf(a, sizeof a, format, t.min);
  std::snprintf(b, sizeof b, format, t.median);
  return std::string(a) + " / " + b;
}

/// "at min / at median" of a rate `work` / time: the rate of the fastest run, then of the median
/// run (so the first figure is the larger one).
inline std::string rate_min_median(double work, const Timing& t, const char* format = "%.1f") {
  const Timing r{t.min > 0 ? work / t.min : 0.0, t.median > 0 ? work / t.median : 0.0, t.runs};
  return min_median(r, format);
}

}  // namespace cmgeom_bench

#endif  // CMGEOM_BENCH_SUPPORT_H
