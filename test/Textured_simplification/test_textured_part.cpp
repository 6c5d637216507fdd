// Tests of the texture part of Textured_simplification (thesis §3.3, §3.5, §3.6): chart
// constraints and UV placement on every model of shared/data/textured, index-texture resampling,
// output textures, the red-filled-atlas test (Fig. 3.8), weighted vs plain texture deviation.
#include "cmgeom_test_config.h"

#include <CMGeom/Metrics/texture_deviation.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>
#ifdef CMGEOM_HAS_OSMESA
#include <CMGeom/Textured_simplification/Osmesa_index_texture_resampler.h>
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#include <CMGeom/Rendering/views.h>
#endif

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
namespace fs = std::filesystem;
using TS::UV2;

struct Model {
  const char* dir;
  const char* file;
};
const Model kModels[] = {{"spot", "spot.obj"},       {"bob", "bob_tri.obj"},
                         {"fuze", "fuze.obj"},       {"DamagedHelmet", "DamagedHelmet.obj"},
                         {"WaterBottle", "WaterBottle.obj"}, {"Duck", "Duck.obj"},
                         {"bunny10k_textured", "bunny10k_textured.obj"}, {"texturedknot", "texturedknot.obj"}};

std::string model_path(const Model& m) {
  return std::string(CMGEOM_DATA_DIR) + "/textured/" + m.dir + "/" + m.file;
}

bool read_model(const Model& m, CMGeom::Textured_mesh& tm, bool textures) {
  const std::string path = model_path(m);
  if (!fs::exists(path)) return false;
  CMGeom::IO::Read_options ro;
  ro.repair = true;  // DamagedHelmet has a few non-manifold edges
  if (textures) CMGeom::IO::read_textured_mesh(path, tm, ro);
  else CMGeom::IO::read_mesh(path, tm, ro);
  return true;
}

double signed_area(const std::array<UV2, 3>& t) {
  return 0.5 * ((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]));
}

// Per-face UV triangles and chart ids (independent of the package: charts.h from Mesh_IO).
std::size_t layout(const CMGeom::Textured_mesh& tm, std::vector<std::array<UV2, 3>>& tris, std::vector<int>& ids) {
  return TS::internal::uv_layout(tm, tris, ids);
}

// Original UV triangles bucketed on a grid, for exact point-in-chart queries.
struct Chart_regions {
  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> ids;
  double u0 = 0, v0 = 0, su = 1, sv = 1;
  int G = 128;
  std::vector<std::vector<std::size_t>> cells;
  Chart_regions(const std::vector<std::array<UV2, 3>>& t, const std::vector<int>& i) : tris(t), ids(i), cells(std::size_t(G) * G) {
    double u1 = -1e300, v1 = -1e300;
    u0 = v0 = 1e300;
    for (const auto& tri : tris)
      for (const auto& p : tri) {
        u0 = std::min(u0, p[0]); v0 = std::min(v0, p[1]);
        u1 = std::max(u1, p[0]); v1 = std::max(v1, p[1]);
      }
    su = G / std::max(u1 - u0, 1e-12) * 0.999999;
    sv = G / std::max(v1 - v0, 1e-12) * 0.999999;
    for (std::size_t k = 0; k < tris.size(); ++k) {
      double a0 = 1e300, b0 = 1e300, a1 = -1e300, b1 = -1e300;
      for (const auto& p : tris[k]) {
        a0 = std::min(a0, p[0]); b0 = std::min(b0, p[1]);
        a1 = std::max(a1, p[0]); b1 = std::max(b1, p[1]);
      }
      for (int y = cell_y(b0); y <= cell_y(b1); ++y)
        for (int x = cell_x(a0); x <= cell_x(a1); ++x) cells[std::size_t(y) * G + x].push_back(k);
    }
  }
  int cell_x(double u) const { return std::clamp(int((u - u0) * su), 0, G - 1); }
  int cell_y(double v) const { return std::clamp(int((v - v0) * sv), 0, G - 1); }
  /// Charts of the original triangles containing p (closed, with a relative tolerance).
  std::set<int> charts_at(const UV2& p) const {
    std::set<int> out;
    for (std::size_t k : cells[std::size_t(cell_y(p[1])) * G + cell_x(p[0])]) {
      const auto& t = tris[k];
      const double d = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
      if (d == 0) continue;
      const double l1 = ((p[0] - t[0][0]) * (t[2][1] - t[0][1]) - (p[1] - t[0][1]) * (t[2][0] - t[0][0])) / d;
      const double l2 = ((t[1][0] - t[0][0]) * (p[1] - t[0][1]) - (t[1][1] - t[0][1]) * (p[0] - t[0][0])) / d;
      const double eps = 1e-7;
      if (l1 >= -eps && l2 >= -eps && 1 - l1 - l2 >= -eps) out.insert(ids[k]);
    }
    return out;
  }
};

