// Tests of textured Compact Models (§4.5.4): charts, uvs and the new atlas, the appearance of the
// reconstruction, files with an atlas.
#include "compact_model_test_util.h"

// ---------------------------------------------------------------------------------------------
// Textured Compact Models (§4.5.4), on cmgeom_test::two_chart_grid (two charts, a quadratically
// stretched map, a procedural texture).
namespace {

using cmgeom_test::two_chart_grid;

// Bilinear look-up (uv in [0,1]², v up; image row 0 at the top), clamped.
std::array<double, 3> look_up(const CMGeom::Image& img, double u, double v) {
  const double px = u * img.width() - 0.5, py = (1.0 - v) * img.height() - 0.5;
  const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
  const double fx = px - x0, fy = py - y0;
  std::array<double, 3> out{{0, 0, 0}};
  for (int k = 0; k < 4; ++k) {
    const int x = std::clamp(x0 + (k & 1), 0, img.width() - 1), y = std::clamp(y0 + (k >> 1), 0, img.height() - 1);
    const double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
    for (int c = 0; c < 3; ++c) out[std::size_t(c)] += w * img.value(x, y, c);
  }
  return out;
}

}  // namespace

TEST(CompactModelTextured, BuildCarriesChartsUvsAndANewAtlas) {
  const CMGeom::Textured_mesh input = two_chart_grid(24, 256);
  Textured_build_result tr;
  Build_statistics st;
  const Compact_model m = build_textured_compact_model(input, 250, Build_options(), Quadric_surface_traits(), &tr, &st);
  ASSERT_TRUE(m.has_uvs());
  ASSERT_EQ(m.uvs.size(), m.faces.size());
  EXPECT_LE(m.faces.size(), 260u);
  EXPECT_EQ(tr.simplification.charts_in, 2u);
  EXPECT_EQ(tr.simplification.charts_out, 2u);
  ASSERT_FALSE(tr.texture.empty());
  EXPECT_EQ(tr.texture.width(), 256);
  EXPECT_TRUE(m.texture.empty()) << "a regenerated atlas is named by the caller";
  // every base face lies in one chart: its uvs are all in the left or all in the right half
  std::size_t left = 0, right = 0;
  for (const Face_uvs& f : m.uvs) {
    int l = 0;
    for (const auto& uv : f) {
      EXPECT_GE(uv[0], 0.f);
      EXPECT_LE(uv[0], 1.f);
      EXPECT_GE(uv[1], 0.f);
      EXPECT_LE(uv[1], 1.f);
      l += uv[0] < 0.5f;
    }
    EXPECT_TRUE(l == 0 || l == 3) << "a base face straddles the two charts";
    (l == 3 ? left : right) += 1;
  }
  EXPECT_GT(left, 50u);
  EXPECT_GT(right, 50u);
  // the file keeps them
  const Compact_model back = parse_cm(cm_bytes(m));
  EXPECT_EQ(back.uvs, m.uvs);
  EXPECT_EQ(back.texture, m.texture);
}

