// Tests of the index texture of Textured_simplification (thesis §3.3, §3.6): the red-filled-atlas
// test (Fig. 3.8), resampling of a flat isometric patch, the CPU and OSMesa resampling backends.
#include "textured_part_test_util.h"

namespace {

// Red-filled atlas (thesis Fig. 3.8): texels outside every chart get a marker colour (pure red in
// the thesis; bunny10k's test atlas has pure red charts, so the first of red, magenta, cyan,
// yellow that no chart texel is close to is used); after the simplification with index-texture
// resampling no texel of the output texture — and no rendered pixel of the output model — has
// the marker colour.
void red_filled_atlas_shows_no_red(bool keep_charts) {
  const Model m{"bunny10k_textured", "bunny10k_textured.obj"};
  CMGeom::Textured_mesh tm;
  if (!read_model(m, tm, true)) GTEST_SKIP() << "shared data not found: " << model_path(m);
  ASSERT_FALSE(tm.materials().empty());
  CMGeom::Image& atlas = tm.materials()[0].diffuse_image;
  ASSERT_FALSE(atlas.empty());
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  layout(tm, tris, ids);
  const TS::Texture_domain dom = TS::make_texture_domain(tris, atlas.width(), atlas.height(), 8192);
  ASSERT_EQ(dom.width, atlas.width()) << "bunny10k's UVs are expected inside [0,1]";
  const TS::Chart_map region(dom, tris, ids, 2);
  auto in_chart = [&](int x, int y) { return region.chart(x, atlas.height() - 1 - y) != 0; };
  const std::array<std::array<float, 3>, 4> candidates{{{{1, 0, 0}}, {{1, 0, 1}}, {{0, 1, 1}}, {{1, 1, 0}}}};
  auto close_to = [](const CMGeom::Image& img, int x, int y, const std::array<float, 3>& c, float tol) {
    for (int k = 0; k < 3; ++k)
      if (std::abs(img.value(x, y, k) - c[k]) > tol) return false;
    return true;
  };
  int marker = -1;
  for (int k = 0; k < 4 && marker < 0; ++k) {
    bool used = false;
    for (int y = 0; y < atlas.height() && !used; ++y)
      for (int x = 0; x < atlas.width() && !used; ++x)
        used = in_chart(x, y) && close_to(atlas, x, y, candidates[k], 0.25f);
    if (!used) marker = k;
  }
  ASSERT_GE(marker, 0);
  const auto mc = candidates[std::size_t(marker)];
  std::size_t filled = 0;
  for (int y = 0; y < atlas.height(); ++y)
    for (int x = 0; x < atlas.width(); ++x)
      if (!in_chart(x, y)) {
        for (int c = 0; c < 3; ++c) atlas.set_value(x, y, c, mc[c]);
        ++filled;
      }
  ASSERT_GT(filled, 1000u);
  TS::Textured_simplification_options o;
  o.target_faces = tm.mesh().number_of_faces() / 5;
  o.keep_charts = keep_charts;
  const std::size_t faces_in = tm.mesh().number_of_faces();
  const auto r = TS::simplify_textured_mesh(tm, o);
  EXPECT_EQ(r.charts_kept, keep_charts);
  if (keep_charts) EXPECT_EQ(r.charts_out, r.charts_in);
  // bunny10k's 190 charts let the chart-keeping path reach 1/5 of the faces (measured: exactly);
  // the rebuilt atlas reaches any target
  // (a collapse removes two faces, so the count may land one below)
  EXPECT_LE(r.faces_out, o.target_faces) << "from " << faces_in;
  EXPECT_GE(r.faces_out + 1, o.target_faces) << "from " << faces_in;
  EXPECT_EQ(r.stopped_by, TS::Stop_reason::target);
  const CMGeom::Image& out = tm.materials()[0].diffuse_image;
  ASSERT_EQ(out.width(), dom.width);
  std::size_t marked = 0;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) marked += close_to(out, x, y, mc, 0.1f) ? 1 : 0;
  if (std::getenv("CMGEOM_TS_DIAG")) CMGeom::IO::write_image("/tmp/ts_red_out.png", out);
  EXPECT_EQ(marked, 0u) << "marker-coloured texels in the output texture (of " << out.width() * out.height() << ")";
#ifdef CMGEOM_HAS_OSMESA
  // through the renderer: no marker-coloured pixel on the simplified model, from 12 directions
  CMGeom::Rendering::Renderer renderer;
  CMGeom::Rendering::Render_mesh_inputs<CMGeom::Textured_mesh::UV_map> in;
  const auto uv = tm.uv_map();
  in.uv = &uv;
  in.texture_of = [&](std::size_t) -> const CMGeom::Image* { return &out; };
  const auto rm = CMGeom::Rendering::make_render_mesh(tm.mesh(), get(CGAL::vertex_point, tm.mesh()), in);
  std::size_t marked_pixels = 0, covered = 0;
  for (double az : {0., 90., 180., 270.})
    for (double el : {-60., 0., 60.}) {
      CMGeom::Rendering::Render_options ro;
      ro.width = ro.height = 256;
      ro.lighting = false;
      ro.background = {{0.5, 0.5, 0.5}};
      ro.view(az, el);
      const CMGeom::Image img = renderer.render(rm, ro);
      for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
          if (img.value(x, y, 3) < 1.f) continue;
          ++covered;
          if (close_to(img, x, y, mc, 0.15f)) ++marked_pixels;
        }
    }
  EXPECT_GT(covered, 10000u);
  EXPECT_EQ(marked_pixels, 0u) << "marker-coloured pixels on the rendered simplified model";
