// Tests of the reconstruction of a Compact Model: analytic reproduction, crack-free and shared
// vertices, parallel == serial, progress hook, along-normal rows, reused buffers (every element
// written), streamed connectivity, huge-page resizes, error decreasing with the level.
#include "compact_model_test_util.h"

#include <CMGeom/Mesh_IO/Image.h>
#include <CMGeom/internal/huge_pages.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace {

// sphere_model() with texture coordinates: every face maps to a triangle of [0, 1]², five shapes.
Compact_model textured_sphere_model() {
  Compact_model textured = sphere_model();
  textured.uvs.resize(textured.faces.size());
  for (std::size_t f = 0; f < textured.faces.size(); ++f)
    textured.uvs[f] = {{{0.f, 0.f}, {1.f, float(f % 5) / 5.f}, {0.5f, 1.f}}};
  return textured;
}

// ------------------------------------------------------------------ reconstruction
TEST(CompactModelReconstruction, ParaboloidReproducedAtEveryLevel) {
  const double a = 0.6, b = 0.2, c = -0.4, d = 0.1, e = -0.2;
  auto g = [&](double x, double y) { return a * x * x + b * x * y + c * y * y + d * x + e * y; };
  const Compact_model m = height_field_model(a, b, c, d, e, 4);
  for (Projection proj : {Projection::along_normal, Projection::closest_point}) {
    Reconstruction_options o;
    o.projection = proj;
    for (int level = 0; level <= 4; ++level) {
      const Reconstruction r = reconstruct_regular(m, level, o);
      EXPECT_EQ(r.triangles.size(), m.faces.size() << (2 * level));
      double err = 0;
      for (const Vec3& p : r.points) err = std::max(err, std::abs(p.z - g(p.x, p.y)));
      EXPECT_LT(err, 1e-9) << "level " << level;
    }
  }
}

TEST(CompactModelReconstruction, ParabolicCylinderReproducedAdaptively) {
  auto g = [](double x, double) { return 0.8 * x * x - 0.3 * x; };
  const Compact_model m = height_field_model(0.8, 0, 0, -0.3, 0, 3);
  const Reconstruction r = reconstruct_adaptive(m, Region_of_interest_criterion{Vec3(0.5, 0.5, 0.), 0.6}, 4);
  double err = 0;
  for (const Vec3& p : r.points) err = std::max(err, std::abs(p.z - g(p.x, p.y)));
  EXPECT_LT(err, 1e-9);
  EXPECT_GT(r.points.size(), m.vertices.size());
}

