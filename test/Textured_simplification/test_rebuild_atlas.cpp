// Tests of the rebuilt atlas (rebuild_atlas.h), the default of simplify_textured_mesh(): any
// target reached on every shared textured model, a layout without folds, overlaps or UVs outside
// [0,1]², colours and tangent-space normals reproduced where the reference is known exactly (a
// flat model, whose simplification keeps the geometry), the chart-keeping mode's stop reason, and
// the command line's stop report, repair warning and missing-texture message.
#include "cmgeom_test_config.h"
#include "cmgeom_test_support.h"

#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
namespace fs = std::filesystem;
using CMGeom::Point_2;
using CMGeom::Point_3;
using CMGeom::Vector_3;

const char* const kTextured[][2] = {{"spot", "spot.obj"},
                                    {"bob", "bob_tri.obj"},
                                    {"fuze", "fuze.obj"},
                                    {"DamagedHelmet", "DamagedHelmet.obj"},
                                    {"WaterBottle", "WaterBottle.obj"},
                                    {"Duck", "Duck.obj"},
                                    {"bunny10k_textured", "bunny10k_textured.obj"},
                                    {"texturedknot", "texturedknot.obj"}};

std::string textured_path(int i) {
  return std::string(CMGEOM_DATA_DIR) + "/textured/" + kTextured[i][0] + "/" + kTextured[i][1];
}

// Reads model i with decoded textures (spot's OBJ names none: its PNG is beside it).
bool read_textured(int i, CMGeom::Textured_mesh& tm) {
  const std::string path = textured_path(i);
  if (!fs::exists(path)) return false;
  CMGeom::IO::Read_options ro;
  ro.repair = true;  // DamagedHelmet has 7 non-manifold edges
  CMGeom::IO::read_mesh(path, tm, ro);
  if (std::string(kTextured[i][0]) == "spot") {
    tm.materials().assign(1, CMGeom::Material());
    tm.materials()[0].name = "spot";
    tm.materials()[0].diffuse_texture = std::string(CMGEOM_DATA_DIR) + "/textured/spot/spot_texture.png";
    for (auto f : tm.mesh().faces()) tm.material_map()[f] = 0;
  }
  CMGeom::IO::load_textures(tm);
  return true;
}

struct Layout_check {
  std::size_t outside = 0, folded = 0, overlapping_texels = 0;
};

// Output layout, tested independently of the package's packer: corners in [0,1]², every UV
// triangle positively oriented, no texel centre (at the texture's resolution) inside two UV
// triangles (half-open edge rule, so that neighbours sharing an edge count once).
Layout_check check_layout(const CMGeom::Textured_mesh& tm, int W, int H) {
  Layout_check c;
  const auto& m = tm.mesh();
  std::vector<unsigned char> hit(std::size_t(W) * std::size_t(H), 0);
  for (auto f : m.faces()) {
    std::array<Point_2, 3> t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) t[std::size_t(k++)] = tm.uv(h);
    for (const auto& p : t)
      if (!(p.x() >= 0 && p.x() <= 1 && p.y() >= 0 && p.y() <= 1)) ++c.outside;
    const double area = (t[1].x() - t[0].x()) * (t[2].y() - t[0].y()) - (t[1].y() - t[0].y()) * (t[2].x() - t[0].x());
    if (!(area > 0)) {
      ++c.folded;
      continue;
    }
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const auto& p : t) {
      x0 = std::min(x0, p.x() * W);
      x1 = std::max(x1, p.x() * W);
      y0 = std::min(y0, p.y() * H);
      y1 = std::max(y1, p.y() * H);
    }
    for (int y = std::max(0, int(std::floor(y0))); y <= std::min(H - 1, int(std::ceil(y1))); ++y)
      for (int x = std::max(0, int(std::floor(x0))); x <= std::min(W - 1, int(std::ceil(x1))); ++x) {
        const double px = x + 0.5, py = y + 0.5;
        bool inside = true;
        for (int e = 0; e < 3 && inside; ++e) {
          const Point_2& a = t[std::size_t(e)];
          const Point_2& b = t[std::size_t((e + 1) % 3)];
          const double ax = a.x() * W, ay = a.y() * H, bx = b.x() * W, by = b.y() * H;
          const double s = (bx - ax) * (py - ay) - (by - ay) * (px - ax);
          // half-open: on an edge counts only for edges going "up" or "left"
          inside = s > 0 || (s == 0 && (by > ay || (by == ay && bx < ax)));
        }
        if (!inside) continue;
        unsigned char& hcount = hit[std::size_t(y) * std::size_t(W) + std::size_t(x)];
        if (hcount) ++c.overlapping_texels;
        hcount = 1;
      }
  }
  return c;
}

