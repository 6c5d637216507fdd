// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CMGeom/huge_page_new.h, included here as a program includes it (once): blocks of
// huge_page_new_threshold bytes or more come 2 MB-aligned (the default allocator's large blocks
// never are: glibc's start 16 bytes into a page), smaller ones as before, every byte usable; the
// replacements keep operator new's contract (new-handler, std::bad_alloc, nothrow returns null);
// CMGEOM_HUGE_PAGES=0 turns huge pages off for the process, other values are refused.
#include <CMGeom/huge_page_new.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
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

// CMGEOM_HUGE_PAGES=0 (apply_huge_page_setting(), which the cmgeom tool calls first): the process
// runs without transparent huge pages (the kernel's own record, /proc/self/status, says so), the
// library's helpers see them off and large blocks come from malloc() again. Run in a child
// process: the setting cannot be undone.
int thp_enabled_in_status() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("THP_enabled:", 0) == 0) return std::atoi(line.c_str() + 12);
  return -1;
}

TEST(HugePageNew, SettingZeroTurnsHugePagesOffForTheProcess) {
  if (thp_enabled_in_status() < 0) GTEST_SKIP() << "this kernel's /proc/self/status has no THP_enabled line";
  EXPECT_EXIT(
      {
        setenv(CMGeom::internal::huge_page_setting_variable, "0", 1);
        const bool before = thp_enabled_in_status() == 1;
        const bool off = CMGeom::internal::apply_huge_page_setting();
        const bool after = thp_enabled_in_status() == 0;
        std::vector<double> v(3'000'000, 1.5);  // 24 MB: 2 MB-aligned when huge pages are on
        const bool from_malloc = !aligned_2mb(v.data()) && v.back() == 1.5;
        std::exit(before && off && after && from_malloc && !CMGeom::internal::huge_pages_enabled() ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

TEST(HugePageNew, SettingUnsetOrOneChangesNothingAndOtherValuesAreRefused) {
  const char* name = CMGeom::internal::huge_page_setting_variable;
  unsetenv(name);
  EXPECT_FALSE(CMGeom::internal::apply_huge_page_setting());
  setenv(name, "1", 1);
  EXPECT_FALSE(CMGeom::internal::apply_huge_page_setting());
  for (const char* bad : {"yes", "00", "off", "2"}) {
    setenv(name, bad, 1);
    try {
      (void)CMGeom::internal::apply_huge_page_setting();
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string(name) + "=" + bad + ": expected 0"), std::string::npos)
          << e.what();
    }
  }
  unsetenv(name);
  EXPECT_FALSE(CMGeom::internal::huge_page_new_off());
  if (thp_enabled_in_status() >= 0) EXPECT_EQ(thp_enabled_in_status(), 1);
  std::vector<double> v(3'000'000, 1.5);
  EXPECT_TRUE(aligned_2mb(v.data()));
}

}  // namespace
