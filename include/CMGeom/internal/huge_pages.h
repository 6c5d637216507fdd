// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// resize_on_huge_pages(v, n): std::vector::resize() for large outputs. When the resize needs a
// new block of at least `huge_page_threshold` bytes, the block is reserved first and, on Linux,
// marked for transparent huge pages (madvise(MADV_HUGEPAGE)) before anything touches it, so that
// the first writes fault in 2 MB pages instead of 4 kB ones. On a machine whose kernel hands out
// huge pages only on request (transparent_hugepage/enabled = madvise, Debian's default), this is
// what a fresh 4M-vertex Compact Model reconstruction spends most of its extra time on: 80,000
// page faults for 330 MB of output (doc/Compact_model/README.md, "Reconstruction speed").
// Elsewhere, or when the kernel refuses, it is a plain resize(); the contents are the same.
#ifndef CMGEOM_INTERNAL_HUGE_PAGES_H
#define CMGEOM_INTERNAL_HUGE_PAGES_H

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace CMGeom {
namespace internal {

/// Blocks smaller than this are resized as usual (a huge page is 2 MB on x86-64).
constexpr std::size_t huge_page_threshold = std::size_t(8) << 20;

/// Asks the kernel to back [p, p + bytes) by transparent huge pages where it can; a hint only.
inline void advise_huge_pages(void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  static const std::uintptr_t page = [] {
    const long s = sysconf(_SC_PAGESIZE);
    return s > 0 ? std::uintptr_t(s) : std::uintptr_t(4096);
  }();
  const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + page - 1) / page * page;
  const std::uintptr_t end = reinterpret_cast<std::uintptr_t>(p) + bytes;
  if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)p;
  (void)bytes;
#endif
}

/// v.resize(n), with a newly needed block of huge_page_threshold bytes or more advised for huge
/// pages before its first touch (see the file comment). Elements already in v are kept.
template <class T, class Allocator>
void resize_on_huge_pages(std::vector<T, Allocator>& v, std::size_t n) {
  if (n > v.capacity() && n * sizeof(T) >= huge_page_threshold) {
    v.reserve(n);
    advise_huge_pages(v.data() + v.size(), (n - v.size()) * sizeof(T));
  }
  v.resize(n);
}

}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_INTERNAL_HUGE_PAGES_H
