// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Replaces the global operator new and delete of a program so that every block of
// internal::huge_page_new_threshold bytes or more (std::vector storage, CGAL::Surface_mesh's property
// arrays, file buffers) is aligned to 2 MB and, on Linux, advised for transparent huge pages
// (madvise(MADV_HUGEPAGE)) before its first touch; smaller blocks come from malloc() as before.
// Include it in exactly ONE source file of a program (it defines the replacement functions, as a
// memory allocator's "new/delete" header does); a library never includes it. The `cmgeom` tool
// does (tools/cmgeom/main.cpp).
//
// Why: on a kernel that gives huge pages only on request (transparent_hugepage/enabled = madvise,
// Debian's default), each 4 kB page of a fresh block costs a page fault on first touch, and on a
// virtual machine each fault costs microseconds: reading and simplifying a 1M-face mesh spends a
// sixth of its time there. internal/huge_pages.h advises the library's own large texel and output
// buffers (sized so that malloc's mapping of each falls on 2 MB boundaries, with its first range,
// where malloc writes the block's header before anyone can advise it, collapsed into a huge page); this
// header aligns and advises every large allocation of a program, those of CGAL and the standard
// library included, whose first and last 2 MB otherwise fault in 4 kB at a time (a fresh
// 2M-vertex Compact Model reconstruction: 1,822 page faults per call with neither, 76 with the
// library's own sizing, 88 with this header; doc/Compact_model/README.md, "Reconstruction
// speed"). glibc's tunable
// glibc.malloc.hugetlb=1 (GLIBC_TUNABLES, glibc 2.35 and later) has part of this effect without the
// header, for programs that cannot be changed: it advises malloc's blocks before their first touch,
// the smaller blocks of its heap too, but does not align them (that fresh reconstruction, one
// thread, before the library sized its own arrays: 29 M vertices/s with the tunable alone, 29 with
// neither, 38-39 with this header; now 38-39 with neither); the
// `cmgeom` tool uses both (it executes itself again with the tunable set, tools/cmgeom/main.cpp).
//
// A program's user can turn huge pages off for the whole process (CMGEOM_HUGE_PAGES=0, see
// apply_huge_page_setting(); the `cmgeom` tool calls it first).
//
// Memory: a large block is rounded up to a multiple of 2 MB (at most a quarter again as much, for
// an 8 MB block; the kernel backs with huge pages only the 2 MB ranges a block covers, so untouched
// ranges cost no memory). The aligned new and delete (alignment above the default) are not
// replaced; they allocate with aligned_alloc() and release with free(), as these do.
#ifndef CMGEOM_HUGE_PAGE_NEW_H
#define CMGEOM_HUGE_PAGE_NEW_H

#include <CMGeom/internal/huge_pages.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#if defined(__linux__)
#include <sys/prctl.h>
#endif

namespace CMGeom {
namespace internal {

/// Blocks of at least this many bytes go on huge pages. Twice internal::huge_page_threshold: on the
/// 1M-face igea (read, simplify to 1 %, write) 4 MB gave the same time as 8 MB (2.1-2.5 s against
/// 2.2-2.3 s, 2.6-3.4 s without) but 20 MB more peak memory (271 against 251 MB, 246 without);
/// 16 MB and above gave no gain.
constexpr std::size_t huge_page_new_threshold = std::size_t(8) << 20;

/// Set by apply_huge_page_setting() when huge pages are turned off: large blocks then come from
/// malloc() as the small ones do (no 2 MB alignment or rounding, which would buy nothing).
inline bool& huge_page_new_off() {
  static bool off = false;
  return off;
}

/// The environment variable of apply_huge_page_setting().
constexpr const char* huge_page_setting_variable = "CMGEOM_HUGE_PAGES";

/// Applies the program's user's choice in the environment variable CMGEOM_HUGE_PAGES: "0" turns
/// transparent huge pages off for the whole process (prctl(PR_SET_THP_DISABLE); the kernel then
/// ignores every madvise(MADV_HUGEPAGE) of the library, of this header and of glibc, and the
/// programs the process executes inherit the setting) and this header's large blocks go back to
/// malloc(); unset, empty or "1": nothing changes. Returns whether huge pages are off. Throws
/// std::invalid_argument for any other value, and std::runtime_error when the kernel refuses (or
/// is not Linux). Call it first in main(), before any thread starts.
///
/// Why a program offers it: on a virtual machine whose host takes back the guest's free memory
/// (virtio-balloon free page reporting, which reports free 2 MB blocks), a fresh huge page can
/// cost the host's faults for all its 512 small pages, and a run that frees and allocates large
/// blocks again and again pays that at random: on this project's 2-core VM (six interleaved runs
/// each), `cmgeom lod` of DamagedHelmet (shared texture) took 0.95-1.21 s with huge pages and
/// 0.79-0.82 s without, of the 1M-face igea 4.2-5.6 s against 3.3-3.4 s, while `cmgeom simplify`
/// of igea and of the 1M-face igea ran 7 % and 3 % faster with them
/// (doc/Textured_simplification/README.md, "Huge pages on a virtual machine").
inline bool apply_huge_page_setting() {
  const char* value = std::getenv(huge_page_setting_variable);
  if (value == nullptr || *value == '\0' || std::strcmp(value, "1") == 0) return false;
  if (std::strcmp(value, "0") != 0)
    throw std::invalid_argument(std::string(huge_page_setting_variable) + "=" + value +
                                ": expected 0 (no transparent huge pages) or 1 (the default)");
#if defined(__linux__) && defined(PR_SET_THP_DISABLE)
  if (prctl(PR_SET_THP_DISABLE, 1, 0, 0, 0) != 0)
    throw std::runtime_error(std::string(huge_page_setting_variable) +
                             "=0: the kernel refused to turn transparent huge pages off: " + std::strerror(errno));
  huge_page_new_off() = true;
  return true;
#else
  throw std::runtime_error(std::string(huge_page_setting_variable) +
                           "=0: turning transparent huge pages off needs Linux (prctl(PR_SET_THP_DISABLE))");
#endif
}

/// A block of `n` bytes (see the file comment), or null.
inline void* allocate_on_huge_pages_if_large(std::size_t n) noexcept {
  constexpr std::size_t huge_page = huge_page_bytes;
  // (no object is larger than PTRDIFF_MAX bytes; the rounding below cannot wrap around)
  if (n > std::size_t(PTRDIFF_MAX) - huge_page) return nullptr;
  if (n >= huge_page_new_threshold && !huge_page_new_off()) {
    const std::size_t rounded = (n + huge_page - 1) / huge_page * huge_page;
    void* p = std::aligned_alloc(huge_page, rounded);
    if (p) advise_huge_pages(p, rounded);
    return p;
  }
  return std::malloc(n == 0 ? 1 : n);
}

/// operator new's contract: calls the new-handler until the block can be had, throws
/// std::bad_alloc when there is none.
inline void* new_on_huge_pages_if_large(std::size_t n) {
  while (true) {
    if (void* p = allocate_on_huge_pages_if_large(n)) return p;
    const std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

}  // namespace internal
}  // namespace CMGeom

void* operator new(std::size_t n) { return CMGeom::internal::new_on_huge_pages_if_large(n); }
void* operator new[](std::size_t n) { return CMGeom::internal::new_on_huge_pages_if_large(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return CMGeom::internal::new_on_huge_pages_if_large(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return CMGeom::internal::new_on_huge_pages_if_large(n);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

#endif  // CMGEOM_HUGE_PAGE_NEW_H