#endif
}

TEST(TexturedSimplification, RedFilledAtlasShowsNoRed) { red_filled_atlas_shows_no_red(true); }
TEST(TexturedSimplification, RedFilledAtlasShowsNoRedInARebuiltAtlas) { red_filled_atlas_shows_no_red(false); }

// The chart map's margin (Chart_map's chart_margin rings): each ring gives every texel outside
// the charts the smallest chart id among its 8 neighbours, as a plain scan of the 3 x 3
// neighbourhood computes it here, from the map without margin; charts touching the image's
// borders and corners, and overlapping triangles (the `contested` id, the largest) included.
// An Index_texture holds the same map, beside the identity index (each texel's own centre).
TEST(TexturedSimplification, ChartMarginsGrowTheSmallestNeighbouringChart) {
  TS::Texture_domain dom;
  dom.width = 37;
  dom.height = 29;
  auto uv = [&](double x, double y) { return UV2{{x / dom.width, y / dom.height}}; };
  const std::vector<std::array<UV2, 3>> tris{{{uv(-2, -2), uv(6, -1), uv(-1, 7)}},     // a corner
                                             {{uv(10, 3), uv(16, 4), uv(12, 9)}},      // inside
                                             {{uv(12, 4), uv(20, 5), uv(15, 12)}},     // overlaps the one before
                                             {{uv(30, 20), uv(39, 22), uv(33, 31)}},   // over the far corner
                                             {{uv(3, 15), uv(8, 15.5), uv(4.5, 16)}},  // a sliver
                                             {{uv(20, 18), uv(24, 18), uv(22, 19)}}};
  const std::vector<int> ids{4, 0, 2, 1, 3, 5};
  for (const bool overlaps : {false, true}) {
    const TS::Chart_map base(dom, tris, ids, 0, overlaps);
    std::vector<std::uint32_t> ref(std::size_t(dom.width) * std::size_t(dom.height));
    for (int y = 0; y < dom.height; ++y)
      for (int x = 0; x < dom.width; ++x) ref[std::size_t(y) * dom.width + x] = base.chart(x, y);
    if (overlaps) ASSERT_NE(std::count(ref.begin(), ref.end(), TS::Chart_map::contested), 0);
    for (int margin = 1; margin <= 4; ++margin) {
      std::vector<std::uint32_t> next = ref;
      for (int y = 0; y < dom.height; ++y)
        for (int x = 0; x < dom.width; ++x) {
          if (ref[std::size_t(y) * dom.width + x] != 0) continue;
          std::uint32_t best = 0;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int qx = x + dx, qy = y + dy;
              if (qx < 0 || qy < 0 || qx >= dom.width || qy >= dom.height) continue;
              const std::uint32_t c = ref[std::size_t(qy) * dom.width + qx];
              if (c != 0 && (best == 0 || c < best)) best = c;
            }
          next[std::size_t(y) * dom.width + x] = best;
        }
      ref = next;
      const TS::Chart_map grown(dom, tris, ids, margin, overlaps);
      const TS::Index_texture with_index(dom, tris, ids, margin, overlaps);
      int wrong = 0, wrong_in_index = 0, not_identity = 0;
      for (int y = 0; y < dom.height; ++y)
        for (int x = 0; x < dom.width; ++x) {
          wrong += grown.chart(x, y) != ref[std::size_t(y) * dom.width + x];
          wrong_in_index += with_index.chart(x, y) != ref[std::size_t(y) * dom.width + x];
          not_identity += with_index.at(x, y)[0] != float(x) + 0.5f || with_index.at(x, y)[1] != float(y) + 0.5f;
        }
      EXPECT_EQ(wrong, 0) << "margin " << margin << (overlaps ? ", overlaps marked" : "");
      EXPECT_EQ(wrong_in_index, 0) << "margin " << margin << (overlaps ? ", overlaps marked" : "");
      EXPECT_EQ(not_identity, 0) << "margin " << margin;
    }
    // the margins reached texels of no chart, and some stayed without one
    EXPECT_GT(std::count(ref.begin(), ref.end(), 0u), 0);
  }
}

