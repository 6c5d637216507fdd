// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// reserve_on_huge_pages(v, n), resize_on_huge_pages(v, n), assign_on_huge_pages(v, n, value),
// filled_on_huge_pages<T>(n, value) and copy_on_huge_pages(v): std::vector's reserve(), resize(),
// assign() and copy for large buffers (texture atlases, index textures, Compact Model outputs);
// and Unwritten_allocator, with which a vector's resize() leaves new elements unwritten (Compact
// Model outputs, whose every element the reconstruction writes).
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
// A block this code reserves is also sized so that glibc's malloc, which maps a large block on its
// own with a 16-byte header before it, asks the kernel for a whole number of 2 MB pages: the kernel
// then places the mapping on a 2 MB boundary (measured on Linux 6.18), its last 2 MB range is a
// whole huge page, and its first, whose 4 kB page malloc has already written, is made a huge page by
// madvise(MADV_COLLAPSE) (Linux 6.1 and later). Without this the block's first and last 2 MB fault
// in 4 kB at a time, about 10 microseconds each on a virtual machine: a fresh 100 MB block filled
// once took 12.3 ms against 6.6 ms so (and 270 ms with no advice at all). The capacity grows by
// less than 2 MB; the pages past the elements are not touched.
// Elsewhere, or when the kernel refuses, each is the plain std::vector operation; the contents are
// the same.
#ifndef CMGEOM_INTERNAL_HUGE_PAGES_H
#define CMGEOM_INTERNAL_HUGE_PAGES_H

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__linux__)
#include <sys/mman.h>
#include <sys/prctl.h>
#include <unistd.h>
#endif

