// Helpers shared by the CMGeom test programs: shared-data lookup with a clear skip, scratch
// directories, files written by the test itself, and running the cmgeom CLI.
#ifndef CMGEOM_TEST_SUPPORT_H
#define CMGEOM_TEST_SUPPORT_H

#include "cmgeom_test_config.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace cmgeom_test {

namespace fs = std::filesystem;

/// Path of a file of the shared data set, or "" when the data set is absent.
inline std::string shared_data(const std::string& relative) {
  const fs::path p = fs::path(CMGEOM_DATA_DIR) / relative;
  std::error_code ec;
  return fs::exists(p, ec) ? p.string() : std::string();
}

/// Skips the current test when the shared data set (../shared/data) is missing.
#define CMGEOM_REQUIRE_SHARED_DATA()                                                 \
  do {                                                                               \
    if (cmgeom_test::shared_data("SOURCES.md").empty())                              \
      GTEST_SKIP() << "shared data not found at " CMGEOM_DATA_DIR                    \
                      " (set -DCMGEOM_DATA_DIR); this test needs the public models"; \
  } while (0)

/// A fresh, empty scratch directory unique to the current test.
inline std::string scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path p = fs::path(CMGEOM_TEST_TMP_DIR) /
               (std::string(info->test_suite_name()) + "." + info->name() + "." + std::to_string(::getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

inline std::string write_text(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = (fs::path(dir) / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

/// A file from the shared data, decompressed into `dir` when it is gzipped (name without .gz).
inline std::string shared_mesh(const std::string& relative, const std::string& dir) {
  const std::string src = shared_data(relative);
  if (src.empty()) return src;
  if (src.size() > 3 && src.compare(src.size() - 3, 3, ".gz") == 0) {
    const std::string out = (fs::path(dir) / fs::path(src).stem()).string();
    const std::string cmd = "gunzip -c '" + src + "' > '" + out + "'";
    if (std::system(cmd.c_str()) != 0) return std::string();
    return out;
  }
  return src;
}

struct Cli_result {
  int exit_code = -1;
  std::string out, err;
};

/// Runs the cmgeom tool with `args` (already shell-quoted) and captures its output.
inline Cli_result run_cli(const std::string& args, const std::string& dir) {
  const std::string out = (fs::path(dir) / "cli.stdout").string();
  const std::string err = (fs::path(dir) / "cli.stderr").string();
  const std::string cmd = std::string("'") + CMGEOM_CMGEOM_EXE + "' " + args + " > '" + out + "' 2> '" + err + "'";
  const int status = std::system(cmd.c_str());
  Cli_result r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream o(out), e(err);
  std::stringstream so, se;
  so << o.rdbuf();
  se << e.rdbuf();
  r.out = so.str();
  r.err = se.str();
  fs::remove(out);
  fs::remove(err);
  return r;
}

/// Number of files in a directory (to check that failed commands leave nothing behind).
inline std::size_t count_files(const std::string& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.is_regular_file() ? 1 : 0;
  return n;
}

}  // namespace cmgeom_test

#endif
