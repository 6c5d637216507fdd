// Tests of the output textures of Textured_simplification: the triangle rasterizer and the
// generated texture's gutters, filled ring by ring.
#include "textured_part_test_util.h"

namespace {

// rasterize_triangle draws exactly the texels whose centre passes the three edge tests (8
// sub-texel bits, top-left rule), each once: against a reference that tests every texel of the
// image, on random triangles of all shapes (slivers, both orientations, partly off the image,
// corners on the sub-texel grid so that centres fall on edges).
TEST(TexturedSimplification, RasterizerCoversExactlyTheTexelsWhoseCentrePassesTheEdgeTests) {
  const int W = 37, H = 29;
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> coord(-8.0, 45.0);
  std::uniform_int_distribution<int> grid(-4, 44);
  std::size_t drawn = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::array<UV2, 3> t;
    for (int c = 0; c < 3; ++c) {
      if (trial % 3 == 0)
        t[c] = {{grid(rng) + 0.5, grid(rng) + 0.5}};  // corners on texel centres
      else
        t[c] = {{coord(rng), coord(rng)}};
    }
    if (trial % 5 == 0) t[2] = {{t[0][0] + 1e-3 * (t[1][0] - t[0][0]) + 0.01, t[0][1] + 1e-3 * (t[1][1] - t[0][1])}};
    std::vector<int> count(std::size_t(W) * H, 0);
    TS::rasterize_triangle(t, W, H, [&](int x, int y) {
      ASSERT_TRUE(x >= 0 && y >= 0 && x < W && y < H);
      ++count[std::size_t(y) * W + x];
    });
    // reference: snap to 1/256, orient counter-clockwise, test every texel centre
    long long X[3], Y[3];
    for (int c = 0; c < 3; ++c) {
      X[c] = std::llround(t[c][0] * 256.0);
      Y[c] = std::llround(t[c][1] * 256.0);
    }
    const long long area = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    if (area < 0) {
      std::swap(X[1], X[2]);
      std::swap(Y[1], Y[2]);
    }
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        bool inside = area != 0;
        for (int i = 0; i < 3 && inside; ++i) {
          const int j = (i + 1) % 3;
          const long long dx = X[j] - X[i], dy = Y[j] - Y[i];
          const long long px = 256LL * x + 128, py = 256LL * y + 128;
          const long long e = dx * (py - Y[i]) - dy * (px - X[i]);
          const bool top_left = (dy == 0 && dx < 0) || dy < 0;
          inside = top_left ? e >= 0 : e > 0;
        }
        ASSERT_EQ(count[std::size_t(y) * W + x], inside ? 1 : 0)
            << "trial " << trial << ", texel (" << x << ", " << y << ")";
        drawn += inside;
      }
  }
  EXPECT_GT(drawn, 10000u);
}

// The reference gutter fill: rings grown by rescanning the whole W x H image (C channels in `acc`,
// rows upwards) until none grows; each texel not in `filled` gets the mean of its 8-neighbours filled
// by an earlier ring. Returns the number of scans.
int grow_rings_by_rescanning(int W, int H, int C, std::vector<int>& filled, std::vector<float>& acc) {
  int rings = 0;
  for (bool grew = true; grew; ++rings) {
    grew = false;
    std::vector<int> next = filled;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = std::size_t(y) * W + x;
        if (filled[i]) continue;
        float sum[4] = {0, 0, 0, 0};
        int cnt = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= W || qy >= H || !filled[std::size_t(qy) * W + qx]) continue;
            for (int c = 0; c < C; ++c) sum[c] += acc[(std::size_t(qy) * W + qx) * C + c];
            ++cnt;
          }
        if (cnt == 0) continue;
        for (int c = 0; c < C; ++c) acc[i * C + c] = sum[c] / float(cnt);
        next[i] = 1;
        grew = true;
      }
    filled.swap(next);
  }
  return rings;
}