// The index texture after resampling only stores positions inside original charts, and texels
// of an interior-only collapse sequence on a flat single-chart grid keep the identity map
// (projection onto the plane = the UV map up to scale): resampling a flat isometric patch is exact.
TEST(TexturedSimplification, ResamplingIsIdentityOnAFlatIsometricPatch) {
  CMGeom::Textured_mesh tm;
  auto& m = tm.mesh();
  const int N = 16;
  std::vector<CMGeom::Surface_mesh::Vertex_index> v;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) {
      // irregular interior spacing so that collapses happen, flat (z = 0)
      const double x = i + ((i > 0 && i < N) ? 0.3 * std::sin(1.7 * i + 3.1 * j) : 0.);
      const double y = j + ((j > 0 && j < N) ? 0.3 * std::cos(2.3 * i + 0.7 * j) : 0.);
      v.push_back(m.add_vertex(CMGeom::Point_3(x, y, 0)));
    }
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const auto a = v[j * (N + 1) + i], b = v[j * (N + 1) + i + 1], c = v[(j + 1) * (N + 1) + i + 1],
                 d = v[(j + 1) * (N + 1) + i];
      for (auto f : {m.add_face(a, b, c), m.add_face(a, c, d)})
        for (auto h : CGAL::halfedges_around_face(halfedge(f, m), m)) {
          const auto p = m.point(target(h, m));
          tm.set_uv(h, CMGeom::Point_2(p.x() / N, p.y() / N));
        }
    }
  tm.set_has_uvs(true);
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  layout(tm, tris, ids);
  TS::Texture_domain dom = TS::make_texture_domain(tris, 128, 128, 8192);
  TS::Index_texture it(dom, tris, ids);
  using VPM = boost::property_map<CMGeom::Surface_mesh, CGAL::vertex_point_t>::type;
  using CC = TS::Chart_constraints<CMGeom::Surface_mesh, VPM, CMGeom::Textured_mesh::UV_map>;
  CC cc(m, get(CGAL::vertex_point, m), tm.uv_map());
  TS::Index_texture_resampler rs(it);
  TS::Area_weighted_quadric_policies<CMGeom::Surface_mesh> policy(m);
  TS::edge_collapse(m, TS::Face_count_stop_predicate<CMGeom::Surface_mesh>(m, 60),
                    CGAL::parameters::get_cost(policy)
                        .get_placement(policy)
                        .filter(TS::Chart_constraint_filter<CC>(cc))
                        .visitor(TS::Chart_constraint_visitor<CC, TS::Index_texture_resampler>(cc, &rs)));
  EXPECT_GT(cc.statistics().accepted, 100u);
  // On a flat patch whose UVs are its xy coordinates scaled, PM maps are similarities and the
  // composed maps are the identity: each texel keeps its own coordinates (up to float rounding
  // and bilinear weights summing to one).
  double worst = 0;
  for (int y = 0; y < it.height(); ++y)
    for (int x = 0; x < it.width(); ++x) {
      const float* p = it.at(x, y);
      worst = std::max({worst, std::abs(p[0] - (x + 0.5)), std::abs(p[1] - (y + 0.5))});
    }
  EXPECT_LT(worst, 1e-3) << "index texture drifted from the identity (texels)";
}

