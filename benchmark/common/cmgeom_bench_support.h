// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Helpers shared by the benchmark programs (header only; no test framework).
#ifndef CMGEOM_BENCH_SUPPORT_H
#define CMGEOM_BENCH_SUPPORT_H

#include <CGAL/Bbox_3.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

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

}  // namespace cmgeom_bench

#endif  // CMGEOM_BENCH_SUPPORT_H