struct Layout_counts {
  std::size_t folded = 0, overlaps = 0, outside = 0;
};

// Counts, for a layout `out` against the original layout `in`:
//  * folded: UV triangles degenerate or oriented against their chart's majority;
//  * overlaps: texel centres (1024 per UV unit) covered twice by triangles of one chart;
//  * outside: UV corners neither inside the original chart their chart corresponds to (the
//    original chart containing most of its corners; exact point-in-triangle tests) nor within 3
//    texels of it (charts may grow by 2 texels across concave corners).
Layout_counts count_layout(const std::vector<std::array<UV2, 3>>& in_tris, const std::vector<int>& in_ids,
                           const std::vector<std::array<UV2, 3>>& out_tris, const std::vector<int>& out_ids) {
  Layout_counts n;
  std::vector<std::array<UV2, 3>> all = in_tris;
  all.insert(all.end(), out_tris.begin(), out_tris.end());
  const TS::Texture_domain dom = TS::make_texture_domain(all, 1024, 1024, 8192);
  std::map<int, double> chart_sign;
  for (std::size_t i = 0; i < out_tris.size(); ++i) chart_sign[out_ids[i]] += signed_area(out_tris[i]);
  for (std::size_t i = 0; i < out_tris.size(); ++i)
    if (!(signed_area(out_tris[i]) * chart_sign[out_ids[i]] > 0)) ++n.folded;
  // chart correspondence, then containment
  const Chart_regions regions(in_tris, in_ids);
  std::map<int, std::map<int, int>> votes;
  std::vector<std::array<std::set<int>, 3>> at(out_tris.size());
  for (std::size_t i = 0; i < out_tris.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      at[i][c] = regions.charts_at(out_tris[i][c]);
      for (int k : at[i][c]) ++votes[out_ids[i]][k];
    }
  std::map<int, int> match;
  for (const auto& kv : votes) {
    int best = -1, bv = -1;
    for (const auto& kc : kv.second)
      if (kc.second > bv) { bv = kc.second; best = kc.first; }
    match[kv.first] = best;
  }
  // charts may grow across concave corners by slivers within 2 texels (1024 per UV unit) of
  // their original texels (Textured_simplification_options::chart_growth_texels): accept corners
  // within 3 texels of the matched chart (rasterised chart ids grown by 3 rings, no other chart)
  const TS::Index_texture margin(dom, in_tris, in_ids, 3);
  for (std::size_t i = 0; i < out_tris.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      if (!match.count(out_ids[i])) { ++n.outside; continue; }
      if (at[i][c].count(match[out_ids[i]])) continue;
      const UV2 t = dom.to_texel(out_tris[i][c]);
      if (margin.chart_of(float(t[0]), float(t[1])) != std::uint32_t(match[out_ids[i]] + 1)) ++n.outside;
    }
  std::map<int, std::vector<std::size_t>> by_chart;
  for (std::size_t i = 0; i < out_tris.size(); ++i) by_chart[out_ids[i]].push_back(i);
  std::vector<int> owner(std::size_t(dom.width) * std::size_t(dom.height), -1);
  for (const auto& kv : by_chart) {
    std::vector<std::size_t> touched;
    for (std::size_t i : kv.second) {
      std::array<UV2, 3> t;
      for (int c = 0; c < 3; ++c) t[c] = dom.to_texel(out_tris[i][c]);
      TS::rasterize_triangle(t, dom.width, dom.height, [&](int x, int y) {
        const std::size_t k = std::size_t(y) * dom.width + x;
        if (owner[k] == kv.first) ++n.overlaps;
        owner[k] = kv.first;
        touched.push_back(k);
      });
    }
    for (std::size_t k : touched) owner[k] = -1;
  }
  return n;
}