TEST(RebuiltAtlas, ReachesTheTargetOnEveryTexturedModelWithAValidLayout) {
  int tested = 0;
  for (int i = 0; i < 8; ++i) {
    CMGeom::Textured_mesh tm;
    if (!read_textured(i, tm)) GTEST_SKIP() << "shared data not found: " << textured_path(i);
    SCOPED_TRACE(kTextured[i][0]);
    const std::size_t faces_in = tm.mesh().number_of_faces();
    TS::Textured_simplification_options o;
    o.target_faces = std::size_t(std::llround(0.02 * double(faces_in)));
    const TS::Textured_simplification_result r = TS::simplify_textured_mesh(tm, o);
    EXPECT_FALSE(r.charts_kept);
    EXPECT_EQ(r.stopped_by, TS::Stop_reason::target);
    EXPECT_LE(double(r.faces_out), 1.02 * double(o.target_faces) + 4);
    EXPECT_EQ(r.faces_out, tm.mesh().number_of_faces());
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(tm.mesh()));
    ASSERT_EQ(tm.materials().size(), 1u);
    const CMGeom::Image& img = tm.materials()[0].diffuse_image;
    ASSERT_FALSE(img.empty());
    EXPECT_EQ(img.width(), r.texture_width);
    EXPECT_EQ(r.charts_out, r.atlas.charts);
    const Layout_check c = check_layout(tm, img.width(), img.height());
    EXPECT_EQ(c.outside, 0u);
    EXPECT_EQ(c.folded, 0u);
    EXPECT_EQ(c.overlapping_texels, 0u);
    EXPECT_GT(r.atlas.coverage, 0.2) << "the packing wastes most of the texture";
    std::cout << kTextured[i][0] << ": " << faces_in << " -> " << r.faces_out << " faces, " << r.charts_out
              << " charts, coverage " << r.atlas.coverage << ", unmatched texels " << r.atlas.texels_unmatched << "\n";
    ++tested;
  }
  EXPECT_EQ(tested, 8);
}

// A flat square (z = 0) whose UVs are the plane coordinates turned by `turn` radians about the
// square's centre and scaled into [0.15, 0.85]²; a smooth colour texture, and optionally a
// constant tangent-space normal map.
struct Flat_square {
  CMGeom::Textured_mesh tm;
  double turn;
  Point_2 uv_of(const Point_3& p) const {
    const double x = p.x() - 0.5, y = p.y() - 0.5;
    const double c = std::cos(turn), s = std::sin(turn);
    return Point_2(0.5 + 0.45 * (c * x - s * y), 0.5 + 0.45 * (s * x + c * y));
  }
};

Flat_square flat_square(int N, int texels, double turn, const double* tangent_normal) {
  Flat_square sq{CMGeom::Textured_mesh(), turn};
  auto& m = sq.tm.mesh();
  std::vector<CMGeom::Surface_mesh::Vertex_index> v;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) v.push_back(m.add_vertex(Point_3(double(i) / N, double(j) / N, 0)));
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const auto a = v[std::size_t(j * (N + 1) + i)], b = v[std::size_t(j * (N + 1) + i + 1)],
                 c = v[std::size_t((j + 1) * (N + 1) + i + 1)], d = v[std::size_t((j + 1) * (N + 1) + i)];
      for (auto f : {m.add_face(a, b, c), m.add_face(a, c, d)})
        for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) sq.tm.set_uv(h, sq.uv_of(m.point(m.target(h))));
    }
  sq.tm.set_has_uvs(true);
  CMGeom::Image img(texels, texels, 3);
  for (int y = 0; y < texels; ++y)
    for (int x = 0; x < texels; ++x) {
      const double u = (x + 0.5) / texels, w = (y + 0.5) / texels;
      img.set_value(x, y, 0, float(0.5 + 0.4 * std::sin(9 * u) * std::cos(7 * w)));
      img.set_value(x, y, 1, float(0.5 + 0.4 * std::cos(11 * u + 3 * w)));
      img.set_value(x, y, 2, float(u * w));
    }
  sq.tm.materials().resize(1);
  sq.tm.materials()[0].name = "square";
  sq.tm.materials()[0].diffuse_image = img;
  if (tangent_normal) {
    CMGeom::Image nm(64, 64, 3);
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x)
        for (int k = 0; k < 3; ++k) nm.set_value(x, y, k, float(0.5 * tangent_normal[k] + 0.5));
    sq.tm.materials()[0].normal_image = nm;
  }
  return sq;
}

