// Tests of the collapse queue of the Textured_simplification engine (thesis §3.4).
#include "textured_simplification_test_util.h"

// ------------------------------------------------------------------------- queue

TEST(TexturedSimplificationHeap, PopsInKeyThenIdOrderUnderUpdates) {
  // The engine's output depends on the pop order being exactly (key, id): check it against an
  // ordered set under random inserts, key changes, removals and re-insertions with the stored key.
  // Integer keys are exact as floats, and few distinct values force ties broken by id.
  TS::internal::Indexed_heap heap;
  const std::uint32_t n = 5000;
  heap.reset(n);
  std::set<std::pair<double, std::uint32_t>> ref;
  std::vector<double> key(n, 0.0);
  std::vector<bool> queued(n, false);
  std::mt19937 rng(7);
  for (int step = 0; step < 40000; ++step) {
    const std::uint32_t id = rng() % n;
    const int op = int(rng() % 4);
    if (op <= 1) {
      const double k = double(rng() % 50);
      if (queued[id]) ref.erase({key[id], id});
      heap.set(id, k);
      key[id] = k;
      queued[id] = true;
      ref.insert({k, id});
    } else if (op == 2) {
      heap.remove(id);
      if (queued[id]) ref.erase({key[id], id});
      queued[id] = false;
    } else {
      heap.restore(id);  // back with its last key, if it has one and is out
      if (!queued[id] && heap.contains(id)) {
        queued[id] = true;
        ref.insert({key[id], id});
      }
    }
    heap.user(id) = std::uint32_t(step);  // caller data must not disturb the queue
    ASSERT_EQ(heap.size(), ref.size());
    if (step % 7 == 0 && !ref.empty()) {
      // the first ids without popping them: those of the ordered set, in its order
      std::vector<std::uint32_t> first;
      const std::size_t k = std::size_t(rng() % (TS::internal::Indexed_heap::max_first + 1));
      heap.for_each_first(k, [&](std::uint32_t i) { first.push_back(i); });
      ASSERT_EQ(first.size(), (std::min)(k, ref.size()));
      auto it = ref.begin();
      for (std::size_t j = 0; j < first.size(); ++j, ++it) ASSERT_EQ(first[j], it->second);
      ASSERT_EQ(heap.size(), ref.size());
      ASSERT_EQ(heap.top(), ref.begin()->second);
      const std::uint32_t top = heap.pop();
      ASSERT_EQ(top, ref.begin()->second);
      ASSERT_EQ(heap.key(top), key[top]);  // the key survives the pop
      ref.erase(ref.begin());
      queued[top] = false;
    }
  }
  while (!ref.empty()) {
    ASSERT_EQ(heap.pop(), ref.begin()->second);
    ref.erase(ref.begin());
  }
  EXPECT_TRUE(heap.empty());
}