// The result introduces no fold, no overlap within a chart and no UV outside its chart (inputs
// that already have folded or self-overlapping charts: not more than they had).
void check_layout(const std::vector<std::array<UV2, 3>>& in_tris, const std::vector<int>& in_ids,
                  const std::vector<std::array<UV2, 3>>& out_tris, const std::vector<int>& out_ids,
                  const std::string& name) {
  const Layout_counts a = count_layout(in_tris, in_ids, in_tris, in_ids);
  const Layout_counts b = count_layout(in_tris, in_ids, out_tris, out_ids);
  EXPECT_EQ(a.outside, 0u) << name << ": input corners outside their own chart";
  EXPECT_LE(b.folded, a.folded) << name << ": folded or degenerate UV triangles";
  EXPECT_LE(b.overlaps, a.overlaps) << name << ": texel centres covered twice within one chart";
  EXPECT_EQ(b.outside, 0u) << name << ": UV corners outside their original chart";
  if (std::getenv("CMGEOM_TS_DIAG"))
    std::cout << name << ": folded " << a.folded << " -> " << b.folded << ", overlap texels " << a.overlaps << " -> "
              << b.overlaps << ", outside " << b.outside << "\n";
}

TEST(TexturedSimplification, ChartConstraintsOnEveryTexturedModel) {
  int tested = 0;
  for (const Model& m : kModels) {
    CMGeom::Textured_mesh tm;
    if (!read_model(m, tm, false)) GTEST_SKIP() << "shared data not found: " << model_path(m);
    ASSERT_TRUE(tm.has_uvs()) << m.file;
    std::vector<std::array<UV2, 3>> in_tris;
    std::vector<int> in_ids;
    const std::size_t charts_in = layout(tm, in_tris, in_ids);
    TS::Textured_simplification_options o;
    o.target_faces = tm.mesh().number_of_faces() / 10;
    o.resample_textures = false;
    const auto r = TS::simplify_textured_mesh(tm, o);
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(tm.mesh())) << m.file;
    std::vector<std::array<UV2, 3>> out_tris;
    std::vector<int> out_ids;
    const std::size_t charts_out = layout(tm, out_tris, out_ids);
    EXPECT_EQ(r.charts_in, charts_in);
    EXPECT_EQ(charts_out, charts_in) << m.file << ": chart count changed";
    EXPECT_EQ(r.charts_out, charts_out);
    check_layout(in_tris, in_ids, out_tris, out_ids, m.file);
    std::cout << m.file << ": " << r.faces_in << " -> " << r.faces_out << " faces (target " << o.target_faces
              << "), charts " << charts_in << " -> " << charts_out << ", refused: topology "
              << r.statistics.topology << ", uv " << r.statistics.uv_fold << ", projection "
              << r.statistics.projection_overlap << "\n";
    // The target is reached, or the run says it stopped at the chart limit (chart corners never
    // move, concave boundary corners move only by slivers within 2 texels, wedges whose input UVs
    // are folded are frozen; measured: bunny10k 1291 faces for 999, Duck 726 for 421,
    // DamagedHelmet 5750 for 1545) — one rule for every model, no per-file slack.
    if (r.stopped_by == TS::Stop_reason::target) {
      EXPECT_LE(r.faces_out, o.target_faces) << m.file;
    } else {
      EXPECT_EQ(r.stopped_by, TS::Stop_reason::chart_limit) << m.file;
      EXPECT_GT(r.faces_out, o.target_faces) << m.file;
    }
    EXPECT_EQ(r.faces_out, tm.mesh().number_of_faces()) << m.file;
    // and the chart limit is far below the input on every model (the worst, DamagedHelmet, keeps 37 %)
    EXPECT_LE(r.faces_out, r.faces_in / 2) << m.file;
    ++tested;
  }
  EXPECT_EQ(tested, 8);
}