// Bilinear texel value of `img` at uv (v up, image row 0 at the top), clamped at the borders.
double bilinear(const CMGeom::Image& img, double u, double v, int c) {
  const double px = u * img.width() - 0.5, py = (1 - v) * img.height() - 0.5;
  const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
  const double fx = px - x0, fy = py - y0;
  auto at = [&](int x, int y) {
    return double(img.value(std::clamp(x, 0, img.width() - 1), std::clamp(y, 0, img.height() - 1), c));
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// For every output texel centre inside an output UV triangle: its 3D point (barycentric in the
// output triangle), the original UV there (known in closed form), and f(texel, original uv, face
// corners' positions and UVs).
template <class F>
void for_each_output_texel(const CMGeom::Textured_mesh& out, int W, int H, F&& f) {
  const auto& m = out.mesh();
  for (auto face : m.faces()) {
    std::array<Point_2, 3> t;
    std::array<Point_3, 3> p;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(face), m)) {
      t[std::size_t(k)] = out.uv(h);
      p[std::size_t(k++)] = m.point(m.target(h));
    }
    const double det = (t[1].x() - t[0].x()) * (t[2].y() - t[0].y()) - (t[2].x() - t[0].x()) * (t[1].y() - t[0].y());
    ASSERT_GT(det, 0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const double u = (x + 0.5) / W, v = (y + 0.5) / H;
        const double b1 = ((u - t[0].x()) * (t[2].y() - t[0].y()) - (t[2].x() - t[0].x()) * (v - t[0].y())) / det;
        const double b2 = ((t[1].x() - t[0].x()) * (v - t[0].y()) - (u - t[0].x()) * (t[1].y() - t[0].y())) / det;
        // strictly inside (a margin of a few texels' worth of barycentric tolerance is not needed:
        // texels on edges are covered by one of the two faces)
        if (b1 < 1e-9 || b2 < 1e-9 || b1 + b2 > 1 - 1e-9) continue;
        const double b0 = 1 - b1 - b2;
        const Point_3 q(b0 * p[0].x() + b1 * p[1].x() + b2 * p[2].x(), b0 * p[0].y() + b1 * p[1].y() + b2 * p[2].y(),
                        0);
        f(x, H - 1 - y, q, t, p);
      }
  }
}

TEST(RebuiltAtlas, ReproducesTheColoursOfAFlatModel) {
  Flat_square sq = flat_square(24, 256, 0.5, nullptr);
  const CMGeom::Textured_mesh original = sq.tm;
  TS::Textured_simplification_options o;
  o.target_faces = 40;
  const auto r = TS::simplify_textured_mesh(sq.tm, o);
  ASSERT_FALSE(r.charts_kept);
  ASSERT_LE(r.faces_out, 40u);
  const CMGeom::Image& out = sq.tm.materials()[0].diffuse_image;
  const CMGeom::Image& in = original.materials()[0].diffuse_image;
  ASSERT_EQ(out.width(), 256);
  double worst = 0;
  std::size_t n = 0;
  for_each_output_texel(sq.tm, out.width(), out.height(), [&](int x, int y, const Point_3& q, auto&, auto&) {
    const Point_2 uv = sq.uv_of(q);  // where the original shows this point
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(double(out.value(x, y, c)) - bilinear(in, uv.x(), uv.y(), c)));
    ++n;
  });
  EXPECT_GT(n, 10000u);
  // 8-bit storage of both textures (half a level each) and the bilinear filter of a smooth ramp
  EXPECT_LE(worst, 2.5 / 255) << "largest colour difference over " << n << " texels";
}