// generate_texture: covered texels hold the original looked up through the index texture, and
// the gutters are filled ring by ring, each texel with the mean of its 8-neighbours filled by an
// earlier ring. The reference grows the rings by scanning the whole image once per ring.
TEST(TexturedSimplification, GeneratedTextureDilatesRingByRing) {
  const int W = 23, H = 17;
  const std::vector<std::array<UV2, 3>> layout_tris = {{{{{0.0, 0.0}}, {{1.0, 0.0}}, {{0.0, 1.0}}}}};
  TS::Texture_domain dom;
  dom.width = W;
  dom.height = H;
  const TS::Index_texture it(dom, layout_tris, {0});
  CMGeom::Image original(W, H, 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) original.set_value(x, y, c, float((7 * x + 13 * y + 29 * c) % 256) / 255.f);
  // two small triangles far apart, so rings from both meet
  const std::vector<std::array<UV2, 3>> final_tris = {{{{{0.05, 0.1}}, {{0.3, 0.1}}, {{0.1, 0.35}}}},
                                                      {{{{0.6, 0.7}}, {{0.8, 0.65}}, {{0.75, 0.9}}}}};
  const CMGeom::Image out = TS::generate_texture(it, original, final_tris);
  ASSERT_EQ(out.width(), W);
  ASSERT_EQ(out.height(), H);
  // reference, in index-texture rows (row 0 at the bottom)
  std::vector<float> acc(std::size_t(W) * H * 3, 0.f);
  std::vector<int> filled(std::size_t(W) * H, 0);
  std::size_t covered = 0;
  for (const auto& tri : final_tris) {
    std::array<UV2, 3> t;
    for (int c = 0; c < 3; ++c) t[c] = dom.to_texel(tri[c]);
    TS::rasterize_triangle(t, W, H, [&](int x, int y) {
      const std::size_t i = std::size_t(y) * W + x;
      if (filled[i]) return;
      float v[4];
      TS::sample_original(it, original, it.at(x, y)[0], it.at(x, y)[1], v);
      for (int c = 0; c < 3; ++c) acc[i * 3 + c] = v[c];
      filled[i] = 1;
      ++covered;
    });
  }
  ASSERT_GT(covered, 4u);
  ASSERT_LT(covered, std::size_t(W) * H / 4);
  const int rings = grow_rings_by_rescanning(W, H, 3, filled, acc);
  EXPECT_GT(rings, 5);
  CMGeom::Image expected(W, H, 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      ASSERT_TRUE(filled[std::size_t(y) * W + x]) << "texel (" << x << ", " << y << ") never reached";
      for (int c = 0; c < 3; ++c) expected.set_value(x, H - 1 - y, c, acc[(std::size_t(y) * W + x) * 3 + c]);
    }
  EXPECT_TRUE(out == expected);
}

// internal::dilate_into_image's distances (a separable chessboard distance transform, on all
// cores) and rings, against rings grown by rescanning the whole image: random sparse coverage
// (columns and rows with none, one covered texel, a single row or column, nothing covered), each
// texel's distance checked against the brute-force minimum and the image against the reference.
TEST(TexturedSimplification, GutterDistancesAndRingsMatchABruteForceReference) {
  std::mt19937 rng(2026);
  struct Case {
    int W, H;
    double density;
  };
  for (const Case& k : {Case{301, 187, 0.0015}, Case{64, 400, 0.0005}, Case{517, 3, 0.01}, Case{1, 90, 0.05},
                        Case{90, 1, 0.05}, Case{40, 30, 0.0}, Case{200, 150, -1.0}}) {
    const int W = k.W, H = k.H, C = 3;
    const std::size_t n = std::size_t(W) * H;
    std::vector<std::uint32_t> dist(n, 0xffffffffu);
    std::vector<float> acc(n * C, 0.f);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::size_t covered = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (u(rng) < k.density) dist[i] = 0;
    if (k.density < 0) dist[std::size_t(H / 2) * W + std::size_t(W / 3)] = 0;  // one texel
    for (std::size_t i = 0; i < n; ++i)
      if (dist[i] == 0) {
        ++covered;
        for (int c = 0; c < C; ++c) acc[i * C + c] = float(u(rng));
      }
    // brute force: chessboard distance to the nearest covered texel
    std::vector<std::uint32_t> expected_dist(n, 0xffffffffu);
    std::vector<std::pair<int, int>> seeds;
    for (std::size_t i = 0; i < n; ++i)
      if (dist[i] == 0) seeds.emplace_back(int(i % std::size_t(W)), int(i / std::size_t(W)));
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        for (const auto& [qx, qy] : seeds) {
          const std::uint32_t d = std::uint32_t((std::max)(std::abs(qx - x), std::abs(qy - y)));
          std::uint32_t& e = expected_dist[std::size_t(y) * W + x];
          e = (std::min)(e, d);
        }
    // reference rings (scans until none grows)
    std::vector<float> ref = acc;
    std::vector<int> filled(n, 0);
    for (std::size_t i = 0; i < n; ++i) filled[i] = dist[i] == 0;
    grow_rings_by_rescanning(W, H, C, filled, ref);
    CMGeom::Image expected(W, H, C, CMGeom::Image::Format::UInt8);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        for (int c = 0; c < C; ++c) expected.set_value(x, H - 1 - y, c, ref[(std::size_t(y) * W + x) * C + c]);
    const CMGeom::Image out = TS::internal::dilate_into_image(W, H, C, dist, acc);
    SCOPED_TRACE(std::to_string(W) + " x " + std::to_string(H) + ", " + std::to_string(covered) + " covered");
    EXPECT_TRUE(dist == expected_dist);
    EXPECT_TRUE(out == expected);
  }
}