// The appearance survives: a reconstructed point's colour in the new atlas at its interpolated uv
// is the input's colour at the closest input surface point (uv interpolated on the input
// triangle, original texture); looking the same uvs up in the original texture instead (no
// regenerated atlas) is measurably worse, so the check can fail.
TEST(CompactModelTextured, ReconstructionShowsTheInputsAppearance) {
  const CMGeom::Textured_mesh input = two_chart_grid(24, 256);
  Textured_build_result tr;
  const Compact_model m = build_textured_compact_model(input, 200, Build_options(), Quadric_surface_traits(), &tr);
  ASSERT_FALSE(tr.texture.empty());
  Reconstruction_options ro;
  ro.projection = Projection::along_normal;
  const Reconstruction r = reconstruct_regular(m, 2, ro);
  ASSERT_EQ(r.corner_uvs.size(), 3 * r.triangles.size());
  // input triangles with their uvs
  const auto& im = input.mesh();
  struct Tri {
    std::array<Point_3, 3> p;
    std::array<CMGeom::Point_2, 3> uv;
  };
  std::vector<Tri> tris;
  for (auto f : im.faces()) {
    Tri t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(im.halfedge(f), im)) {
      t.p[std::size_t(k)] = im.point(im.target(h));
      t.uv[std::size_t(k)] = input.uv(h);
      ++k;
    }
    tris.push_back(t);
  }
  const CMGeom::Image& original = input.materials()[0].diffuse_image;
  double err_atlas = 0, err_plain = 0;
  std::size_t n = 0;
  for (std::size_t t = 0; t < r.triangles.size(); t += 7) {
    // the triangle's centroid, with its interpolated uv
    Point_3 c(0, 0, 0);
    double u = 0, v = 0;
    for (int k = 0; k < 3; ++k) {
      const auto& q = r.points[r.triangles[t][std::size_t(k)]];
      c = Point_3(c.x() + q.x / 3, c.y() + q.y / 3, c.z() + q.z / 3);
      u += r.corner_uvs[3 * t + std::size_t(k)][0] / 3.0;
      v += r.corner_uvs[3 * t + std::size_t(k)][1] / 3.0;
    }
    // closest input triangle point (brute force) and its uv
    double best = 1e300;
    CMGeom::Point_2 ref_uv(0, 0);
    for (const Tri& tri : tris) {
      const CMGeom::Kernel::Triangle_3 T(tri.p[0], tri.p[1], tri.p[2]);
      const double d = CGAL::to_double(CGAL::squared_distance(c, T));
      if (d >= best) continue;
      best = d;
      const Point_3 q = T.supporting_plane().projection(c);
      const double area = std::sqrt(CGAL::to_double(T.squared_area()));
      double w[3];
      for (int k = 0; k < 3; ++k)
        w[k] = std::sqrt(CGAL::to_double(
                   CMGeom::Kernel::Triangle_3(q, tri.p[std::size_t((k + 1) % 3)], tri.p[std::size_t((k + 2) % 3)])
                       .squared_area())) /
               area;
      const double s = w[0] + w[1] + w[2];
      ref_uv = CMGeom::Point_2((w[0] * tri.uv[0].x() + w[1] * tri.uv[1].x() + w[2] * tri.uv[2].x()) / s,
                               (w[0] * tri.uv[0].y() + w[1] * tri.uv[1].y() + w[2] * tri.uv[2].y()) / s);
    }
    const auto want = look_up(original, ref_uv.x(), ref_uv.y());
    const auto got = look_up(tr.texture, u, v);
    const auto plain = look_up(original, u, v);
    for (int k = 0; k < 3; ++k) {
      err_atlas += std::abs(got[std::size_t(k)] - want[std::size_t(k)]);
      err_plain += std::abs(plain[std::size_t(k)] - want[std::size_t(k)]);
    }
    ++n;
  }
  ASSERT_GT(n, 100u);
  err_atlas /= double(3 * n);
  err_plain /= double(3 * n);
  std::cout << "  mean colour error: new atlas " << err_atlas << ", original texture " << err_plain << "\n";
  EXPECT_LT(err_atlas, 0.02);
  EXPECT_LT(err_atlas, 0.7 * err_plain);
}

TEST(CompactModelTextured, InputWithoutUvsIsRejected) {
  CMGeom::Textured_mesh tm = two_chart_grid(6, 16);
  tm.set_has_uvs(false);
  EXPECT_THROW(build_textured_compact_model(tm, 20), CMGeom::Invalid_input);
}

// A CM and its atlas are written together (write_cm and write_file into one Atomic_output) and a relative
// texture path is read relative to the CM file (texture_path), as `cmgeom cm build` writes them.
TEST(CompactModelTextured, WriteWithAtlasAndTexturePathRelativeToTheFile) {
  const CMGeom::Textured_mesh input = two_chart_grid(6, 16);
  Textured_build_result tr;
  Compact_model m = build_textured_compact_model(input, 40, Build_options(), Quadric_surface_traits(), &tr);
  ASSERT_FALSE(tr.texture.empty());
  m.texture = "grid.png";
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string cm = dir + "/grid.cm", png = dir + "/grid.png";
  std::size_t bytes = 0;
  {
    CMGeom::IO::Atomic_output out;
    CMGeom::IO::write_file(png, "atlas bytes", out);  // stands for the atlas (no image codec here)
    bytes = write_cm(cm, m, out);
    // nothing appears before the commit
    EXPECT_FALSE(std::filesystem::exists(cm));
    EXPECT_FALSE(std::filesystem::exists(png));
    out.commit();
  }
  EXPECT_EQ(bytes, cm_bytes(m).size());
  EXPECT_EQ(std::filesystem::file_size(cm), bytes);
  const Compact_model back = read_cm(cm);
  EXPECT_EQ(back.texture, "grid.png");  // stored as given
  EXPECT_EQ(texture_path(back, cm), (std::filesystem::path(dir) / "grid.png").string());
  EXPECT_TRUE(std::filesystem::exists(texture_path(back, cm)));
  Compact_model absolute = back;
  absolute.texture = "/textures/a.png";
  EXPECT_EQ(texture_path(absolute, cm), "/textures/a.png");
  absolute.texture.clear();
  EXPECT_EQ(texture_path(absolute, cm), "");
  // a write that is never committed leaves nothing
  {
    CMGeom::IO::Atomic_output out;
    write_cm(dir + "/uncommitted.cm", m, out);
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/uncommitted.cm"));
}
