// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// An 8-ary min-heap of (key, id) pairs with a position table indexed by id, so that any entry can
// be updated or removed in place in O(log n). Keys sit next to ids in the heap array (no
// indirection while sifting) and are stored as float: a node is 8 bytes and the eight children of
// a node fill exactly one 64-byte cache line (the array is offset so that every group of siblings
// starts on a line boundary), so a sift touches a third of the cache lines of a binary heap (heap
// operations dominated the collapse loop in profiles). The exact double key is kept per id, in a
// 16-byte slot that also holds the id's heap position and a 32-bit field owned by the caller
// (the engine keeps its per-edge flags there: one record, one cache miss per edge); keys and that
// field survive remove(). Float rounding can only reorder keys equal to 7 significant digits.
// Ties are broken by id, which makes the order of pops, hence the output, deterministic (and
// independent of the heap's internal layout: (key, id) is a strict total order). All storage is
// allocated once by reset(); no operation allocates.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_INDEXED_HEAP_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_INDEXED_HEAP_H

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

class Indexed_heap {
public:
  static constexpr std::uint32_t npos = 0xffffffffu;

  Indexed_heap() = default;
  Indexed_heap(const Indexed_heap&) = delete;  // base_ points into storage_
  Indexed_heap& operator=(const Indexed_heap&) = delete;

  void reset(std::size_t max_id) {
    // one spare line: base_ is placed so that &base_[1] (the root's children) is 64-byte aligned
    storage_.assign(max_id + 16, Node{0.0f, 0});
    const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(storage_.data() + 1);
    const std::size_t shift = ((64 - a % 64) % 64) / sizeof(Node);
    base_ = storage_.data() + shift;
    size_ = 0;
    slot_.assign(max_id, Slot{0.0, npos, 0u});
  }
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  bool contains(std::uint32_t id) const { return slot_[id].pos != npos; }
  /// The key of id (one memory access: keys are mirrored per id); kept after remove().
  double key(std::uint32_t id) const { return slot_[id].key; }
  /// A 32-bit field per id for the caller's use, in the same 16-byte record as the key.
  std::uint32_t& user(std::uint32_t id) { return slot_[id].user; }
  std::uint32_t user(std::uint32_t id) const { return slot_[id].user; }
  std::uint32_t top() const { return base_[0].id; }
  double top_key() const { return slot_[base_[0].id].key; }
  /// Hints the processor to load id's record (no effect on the heap).
  void prefetch(std::uint32_t id) const {
#if defined(__GNUC__)
    __builtin_prefetch(&slot_[id]);
#else
    (void)id;
#endif
  }

  /// Hints the processor to load the heap node of id, if queued (no effect on the heap).
  void prefetch_node(std::uint32_t id) const {
#if defined(__GNUC__)
    const std::uint32_t p = slot_[id].pos;
    if (p != npos) __builtin_prefetch(&base_[p]);
#else
    (void)id;
#endif
  }

  /// Inserts id or changes its key.
  void set(std::uint32_t id, double key) {
    Slot& s = slot_[id];
    std::uint32_t p = s.pos;
    s.key = key;
    if (p == npos) {
      p = static_cast<std::uint32_t>(size_++);
      base_[p] = Node{to_key(key), id};
      s.pos = p;
      sift_up(p);
    } else {
      const float old = base_[p].key;
      const float k = to_key(key);
      if (k == old) return;  // same float key, same id: the node's place is unchanged
      base_[p].key = k;
      if (k < old)
        sift_up(p);
      else
        sift_down(p);
    }
  }

  /// Re-inserts id with its stored key (no effect if it is queued).
  void restore(std::uint32_t id) {
    if (slot_[id].pos == npos) set(id, slot_[id].key);
  }

  void remove(std::uint32_t id) {
    const std::uint32_t p = slot_[id].pos;
    if (p == npos) return;
    slot_[id].pos = npos;
    const std::uint32_t last = static_cast<std::uint32_t>(--size_);
    if (p != last) {
      base_[p] = base_[last];
      slot_[base_[p].id].pos = p;
      sift_down(p);
      sift_up(p);
    }
  }