TEST(TexturedSimplification, InteriorCollapseKeepsUVsInsideAndChartsOnASimpleGrid) {
  // a flat 10x10 grid with two charts (left/right halves, mirrored right chart): the seam must
  // survive, UVs stay in their half, no folds.
  CMGeom::Textured_mesh tm;
  auto& m = tm.mesh();
  const int N = 10;
  std::vector<CMGeom::Surface_mesh::Vertex_index> v;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) v.push_back(m.add_vertex(CMGeom::Point_3(i, j, 0.01 * ((i * 7 + j * 3) % 5))));
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const auto a = v[j * (N + 1) + i], b = v[j * (N + 1) + i + 1], c = v[(j + 1) * (N + 1) + i + 1],
                 d = v[(j + 1) * (N + 1) + i];
      const auto f1 = m.add_face(a, b, c), f2 = m.add_face(a, c, d);
      for (auto f : {f1, f2})
        for (auto h : CGAL::halfedges_around_face(halfedge(f, m), m)) {
          const auto p = m.point(target(h, m));
          const bool right = (i >= N / 2);
          // left chart: u = x/20; right chart mirrored: u = 1 - (x - 5)/20 at an offset
          const double u = right ? 0.9 - (p.x() - N / 2) / 20.0 : p.x() / 20.0;
          tm.set_uv(h, CMGeom::Point_2(u, p.y() / 10.0));
        }
    }
  tm.set_has_uvs(true);
  std::vector<std::array<UV2, 3>> in_tris, out_tris;
  std::vector<int> in_ids, out_ids;
  ASSERT_EQ(layout(tm, in_tris, in_ids), 2u);
  TS::Textured_simplification_options o;
  o.target_faces = 20;
  o.resample_textures = false;
  const auto r = TS::simplify_textured_mesh(tm, o);
  EXPECT_EQ(layout(tm, out_tris, out_ids), 2u);
  EXPECT_LE(r.faces_out, 40u);
  EXPECT_GT(r.statistics.accepted, 50u);
  check_layout(in_tris, in_ids, out_tris, out_ids, "grid");
}

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
  const TS::Index_texture region(dom, tris, ids, 2);
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
      for (int x = 0; x < atlas.width() && !used; ++x) used = in_chart(x, y) && close_to(atlas, x, y, candidates[k], 0.25f);
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
                    CGAL::parameters::get_cost(policy).get_placement(policy).filter(TS::Chart_constraint_filter<CC>(cc)).visitor(
                        TS::Chart_constraint_visitor<CC, TS::Index_texture_resampler>(cc, &rs)));
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
      if (trial % 3 == 0) t[c] = {{grid(rng) + 0.5, grid(rng) + 0.5}};  // corners on texel centres
      else t[c] = {{coord(rng), coord(rng)}};
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
  int rings = 0;
  for (bool grew = true; grew; ++rings) {
    grew = false;
    std::vector<int> next = filled;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = std::size_t(y) * W + x;
        if (filled[i]) continue;
        float s[3] = {0, 0, 0};
        int cnt = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= W || qy >= H || !filled[std::size_t(qy) * W + qx]) continue;
            for (int c = 0; c < 3; ++c) s[c] += acc[(std::size_t(qy) * W + qx) * 3 + c];
            ++cnt;
          }
        if (cnt == 0) continue;
        for (int c = 0; c < 3; ++c) acc[i * 3 + c] = s[c] / float(cnt);
        next[i] = 1;
        grew = true;
      }
    filled.swap(next);
  }
  EXPECT_GT(rings, 5);
  CMGeom::Image expected(W, H, 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      ASSERT_TRUE(filled[std::size_t(y) * W + x]) << "texel (" << x << ", " << y << ") never reached";
      for (int c = 0; c < 3; ++c) expected.set_value(x, H - 1 - y, c, acc[(std::size_t(y) * W + x) * 3 + c]);
    }
  EXPECT_TRUE(out == expected);
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
                    CGAL::parameters::get_cost(policy).get_placement(policy).filter(TS::Chart_constraint_filter<CC>(cc)).visitor(
                        TS::Chart_constraint_visitor<CC, Both_backends>(cc, &both)));
  gl.synchronize();
  ASSERT_GT(gl.collapses(), 100u) << model.file;
  std::cout << "  " << model.file << ": " << gl.collapses() << " collapses resampled in " << gl.draws() << " draws\n";
  EXPECT_LE(gl.draws(), gl.collapses());
  if (max_batch == 1) EXPECT_GT(gl.draws() * 2, gl.collapses()) << "expected about one draw per collapse";
  else EXPECT_LT(gl.draws() * 3, gl.collapses()) << "independent collapses were not batched";
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

