// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Deterministic input mutations for the plain (non-libFuzzer) smoke runs of the CMGeom fuzz
// targets (test/Mesh_IO/fuzz_readers.cpp, test/Reliability/fuzz_model_readers.cpp).
//
// An input is a format byte followed by file content. mutate() applies 1 to 4 rounds of: bit flip,
// byte erase/insert, truncation, digit or number replacement (0, -1, 2^32-1, 10^11, nan, inf,
// 1e308, -0), line duplication/removal, format-byte change, splice with another seed, overwrite
// with interesting bytes, and, for binary formats (`binary_integers`), overwrite of an aligned
// 4- or 8-byte little-endian integer with an extreme value (huge declared counts, indices just
// past the end). With `binary_integers` false the random sequence is the one the Mesh_IO smoke run
// has always used, so its inputs do not change.
//
// Complexity: O(input size) per mutation.
#ifndef CMGEOM_TEST_RELIABILITY_FUZZ_MUTATE_H
#define CMGEOM_TEST_RELIABILITY_FUZZ_MUTATE_H

#include <algorithm>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace cmgeom_fuzz {

using Bytes = std::vector<std::uint8_t>;

inline Bytes mutate(Bytes s, std::mt19937_64& rng, const std::vector<Bytes>& pool, bool binary_integers = false) {
  auto pick = [&](std::size_t n) { return n ? std::size_t(rng() % n) : 0; };
  const int rounds = 1 + int(rng() % 4);
  for (int r = 0; r < rounds; ++r) {
    switch (rng() % (binary_integers ? 10 : 9)) {
      case 0:
        if (s.size() > 1) s[1 + pick(s.size() - 1)] ^= std::uint8_t(1u << (rng() % 8));
        break;
      case 1:
        if (s.size() > 1) s.erase(s.begin() + std::ptrdiff_t(1 + pick(s.size() - 1)));
        break;
      case 2:
        s.insert(s.begin() + std::ptrdiff_t(1 + pick(s.size())), std::uint8_t(rng()));
        break;
      case 3:
        if (s.size() > 2) s.resize(1 + pick(s.size() - 1));
        break;   // truncation
      case 4: {  // change a digit, or a whole number into a huge or negative one
        std::vector<std::size_t> digits;
        for (std::size_t i = 1; i < s.size(); ++i)
          if (s[i] >= '0' && s[i] <= '9') digits.push_back(i);
        if (digits.empty()) break;
        const std::size_t at = digits[pick(digits.size())];
        static const char* const repl[] = {"0", "-1", "4294967295", "99999999999", "nan", "inf", "1e308", "-0"};
        const std::string w = repl[rng() % 8];
        s.erase(s.begin() + std::ptrdiff_t(at));
        s.insert(s.begin() + std::ptrdiff_t(at), w.begin(), w.end());
        break;
      }
      case 5: {  // duplicate or drop a line
        std::vector<std::size_t> nl;
        for (std::size_t i = 1; i < s.size(); ++i)
          if (s[i] == '\n') nl.push_back(i);
        if (nl.size() < 2) break;
        const std::size_t k = pick(nl.size() - 1);
        Bytes line(s.begin() + std::ptrdiff_t(nl[k] + 1), s.begin() + std::ptrdiff_t(nl[k + 1] + 1));
        if (rng() % 2)
          s.insert(s.begin() + std::ptrdiff_t(nl[k] + 1), line.begin(), line.end());
        else
          s.erase(s.begin() + std::ptrdiff_t(nl[k] + 1), s.begin() + std::ptrdiff_t(nl[k + 1] + 1));
        break;
      }
      case 6:
        if (!s.empty()) s[0] = std::uint8_t(rng());
        break;   // same bytes, another reader
      case 7: {  // splice with another seed
        const auto& o = pool[pick(pool.size())];
        if (o.size() < 2 || s.size() < 2) break;
        const std::size_t a = 1 + pick(s.size() - 1), b = 1 + pick(o.size() - 1);
        s.resize(a);
        s.insert(s.end(), o.begin() + std::ptrdiff_t(b), o.end());
        break;
      }
      case 8: {  // overwrite a few bytes with interesting values
        if (s.size() < 5) break;
        static const std::uint8_t vals[] = {0, 0xff, 0x7f, 0x80, '/', ' ', '\n', '-'};
        const std::size_t at = 1 + pick(s.size() - 1);
        for (std::size_t i = at; i < std::min(s.size(), at + 4); ++i) s[i] = vals[rng() % 8];
        break;
      }
      default: {  // an aligned little-endian integer (of the content) becomes an extreme value
        const std::size_t width = rng() % 2 ? 8 : 4;
        if (s.size() < 1 + width) break;
        const std::size_t at = 1 + pick((s.size() - 1) / width) * width;
        if (at + width > s.size()) break;
        static const std::uint64_t vals[] = {0,
                                             1,
                                             0xffffffffull,
                                             0x7fffffffull,
                                             0x80000000ull,
                                             0xffffffffffffffffull,
                                             0x100000000ull,
                                             0x0fffffffffffffffull};
        std::uint64_t v = vals[rng() % 8];
        if (rng() % 4 == 0) {  // or one more than the value there (an index just past the end)
          v = 0;
          for (std::size_t i = 0; i < width; ++i) v |= std::uint64_t(s[at + i]) << (8 * i);
          ++v;
        }
        for (std::size_t i = 0; i < width; ++i) s[at + i] = std::uint8_t(v >> (8 * i));
      }
    }
  }
  return s;
}

}  // namespace cmgeom_fuzz

#endif  // CMGEOM_TEST_RELIABILITY_FUZZ_MUTATE_H