TEST(CompactModelReconstruction, RegularIsCrackFreeWithSharedVertices) {
  const Compact_model& m = sphere_model();
  for (int level = 0; level <= 3; ++level) {
    const Reconstruction r = reconstruct_regular(m, level);
    std::string why;
    EXPECT_TRUE(is_closed_and_shared(r, &why)) << "level " << level << ": " << why;
    // Euler characteristic of a sphere.
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (const auto& t : r.triangles)
      for (int k = 0; k < 3; ++k) edges.insert({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
    EXPECT_EQ(long(r.points.size()) - long(edges.size()) + long(r.triangles.size()), 2);
    const Surface_mesh mesh = to_surface_mesh(r);
    EXPECT_TRUE(CGAL::is_closed(mesh));
    EXPECT_TRUE(mesh.is_valid(false));
  }
}

TEST(CompactModelReconstruction, AdaptiveIsCrackFreeForEveryCriterion) {
  const Compact_model& m = sphere_model();
  std::string why;
  const Reconstruction len = reconstruct_adaptive(m, Edge_length_criterion{0.08}, 5);
  EXPECT_TRUE(is_closed_and_shared(len, &why)) << why;
  const Reconstruction roi = reconstruct_adaptive(m, Region_of_interest_criterion{Vec3(0, 0, 1), 0.5}, 4);
  EXPECT_TRUE(is_closed_and_shared(roi, &why)) << why;
  const Reconstruction sil = reconstruct_adaptive(m, Silhouette_criterion{Vec3(0, 0, 6), 0.25}, 4);
  EXPECT_TRUE(is_closed_and_shared(sil, &why)) << why;
  // Adaptivity: the ROI refines near its centre only.
  const Reconstruction full = reconstruct_regular(m, 4);
  EXPECT_LT(roi.triangles.size(), full.triangles.size());
  EXPECT_GT(roi.triangles.size(), m.faces.size());
  // Edge length: every output edge respects the bound up to the deepest level allowed.
  double longest = 0;
  for (const auto& t : len.triangles)
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, CMGeom::CM::internal::length(len.points[t[k]] - len.points[t[(k + 1) % 3]]));
  EXPECT_LE(longest, 0.08 * 1.0001);
  // Always_split with level L is the regular subdivision (same triangle count, same points set).
  const Reconstruction always = reconstruct_adaptive(m, Always_split(), 2);
  const Reconstruction reg = reconstruct_regular(m, 2);
  EXPECT_EQ(always.triangles.size(), reg.triangles.size());
  EXPECT_EQ(always.points.size(), reg.points.size());
}

TEST(CompactModelReconstruction, ParallelEqualsSerial) {
  const Compact_model& m = sphere_model();
  Reconstruction_options par, ser;
  ser.parallel = false;
  EXPECT_TRUE(same(reconstruct_regular(m, 3, par), reconstruct_regular(m, 3, ser)));
  EXPECT_TRUE(same(reconstruct_adaptive(m, Edge_length_criterion{0.05}, 5, par),
                   reconstruct_adaptive(m, Edge_length_criterion{0.05}, 5, ser)));
  par.projection = ser.projection = Projection::along_normal;
  EXPECT_TRUE(same(reconstruct_regular(m, 2, par), reconstruct_regular(m, 2, ser)));
}

// The progress hook (CMGeom/Progress.h) of the reconstructions: fractions never decreasing and
// ending at 1, every call from the calling thread although the work runs on TBB workers, far
// fewer calls than points, and the same bits as without the hook.
TEST(CompactModelReconstruction, ProgressHookReportsFromTheCallingThreadAndChangesNothing) {
  const Compact_model& m = sphere_model();
  for (const bool parallel : {true, false}) {
    Reconstruction_options plain, hooked;
    plain.parallel = hooked.parallel = parallel;
    Progress_record regular, adaptive;
    hooked.progress = regular.hook();
    const Reconstruction r = reconstruct_regular(m, 5, hooked);
    EXPECT_TRUE(same(r, reconstruct_regular(m, 5, plain)));
    regular.check(2 * 260);  // two phases: edges, faces
    EXPECT_LT(regular.fractions.size(), r.points.size() / 100);
    hooked.progress = adaptive.hook();
    EXPECT_TRUE(same(reconstruct_adaptive(m, Edge_length_criterion{0.02}, 6, hooked),
                     reconstruct_adaptive(m, Edge_length_criterion{0.02}, 6, plain)));
    adaptive.check(3 * 260);  // edges, faces, assembly
  }
}

// Points and normals of a reconstruction, sorted (regular and adaptive outputs list the same
// points in different orders).
std::vector<std::array<double, 6>> sorted_samples(const Reconstruction& r) {
  std::vector<std::array<double, 6>> v;
  for (std::size_t i = 0; i < r.points.size(); ++i)
    v.push_back({r.points[i].x, r.points[i].y, r.points[i].z, r.normals[i].x, r.normals[i].y, r.normals[i].z});
  std::sort(v.begin(), v.end());
  return v;
}

// Along N, regular reconstruction evaluates interior points row by row, while a reconstruction
// with vertex maps goes point by point through interior(); with identity maps both must give the
// same bits (points and normals).
TEST(CompactModelReconstruction, IdentityVertexMapsAlongNormalGiveThePlainReconstruction) {
  const Compact_model& m = sphere_model();
  const std::vector<CMGeom::CM::Vertex_affine_map> maps(m.vertices.size());
  Reconstruction_options plain, mapped;
  plain.projection = mapped.projection = Projection::along_normal;
  mapped.vertex_maps = &maps;
  for (int level : {2, 4})
    EXPECT_TRUE(same(reconstruct_regular(m, level, plain), reconstruct_regular(m, level, mapped)));
}

// The same with every kind of local surface: the row kernel evaluates quadrics and cones itself
// (several points at once) and cubics through the traits, and must still give interior()'s bits,
// also where a cone's quadric form is negative (derivatives NaN: the normal falls back to N) and
// on rows whose length is not a multiple of the kernel's width (levels 1 to 6), and across the face
// kernel's chunks of 512 points (level 6: 1,953 points a face); the same for the points of base edges.
TEST(CompactModelReconstruction, AlongNormalRowsGiveThePointwiseBitsForEverySurfaceModel) {
  Compact_model m = sphere_model();
  std::size_t cones = 0, negative = 0;
  for (std::size_t k = 0; k < m.surfaces.size(); ++k) {
    Local_surface& s = m.surfaces[k];
    if (k % 3 == 1) {  // cone on the quadric form, apex side alternating; half with q < 0 near v
      s.model = CONE_MODEL;
      s.c[5] = k % 2 ? 1. : -1.;
      if (k % 4 == 1) {
        for (int i = 0; i < 5; ++i) s.c[i] = -s.c[i];
        ++negative;
      }
      ++cones;
    } else if (k % 3 == 2) {
      s.model = CUBIC_MODEL;
      for (int i = 5; i < 9; ++i) s.c[i] = 0.05 * double(int(k % 7) - 3 + i);
    }
  }
  ASSERT_GT(cones, 10u);
  ASSERT_GT(negative, 5u);
  const std::vector<CMGeom::CM::Vertex_affine_map> maps(m.vertices.size());
  Reconstruction_options plain, mapped;
  plain.projection = mapped.projection = Projection::along_normal;
  mapped.vertex_maps = &maps;
  for (int level = 1; level <= 6; ++level) {
    const Reconstruction rows = reconstruct_regular(m, level, plain);
    EXPECT_TRUE(same(rows, reconstruct_regular(m, level, mapped))) << "level " << level;
    // the kernels' points (face interiors and base edges, four at a time) against interior()'s
    // and on_edge()'s, point by point through adaptive reconstruction
    EXPECT_TRUE(sorted_samples(rows) == sorted_samples(reconstruct_adaptive(m, Always_split(), level, plain)))
        << "level " << level;
    std::size_t non_finite = 0;
    for (std::size_t i = 0; i < rows.points.size(); ++i)
      non_finite += !std::isfinite(rows.points[i].x) || !std::isfinite(rows.normals[i].x);
    EXPECT_EQ(non_finite, 0u) << "level " << level;
  }
}

// With vertex maps that move the model, regular reconstruction along N maps the rows' points
// after the row kernel (an edge's or a face's points share their maps: four at a time with AVX),
// adaptive reconstruction maps each point of interior(): Always_split at the same level gives the
// same points (in another order), bit for bit; also when some base vertices keep the identity
// (faces and edges with moving and still corners, or only still ones), and at levels whose
// faces hold more points than the kernel's chunk of 64.
TEST(CompactModelReconstruction, MappedAlongNormalRowsGiveTheAdaptivePointsBitForBit) {
  const Compact_model& m = sphere_model();
  for (const bool some_still : {false, true}) {
    std::vector<CMGeom::CM::Vertex_affine_map> maps(m.vertices.size());
    for (std::size_t i = 0; i < maps.size(); ++i) {
      if (some_still && i % 3 == 0) continue;
      const double a = 0.3 * m.vertices[i].z, c = std::cos(a), s = std::sin(a);
      auto& T = maps[i];
      T.M[0][0] = c, T.M[0][1] = -s, T.M[1][0] = s, T.M[1][1] = c, T.M[2][2] = 1. + 0.1 * m.vertices[i].x;
      T.rest = m.vertices[i];
      T.deformed = Vec3(c * m.vertices[i].x - s * m.vertices[i].y, s * m.vertices[i].x + c * m.vertices[i].y,
                        m.vertices[i].z + 0.05);
      T.identity = false;
    }
    Reconstruction_options o;
    o.projection = Projection::along_normal;
    o.vertex_maps = &maps;
    for (int level : {2, 3, 5}) {
      const Reconstruction regular = reconstruct_regular(m, level, o);
      EXPECT_TRUE(sorted_samples(regular) == sorted_samples(reconstruct_adaptive(m, Always_split(), level, o)))
          << "level " << level << (some_still ? ", some maps the identity" : "");
      Reconstruction_options plain = o;
      plain.vertex_maps = nullptr;
      EXPECT_FALSE(sorted_samples(regular) ==
                   sorted_samples(reconstruct_regular(m, level, plain)));  // the maps do move it
    }
  }
}

// A box's CM has base edges sharp at an end, whose points the reconstructor computes once and
// keeps (Regular_reconstructor::number_of_kept_edges()), mapping them per call: with maps that
// move the model, on both projections, regular reconstruction (kept sharp-edge points, smooth
// edges and face interiors mapped inside the four-lane kernels) gives adaptive reconstruction's
// point-by-point bits (on_edge() and interior(), each point mapped alone), call after call.
TEST(CompactModelReconstruction, KeptSharpEdgePointsGiveTheAdaptivePointsBitForBit) {
  const Compact_model m = build_compact_model(make_box(8), 150);
  std::vector<CMGeom::CM::Vertex_affine_map> maps(m.vertices.size());
  for (std::size_t i = 0; i < maps.size(); ++i) {
    if (i % 4 == 0) continue;  // some base vertices keep the identity
    const Vec3& v = m.vertices[i];
    const double a = 0.2 * v.z, c = std::cos(a), s = std::sin(a);
    auto& T = maps[i];
    T.M[0][0] = c, T.M[0][1] = -s, T.M[1][0] = s, T.M[1][1] = c, T.M[2][2] = 1. + 0.1 * v.x;
    T.rest = v;
    T.deformed = Vec3(c * v.x - s * v.y, s * v.x + c * v.y, v.z + 0.05);
    T.identity = false;
  }
  for (const Projection proj : {Projection::along_normal, Projection::closest_point})
    for (const int level : {1, 2, 3, 4}) {
      SCOPED_TRACE("projection " + std::to_string(int(proj)) + ", level " + std::to_string(level));
      Reconstruction_options o;
      o.projection = proj;
      o.vertex_maps = &maps;
      const Regular_reconstructor<> rec(m, level, o);
      EXPECT_GT(rec.number_of_kept_edges(), 0u);
      Reconstruction_options plain = o;
      plain.vertex_maps = nullptr;
      Reconstruction out;
      rec.reconstruct(out, plain);  // unmapped first, then mapped into the same output
      EXPECT_TRUE(sorted_samples(out) == sorted_samples(reconstruct_adaptive(m, Always_split(), level, plain)));
      rec.reconstruct_points(out, o);
      EXPECT_TRUE(sorted_samples(out) == sorted_samples(reconstruct_adaptive(m, Always_split(), level, o)));
    }
  // A smooth model keeps no edge.
  EXPECT_EQ(Regular_reconstructor<>(sphere_model(), 3).number_of_kept_edges(), 0u);
}

TEST(CompactModelReconstruction, ReusedBufferGivesTheFreshResult) {
  const Compact_model& m = sphere_model();
  const Compact_model textured = textured_sphere_model();
  Reconstruction buffer;
  // Growing, shrinking, the other projection, and a textured model followed by an untextured one:
  // every field is rewritten, nothing of the previous content survives.
  for (const Projection proj : {Projection::along_normal, Projection::closest_point})
    for (const auto& [model, level] :
         {std::pair<const Compact_model*, int>{&m, 1}, {&m, 3}, {&textured, 2}, {&m, 2}, {&textured, 1}}) {
      Reconstruction_options o;
      o.projection = proj;
      const Reconstruction fresh = reconstruct_regular(*model, level, o);
      reconstruct_regular(*model, level, buffer, o);
      EXPECT_TRUE(same(fresh, buffer)) << "level " << level;
      EXPECT_EQ(fresh.base_face, buffer.base_face);
      EXPECT_EQ(fresh.corner_uvs, buffer.corner_uvs);
      EXPECT_EQ(buffer.corner_uvs.empty(), !model->has_uvs());
    }
}

// An output's arrays are sized without writing their new elements (Output_array): every element
// must then be written by the reconstruction. Storage holding NaNs and out-of-range indices (an
// earlier, larger output's, then cleared) gives the fresh result, with no element left unwritten.
TEST(CompactModelReconstruction, EveryElementOfAReusedOutputIsWritten) {
  const Compact_model textured = textured_sphere_model();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Compact_model* model : {&sphere_model(), &textured})
    for (const Projection proj : {Projection::along_normal, Projection::closest_point})
      for (int level = 1; level <= 4; ++level) {
        Reconstruction_options o;
        o.projection = proj;
        const Reconstruction fresh = reconstruct_regular(*model, level, o);
        Reconstruction buffer;
        const std::size_t room = 4 * fresh.triangles.size();  // more than any of its arrays needs
        buffer.points.assign(room, Vec3(nan, nan, nan));
        buffer.normals.assign(room, Vec3(nan, nan, nan));
        buffer.triangles.assign(room, {0xffffffffu, 0xffffffffu, 0xffffffffu});
        buffer.base_face.assign(room, 0xffffffffu);
        buffer.corner_uvs.assign(3 * room, {float(nan), float(nan)});
        for (auto* a : {&buffer.points, &buffer.normals}) a->clear();
        buffer.triangles.clear();
        buffer.base_face.clear();
        buffer.corner_uvs.clear();
        reconstruct_regular(*model, level, buffer, o);
        EXPECT_TRUE(same(fresh, buffer)) << "level " << level;
        EXPECT_EQ(fresh.base_face, buffer.base_face);
        EXPECT_EQ(fresh.corner_uvs, buffer.corner_uvs);
        for (std::size_t i = 0; i < buffer.points.size(); ++i)
          ASSERT_TRUE(std::isfinite(buffer.points[i].x + buffer.points[i].y + buffer.points[i].z + buffer.normals[i].x +
                                    buffer.normals[i].y + buffer.normals[i].z))
              << "point " << i << ", level " << level;
        for (const auto& t : buffer.triangles)
          for (std::uint32_t id : t) ASSERT_LT(id, buffer.points.size());
        for (std::uint32_t f : buffer.base_face) ASSERT_LT(f, model->faces.size());
      }
}