// Texture deviation (Metrics) of the weighted policy against plain quadrics, charts kept (the
// thesis' path, where UVs keep their meaning), default merge, equal face counts. The weighting does
// not lower it in general: measured at 20 % and 30 % on the eight shared textured models, weighted is
// lower in 5 of 16 cases and plain in 11 (doc/Textured_simplification/README.md). The test pins one
// model on each side with a margin of more than 15 %: bob (weighted 0.0247 vs 0.0303 at 30 %) and
// Spot (plain 0.0610 vs 0.0840), so a change of either policy that moves the balance is noticed.
TEST(TexturedSimplification, WeightedPolicyTextureDeviationDependsOnTheModel) {
  for (const char* dir : {"bob", "spot"}) {
    SCOPED_TRACE(dir);
    Model m{};
    for (const Model& k : kModels)
      if (std::string(k.dir) == dir) m = k;
    CMGeom::Textured_mesh base;
    if (!read_model(m, base, false)) GTEST_SKIP() << "shared data not found: " << model_path(m);
    double dev[2];
    std::size_t faces[2];
    for (int weighted = 0; weighted < 2; ++weighted) {
      CMGeom::Textured_mesh tm = base;
      TS::Textured_simplification_options o;
      o.target_faces = base.mesh().number_of_faces() * 3 / 10;
      o.keep_charts = true;
      o.resample_textures = false;
      o.quadric.weighted = weighted == 1;
      TS::simplify_textured_mesh(tm, o);
      CMGeom::Metrics::Error_options eo;
      eo.threads = 1;
      dev[weighted] =
          CMGeom::Metrics::texture_deviation(base.mesh(), base.uv_map(), tm.mesh(), tm.uv_map(), eo).deviation;
      faces[weighted] = tm.mesh().number_of_faces();
    }
    ASSERT_EQ(faces[0], faces[1]) << "compare at equal face counts";
    if (std::string(dir) == "bob")
      EXPECT_LT(dev[1], 0.9 * dev[0]) << "texture deviation: plain " << dev[0] << ", weighted " << dev[1];
    else
      EXPECT_LT(dev[0], 0.9 * dev[1]) << "texture deviation: plain " << dev[0] << ", weighted " << dev[1];
  }
}

// `cmgeom simplify` on a textured input: OBJ + MTL + PNG, JSON keys, charts kept, target
// reached; identical bytes on a second run; clear errors for unusable texture options.
TEST(TexturedSimplification, CommandLineWritesObjMtlPng) {
  const std::string in = std::string(CMGEOM_DATA_DIR) + "/textured/bunny10k_textured/bunny10k_textured.obj";
  if (!fs::exists(in)) GTEST_SKIP() << "shared data not found: " << in;
  const std::string exe = CMGEOM_CMGEOM_EXE;
  const std::string dir = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_textured_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto run = [](const std::string& cmd, std::string* out = nullptr) {
    FILE* p = popen((cmd + " 2>/dev/null").c_str(), "r");
    std::string text;
    char buf[4096];
    std::size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
    const int status = pclose(p);
    if (out) *out = text;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  auto slurp = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  };
  std::string text;
  for (const char* name : {"a", "b"}) {
    ASSERT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/" + name + ".obj' --ratio 0.3 --keep-charts --json", &text), 0);
  }
  const auto j = nlohmann::json::parse(text);
  for (const char* key : {"faces_in", "faces_out", "charts_in", "charts_out", "seconds", "stopped_by"})
    ASSERT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["charts_in"], j["charts_out"]);
  EXPECT_EQ(j["charts"], "kept");
  EXPECT_EQ(j["faces_in"].get<int>(), 9999);
  EXPECT_LE(j["faces_out"].get<int>(), 3000);
  EXPECT_TRUE(fs::exists(dir + "/a.mtl"));
  EXPECT_TRUE(fs::exists(dir + "/a_0_diffuse.png"));
  EXPECT_EQ(slurp(dir + "/a.obj").size() > 1000, true);
  // deterministic (the OBJ names its own MTL, so compare the textures and the MTL-free body)
  EXPECT_EQ(slurp(dir + "/a_0_diffuse.png"), slurp(dir + "/b_0_diffuse.png"));
  std::string a = slurp(dir + "/a.obj"), b = slurp(dir + "/b.obj");
  a = a.substr(a.find("\nv "));
  b = b.substr(b.find("\nv "));
  EXPECT_EQ(a, b);
  // the written mesh reads back with its UVs and texture
  CMGeom::Textured_mesh back;
  CMGeom::IO::read_textured_mesh(dir + "/a.obj", back);
  EXPECT_TRUE(back.has_uvs());
  ASSERT_FALSE(back.materials().empty());
  EXPECT_EQ(back.materials()[0].diffuse_image.width(), 512);
  // errors: one line, exit code 1, no output file
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/c.ply' --ratio 0.3"), 1);
#ifdef CMGEOM_HAS_OSMESA
  // the OpenGL backend writes the same files, byte for byte
  ASSERT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/gl.obj' --ratio 0.3 --keep-charts --texture-backend osmesa --json", &text), 0);
  EXPECT_EQ(nlohmann::json::parse(text).value("texture_backend", ""), "osmesa");
  EXPECT_EQ(slurp(dir + "/a_0_diffuse.png"), slurp(dir + "/gl_0_diffuse.png"));
  std::string g = slurp(dir + "/gl.obj");
  EXPECT_EQ(a, g.substr(g.find("\nv ")));