// Object-space normal of a tangent-space value `t` in the tangent frame of the UV map of a
// triangle: T and B follow the UV gradients, N the face (here +z).
Vector_3 object_normal(const double* t, const std::array<Point_2, 3>& uv, const std::array<Point_3, 3>& p) {
  const Vector_3 e1 = p[1] - p[0], e2 = p[2] - p[0];
  const double du1 = uv[1].x() - uv[0].x(), dv1 = uv[1].y() - uv[0].y(), du2 = uv[2].x() - uv[0].x(),
               dv2 = uv[2].y() - uv[0].y();
  const double det = du1 * dv2 - du2 * dv1;
  Vector_3 T = (e1 * dv2 - e2 * dv1) / det, B = (e2 * du1 - e1 * du2) / det;
  T = T / std::sqrt(T.squared_length());
  B = B / std::sqrt(B.squared_length());
  const Vector_3 N(0, 0, 1);
  const Vector_3 n = t[0] * T + t[1] * B + t[2] * N;
  return n / std::sqrt(n.squared_length());
}

TEST(RebuiltAtlas, CarriesATangentSpaceNormalMapThroughTheNewFrames) {
  const double tn[3] = {0.48, -0.36, 0.8};  // unit length
  for (double turn : {0.0, 0.6, 2.0}) {
    SCOPED_TRACE(turn);
    Flat_square sq = flat_square(16, 128, turn, tn);
    // the original's object-space normal (the same everywhere: a flat square, one rotation)
    std::array<Point_2, 3> uv0;
    std::array<Point_3, 3> p0{{Point_3(0, 0, 0), Point_3(1, 0, 0), Point_3(0, 1, 0)}};
    for (int k = 0; k < 3; ++k) uv0[std::size_t(k)] = sq.uv_of(p0[std::size_t(k)]);
    const Vector_3 expected = object_normal(tn, uv0, p0);
    TS::Textured_simplification_options o;
    o.target_faces = 30;
    TS::simplify_textured_mesh(sq.tm, o);
    ASSERT_EQ(sq.tm.materials().size(), 1u);
    const CMGeom::Image& nm = sq.tm.materials()[0].normal_image;
    ASSERT_FALSE(nm.empty()) << "the normal map was dropped";
    double worst = 0;
    std::size_t n = 0;
    for_each_output_texel(
        sq.tm, nm.width(), nm.height(), [&](int x, int y, const Point_3&, const auto& t, const auto& p) {
          double v[3];
          for (int c = 0; c < 3; ++c) v[c] = 2.0 * nm.value(x, y, c) - 1.0;
          const Vector_3 got = object_normal(v, t, p);
          worst = std::max(worst, std::acos(std::clamp(got * expected, -1.0, 1.0)) * 180 / 3.14159265358979);
          ++n;
        });
    EXPECT_GT(n, 1000u);
    EXPECT_LE(worst, 1.5) << "degrees between the carried and the original object-space normal";
  }
}

TEST(RebuiltAtlas, KeepChartsStopsAtTheChartLimitAndSaysSo) {
  const int helmet = 3;
  CMGeom::Textured_mesh tm;
  if (!fs::exists(textured_path(helmet))) GTEST_SKIP() << "shared data not found: " << textured_path(helmet);
  CMGeom::IO::Read_options ro;
  ro.repair = true;
  CMGeom::IO::read_mesh(textured_path(helmet), tm, ro);
  TS::Textured_simplification_options o;
  o.target_faces = tm.mesh().number_of_faces() / 10;
  o.keep_charts = true;
  o.resample_textures = false;
  const auto r = TS::simplify_textured_mesh(tm, o);
  EXPECT_TRUE(r.charts_kept);
  EXPECT_EQ(r.charts_out, r.charts_in);
  // 486 charts: the thesis' rules stop far above 10 %
  EXPECT_GT(r.faces_out, 2 * o.target_faces);
  EXPECT_EQ(r.stopped_by, TS::Stop_reason::chart_limit);
}

// cmgeom with `args` (shell-quoted), its output in `out` and `err`; returns the exit code.
int run(const std::string& args, std::string* out, std::string* err, const std::string& dir) {
  const cmgeom_test::Cli_result r = cmgeom_test::run_cli(args, dir);
  *out = r.out;
  *err = r.err;
  return r.exit_code;
}