// internal::grow_rings (the gutters of the atlases: every chart's texels grow ring by ring into the
// free texels, the first to reach a texel taking it) against a serial reference written from its
// contract: the first front is the labelled texels next to an open one in texel order, each ring
// visits its front in order and each front texel its neighbours left, right, below, above. On
// random labellings of grids taller than one band of the parallel first scan, whole and partial
// rows labelled, texel by texel: the owner, and the neighbour each texel was taken from (the order
// decides which texel's colour a gutter texel copies, even between texels of one owner). Then the
// growth's own property: a texel is taken exactly when its 4-neighbour distance to the labelled
// texels is 1 to `rings`, by the owner of a labelled texel at that distance.
TEST(TexturedSimplification, GrowRingsMatchesASerialReferenceAndTakesTheTexelsWithinItsRings) {
  std::mt19937 rng(777);
  const int sizes[][2] = {{1, 1}, {5, 1}, {1, 200}, {37, 65}, {97, 150}, {256, 129}};
  int tried = 0;
  for (const auto& size : sizes)
    for (double density : {0.0, 0.002, 0.03, 0.3, 1.0})
      for (int rings : {1, 3, 8}) {
        const int W = size[0], H = size[1];
        const std::size_t n = std::size_t(W) * std::size_t(H);
        std::vector<int> start(n, -1);
        std::bernoulli_distribution labelled(density);
        for (std::size_t i = 0; i < n; ++i)
          if (labelled(rng)) start[i] = int(rng() % 7);
        if (H > 3)
          for (int x = 0; x < W; x += 2)
            start[std::size_t(H / 2) * std::size_t(W) + std::size_t(x)] = 9;  // part of a row
        // the library's growth
        std::vector<int> got = start;
        std::vector<int> ring_of(n, 0);
        std::vector<std::size_t> got_from(n, n);  // the texel each was taken from (what a colour is copied from)
        int taken = 0;
        TS::internal::grow_rings(
            W, H, rings, [&](std::size_t at) { return got[at] != -1; }, [&](std::size_t at) { return got[at] == -1; },
            [&](const TS::internal::Grid_texel& to, const TS::internal::Grid_texel& from) {
              EXPECT_EQ(to.at, std::size_t(to.y) * std::size_t(W) + std::size_t(to.x));
              EXPECT_EQ(from.at, std::size_t(from.y) * std::size_t(W) + std::size_t(from.x));
              EXPECT_EQ(std::abs(to.x - from.x) + std::abs(to.y - from.y), 1);
              got[to.at] = got[from.at];
              got_from[to.at] = from.at;
              ring_of[to.at] = ring_of[from.at] + 1;
              ++taken;
              return true;
            });
        // the reference, serial, with divisions
        std::vector<int> ref = start;
        std::vector<std::size_t> ref_from(n, n);
        std::vector<std::size_t> front, next;
        const auto neighbours = [&](std::size_t at) {
          std::vector<std::size_t> out;
          const std::size_t x = at % std::size_t(W);
          if (x > 0) out.push_back(at - 1);
          if (x + 1 < std::size_t(W)) out.push_back(at + 1);
          if (at >= std::size_t(W)) out.push_back(at - std::size_t(W));
          if (at + std::size_t(W) < n) out.push_back(at + std::size_t(W));
          return out;
        };
        for (std::size_t at = 0; at < n; ++at) {
          if (ref[at] == -1) continue;
          bool border = false;
          for (std::size_t b : neighbours(at)) border = border || ref[b] == -1;
          if (border) front.push_back(at);
        }
        for (int r = 0; r < rings && !front.empty(); ++r) {
          next.clear();
          for (std::size_t at : front)
            for (std::size_t b : neighbours(at))
              if (ref[b] == -1) {
                ref[b] = ref[at];
                ref_from[b] = at;
                next.push_back(b);
              }
          front.swap(next);
        }
        SCOPED_TRACE(std::to_string(W) + " x " + std::to_string(H) + ", density " + std::to_string(density) +
                     ", rings " + std::to_string(rings));
        ASSERT_TRUE(got == ref);
        ASSERT_TRUE(got_from == ref_from);
        // distances to the labelled texels, to all and to those of each owner (breadth first,
        // independent of the growth's order)
        const auto distances = [&](int owner) {  // (owner -1: any)
          std::vector<int> dist(n, -1);
          std::vector<std::size_t> queue;
          for (std::size_t at = 0; at < n; ++at)
            if (start[at] != -1 && (owner == -1 || start[at] == owner)) {
              dist[at] = 0;
              queue.push_back(at);
            }
          for (std::size_t q = 0; q < queue.size(); ++q)
            for (std::size_t b : neighbours(queue[q]))
              if (dist[b] == -1) {
                dist[b] = dist[queue[q]] + 1;
                queue.push_back(b);
              }
          return dist;
        };
        const std::vector<int> dist = distances(-1);
        std::map<int, std::vector<int>> dist_to_owner;
        for (int owner : {0, 1, 2, 3, 4, 5, 6, 9}) dist_to_owner[owner] = distances(owner);
        int expected_taken = 0;
        for (std::size_t at = 0; at < n; ++at) {
          const bool within = dist[at] >= 1 && dist[at] <= rings;
          expected_taken += within;
          if (start[at] != -1) continue;
          ASSERT_EQ(got[at] != -1, within) << "texel " << at;
          if (!within) continue;
          ASSERT_EQ(ring_of[at], dist[at]) << "texel " << at;
          ASSERT_EQ(dist_to_owner.at(got[at])[at], dist[at]) << "texel " << at;  // an owner at that distance
        }
        EXPECT_EQ(taken, expected_taken);
        tried += taken > 0;
      }
  EXPECT_GT(tried, 40);
}

}  // namespace
