// cmgeom: the command-line face of CMGeom. Every sub-command lives in its own cmd_<name>.cpp
// and registers itself (see cli_common.h), so adding one never touches this file.
//
// Errors: a sub-command throws; the message is printed on stderr as one line, prefixed with
// "cmgeom <sub-command>: error: ", and the exit code is 1 (2 for command-line usage errors).
#include "cli_common.h"

// every large block of the tool on transparent huge pages (see the header; once per program)
#include <CMGeom/huge_page_new.h>

#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#if defined(__linux__)
#include <unistd.h>
#endif

namespace {

/// The glibc tunable that has malloc advise its heap and its mapped blocks for transparent huge
/// pages (glibc 2.35 and later).
constexpr const char* huge_page_heap_tunable = "glibc.malloc.hugetlb";

/// Executes the tool again, once, with glibc's huge-page tunable added to GLIBC_TUNABLES, where that
/// helps; returns (and the tool runs as it is) otherwise or when the execution fails.
///
/// Why: glibc reads its tunables from the environment when a process starts, and a program cannot
/// set them for itself. CMGeom/huge_page_new.h puts the blocks of 8 MB and more on huge pages;
/// the smaller ones (the copies a level-of-detail chain takes of its levels, the memoryful cost's
/// point lists, CGAL's property arrays of a mid-size mesh) come from malloc's heap, whose fresh 4 kB
/// pages each cost a fault on first touch, several microseconds on a virtual machine. With the
/// tunable, `cmgeom lod` of the horse (97k faces, four levels) took 0.51 s instead of 0.64 s and
/// `cmgeom simplify` of igea to 10 % 0.65-0.70 s instead of 0.81-0.83 s
/// (doc/Textured_simplification/README.md, "Large meshes on all cores"). The cost is one more start
/// of the program, about 7 ms.
///
/// Where: Linux with glibc 2.35 or later, a kernel that gives huge pages on request only
/// (transparent_hugepage/enabled = madvise, Debian's default; with "always" the heap has them
/// already, with "never" the tunable does nothing); not in a build with a sanitizer or under
/// valgrind (their allocators replace glibc's); not when GLIBC_TUNABLES names the tunable already
/// (which also ends the second execution), when CMGEOM_HUGE_PAGE_HEAP is 0 or when
/// CMGEOM_HUGE_PAGES=0 turned huge pages off altogether (huge_page_new.h).
void execute_again_with_huge_page_heap(char** argv) {
#if defined(__linux__) && defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35)) && \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  if (argv == nullptr || argv[0] == nullptr) return;
  const char* off = std::getenv("CMGEOM_HUGE_PAGE_HEAP");
  if (off != nullptr && std::strcmp(off, "0") == 0) return;
  const char* preload = std::getenv("LD_PRELOAD");
  if (preload != nullptr && std::strstr(preload, "vgpreload") != nullptr) return;  // (valgrind)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, huge_page_heap_tunable) != nullptr) return;
  std::ifstream mode_file("/sys/kernel/mm/transparent_hugepage/enabled");
  const std::string mode((std::istreambuf_iterator<char>(mode_file)), std::istreambuf_iterator<char>());
  if (mode.find("[madvise]") == std::string::npos) return;
  const bool had_tunables = tunables != nullptr;
  const std::string before = had_tunables ? tunables : "";
  const std::string after = (before.empty() ? "" : before + ":") + huge_page_heap_tunable + "=1";
  // (the program's own file, by its path, as cmd_pipeline.cpp finds it: executing /proc/self/exe
  // would name the process "exe")
  std::error_code ec;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe", ec).string();
  if (ec || self.empty()) return;
  if (setenv("GLIBC_TUNABLES", after.c_str(), 1) != 0) return;
  execv(self.c_str(), argv);
  // (the execution failed: the tool runs as it is, in the environment it was given)
  if (had_tunables)
    setenv("GLIBC_TUNABLES", before.c_str(), 1);
  else
    unsetenv("GLIBC_TUNABLES");
#else
  (void)argv;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  // CMGEOM_HUGE_PAGES=0: no transparent huge pages at all (then no heap tunable either)
  bool huge_pages_off = false;
  try {
    huge_pages_off = CMGeom::internal::apply_huge_page_setting();
  } catch (const std::exception& e) {
    std::cerr << "cmgeom: error: " << e.what() << "\n";
    return 2;
  }
  if (!huge_pages_off) execute_again_with_huge_page_heap(argv);
  return cmgeom_cli::run(std::vector<std::string>(argv + 1, argv + argc));
}