TEST(RebuiltAtlas, CommandLineReportsRepairStopReasonAndMissingTexture) {
  const std::string helmet = textured_path(3), spot = textured_path(0);
  if (!fs::exists(helmet) || !fs::exists(spot)) GTEST_SKIP() << "shared data not found: " << helmet;
  const std::string dir = cmgeom_test::scratch_dir();
  std::string out, err;
  // repaired by default, one warning line saying what changed; the chart-keeping mode stops
  // above the target and says why on stderr and in the JSON
  ASSERT_EQ(run("simplify '" + helmet + "' -o '" + dir + "/k.obj' --ratio 0.1 --keep-charts --json", &out, &err, dir),
            0)
      << err;
  EXPECT_NE(err.find("warning: " + helmet + ": repaired: 7 non-manifold edges split"), std::string::npos) << err;
  EXPECT_NE(err.find("chart limit"), std::string::npos) << err;
  auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j["stopped_by"], "chart_limit");
  EXPECT_EQ(j["charts"], "kept");
  EXPECT_GT(j["faces_out"].get<int>(), j["target_faces"].get<int>());
  // --no-repair refuses, with the file and what is wrong; nothing written
  EXPECT_EQ(run("simplify '" + helmet + "' -o '" + dir + "/n.obj' --ratio 0.1 --no-repair", &out, &err, dir), 1);
  EXPECT_NE(err.find("non-manifold edges"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir + "/n.obj"));
  // an OBJ naming no texture with an image beside it: no guess, a message naming --texture
  EXPECT_EQ(run("simplify '" + spot + "' -o '" + dir + "/s.obj' --ratio 0.1", &out, &err, dir), 1);
  EXPECT_NE(err.find("--texture"), std::string::npos) << err;
  EXPECT_NE(err.find("spot_texture.png"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir + "/s.obj"));
  // with it: the default bakes a new atlas and reaches the target
  ASSERT_EQ(run("simplify '" + spot + "' -o '" + dir + "/s.obj' --ratio 0.02 --json --texture '" +
                    std::string(CMGEOM_DATA_DIR) + "/textured/spot/spot_texture.png'",
                &out, &err, dir),
            0)
      << err;
  j = nlohmann::json::parse(out);
  EXPECT_EQ(j["stopped_by"], "target");
  EXPECT_EQ(j["charts"], "rebuilt");
  EXPECT_LE(j["faces_out"].get<int>(), j["target_faces"].get<int>());
  EXPECT_GE(j["faces_out"].get<int>() + 1, j["target_faces"].get<int>());  // a collapse removes two faces
  EXPECT_TRUE(fs::exists(dir + "/s_0_diffuse.png"));
}

}  // namespace

namespace {

// Smallest angle (degrees) over the triangles of a mesh, and the mean over the triangles of
// each triangle's smallest angle.
std::pair<double, double> angle_stats(const CMGeom::Surface_mesh& m) {
  double best = 180, sum = 0;
  for (auto f : m.faces()) {
    std::array<Point_3, 3> p;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) p[std::size_t(k++)] = m.point(v);
    double smallest = 180;
    for (int i = 0; i < 3; ++i) {
      const Vector_3 a = p[std::size_t((i + 1) % 3)] - p[std::size_t(i)],
                     b = p[std::size_t((i + 2) % 3)] - p[std::size_t(i)];
      const double c = (a * b) / std::sqrt(a.squared_length() * b.squared_length());
      smallest = std::min(smallest, std::acos(std::clamp(c, -1.0, 1.0)) * 180 / 3.14159265358979);
    }
    best = std::min(best, smallest);
    sum += smallest;
  }
  return {best, m.number_of_faces() > 0 ? sum / double(m.number_of_faces()) : 0.};
}

