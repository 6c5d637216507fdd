// Tests of the Rendering package: coverage of a rendered sphere, texel colours of a textured
// quad, chart-boundary overlay on a hand-made mesh, bit-identical PNGs, colour map, UV atlas,
// image-space error, grids.
#include <CMGeom/Rendering.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>

#include "cmgeom_test_meshes.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "cmgeom_test_config.h"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
namespace R = CMGeom::Rendering;
using CMGeom::Image;

// The tests that draw need the renderer (target CMGeom::OSMesa); without it they are replaced by
// one test that reports the skip.

#ifdef CMGEOM_HAS_OSMESA
// One renderer for the whole suite (contexts are cheap, shader JIT is not).
R::Renderer& renderer() {
  static R::Renderer* r = [] {
    // Mesa's shader cache goes to the build tree, not to the user's home.
    setenv("MESA_SHADER_CACHE_DIR", CMGEOM_TEST_TMP_DIR "/mesa_shader_cache", 0);
    return new R::Renderer();
  }();
  return *r;
}

Mesh make_mesh(const std::vector<K::Point_3>& pts, const std::vector<std::vector<std::size_t>>& faces) {
  Mesh m;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(pts, faces, m);
  return m;
}

Mesh icosphere(int level) {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(level, p, f);
  std::vector<K::Point_3> pts;
  for (const auto& q : p) pts.emplace_back(q[0], q[1], q[2]);
  std::vector<std::vector<std::size_t>> faces;
  for (const auto& tri : f) faces.push_back({tri[0], tri[1], tri[2]});
  return make_mesh(pts, faces);
}

// n x n grid of [0,1]^2 at z = 0, two triangles per cell.
Mesh grid(int n) {
  std::vector<K::Point_3> pts;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) pts.emplace_back(double(i) / n, double(j) / n, 0.);
  std::vector<std::vector<std::size_t>> faces;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      faces.push_back({a, b, d});
      faces.push_back({a, d, c});
    }
  return make_mesh(pts, faces);
}

using UV_map = Mesh::Property_map<Mesh::Halfedge_index, K::Point_2>;

// Looks at [0,1]^2 from +Z so that the square fills the picture exactly.
R::Render_options square_view(int size) {
  R::Render_options o;
  o.width = o.height = size;
  o.projection = R::Projection::Orthographic;
  o.ortho_half_height = 0.5;
  o.view(0., 0.);
  o.lighting = false;
  return o;
}

std::array<int, 4> pixel(const Image& img, int x, int y) {
  return {img.bytes()[img.index(x, y, 0)], img.bytes()[img.index(x, y, 1)], img.bytes()[img.index(x, y, 2)],
          img.bytes()[img.index(x, y, 3)]};
}

TEST(Rendering, SphereCoverageMatchesDiscArea) {
  const Mesh sphere = icosphere(5);
  const R::Render_mesh rm = R::make_render_mesh(sphere);
  R::Render_options o;
  o.width = o.height = 512;
  o.projection = R::Projection::Orthographic;
  const Image img = renderer().render(rm, o);
  ASSERT_EQ(img.width(), 512);
  ASSERT_EQ(img.channels(), 4);
  std::size_t covered = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) covered += img.bytes()[img.index(x, y, 3)] >= 128;
  // Bounding box [-1,1]^3: R = sqrt(3); the unit sphere covers a disc of radius
  // 1 / (R margin) * 256 pixels (Render_options' framing rule).
  const double r = 1. / (std::sqrt(3.) * o.margin) * 256.;
  const double expected = 3.14159265358979 * r * r;
  EXPECT_NEAR(double(covered), expected, 0.01 * expected);
  // Centred: the centre pixel is covered and shaded (not the background), the corners are not.
  EXPECT_EQ(pixel(img, 256, 256)[3], 255);
  EXPECT_EQ(pixel(img, 0, 0)[3], 0);
  EXPECT_EQ(pixel(img, 0, 0)[0], 255);  // white background
}

