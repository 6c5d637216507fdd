// The texture work of Textured_simplification runs on several threads (TBB): index texture
// set-up, resampling of collapses covering many texels, output texture generation and dilation;
// so does the engine's memoryful cost (edges priced ahead, the faces of moving points found on all
// cores). These tests check that the results are bit-identical whatever the number of threads. They are a
// program of their own, small enough to be built and run under ThreadSanitizer in CI
// (scripts/test.sh), on a synthetic model so that they never depend on the shared data.
#include "cmgeom_test_surface_meshes.h"
#include "cmgeom_test_textured_grid.h"

#include <CMGeom/Textured_simplification.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
using TS::UV2;

using cmgeom_test::two_chart_grid;

template <class F>
auto with_threads(int threads, const F& f) {
  tbb::task_arena arena(threads);
  return arena.execute(f);
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0);
}

bool same_image(const CMGeom::Image& a, const CMGeom::Image& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels()) return false;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < a.channels(); ++c)
        if (a.value(x, y, c) != b.value(x, y, c)) return false;
  return true;
}

struct Resampled {
  std::vector<float> index;
  CMGeom::Image texture;
  std::size_t collapses = 0, parallel = 0;
};

// Collapses `tm` to a quarter of its faces under the chart constraints, resampling an index
// texture of the atlas' size with the CPU backend, then generates the output texture.
Resampled resample(CMGeom::Textured_mesh tm) {
  auto& m = tm.mesh();
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  TS::internal::uv_layout(tm, tris, ids);
  const CMGeom::Image& atlas = tm.materials()[0].diffuse_image;
  TS::Index_texture it(TS::make_texture_domain(tris, atlas.width(), atlas.height(), 8192), tris, ids);
  using VPM = boost::property_map<CMGeom::Surface_mesh, CGAL::vertex_point_t>::type;
  using CC = TS::Chart_constraints<CMGeom::Surface_mesh, VPM, CMGeom::Textured_mesh::UV_map>;
  CC cc(m, get(CGAL::vertex_point, m), tm.uv_map());
  Resampled out;
  {
    TS::Index_texture_resampler resampler(it);
    TS::Area_weighted_quadric_policies<CMGeom::Surface_mesh> policy(m);
    TS::edge_collapse(m, TS::Face_count_stop_predicate<CMGeom::Surface_mesh>(m, m.number_of_faces() / 4),
                      CGAL::parameters::get_cost(policy)
                          .get_placement(policy)
                          .filter(TS::Chart_constraint_filter<CC>(cc))
                          .visitor(TS::Chart_constraint_visitor<CC, TS::Index_texture_resampler>(cc, &resampler)));
    out.collapses = resampler.collapses();
    out.parallel = resampler.parallel_collapses();
  }
  m.collect_garbage();
  out.index = it.data();
  std::vector<std::array<UV2, 3>> final_tris;
  TS::internal::uv_layout(tm, final_tris, ids);
  out.texture = TS::generate_texture(it, atlas, final_tris);
  return out;
}

TEST(TextureThreads, IndexTextureSetUpIsTheSameOnOneAndTwoThreads) {
  const CMGeom::Textured_mesh tm = two_chart_grid(24, 512);
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  TS::internal::uv_layout(tm, tris, ids);
  const TS::Texture_domain dom = TS::make_texture_domain(tris, 512, 512, 8192);
  auto build = [&] { return TS::Index_texture(dom, tris, ids, 3, true); };
  const TS::Index_texture one = with_threads(1, build), two = with_threads(2, build);
  EXPECT_TRUE(same_bits(one.data(), two.data()));
  std::size_t charted = 0, differ = 0;
  for (int y = 0; y < dom.height; ++y)
    for (int x = 0; x < dom.width; ++x) {
      charted += one.chart(x, y) != 0;
      differ += one.chart(x, y) != two.chart(x, y);
    }
  EXPECT_EQ(differ, 0u);
  // two charts of 0.45 x 0.96 of the atlas, grown by 3 texels
  EXPECT_GT(charted, std::size_t(0.85 * 512 * 512));
}

TEST(TextureThreads, ResamplingAndGeneratedTextureAreTheSameOnOneAndTwoThreads) {
  const CMGeom::Textured_mesh tm = two_chart_grid(24, 1024);
  const Resampled one = with_threads(1, [&] { return resample(tm); });
  const Resampled two = with_threads(2, [&] { return resample(tm); });
  ASSERT_GT(one.collapses, 300u);
  EXPECT_EQ(one.collapses, two.collapses);
  // at 1024² texels for ~1150 faces, collapses cover thousands of texels: most take the parallel
  // path (the same decision on one thread, where its tasks simply run in turn)
  EXPECT_GT(two.parallel * 2, two.collapses);
  EXPECT_EQ(one.parallel, two.parallel);
  EXPECT_TRUE(same_bits(one.index, two.index)) << "index textures differ";
  EXPECT_TRUE(same_image(one.texture, two.texture)) << "generated textures differ";
  // the resampling did change the index texture (it is not the identity any more)
  const CMGeom::Textured_mesh fresh = two_chart_grid(24, 1024);
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  TS::internal::uv_layout(fresh, tris, ids);
  const TS::Index_texture identity(TS::make_texture_domain(tris, 1024, 1024, 8192), tris, ids);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < identity.data().size(); ++i) changed += identity.data()[i] != one.index[i];
  EXPECT_GT(changed, identity.data().size() / 20);
}