#ifdef CMGEOM_HAS_OSMESA
// The two resampling backends see the same collapse records in lockstep (one simplification, the
// record handed to both) and must leave bit-identical index textures, coverage included; the GL
// one batches independent collapses, and one draw per collapse must give the same texels too.
struct Both_backends {
  TS::Index_texture_resampler* cpu;
  TS::Osmesa_index_texture_resampler* gl;
  void operator()(const TS::Collapse_record& r) {
    (*cpu)(r);
    (*gl)(r);
  }
};

void expect_backends_bit_identical(const Model& model, int texels, double ratio, std::size_t max_batch) {
  CMGeom::Textured_mesh tm;
  if (!read_model(model, tm, false)) GTEST_SKIP() << "shared data not found: " << model_path(model);
  auto& m = tm.mesh();
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  layout(tm, tris, ids);
  const TS::Index_texture original(TS::make_texture_domain(tris, texels, texels, 8192), tris, ids);
  TS::Index_texture on_cpu = original, on_gl = original;
  TS::Index_texture_resampler cpu(on_cpu);
  TS::Osmesa_resampler_options go;
  go.max_batch = max_batch;
  TS::Osmesa_index_texture_resampler gl(on_gl, go);
  using VPM = boost::property_map<CMGeom::Surface_mesh, CGAL::vertex_point_t>::type;
  using CC = TS::Chart_constraints<CMGeom::Surface_mesh, VPM, CMGeom::Textured_mesh::UV_map>;
  CC cc(m, get(CGAL::vertex_point, m), tm.uv_map());
  Both_backends both{&cpu, &gl};
  TS::Area_weighted_quadric_policies<CMGeom::Surface_mesh> policy(m);
  const auto target = std::size_t(ratio * double(m.number_of_faces()));
  TS::edge_collapse(m, TS::Face_count_stop_predicate<CMGeom::Surface_mesh>(m, target),
                    CGAL::parameters::get_cost(policy)
                        .get_placement(policy)
                        .filter(TS::Chart_constraint_filter<CC>(cc))
                        .visitor(TS::Chart_constraint_visitor<CC, Both_backends>(cc, &both)));
  gl.synchronize();
  ASSERT_GT(gl.collapses(), 100u) << model.file;
  std::cout << "  " << model.file << ": " << gl.collapses() << " collapses resampled in " << gl.draws() << " draws\n";
  EXPECT_LE(gl.draws(), gl.collapses());
  if (max_batch == 1)
    EXPECT_GT(gl.draws() * 2, gl.collapses()) << "expected about one draw per collapse";
  else
    EXPECT_LT(gl.draws() * 3, gl.collapses()) << "independent collapses were not batched";
  std::size_t changed = 0, differ = 0;
  long long first = -1;
  const std::size_t n = original.data().size();
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t a, b, o;
    std::memcpy(&a, &on_cpu.data()[i], 4);
    std::memcpy(&b, &on_gl.data()[i], 4);
    std::memcpy(&o, &original.data()[i], 4);
    changed += a != o;
    if (a != b) {
      ++differ;
      if (first < 0) first = (long long)i;
    }
  }
  EXPECT_GT(changed, n / 50) << model.file << ": the collapses hardly rewrote the index texture";
  EXPECT_EQ(differ, 0u) << model.file << ": " << differ << " of " << n << " index values differ, first at texel ("
                        << (first / 2) % on_cpu.width() << ", " << (first / 2) / on_cpu.width() << "): cpu "
                        << (first >= 0 ? on_cpu.data()[std::size_t(first)] : 0.f) << ", gl "
                        << (first >= 0 ? on_gl.data()[std::size_t(first)] : 0.f);
}

TEST(TexturedSimplification, OsmesaBackendIsBitIdenticalToCpu) {
  for (const char* dir : {"spot", "bunny10k_textured", "bob"}) {
    SCOPED_TRACE(dir);
    for (const Model& m : kModels)
      if (std::string(m.dir) == dir) expect_backends_bit_identical(m, 512, 0.1, 4096);
  }
}

TEST(TexturedSimplification, OsmesaBackendOneDrawPerCollapseIsBitIdenticalToCpu) {
  expect_backends_bit_identical(kModels[0], 256, 0.3, 1);
}
#endif

}  // namespace
