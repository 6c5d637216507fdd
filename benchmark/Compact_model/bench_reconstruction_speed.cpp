// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Reconstruction throughput of Compact Models (thesis §4.5.2; never run by CTest): output
// vertices per second of reconstruct_regular() at levels 1-6, projection along N and closest
// point, 1 and 2 threads, into a fresh Reconstruction (what a one-off call pays: allocation and
// first touch of the output) and into a reused one (what a per-frame call pays, e.g. a deformable
// CM: no allocation). Minimum and median of several runs. Prints Markdown.
// Built twice: bench_reconstruction_speed with the standard operator new, and
// bench_reconstruction_speed_huge_new, which replaces it by CMGeom/huge_page_new.h as the `cmgeom`
// tool does (large blocks 2 MB-aligned and advised for huge pages before their first touch): a
// fresh output's first touch is most of what separates `fresh` from `reused`, and the header is
// what a program does about it (doc/Compact_model/README.md, "Reconstruction speed").
//
//   bench_reconstruction_speed [data dir] [model:base_faces ...] [--levels A-B] [--along-n]
//                              [--threads T] [--runs R]
//   (default: horse 1000, igea 2000, levels 1-6, both projections, 1 and 2 threads)
#include <CMGeom/Compact_model.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include "cmgeom_bench_support.h"

#if defined(CMGEOM_BENCH_HUGE_PAGE_NEW)
#include <CMGeom/huge_page_new.h>  // this program's operator new (see the file comment)
#endif

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace CM = CMGeom::CM;

namespace {
double seconds(const std::chrono::steady_clock::time_point& t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

int main(int argc, char** argv) {
  std::string data = CMGEOM_BENCH_DATA_DIR;
  std::vector<std::pair<std::string, int>> models;
  int level_min = 1, level_max = 6;
  bool along_n_only = false;
  std::vector<int> thread_counts = {1, 2};
  int forced_runs = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto colon = a.rfind(':');
    if (a == "--threads" && i + 1 < argc) {
      thread_counts = {std::atoi(argv[++i])};
    } else if (a == "--runs" && i + 1 < argc) {
      forced_runs = std::atoi(argv[++i]);
    } else if (a == "--along-n") {
      along_n_only = true;
    } else if (a == "--levels" && i + 1 < argc) {
      const std::string r = argv[++i];
      const auto dash = r.find('-');
      level_min = std::atoi(r.c_str());
      level_max = dash == std::string::npos ? level_min : std::atoi(r.c_str() + dash + 1);
    } else if (colon == std::string::npos)
      data = a;
    else
      models.push_back({a.substr(0, colon), std::atoi(a.c_str() + colon + 1)});
  }
  if (models.empty()) models = {{"classic/horse.ply", 1000}, {"classic/igea.ply.gz", 2000}};
  std::printf(
      "| model | base F | projection | threads | level | out V | fresh s min / median | fresh M vert/s at min / median "
      "| "
      "reused s min / median | reused M vert/s at min / median |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [file, faces] : models) {
    std::string path = data + "/" + file;
    if (!std::filesystem::exists(path)) {
      std::fprintf(stderr, "skipping %s (not found)\n", path.c_str());
      continue;
    }
    path = cmgeom_bench::readable_model(path, std::filesystem::temp_directory_path().string(), "cmgeom_bench_");
    if (path.empty()) continue;
    CMGeom::Textured_mesh tm;
    CMGeom::IO::read_mesh(path, tm);
    const CM::Compact_model model = CM::build_compact_model(tm.mesh(), std::size_t(faces));
    for (CM::Projection proj : {CM::Projection::along_normal, CM::Projection::closest_point})
      for (int threads : thread_counts) {
        if (along_n_only && proj != CM::Projection::along_normal) continue;
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
        for (int level = level_min; level <= level_max; ++level) {
          CM::Reconstruction_options o;
          o.projection = proj;
          const int runs = forced_runs > 0 ? forced_runs : level <= 2 ? 60 : level <= 4 ? 15 : 5;
          std::vector<double> fresh, reused;
          std::size_t n = 0;
          CM::Reconstruction buffer;
          for (int r = 0; r < runs; ++r) {  // interleaved, so that a change of load hits both alike
            auto t0 = std::chrono::steady_clock::now();
            const CM::Reconstruction rec = CM::reconstruct_regular(model, level, o);
            fresh.push_back(seconds(t0));
            n = rec.points.size();
            t0 = std::chrono::steady_clock::now();
            CM::reconstruct_regular(model, level, buffer, o);
            reused.push_back(seconds(t0));
          }
          const cmgeom_bench::Timing tf = cmgeom_bench::summarize(fresh), tr = cmgeom_bench::summarize(reused);
          std::printf("| %s | %zu | %s | %d | %d | %zu | %s | %s | %s | %s |\n",
                      std::filesystem::path(file).filename().string().c_str(), model.faces.size(),
                      proj == CM::Projection::along_normal ? "along N" : "closest", threads, level, n,
                      cmgeom_bench::min_median(tf).c_str(), cmgeom_bench::rate_min_median(double(n) / 1e6, tf).c_str(),
                      cmgeom_bench::min_median(tr).c_str(), cmgeom_bench::rate_min_median(double(n) / 1e6, tr).c_str());
          std::fflush(stdout);
        }
      }
  }
  return 0;
}