TEST(Rendering, CheckerboardTexelsAtKnownPixels) {
  Mesh quad = grid(1);
  UV_map uv = quad.add_property_map<Mesh::Halfedge_index, K::Point_2>("h:uv").first;
  for (auto h : quad.halfedges())
    if (!quad.is_border(h)) uv[h] = K::Point_2(quad.point(quad.target(h)).x(), quad.point(quad.target(h)).y());
  // 8 x 8 texels; texel (i, j) (j = image row, 0 at the top) has a colour that encodes i and j,
  // so that a flipped or transposed texture is detected.
  Image tex(8, 8, 3);
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      tex.bytes()[tex.index(i, j, 0)] = std::uint8_t(30 * i);
      tex.bytes()[tex.index(i, j, 1)] = std::uint8_t(30 * j);
      tex.bytes()[tex.index(i, j, 2)] = (i + j) % 2 ? 255 : 0;
    }
  R::Render_mesh_inputs<UV_map> in;
  in.uv = &uv;
  in.texture_of = [&](std::size_t) { return &tex; };
  const R::Render_mesh rm = R::make_render_mesh(quad, quad.points(), in);
  R::Render_options o = square_view(8 * 33);
  o.shading = R::Shading::Textured;
  const Image img = renderer().render(rm, o);
  // Texel (i, j) covers pixels [33 i, 33 i + 33) x [33 j, 33 j + 33) (v = 1 at the top); the
  // centre of pixel 33 i + 16 is the texel centre, where bilinear filtering returns the texel.
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const auto p = pixel(img, 33 * i + 16, 33 * j + 16);
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(p[k], tex.bytes()[tex.index(i, j, k)], 1) << "texel " << i << "," << j << " channel " << k;
      EXPECT_EQ(p[3], 255);
    }
}

TEST(Rendering, ChartOverlayMarksExactlyTheSeams) {
  // 4 x 4 grid cut into two charts along x = 0.5: the left half maps to the left half of the
  // atlas, the right half to the right half shifted up. Seams: the 4 edges on x = 0.5.
  Mesh m = grid(4);
  UV_map uv = m.add_property_map<Mesh::Halfedge_index, K::Point_2>("h:uv").first;
  for (auto f : m.faces()) {
    double cx = 0.;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) cx += m.point(v).x() / 3.;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
      const auto& p = m.point(m.target(h));
      uv[h] = cx < 0.5 ? K::Point_2(0.5 * p.x(), 0.5 * p.y()) : K::Point_2(0.5 * p.x() + 0.25, 0.5 * p.y() + 0.5);
    }
  }
  const auto seams = R::seam_edges(m, uv);
  ASSERT_EQ(seams.size(), 4u);
  for (auto e : seams) {
    EXPECT_EQ(m.point(m.vertex(e, 0)).x(), 0.5);
    EXPECT_EQ(m.point(m.vertex(e, 1)).x(), 0.5);
  }
  R::Render_mesh_inputs<UV_map> in;
  in.uv = &uv;
  const R::Render_mesh rm = R::make_render_mesh(m, m.points(), in);
  EXPECT_EQ(rm.chart_lines.size(), 4u * 6u);
  R::Render_options o = square_view(256);
  o.charts = true;
  const Image img = renderer().render(rm, o);
  // x = 0.5 is the pixel column boundary 128: red pixels must be there and nowhere else.
  std::size_t red = 0, stray = 0;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const auto p = pixel(img, x, y);
      if (p[0] > 200 && p[1] < 80 && p[2] < 80) {
        ++red;
        if (std::abs(x - 127.5) > 2.) ++stray;
      }
    }
  EXPECT_GE(red, 250u);  // a 2-pixel line over the full height
  EXPECT_EQ(stray, 0u);
  // Without the overlay there is no red at all.
  o.charts = false;
  const Image plain = renderer().render(rm, o);
  for (int y = 0; y < 256; ++y) EXPECT_EQ(pixel(plain, 128, y), pixel(plain, 40, y));  // uniform
}