#else
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/c.obj' --ratio 0.3 --keep-charts --texture-backend osmesa"), 1);
#endif
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/c.obj' --ratio 0.3 --texture-size 4"), 1);
  EXPECT_FALSE(fs::exists(dir + "/c.obj"));
  EXPECT_FALSE(fs::exists(dir + "/c.ply"));
}

// The tangent-plane bijectivity test of §3.5 (Chart_constraints::projections_are_bijective), on an
// interior edge of a flat 5 x 5 grid collapsed to its midpoint. Flat, the star's projections onto
// its plane tile the star: accepted. With one ring vertex of the star pulled over the edge's first
// vertex and lifted (an overhang: its triangles project reversed onto the star's plane) the test
// refuses and counts a projection overlap; the same collapse passes when only that test is switched
// off (the texture coordinates stay those of the flat grid, so no other rule refuses it).
TEST(TexturedSimplification, BijectivityTestRefusesAnOverhangingStarAndPassesAFlatOne) {
  auto grid = [](bool overhang) {
    CMGeom::Textured_mesh tm;
    auto& m = tm.mesh();
    std::vector<CMGeom::Surface_mesh::Vertex_index> v;
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i) {
        CMGeom::Point_3 p(i, j, 0);
        if (overhang && i == 1 && j == 2) p = CMGeom::Point_3(2.3, 2.2, 0.5);
        v.push_back(m.add_vertex(p));
      }
    auto at = [&](int i, int j) { return v[std::size_t(j * 5 + i)]; };
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) {
        m.add_face(at(i, j), at(i + 1, j), at(i + 1, j + 1));
        m.add_face(at(i, j), at(i + 1, j + 1), at(i, j + 1));
      }
    for (auto h : m.halfedges()) {  // UVs: the flat grid's, whatever the 3D positions
      if (m.is_border(h)) continue;
      const std::size_t k = std::size_t(m.target(h));
      tm.set_uv(h, CMGeom::Point_2(double(k % 5) / 4, double(k / 5) / 4));
    }
    tm.set_has_uvs(true);
    return tm;
  };
  using VPM = boost::property_map<CMGeom::Surface_mesh, CGAL::vertex_point_t>::type;
  using CC = TS::Chart_constraints<CMGeom::Surface_mesh, VPM, CMGeom::Textured_mesh::UV_map>;
  auto try_collapse = [](CMGeom::Textured_mesh& tm, bool bijectivity, TS::Chart_constraint_statistics& stats) {
    auto& m = tm.mesh();
    const CMGeom::Surface_mesh::Vertex_index v0(12), v1(13);  // grid points (2,2) and (3,2): interior
    const auto h = m.halfedge(v0, v1);
    EXPECT_TRUE(h != CMGeom::Surface_mesh::null_halfedge());
    TS::Chart_constraint_options o;
    o.bijectivity = bijectivity;
    o.boundary_half_edge_collapses = false;
    CC cc(m, get(CGAL::vertex_point, m), tm.uv_map(), o);
    const bool ok = cc.test(h, {{2.5, 2.0, 0.0}});
    stats = cc.statistics();
    return ok;
  };
  TS::Chart_constraint_statistics st;
  CMGeom::Textured_mesh flat = grid(false);
  EXPECT_TRUE(try_collapse(flat, true, st)) << "a flat star's collapse must pass the bijectivity test";
  EXPECT_EQ(st.projection_overlap, 0u);
  CMGeom::Textured_mesh folded = grid(true);
  EXPECT_FALSE(try_collapse(folded, true, st)) << "an overhanging star must be refused";
  EXPECT_EQ(st.projection_overlap, 1u);
  EXPECT_EQ(st.uv_fold + st.topology + st.degenerate, 0u) << "refused for another reason than bijectivity";
  EXPECT_TRUE(try_collapse(folded, false, st)) << "without the bijectivity test nothing else refuses it";
}

}  // namespace
