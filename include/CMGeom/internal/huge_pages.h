// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// reserve_on_huge_pages(v, n), resize_on_huge_pages(v, n), assign_on_huge_pages(v, n, value),
// filled_on_huge_pages<T>(n, value) and copy_on_huge_pages(v): std::vector's reserve(), resize(),
// assign() and copy for large buffers (texture atlases, index textures, Compact Model outputs).
// When one needs a new block of at least `huge_page_threshold` bytes, the block is reserved first
// and, on Linux, marked for transparent huge pages (madvise(MADV_HUGEPAGE)) before anything touches it, so that
// the first writes fault in 2 MB pages instead of 4 kB ones. On a machine whose kernel hands out
// huge pages only on request (transparent_hugepage/enabled = madvise, Debian's default), this is
// what a fresh 4M-vertex Compact Model reconstruction spends most of its extra time on: 80,000
// page faults for 330 MB of output (doc/Compact_model/README.md, "Reconstruction speed"), and
// what baking a 2048 x 2048 atlas spent a quarter of its time on (its float colour buffer alone
// is 48 MB).
// A new block of at least `parallel_fault_threshold` bytes is then touched once per page on all
// cores (TBB) before the operation fills it: the kernel zeroes each page as it faults in, and on
// one core that zeroing is what baking a 2048 x 3072 shared atlas spent a tenth of its wall time
// on (about 300 MB of fresh buffers), with the other core idle.
// Elsewhere, or when the kernel refuses, each is the plain std::vector operation; the contents are
// the same.
#ifndef CMGEOM_INTERNAL_HUGE_PAGES_H
#define CMGEOM_INTERNAL_HUGE_PAGES_H

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace CMGeom {
namespace internal {

/// Blocks smaller than this are resized as usual (a huge page is 2 MB on x86-64).
constexpr std::size_t huge_page_threshold = std::size_t(4) << 20;

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

/// Fresh blocks of at least this many bytes are faulted in on all cores (see the file comment).
constexpr std::size_t parallel_fault_threshold = std::size_t(16) << 20;

/// Writes a zero byte into every page of [p, p + bytes), 2 MB ranges spread over the cores, so that
/// the kernel's zeroing of fresh pages runs in parallel. The memory must be writable and hold no
/// value anyone reads (allocated storage not yet filled).
inline void fault_in_on_all_cores(void* p, std::size_t bytes) {
  constexpr std::size_t range = std::size_t(2) << 20, page = 4096;
  unsigned char* const b = static_cast<unsigned char*>(p);
  const std::size_t ranges = (bytes + range - 1) / range;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ranges, 1),
                    [b, bytes](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const std::size_t end = (std::min)(bytes, (i + 1) * range);
                        for (std::size_t o = i * range; o < end; o += page)
                          static_cast<volatile unsigned char*>(b)[o] = 0;
                      }
                    });
}

/// v.reserve(n), with a newly needed block of huge_page_threshold bytes or more advised for huge
/// pages (past v's elements) before its first touch, and faulted in on all cores from
/// parallel_fault_threshold bytes (see the file comment).
template <class T, class Allocator>
void reserve_on_huge_pages(std::vector<T, Allocator>& v, std::size_t n) {
  if (n > v.capacity() && n * sizeof(T) >= huge_page_threshold) {
    v.reserve(n);
    const std::size_t fresh = (n - v.size()) * sizeof(T);
    advise_huge_pages(v.data() + v.size(), fresh);
    if (fresh >= parallel_fault_threshold) fault_in_on_all_cores(v.data() + v.size(), fresh);
  }
}

/// v.resize(n), with a newly needed block advised as in reserve_on_huge_pages(). Elements already
/// in v are kept.
template <class T, class Allocator>
void resize_on_huge_pages(std::vector<T, Allocator>& v, std::size_t n) {
  reserve_on_huge_pages(v, n);
  v.resize(n);
}

/// v.assign(n, value), with a newly needed block advised as in reserve_on_huge_pages() (v is
/// cleared first: its old elements are not moved into the new block).
template <class T, class Allocator>
void assign_on_huge_pages(std::vector<T, Allocator>& v, std::size_t n, const T& value) {
  v.clear();
  reserve_on_huge_pages(v, n);
  v.assign(n, value);
}

/// std::vector<T>(n, value), on huge pages when large (see reserve_on_huge_pages()).
template <class T>
std::vector<T> filled_on_huge_pages(std::size_t n, const T& value) {
  std::vector<T> v;
  assign_on_huge_pages(v, n, value);
  return v;
}

/// A copy of v, on huge pages when large (see reserve_on_huge_pages()).
template <class T, class Allocator>
std::vector<T, Allocator> copy_on_huge_pages(const std::vector<T, Allocator>& v) {
  std::vector<T, Allocator> c(v.get_allocator());
  reserve_on_huge_pages(c, v.size());
  c.assign(v.begin(), v.end());
  return c;
}

}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_INTERNAL_HUGE_PAGES_H