TEST(Rendering, SoupChartsMatchTheHalfedgeMesh) {
  // The same two-chart grid as a polygon soup (quads, UV indices per corner): 4 seam sides.
  CMGeom::Polygon_soup s;
  const int n = 4;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s.positions.push_back({{double(i) / n, double(j) / n, 0.}});
  for (int half = 0; half < 2; ++half)  // uv block per chart: index = half * 25 + vertex
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) s.uvs.push_back({{0.5 * i / n + 0.25 * half, 0.5 * j / n + 0.5 * half}});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = j * (n + 1) + i, quad[4] = {a, a + 1, a + n + 2, a + n + 1};
      const std::uint32_t off = i < n / 2 ? 0 : 25;
      for (std::uint32_t v : quad) {
        s.corner_vertex.push_back(v);
        s.corner_uv.push_back(v + off);
      }
      s.face_start.push_back(std::uint32_t(s.corner_vertex.size()));
      s.face_material.push_back(0);
    }
  const R::Render_mesh rm = R::make_render_mesh(s);
  EXPECT_EQ(rm.triangle_count(), 32u);
  EXPECT_EQ(rm.wire_lines.size() / 6, 40u);  // quad sides, no diagonals
  ASSERT_EQ(rm.chart_lines.size(), 4u * 6u);
  for (std::size_t i = 0; i < rm.chart_lines.size(); i += 3) EXPECT_EQ(rm.chart_lines[i], 0.5f);
  EXPECT_TRUE(rm.has_uvs());
}

TEST(Rendering, ScalarFieldUsesTheColourMap) {
  Mesh quad = grid(2);
  std::vector<double> field(quad.number_of_vertices(), 3.0);
  const R::Render_mesh rm = R::make_render_mesh(quad, &field);
  R::Render_options o = square_view(64);
  o.shading = R::Shading::Field;
  o.field_min = 3.0;
  o.field_max = 5.0;
  auto low = R::viridis(0.);
  Image img = renderer().render(rm, o);
  auto p = pixel(img, 32, 32);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[k], low[k], 1);
  o.field_min = 1.0;  // 3 is now the top of the range
  o.field_max = 3.0;
  img = renderer().render(rm, o);
  p = pixel(img, 32, 32);
  const auto high = R::viridis(1.);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(p[k], high[k], 1);
  // A field of the wrong length is refused.
  std::vector<double> short_field(3, 0.);
  EXPECT_THROW(R::make_render_mesh(quad, &short_field), CMGeom::Invalid_input);
  const R::Render_mesh no_field = R::make_render_mesh(quad);
  EXPECT_THROW(renderer().render(no_field, o), CMGeom::Invalid_input);
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(Rendering, PngIsBitIdenticalTwiceAndUpright) {
  const Mesh sphere = icosphere(3);
  std::vector<double> field;
  for (auto v : sphere.vertices()) field.push_back(sphere.point(v).y());
  const R::Render_mesh rm = R::make_render_mesh(sphere, &field);
  R::Render_options o;
  o.width = 320;
  o.height = 240;
  o.shading = R::Shading::Field;
  o.wireframe = true;
  o.legend_label = "height";
  o.caption = "icosphere 3";
  const std::string a = std::string(CMGEOM_TEST_TMP_DIR) + "/render_a.png";
  const std::string b = std::string(CMGEOM_TEST_TMP_DIR) + "/render_b.png";
  R::render_to_png(a, rm, o);
  R::render_to_png(b, rm, o);
  const std::string da = slurp(a), db = slurp(b);
  ASSERT_GT(da.size(), 1000u);
  EXPECT_EQ(da, db);
  // The file holds the decorated picture, top row first: the field is y, so the top of the
  // sphere (row < centre) shows the high end of the colour map (yellow: red channel high).
  const Image back = CMGeom::IO::read_image(a);
  ASSERT_EQ(back.width(), 320);
  ASSERT_EQ(back.height(), 240);
  EXPECT_EQ(back, R::render_picture(renderer(), rm, o));
  const int top_y = 120 - 40, bottom_y = 120 + 40;
  EXPECT_GT(back.bytes()[back.index(160, top_y, 0)], back.bytes()[back.index(160, bottom_y, 0)]);
}

