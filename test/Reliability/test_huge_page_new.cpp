// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CMGeom/huge_page_new.h, included here as a program includes it (once): blocks of
// huge_page_new_threshold bytes or more come 2 MB-aligned (the default allocator's large blocks
// never are: glibc's start 16 bytes into a page), smaller ones as before, every byte usable; the
// replacements keep operator new's contract (new-handler, std::bad_alloc, nothrow returns null).
#include <CMGeom/huge_page_new.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <vector>

namespace {

constexpr std::uintptr_t two_mb = std::uintptr_t(2) << 20;

bool aligned_2mb(const void* p) { return reinterpret_cast<std::uintptr_t>(p) % two_mb == 0; }

TEST(HugePageNew, LargeBlocksAre2MbAlignedAndUsableSmallOnesAsBefore) {
  const std::size_t big = CMGeom::internal::huge_page_new_threshold + 12345;
  for (int k = 0; k < 3; ++k) {
    char* p = new char[big];
    EXPECT_TRUE(aligned_2mb(p));
    std::memset(p, 0x5a, big);
    EXPECT_EQ(p[big - 1], 0x5a);
    delete[] p;
  }
  // a vector's storage, the blocks CGAL's property arrays and the tool's buffers are
  std::vector<double> v(3'000'000, 1.5);  // 24 MB
  EXPECT_TRUE(aligned_2mb(v.data()));
  EXPECT_EQ(v.back(), 1.5);
  // below the threshold: malloc's blocks, 16-byte aligned as operator new promises
  int unaligned = 0;
  std::vector<std::unique_ptr<char[]>> small;
  for (std::size_t n :
       {std::size_t(1), std::size_t(100), std::size_t(1) << 20, CMGeom::internal::huge_page_new_threshold - 1}) {
    small.emplace_back(new char[n]);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.back().get()) % alignof(std::max_align_t), 0u);
    unaligned += aligned_2mb(small.back().get()) ? 0 : 1;
    small.back()[n - 1] = 1;
  }
  EXPECT_GE(unaligned, 3);  // (one might be 2 MB-aligned by chance; not all)
  // zero bytes: a distinct, usable pointer
  void* z = ::operator new(0);
  EXPECT_NE(z, nullptr);
  ::operator delete(z);
}

int handler_calls = 0;
void count_then_give_up() {
  ++handler_calls;
  std::set_new_handler(nullptr);  // the next failure throws
}

TEST(HugePageNew, KeepsTheContractOfOperatorNew) {
  // (volatile: sizes the compiler cannot see, and warn about, when it inlines the calls)
  volatile std::size_t absurd_size = std::numeric_limits<std::size_t>::max() / 2;
  volatile std::size_t top_size = std::numeric_limits<std::size_t>::max() - 10;
  const std::size_t absurd = absurd_size, top = top_size;
  EXPECT_THROW((void)::operator new(absurd), std::bad_alloc);
  EXPECT_EQ(::operator new(absurd, std::nothrow), nullptr);
  EXPECT_EQ(::operator new[](absurd, std::nothrow), nullptr);
  // the new-handler is called while the block cannot be had; without one, std::bad_alloc
  handler_calls = 0;
  std::set_new_handler(count_then_give_up);
  EXPECT_THROW((void)::operator new[](absurd), std::bad_alloc);
  EXPECT_EQ(handler_calls, 1);
  EXPECT_EQ(std::get_new_handler(), nullptr);
  // rounding a size near the top of size_t up to 2 MB must not wrap around to a small block
  EXPECT_EQ(::operator new(top, std::nothrow), nullptr);
}

}  // namespace