  /// Calls f(id) for the (at most) k queued ids that pop() would give first, in that order,
  /// leaving the heap as it is: a best-first walk down from the root (k <= max_first).
  static constexpr std::size_t max_first = 32;
  template <class F>
  void for_each_first(std::size_t k, F&& f) const {
    if (k > max_first) k = max_first;
    // the positions whose parent was given, ordered by their node (a heap of candidates: each
    // node given adds its up to eight children, so 1 + 7k entries suffice)
    std::uint32_t open[1 + 7 * max_first];
    std::size_t n = 0;
    auto later = [this](std::uint32_t a, std::uint32_t b) {
      return less(base_[b].key, base_[b].id, base_[a].key, base_[a].id);
    };
    if (size_ > 0) open[n++] = 0;
    for (std::size_t given = 0; given < k && n > 0; ++given) {
      std::pop_heap(open, open + n, later);
      const std::uint32_t p = open[--n];
      f(base_[p].id);
      const std::size_t first = arity * std::size_t(p) + 1;
      for (std::size_t c = first; c < first + arity && c < size_; ++c) {
        open[n++] = static_cast<std::uint32_t>(c);
        std::push_heap(open, open + n, later);
      }
    }
  }

  std::uint32_t pop() {
    const std::uint32_t id = base_[0].id;
    slot_[id].pos = npos;
    const std::uint32_t last = static_cast<std::uint32_t>(--size_);
    if (last != 0) {
      base_[0] = base_[last];
      slot_[base_[0].id].pos = 0;
      sift_down(0);
    }
    return id;
  }

private:
  // float keys, rounded upward so that a key never sorts before a smaller double; huge values
  // saturate to +inf (still ordered by id)
  static float to_key(double k) {
    float f = static_cast<float>(k);
    if (static_cast<double>(f) < k) {  // one ulp up, by bits (std::nextafter is a library call)
      std::uint32_t b;
      std::memcpy(&b, &f, 4);
      b = f >= 0 ? b + 1 : b - 1;
      std::memcpy(&f, &b, 4);
    }
    return f;
  }
  static constexpr std::uint32_t arity = 8;
  struct Node {
    float key;
    std::uint32_t id;
  };
  static bool less(float ka, std::uint32_t ia, float kb, std::uint32_t ib) { return ka < kb || (ka == kb && ia < ib); }
  void sift_up(std::uint32_t p) {
    const Node n = base_[p];
    while (p > 0) {
      const std::uint32_t parent = (p - 1) / arity;
      if (!less(n.key, n.id, base_[parent].key, base_[parent].id)) break;
      base_[p] = base_[parent];
      slot_[base_[p].id].pos = p;
      p = parent;
    }
    base_[p] = n;
    slot_[n.id].pos = p;
  }
  void sift_down(std::uint32_t p) {
    const std::uint32_t n = static_cast<std::uint32_t>(size_);
    const Node x = base_[p];
    for (;;) {
      const std::uint32_t first = arity * p + 1;
      if (first >= n) break;
      std::uint32_t c = first;
      const std::uint32_t last = first + arity < n ? first + arity : n;
      for (std::uint32_t k = first + 1; k < last; ++k)
        if (less(base_[k].key, base_[k].id, base_[c].key, base_[c].id)) c = k;
      if (!less(base_[c].key, base_[c].id, x.key, x.id)) break;
      base_[p] = base_[c];
      slot_[base_[p].id].pos = p;
      p = c;
    }
    base_[p] = x;
    slot_[x.id].pos = p;
  }

  std::vector<Node> storage_;
  Node* base_ = nullptr;
  std::size_t size_ = 0;
  struct Slot {
    double key;
    std::uint32_t pos;
    std::uint32_t user;
  };
  std::vector<Slot> slot_;
};

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_INDEXED_HEAP_H