namespace CMGeom {
namespace internal {

/// An allocator whose construct() without arguments writes nothing: std::vector::resize() then
/// leaves the new elements' bytes as the memory holds them (zeros in pages fresh from the kernel,
/// whatever an earlier use left otherwise) instead of writing zeros over them, for arrays whose
/// every element the caller writes next. Measured with `perf`: a fresh 2M-point Compact Model
/// reconstruction spent a ninth of its time on one core in resize()'s zeros, over pages the
/// kernel had just cleared. Any other construction is std::allocator's. T must be trivially
/// copyable and trivially destructible (its objects may then begin life in storage without a
/// constructor call, as malloc's do).
template <class T>
struct Unwritten_allocator : std::allocator<T> {
  static_assert(std::is_trivially_copyable<T>::value && std::is_trivially_destructible<T>::value,
                "Unwritten_allocator: T must be trivially copyable and trivially destructible");
  using value_type = T;
  template <class U>
  struct rebind {
    using other = Unwritten_allocator<U>;
  };
  Unwritten_allocator() noexcept = default;
  template <class U>
  Unwritten_allocator(const Unwritten_allocator<U>&) noexcept {}
  template <class U>
  void construct(U*) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T, class U>
bool operator==(const Unwritten_allocator<T>&, const Unwritten_allocator<U>&) noexcept {
  return true;
}
template <class T, class U>
bool operator!=(const Unwritten_allocator<T>&, const Unwritten_allocator<U>&) noexcept {
  return false;
}

/// Blocks smaller than this are resized as usual (a huge page is 2 MB on x86-64).
constexpr std::size_t huge_page_threshold = std::size_t(4) << 20;

/// The size of a transparent huge page on x86-64 (and of the ranges this file rounds to).
constexpr std::size_t huge_page_bytes = std::size_t(2) << 20;

/// glibc's header before a block it maps on its own (two size_t words).
constexpr std::size_t malloc_mapped_header = 2 * sizeof(std::size_t);

/// The capacity, at least `n`, for which a block of T's that glibc's malloc maps on its own spans
/// whole 2 MB pages (see the file comment): the largest count whose bytes, with malloc's header
/// and its rounding (8 bytes and a multiple of 16), fit the next multiple of 2 MB. `n` itself for
/// over-aligned T, which malloc places otherwise.
template <class T>
std::size_t capacity_on_whole_huge_pages(std::size_t n) {
  constexpr std::size_t slack = malloc_mapped_header + sizeof(std::size_t);  // header + rounding
  if (alignof(T) > alignof(std::max_align_t) || n > (std::size_t(PTRDIFF_MAX) - 2 * huge_page_bytes) / sizeof(T))
    return n;
  const std::size_t pages = (n * sizeof(T) + slack + huge_page_bytes - 1) / huge_page_bytes;
  return (std::max)(n, (pages * huge_page_bytes - slack) / sizeof(T));
}

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

#if defined(__linux__) && !defined(MADV_COLLAPSE)
#define CMGEOM_MADV_COLLAPSE 25  // Linux 6.1's value, for older headers
#elif defined(__linux__)
#define CMGEOM_MADV_COLLAPSE MADV_COLLAPSE
#endif

/// Whether the kernel hands out transparent huge pages at all (transparent_hugepage/enabled is not
/// "never", read once) and this process has not turned them off (prctl(PR_SET_THP_DISABLE), as
/// huge_page_new.h's apply_huge_page_setting() does). MADV_COLLAPSE would make huge pages even
/// then.
inline bool huge_pages_enabled() {
#if defined(__linux__)
  static const bool enabled = [] {
    std::FILE* f = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
    if (!f) return false;
    char text[128] = {};
    const std::size_t n = std::fread(text, 1, sizeof text - 1, f);
    std::fclose(f);
    return n > 0 && std::strstr(text, "[never]") == nullptr;
  }();
#if defined(PR_GET_THP_DISABLE)
  if (enabled && prctl(PR_GET_THP_DISABLE, 0, 0, 0, 0) == 1) return false;
#endif
  return enabled;
#else
  return false;
#endif
}

/// advise_huge_pages() for the `bytes` from `data`, the part of a block about to be filled for the
/// first time: the 2 MB ranges wholly inside it are advised (the advice ends on 2 MB boundaries),
/// and the ranges it begins and ends in part of are made huge pages at once (madvise(MADV_COLLAPSE),
/// which keeps the contents of their other bytes: malloc's header, elements already there, another
/// block of malloc's heap). A range that is not wholly inside one mapping stays as it is (the kernel
/// refuses). Hints only; the contents stay the same but for the first and last 2 MB range's first
/// byte of the block, set to zero (it must hold no value anyone reads).
inline void advise_new_block_huge_pages(void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t H = huge_page_bytes;
  const std::uintptr_t begin = reinterpret_cast<std::uintptr_t>(data), end = begin + bytes;
  const std::uintptr_t first = (begin + H - 1) / H * H, last = end / H * H;  // the whole ranges
  if (!huge_pages_enabled() || first >= last) {
    advise_huge_pages(data, bytes);
    return;
  }
  (void)madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
  // (a range with no page at all is not collapsed: one byte of the block is written first)
  if (begin < first) {
    *static_cast<volatile unsigned char*>(data) = 0;
    (void)madvise(reinterpret_cast<void*>(first - H), H, CMGEOM_MADV_COLLAPSE);
  }
  if (last < end) {
    *reinterpret_cast<volatile unsigned char*>(last) = 0;
    (void)madvise(reinterpret_cast<void*>(last), H, CMGEOM_MADV_COLLAPSE);
  }
#else
  advise_huge_pages(data, bytes);
#endif
}

/// Fresh blocks of at least this many bytes are faulted in on all cores (see the file comment).
constexpr std::size_t parallel_fault_threshold = std::size_t(16) << 20;

/// Writes a zero byte into every page of [p, p + bytes), 2 MB ranges spread over the cores, so that
/// the kernel's zeroing of fresh pages runs in parallel. The memory must be writable and hold no
/// value anyone reads (allocated storage not yet filled).
inline void fault_in_on_all_cores(void* p, std::size_t bytes) {
  constexpr std::size_t range = huge_page_bytes, page = 4096;
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

/// v.reserve(n), with a newly needed block of huge_page_threshold bytes or more sized by
/// capacity_on_whole_huge_pages(), advised for huge pages past v's elements
/// (advise_new_block_huge_pages()) before its first touch, and faulted in on all
/// cores from parallel_fault_threshold bytes (see the file comment).
template <class T, class Allocator>
void reserve_on_huge_pages(std::vector<T, Allocator>& v, std::size_t n) {
  if (n > v.capacity() && n * sizeof(T) >= huge_page_threshold) {
    v.reserve(capacity_on_whole_huge_pages<T>(n));
    const std::size_t fresh = (n - v.size()) * sizeof(T);
    advise_new_block_huge_pages(v.data() + v.size(), fresh);
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