TEST(RebuiltAtlas, FlipsOnTexturedInputKeepAValidAtlas) {
  const int spot = 0;
  CMGeom::Textured_mesh base;
  if (!read_textured(spot, base)) GTEST_SKIP() << "shared data not found: " << textured_path(spot);
  std::pair<double, double> angle[2];
  for (int flips = 0; flips < 2; ++flips) {
    CMGeom::Textured_mesh tm = base;
    TS::Textured_simplification_options o;
    o.target_faces = base.mesh().number_of_faces() / 10;
    o.flips = flips == 1;
    const auto r = TS::simplify_textured_mesh(tm, o);
    EXPECT_EQ(r.stopped_by, TS::Stop_reason::target);
    EXPECT_LE(r.faces_out, o.target_faces);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(tm.mesh()));
    const CMGeom::Image& img = tm.materials()[0].diffuse_image;
    const Layout_check c = check_layout(tm, img.width(), img.height());
    EXPECT_EQ(c.outside + c.folded + c.overlapping_texels, 0u) << "flips " << flips;
    angle[flips] = angle_stats(tm.mesh());
  }
  std::cout << "spot at 10 %: smallest angle " << angle[0].first << " degrees without flips, " << angle[1].first
            << " with; mean smallest angle per triangle " << angle[0].second << " and " << angle[1].second << "\n";
  // flips replace an edge when the opposite angles sum clearly above 180 degrees: the triangles
  // get rounder on the whole (the single worst one depends on the collapse order, which flips change)
  EXPECT_GT(angle[1].second, angle[0].second);
  EXPECT_GT(angle[1].first, 0.5);
  TS::Textured_simplification_options o;
  o.keep_charts = true;
  o.flips = true;
  CMGeom::Textured_mesh tm = base;
  EXPECT_THROW(TS::simplify_textured_mesh(tm, o), CMGeom::Invalid_input);
  // no texture to bake: the charts are kept, and flips are refused rather than dropped
  o.keep_charts = false;
  o.resample_textures = false;
  EXPECT_THROW(TS::simplify_textured_mesh(tm, o), CMGeom::Invalid_input);
}