TEST(Rendering, UvAtlasShowsTextureAndLayout) {
  Mesh quad = grid(2);
  UV_map uv = quad.add_property_map<Mesh::Halfedge_index, K::Point_2>("h:uv").first;
  for (auto h : quad.halfedges())
    if (!quad.is_border(h)) uv[h] = K::Point_2(quad.point(quad.target(h)).x(), quad.point(quad.target(h)).y());
  Image tex(4, 4, 3);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) tex.bytes()[tex.index(i, j, 1)] = 200;  // green
  R::Render_mesh_inputs<UV_map> in;
  in.uv = &uv;
  in.texture_of = [&](std::size_t) { return &tex; };
  const R::Render_mesh rm = R::make_render_mesh(quad, quad.points(), in);
  const Image atlas = renderer().render_uv_atlas(rm, 128);
  ASSERT_EQ(atlas.width(), 128);
  const auto inside = pixel(atlas, 20, 40);  // away from every UV edge
  EXPECT_NEAR(inside[1], 200, 2);
  EXPECT_EQ(inside[0], 0);
  const auto on_line = pixel(atlas, 64, 40);  // the edge u = 0.5 runs along column 64
  EXPECT_LT(on_line[1], 150);
  const R::Render_mesh plain = R::make_render_mesh(quad);
  EXPECT_THROW(renderer().render_uv_atlas(plain, 64), CMGeom::Invalid_input);
}

TEST(Rendering, ImageSpaceErrorOver26Views) {
  const Mesh fine = icosphere(4), coarse = icosphere(1);
  const R::Render_mesh a = R::make_render_mesh(fine), b = R::make_render_mesh(coarse);
  R::Image_space_error_options opt;
  opt.size = 96;
  const auto same = R::image_space_error(renderer(), a, a, opt);
  EXPECT_EQ(same.total.views, 26u);
  EXPECT_GT(same.total.pixels, 0u);
  EXPECT_EQ(same.total.rmse, 0.);
  EXPECT_TRUE(std::isinf(same.total.psnr));
  const auto diff = R::image_space_error(renderer(), a, b, opt);
  EXPECT_GT(diff.total.rmse, 0.);
  EXPECT_LT(diff.total.psnr, 60.);
  EXPECT_GT(diff.total.psnr, 10.);
  ASSERT_EQ(diff.per_view.size(), 26u);
  // Deterministic.
  const auto again = R::image_space_error(renderer(), a, b, opt);
  EXPECT_EQ(again.total.rmse, diff.total.rmse);
}

#else
TEST(Rendering, RendererNotBuilt) { GTEST_SKIP() << R::rendering_unavailable_message(); }
#endif  // CMGEOM_HAS_OSMESA

TEST(Rendering, GridAndViews) {
  std::vector<Image> cells(3, Image(40, 30, 4));
  const Image g = R::make_grid(cells, {"A", "B", "C"}, 2);
  EXPECT_EQ(g.channels(), 3);
  EXPECT_EQ(g.width(), 2 * 40 + 3 * 4);
  EXPECT_GT(g.height(), 2 * 30);
  const auto views = R::cube_views_26();
  EXPECT_EQ(views.size(), 26u);
  EXPECT_NEAR(R::parse_view("top").elevation, 90., 0.);
  EXPECT_NEAR(R::parse_view("10,-20").elevation, -20., 0.);
  EXPECT_THROW(R::parse_view("10,100"), CMGeom::Invalid_input);
  EXPECT_THROW(R::parse_view("sideways"), CMGeom::Invalid_input);
}

}  // namespace
