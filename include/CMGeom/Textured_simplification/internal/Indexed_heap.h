// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// An 8-ary min-heap of (key, id) pairs with a position table indexed by id, so that any entry can
// be updated or removed in place in O(log n). Keys sit next to ids in the heap array (no
// indirection while sifting) and are stored as float: a node is 8 bytes and the eight children of
// a node share one 64-byte cache line, so a sift touches a third of the cache lines of a binary
// heap (heap operations dominated the collapse loop in profiles). The exact double key is kept per
// id; float rounding can only reorder keys equal to 7 significant digits. Ties are broken by id, which makes the collapse order, hence the
// output, deterministic. All storage is allocated once by reset(); no operation allocates.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_INDEXED_HEAP_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_INDEXED_HEAP_H

#include <cstdint>
#include <cstring>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

class Indexed_heap {
public:
  static constexpr std::uint32_t npos = 0xffffffffu;

  void reset(std::size_t max_id) {
    nodes_.clear();
    nodes_.reserve(max_id + 4);
    slot_.assign(max_id, Slot{0.0, npos});
  }
  bool empty() const { return nodes_.empty(); }
  std::size_t size() const { return nodes_.size(); }
  bool contains(std::uint32_t id) const { return slot_[id].pos != npos; }
  /// The key of a queued id (one memory access: keys are mirrored per id).
  double key(std::uint32_t id) const { return slot_[id].key; }
  std::uint32_t top() const { return nodes_[0].id; }
  double top_key() const { return slot_[nodes_[0].id].key; }

  /// Inserts id or changes its key.
  void set(std::uint32_t id, double key) {
    std::uint32_t p = slot_[id].pos;
    slot_[id].key = key;
    if (p == npos) {
      p = static_cast<std::uint32_t>(nodes_.size());
      nodes_.push_back({to_key(key), id});
      slot_[id].pos = p;
      sift_up(p);
    } else {
      const float old = nodes_[p].key;
      const float k = to_key(key);
      nodes_[p].key = k;
      if (less(k, id, old, id)) sift_up(p); else sift_down(p);
    }
  }

  void remove(std::uint32_t id) {
    const std::uint32_t p = slot_[id].pos;
    if (p == npos) return;
    slot_[id].pos = npos;
    const std::uint32_t last = static_cast<std::uint32_t>(nodes_.size() - 1);
    if (p != last) {
      nodes_[p] = nodes_[last];
      slot_[nodes_[p].id].pos = p;
      nodes_.pop_back();
      sift_down(p);
      sift_up(p);
    } else {
      nodes_.pop_back();
    }
  }

  std::uint32_t pop() {
    const std::uint32_t id = nodes_[0].id;
    remove(id);
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
  static bool less(float ka, std::uint32_t ia, float kb, std::uint32_t ib) {
    return ka < kb || (ka == kb && ia < ib);
  }
  bool less(std::uint32_t a, std::uint32_t b) const {
    return less(nodes_[a].key, nodes_[a].id, nodes_[b].key, nodes_[b].id);
  }
  void sift_up(std::uint32_t p) {
    const Node n = nodes_[p];
    while (p > 0) {
      const std::uint32_t parent = (p - 1) / arity;
      if (!less(n.key, n.id, nodes_[parent].key, nodes_[parent].id)) break;
      nodes_[p] = nodes_[parent];
      slot_[nodes_[p].id].pos = p;
      p = parent;
    }
    nodes_[p] = n;
    slot_[n.id].pos = p;
  }
  void sift_down(std::uint32_t p) {
    const std::uint32_t n = static_cast<std::uint32_t>(nodes_.size());
    const Node x = nodes_[p];
    for (;;) {
      const std::uint32_t first = arity * p + 1;
      if (first >= n) break;
      std::uint32_t c = first;
      const std::uint32_t last = first + arity < n ? first + arity : n;
      for (std::uint32_t k = first + 1; k < last; ++k)
        if (less(k, c)) c = k;
      if (!less(nodes_[c].key, nodes_[c].id, x.key, x.id)) break;
      nodes_[p] = nodes_[c];
      slot_[nodes_[p].id].pos = p;
      p = c;
    }
    nodes_[p] = x;
    slot_[x.id].pos = p;
  }

  std::vector<Node> nodes_;
  struct Slot {
    double key;
    std::uint32_t pos;
  };
  std::vector<Slot> slot_;
};

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_INDEXED_HEAP_H