// The baking looks texels up a tile at a time: the facing faces gathered around the tile's centre,
// then scanned per texel (Facing_closest_point::gather(), nearest_among()). Checked against the
// tree's search on a crumpled sheet with duplicated faces (exact ties: the lowest index wins in
// both) and random tiles of points off it, at every bound the baking uses; and against brute force.
TEST(RebuiltAtlas, TileLookupsFindWhatTheTreeSearchFinds) {
  using FCP = TS::internal::Facing_closest_point;
  using SC = FCP::SC;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int n = 24;
  auto height = [](double x, double y) {
    return 0.08 * std::sin(9 * x) * std::cos(7 * y) + 0.03 * std::sin(31 * x * y);
  };
  FCP::Triangles tris;
  std::vector<Vector_3> normals;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x0 = double(i) / n, y0 = double(j) / n, x1 = double(i + 1) / n, y1 = double(j + 1) / n;
      const SC::Point_3 a(x0, y0, height(x0, y0)), b(x1, y0, height(x1, y0)), c(x1, y1, height(x1, y1)),
          d(x0, y1, height(x0, y1));
      for (const auto& t : {SC::Triangle_3(a, b, c), SC::Triangle_3(a, c, d)}) {
        tris.push_back(t);
        const auto nn = CGAL::cross_product(t[1] - t[0], t[2] - t[0]);
        normals.emplace_back(nn.x(), nn.y(), nn.z());
        if ((i + j) % 5 == 0) {  // a coincident copy (a second layer of the same surface)
          tris.push_back(t);
          normals.emplace_back(nn.x(), nn.y(), nn.z());
        }
      }
    }
  // a few faces turned away and a few unusable ones
  for (std::size_t f = 3; f < normals.size(); f += 17) normals[f] = -normals[f];
  std::vector<char> usable(tris.size(), 1);
  for (std::size_t f = 5; f < usable.size(); f += 23) usable[f] = 0;
  const FCP finder(tris, normals, usable);

  // the same rule, by brute force
  auto brute = [&](const double* p, const Vector_3& dir, double bound2) {
    FCP::Hit best;
    best.squared_distance = bound2;
    for (std::size_t f = 0; f < tris.size(); ++f) finder.test(f, p, dir, best);
    return best;
  };
  std::size_t checked = 0, ties = 0, gathered_tiles = 0;
  std::vector<FCP::Candidate> candidates;
  for (int tile = 0; tile < 300; ++tile) {
    const double cx = u01(rng), cy = u01(rng), off = 0.2 * (u01(rng) - 0.3), r = 0.03 * u01(rng);
    const Vector_3 dir =
        tile % 7 == 0 ? Vector_3(0, 0, 0) : Vector_3(0.3 * (u01(rng) - 0.5), 0.3 * (u01(rng) - 0.5), 1);
    const double bound2 = tile % 3 == 0 ? 0.01 : (tile % 3 == 1 ? 0.04 : 1e30);
    std::vector<std::array<double, 3>> pts;
    for (int k = 0; k < 16; ++k)
      pts.push_back(
          {{cx + r * (u01(rng) - 0.5), cy + r * (u01(rng) - 0.5), height(cx, cy) + off + r * (u01(rng) - 0.5)}});
    double q[3] = {0, 0, 0};
    for (const auto& p : pts)
      for (int c = 0; c < 3; ++c) q[c] += p[c] / double(pts.size());
    double radius = 0;
    std::vector<double> pq;
    for (const auto& p : pts) {
      pq.push_back(std::sqrt(CGAL::square(p[0] - q[0]) + CGAL::square(p[1] - q[1]) + CGAL::square(p[2] - q[2])));
      radius = (std::max)(radius, pq.back());
    }
    FCP::Hit at_q;
    at_q.squared_distance = bound2;
    finder.search(q, dir, at_q);
    const double reach = std::sqrt(bound2);
    const double d = at_q.found() ? (std::min)(std::sqrt(at_q.squared_distance) + radius, reach) : reach;
    const double g = (d + radius) * (1 + 1e-9);
    if (!finder.gather(q, dir, g * g, tris.size(), candidates)) continue;
    ++gathered_tiles;
    for (std::size_t c = 1; c < candidates.size(); ++c) ASSERT_LE(candidates[c - 1].distance, candidates[c].distance);
    for (std::size_t k = 0; k < pts.size(); ++k) {
      FCP::Hit by_tree, by_tile;
      by_tree.squared_distance = by_tile.squared_distance = bound2;
      finder.search(pts[k].data(), dir, by_tree);
      finder.nearest_among(pts[k].data(), candidates, pq[k], by_tile);
      const FCP::Hit expected = brute(pts[k].data(), dir, bound2);
      ASSERT_EQ(by_tree.face, expected.face);
      ASSERT_EQ(by_tile.face, expected.face) << "tile " << tile << " point " << k;
      ASSERT_EQ(by_tile.squared_distance, expected.squared_distance);
      if (expected.found()) {
        ++checked;
        // a coincident copy at the same distance: the lower index won
        if (expected.face + 1 < tris.size() && tris[expected.face] == tris[expected.face + 1]) ++ties;
      }
    }
  }
  EXPECT_GT(gathered_tiles, 250u);
  EXPECT_GT(checked, 3000u);
  EXPECT_GT(ties, 100u);
}

TEST(RebuiltAtlas, ATetrahedronStopsWithNoCollapseLeft) {
  CMGeom::Textured_mesh tm;
  auto& m = tm.mesh();
  const auto a = m.add_vertex(Point_3(0, 0, 0)), b = m.add_vertex(Point_3(1, 0, 0)), c = m.add_vertex(Point_3(0, 1, 0)),
             d = m.add_vertex(Point_3(0, 0, 1));
  for (auto f : {m.add_face(a, c, b), m.add_face(a, b, d), m.add_face(b, c, d), m.add_face(a, d, c)}) {
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
      tm.set_uv(h, Point_2(k == 0 ? 0.1 : (k == 1 ? 0.9 : 0.5), k == 2 ? 0.9 : 0.1));
      ++k;
    }
  }
  tm.set_has_uvs(true);
  CMGeom::Image img(64, 64, 3);
  tm.materials().resize(1);
  tm.materials()[0].diffuse_image = img;
  TS::Textured_simplification_options o;
  o.target_faces = 2;
  const auto r = TS::simplify_textured_mesh(tm, o);
  EXPECT_EQ(r.faces_out, 4u);
  EXPECT_EQ(r.stopped_by, TS::Stop_reason::no_collapse);
  EXPECT_STREQ(TS::to_string(r.stopped_by), "no_collapse");
}

}  // namespace