// The triangles, base faces and texture coordinates of a large output go out with non-temporal
// stores (reconstruct.h, internal::copy_streaming()): the same triangles, with the same corners and
// texture coordinates, as adaptive reconstruction's, which builds them one by one.
TEST(CompactModelReconstruction, StreamedConnectivityIsTheAdaptiveOne) {
  const Compact_model textured = textured_sphere_model();
  const int level = 6;  // 120 x 4,096 triangles: 20 MB of triangles, base faces and texture coordinates
  const std::size_t per_face = std::size_t(1) << (2 * level);
  ASSERT_GE(textured.faces.size() * per_face * 40, CMGeom::CM::internal::stream_output_bytes);  // (12 + 4 + 24 bytes)
  Reconstruction_options o;
  o.projection = Projection::along_normal;
  const Reconstruction r = reconstruct_regular(textured, level, o);
  const Reconstruction a = reconstruct_adaptive(textured, Always_split(), level, o);
  ASSERT_EQ(r.triangles.size(), textured.faces.size() * per_face);
  ASSERT_EQ(a.triangles.size(), r.triangles.size());
  for (std::size_t t = 0; t < r.triangles.size(); ++t) ASSERT_EQ(r.base_face[t], t / per_face) << "triangle " << t;
  // every triangle as its base face and its corners' points and texture coordinates, from its
  // least corner on (the orientation kept), sorted
  auto corners = [](const Reconstruction& x) {
    using Corner = std::array<double, 5>;
    std::vector<std::array<double, 16>> out(x.triangles.size());
    for (std::size_t t = 0; t < x.triangles.size(); ++t) {
      std::array<Corner, 3> c;
      for (int k = 0; k < 3; ++k) {
        const Vec3& p = x.points[x.triangles[t][std::size_t(k)]];
        const auto& uv = x.corner_uvs[3 * t + std::size_t(k)];
        c[std::size_t(k)] = {p.x, p.y, p.z, double(uv[0]), double(uv[1])};
      }
      const std::size_t first = std::size_t(std::min_element(c.begin(), c.end()) - c.begin());
      out[t][0] = double(x.base_face[t]);
      for (std::size_t k = 0; k < 3; ++k)
        for (std::size_t q = 0; q < 5; ++q) out[t][1 + 5 * k + q] = c[(first + k) % 3][q];
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_TRUE(corners(r) == corners(a));
}

// The streaming copies give std::copy's and std::fill_n's results at every alignment and length
// (non-temporal stores where both ends are 16-byte aligned, plain ones otherwise).
TEST(CompactModelReconstruction, StreamingCopiesAreCopies) {
  std::vector<std::array<std::uint32_t, 3>> from(1000);
  for (std::size_t i = 0; i < from.size(); ++i)
    from[i] = {std::uint32_t(3 * i), std::uint32_t(7 * i + 1), std::uint32_t(i * i)};
  for (std::size_t offset = 0; offset < 4; ++offset)
    for (const std::size_t count : {std::size_t(0), std::size_t(1), std::size_t(4), std::size_t(5), std::size_t(996)}) {
      std::vector<std::array<std::uint32_t, 3>> to(1004, {{9, 9, 9}}), expected = to;
      CMGeom::CM::internal::copy_streaming(from.data(), count, to.data() + offset);
      std::copy(from.begin(), from.begin() + std::ptrdiff_t(count), expected.begin() + std::ptrdiff_t(offset));
      std::vector<std::uint32_t> filled(1004, 5), filled_expected = filled;
      CMGeom::CM::internal::fill_streaming(filled.data() + offset, count, 77);
      std::fill_n(filled_expected.begin() + std::ptrdiff_t(offset), count, 77u);
      CMGeom::CM::internal::finish_streaming();
      EXPECT_TRUE(to == expected) << "offset " << offset << ", count " << count;
      EXPECT_TRUE(filled == filled_expected) << "offset " << offset << ", count " << count;
    }
}

// resize_on_huge_pages() is resize() with a hint to the kernel: elements already there are kept,
// new ones are value-initialised, whether the block is below or above the huge-page threshold.
TEST(CompactModelReconstruction, HugePageResizeKeepsResizeSemantics) {
  for (const std::size_t n : {std::size_t(1000), 2 * CMGeom::internal::huge_page_threshold / sizeof(Vec3)}) {
    std::vector<Vec3> v = {Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(7, 8, 9)};
    CMGeom::internal::resize_on_huge_pages(v, n);
    ASSERT_EQ(v.size(), n);
    EXPECT_GE(v.capacity(), n);
    EXPECT_EQ(v[1].y, 5.);
    EXPECT_EQ(v[2].z, 9.);
    std::size_t nonzero = 0;
    for (std::size_t i = 3; i < n; ++i) nonzero += v[i].x != 0. || v[i].y != 0. || v[i].z != 0.;
    EXPECT_EQ(nonzero, 0u);
    CMGeom::internal::resize_on_huge_pages(v, 2);  // shrinking keeps the first elements
    ASSERT_EQ(v.size(), 2u);
    EXPECT_EQ(v[1].x, 4.);
  }
}

// The capacity reserved for a large block is at least the count asked for, less than 2 MB more, and
// with malloc's 24 bytes of header and rounding fits a whole number of 2 MB pages; over-aligned
// types keep the count asked for.
TEST(CompactModelReconstruction, HugePageCapacityFillsWholeHugePages) {
  constexpr std::size_t H = CMGeom::internal::huge_page_bytes;
  for (const std::size_t n : {std::size_t(1), std::size_t(174762), std::size_t(174763), std::size_t(1) << 20,
                              std::size_t(4456447), std::size_t(4456448)}) {
    const std::size_t c = CMGeom::internal::capacity_on_whole_huge_pages<Vec3>(n);
    EXPECT_GE(c, n);
    EXPECT_LT((c - n) * sizeof(Vec3), H);
    const std::size_t pages = (c * sizeof(Vec3) + 24 + H - 1) / H;
    EXPECT_LE(c * sizeof(Vec3) + 24, pages * H);
    EXPECT_GT((c + 1) * sizeof(Vec3) + 24, pages * H);  // the largest such count
  }
  struct alignas(64) Wide {
    double v[8];
  };
  EXPECT_EQ(CMGeom::internal::capacity_on_whole_huge_pages<Wide>(100000), 100000u);
}

// Advising a block that begins and ends inside 2 MB ranges it shares with other data (another
// block, malloc's header) changes no byte outside the block, and inside it only the first byte of
// the block and of its last 2 MB range, which it sets to zero.
TEST(CompactModelReconstruction, HugePageAdviceKeepsTheNeighboursBytes) {
  constexpr std::size_t H = CMGeom::internal::huge_page_bytes;
  std::vector<unsigned char> all(5 * H + 12345);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<unsigned char>(1 + i % 251);
  const std::vector<unsigned char> before = all;
  const std::size_t offset = H / 2 + 4099, bytes = 3 * H + 777;  // neither end on a 2 MB boundary
  unsigned char* const block = all.data() + offset;
  CMGeom::internal::advise_new_block_huge_pages(block, bytes);
  const std::uintptr_t last = (reinterpret_cast<std::uintptr_t>(block) + bytes) / H * H;
  std::size_t changed = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    if (all[i] == before[i]) continue;
    ++changed;
    const bool first_byte = i == offset, last_range_byte = reinterpret_cast<std::uintptr_t>(all.data() + i) == last;
    EXPECT_TRUE(first_byte || last_range_byte) << "byte " << i << " changed";
    EXPECT_EQ(all[i], 0);
  }
  EXPECT_LE(changed, 2u);
}

// assign_on_huge_pages(), filled_on_huge_pages() and copy_on_huge_pages() are assign(), the filling
// constructor and the copy, below and above the threshold; an Image copy (which uses them) is equal
// to its original and owns its own pixels.
TEST(CompactModelReconstruction, HugePageAssignFillAndCopyKeepTheirSemantics) {
  for (const std::size_t n : {std::size_t(1000), 2 * CMGeom::internal::huge_page_threshold / sizeof(float)}) {
    std::vector<float> v = {1.f, 2.f};
    CMGeom::internal::assign_on_huge_pages(v, n, 3.5f);
    ASSERT_EQ(v.size(), n);
    EXPECT_EQ(std::count(v.begin(), v.end(), 3.5f), std::ptrdiff_t(n));
    const std::vector<std::uint32_t> f = CMGeom::internal::filled_on_huge_pages(n, 7u);
    EXPECT_EQ(f, std::vector<std::uint32_t>(n, 7u));
    std::vector<float> w = v;
    w[n / 2] = -1.f;
    const std::vector<float> c = CMGeom::internal::copy_on_huge_pages(w);
    EXPECT_EQ(c, w);
    CMGeom::internal::assign_on_huge_pages(v, 3, 0.f);  // shrinking assigns too
    EXPECT_EQ(v, std::vector<float>(3, 0.f));
  }
  CMGeom::Image big(1500, 1000, 3);  // 4.5 MB: above the threshold
  big.set_value(17, 23, 1, 0.5f);
  CMGeom::Image copy(big), assigned;
  assigned = big;
  EXPECT_TRUE(copy == big);
  EXPECT_TRUE(assigned == big);
  copy.set_value(17, 23, 1, 1.f);
  EXPECT_FALSE(copy == big);
  EXPECT_NEAR(big.value(17, 23, 1), 0.5f, 1.f / 255);
  const CMGeom::Image& same = assigned;
  assigned = same;  // self-assignment keeps the pixels
  EXPECT_TRUE(assigned == big);
}

TEST(CompactModelReconstruction, ErrorDecreasesWithLevelOnSmoothModel) {
  const Compact_model& m = sphere_model();
  const Surface_mesh original = make_sphere(5);
  double previous_rms = 1e9, previous_radius = 1e9;
  for (int level = 0; level <= 3; ++level) {
    const Reconstruction r = reconstruct_regular(m, level);
    const double rms = symmetric_vertex_rms(original, to_surface_mesh(r));
    EXPECT_LT(rms, previous_rms) << "level " << level;
    previous_rms = rms;
    // (The maximum radial error cannot decrease: level L's points are a subset of level L+1's.)
    previous_radius = max_radius_error(r);
  }
  // Level 3 of a 120-face base (edges ~0.35) stays within 0.3 % of the radius: the quartic term
  // of the sphere a quadric cannot follow is (0.35^2)^2 / 8 ~ 2e-3 at the fan's rim.
  EXPECT_LT(previous_radius, 3e-3);
}

}  // namespace
