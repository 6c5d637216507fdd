// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Helpers shared by the benchmark programs (header only; no test framework).
#ifndef CMGEOM_BENCH_SUPPORT_H
#define CMGEOM_BENCH_SUPPORT_H

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

}  // namespace cmgeom_bench

#endif  // CMGEOM_BENCH_SUPPORT_H