TEST(TextureThreads, SimplifyTexturedMeshOptionThreadsDoesNotChangeTheResult) {
  const CMGeom::Textured_mesh input = two_chart_grid(20, 512);
  auto run = [&](int threads) {
    CMGeom::Textured_mesh tm = input;
    TS::Textured_simplification_options o;
    o.target_faces = tm.mesh().number_of_faces() / 5;
    o.threads = threads;
    o.keep_charts = true;  // the index-texture work is what runs on threads
    const TS::Textured_simplification_result r = TS::simplify_textured_mesh(tm, o);
    EXPECT_EQ(r.charts_out, 2u);
    EXPECT_LE(r.faces_out, std::size_t(o.target_faces + 2));
    return tm;
  };
  const CMGeom::Textured_mesh one = run(1), two = run(2);
  const auto& a = one.mesh();
  const auto& b = two.mesh();
  ASSERT_EQ(a.number_of_faces(), b.number_of_faces());
  ASSERT_EQ(a.number_of_vertices(), b.number_of_vertices());
  for (auto v : a.vertices()) EXPECT_EQ(a.point(v), b.point(v));
  for (auto h : a.halfedges())
    if (!a.is_border(h)) EXPECT_EQ(one.uv(h), two.uv(h));
  EXPECT_TRUE(same_image(one.materials()[0].diffuse_image, two.materials()[0].diffuse_image));
}

// simplify_mesh's first stage runs its parts at once, then their groups two levels up (the
// pairwise merge): both are a function of the mesh, so the result is the same on any number of
// threads (and, under ThreadSanitizer, free of races).
TEST(TextureThreads, SimplifyMeshInPartsDoesNotDependOnTheThreads) {
  const CMGeom::Textured_mesh input = two_chart_grid(100, 64);
  TS::Mesh_simplification_options o;
  o.parts_min_faces = 4096;
  o.part_faces = 512;  // 12,800 faces: 16 parts, groups of 2 then 4 parts before the whole
  auto run = [&](int threads) {
    CMGeom::Surface_mesh m = input.mesh();
    const TS::Mesh_simplification_result r =
        with_threads(threads, [&] { return TS::simplify_mesh(m, m.number_of_faces() / 50, o); });
    EXPECT_EQ(r.parts, 16u);
    return m;
  };
  const CMGeom::Surface_mesh one = run(1), two = run(2), four = run(4);
  ASSERT_GT(one.number_of_faces(), 0u);
  for (const auto* other : {&two, &four}) {
    ASSERT_EQ(one.number_of_faces(), other->number_of_faces());
    ASSERT_EQ(one.number_of_vertices(), other->number_of_vertices());
    for (auto v : one.vertices()) EXPECT_EQ(one.point(v), other->point(v));
    for (auto h : one.halfedges()) EXPECT_EQ(one.target(h), other->target(h));
  }
}

TEST(TextureThreads, PricingAheadOnSeveralThreadsGivesTheSameCollapses) {
  // On two threads or more the engine prices the edges the queue gives next at once and keeps
  // each cost until something around its edge changes; the collapses must be those of one thread
  // pricing each edge as it pops. Down to 300 faces the late collapses move hundreds of points
  // each (after_collapse() then finds their faces on all cores too); with flips, flips change
  // faces as well.
  using Mesh = CMGeom::Surface_mesh;
  using Memory = TS::Surface_memory<Mesh, boost::property_map<Mesh, CGAL::vertex_point_t>::type>;
  const Mesh input = cmgeom_test::rippled_torus(240, 96, 0.35, 0.35 * 0.15, 5, 3);  // 46,080 faces
  for (bool flips : {false, true}) {
    Mesh out[3];
    for (int k = 0; k < 3; ++k) {
      tbb::task_arena arena(k == 0 ? 1 : 2);  // (two threads even on one core)
      arena.execute([&] {
        Mesh& m = out[k] = input;
        TS::Surface_memory_options mo;
        mo.parallel_pricing = k != 2;  // the last run prices on one thread in a two-thread arena
        Memory memory(m, get(CGAL::vertex_point, m), mo);
        TS::Area_weighted_quadric_policies<Mesh> policy(m, TS::Quadric_options{false});
        TS::Face_count_stop_predicate<Mesh> stop(m, 300);
        TS::edge_collapse(m, stop,
                          CMGeom::parameters::surface_memory(
                              &memory, CMGeom::parameters::edge_flips(
                                           flips, CGAL::parameters::get_cost(policy).get_placement(policy))));
        m.collect_garbage();
      });
    }
    ASSERT_LE(out[0].number_of_faces(), 300u);
    for (int k = 1; k < 3; ++k) {
      ASSERT_EQ(out[k].number_of_faces(), out[0].number_of_faces()) << "flips " << flips << ", run " << k;
      for (auto v : out[0].vertices())
        ASSERT_EQ(out[k].point(v), out[0].point(v)) << "flips " << flips << ", run " << k;
      for (auto f : out[0].faces())
        ASSERT_EQ(out[k].halfedge(f), out[0].halfedge(f)) << "flips " << flips << ", run " << k;
    }
  }
}

}  // namespace
