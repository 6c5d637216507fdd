// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Tests of the compact CM file (format version 3, cm_compact_io.h) and of the rate-distortion
// choice (rate_distortion.h).
#include "cmgeom_test_support.h"

#include <CMGeom/Compact_model.h>
#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/rate_distortion.h>
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <CGAL/Polygon_mesh_processing/bbox.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

namespace {

using namespace CMGeom::CM;

double diagonal_of(const CMGeom::Surface_mesh& m) {
  const CGAL::Bbox_3 b = CGAL::Polygon_mesh_processing::bbox(m);
  return std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
                   CGAL::square(b.zmax() - b.zmin()));
}

struct Built {
  CMGeom::Surface_mesh mesh;
  Compact_model model;
  double diagonal = 0;
};

const Built& fandisk() {
  static const Built b = [] {
    Built r;
    CMGeom::Textured_mesh tm;
    CMGeom::IO::read_mesh(cmgeom_test::shared_data("classic/fandisk.obj"), tm);
    r.mesh = tm.mesh();
    r.model = build_compact_model(r.mesh, 250);
    r.diagonal = diagonal_of(r.mesh);
    return r;
  }();
  return b;
}

double distance_between(const Reconstruction& a, const Reconstruction& b, bool hausdorff) {
  CMGeom::Metrics::Error_options o;
  o.vertex_field = false;
  const auto e = CMGeom::Metrics::approximation_error(to_surface_mesh(a), to_surface_mesh(b), o);
  return (hausdorff ? e.hausdorff : e.rms) * e.diagonal;  // absolute
}

// Rewrites the trailing FNV-1a checksum so that a modified file passes it (to reach the checks
// behind it).
void reseal(std::string& bytes) {
  const std::uint64_t h = internal::fnv1a64(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size() - 8);
  for (int i = 0; i < 8; ++i) bytes[bytes.size() - 8 + std::size_t(i)] = char((h >> (8 * i)) & 0xffu);
}

}  // namespace

TEST(CompactModelCompactFile, DecodesToTheSameModelUpToItsTolerance) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const Built& f = fandisk();
  Compact_encoding enc;
  enc.tolerance = 1e-4 * f.diagonal;
  CM_file_parts parts;
  const std::string bytes = compact_cm_bytes(f.model, enc, &parts);
  EXPECT_EQ(parts.total(), bytes.size());
  const Compact_model q = parse_cm(bytes, "q.cm");
  EXPECT_EQ(q, quantized_model(f.model, enc));
  // Same faces, and the same sharp edges and cone vertices (as position pairs: vertices are renumbered).
  ASSERT_EQ(q.faces.size(), f.model.faces.size());
  ASSERT_EQ(q.vertices.size(), f.model.vertices.size());
  EXPECT_EQ(q.sharp_edges().size(), f.model.sharp_edges().size());
  EXPECT_EQ(q.cone_vertices().size(), f.model.cone_vertices().size());
  // Every decoded vertex lies within half a grid step per axis of an original one.
  for (const auto& v : q.vertices) {
    double best = 1e300;
    for (const auto& w : f.model.vertices)
      best = std::min(best, std::max({std::abs(v.x - w.x), std::abs(v.y - w.y), std::abs(v.z - w.z)}));
    EXPECT_LE(best, 0.5 * enc.tolerance * (1 + 1e-6));
  }
  // The reconstructions differ by about the tolerance, far less than the CM's own error (about 1 %).
  for (int level : {1, 3}) {
    const Reconstruction a = reconstruct_regular(f.model, level), b = reconstruct_regular(q, level);
    EXPECT_EQ(a.points.size(), b.points.size());
    EXPECT_LT(distance_between(a, b, true), 10 * enc.tolerance) << "level " << level;
    EXPECT_LT(distance_between(a, b, false), 2 * enc.tolerance) << "level " << level;
  }
  // Much smaller than the float32 file.
  EXPECT_LT(3 * bytes.size(), cm_bytes(f.model).size());
}

// A base edge shorter than the grid step (the chart-keeping simplification of a textured base
// leaves such edges along chart borders) would round two vertices onto one grid point and
// reconstruct into degenerate faces: the encoder refines its grid until no base face loses its
// area, so every decoded base face and every reconstructed triangle keeps one.
TEST(CompactModelCompactFile, NoBaseFaceIsFlattenedByTheGrid) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const Built& f = fandisk();
  Compact_model m = f.model;
  Compact_encoding enc;
  enc.tolerance = 1e-4 * f.diagonal;
  // a corner of the first face moved to 1 % of a step beside another
  const std::uint32_t a = m.faces[0][0].vertex, b = m.faces[0][1].vertex;
  m.vertices[b] = m.vertices[a] + Vec3(0.01 * enc.tolerance, 0, 0);
  auto area = [](const Vec3& p, const Vec3& q, const Vec3& r) {
    return CMGeom::CM::internal::length(CMGeom::CM::internal::cross(q - p, r - p));
  };
  const Compact_model q = quantized_model(m, enc);
  EXPECT_EQ(q, parse_cm(compact_cm_bytes(m, enc), "q.cm"));
  ASSERT_EQ(q.faces.size(), m.faces.size());
  for (std::size_t i = 0; i < q.faces.size(); ++i)
    EXPECT_GT(
        area(q.vertices[q.faces[i][0].vertex], q.vertices[q.faces[i][1].vertex], q.vertices[q.faces[i][2].vertex]), 0.)
        << "base face " << i;
  const Reconstruction r = reconstruct_regular(q, 2);
  std::size_t flat = 0;
  for (const auto& t : r.triangles) flat += !(area(r.points[t[0]], r.points[t[1]], r.points[t[2]]) > 0.);
  EXPECT_EQ(flat, 0u);
}

TEST(CompactModelCompactFile, CoarserToleranceGivesSmallerFilesAndLargerDifferences) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const Built& f = fandisk();
  std::size_t last_bytes = SIZE_MAX;
  for (double t : {1e-5, 1e-4, 1e-3, 1e-2}) {
    Compact_encoding enc;
    enc.tolerance = t * f.diagonal;
    const std::string bytes = compact_cm_bytes(f.model, enc);
    EXPECT_LT(bytes.size(), last_bytes) << t;
    last_bytes = bytes.size();
    const Reconstruction a = reconstruct_regular(f.model, 2), b = reconstruct_regular(parse_cm(bytes), 2);
    EXPECT_LT(distance_between(a, b, false), 2 * enc.tolerance) << t;
  }
  // A tolerance so coarse that the grid collapses the model is refused or decodes to a valid model.
  Compact_encoding rough;
  rough.tolerance = 0.5 * f.diagonal;
  try {
    const Compact_model q = quantized_model(f.model, rough);
    EXPECT_NO_THROW(q.validate());
  } catch (const CMGeom::Invalid_input&) {
  } catch (const CMGeom::IO_error&) {}
}

TEST(CompactModelCompactFile, TextureCoordinatesAndPathSurvive) {
  CMGEOM_REQUIRE_SHARED_DATA();
  Compact_model m = fandisk().model;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.25f, 1.75f);
  m.uvs.resize(m.faces.size());
  // one uv per (vertex) for most corners, a seam on every tenth face
  std::vector<std::array<float, 2>> per_vertex(m.vertices.size());
  for (auto& uv : per_vertex) uv = {u(rng), u(rng)};
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      m.uvs[f][k] = f % 10 == 0 ? std::array<float, 2>{u(rng), u(rng)} : per_vertex[m.faces[f][k].vertex];
  m.texture = "textures/atlas é.png";
  const Compact_model q = quantized_model(m);
  ASSERT_TRUE(q.has_uvs());
  EXPECT_EQ(q.texture, m.texture);
  // Corner uvs (matched through the vertex positions and the face's corner set) within the 16-bit grid.
  const double step = 2.0 / 65535.;
  double worst = 0;
  std::vector<std::array<float, 2>> a, b;
  for (const auto& f : m.uvs)
    for (const auto& uv : f) a.push_back(uv);
  for (const auto& f : q.uvs)
    for (const auto& uv : f) b.push_back(uv);
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max({worst, double(std::abs(a[i][0] - b[i][0])), double(std::abs(a[i][1] - b[i][1]))});
  EXPECT_LE(worst, step);
}

TEST(CompactModelCompactFile, CorruptFilesGiveOneLineErrorsAndNoModel) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string good = compact_cm_bytes(fandisk().model);
  // Any flipped byte fails the checksum; any truncation is refused.
  for (std::size_t i = 0; i < good.size(); i += 97) {
    std::string b = good;
    b[i] = char(b[i] ^ 0x5a);
    EXPECT_THROW(parse_cm(b, "flip.cm"), CMGeom::IO_error) << i;
  }
  for (std::size_t n : {std::size_t(0), std::size_t(12), std::size_t(70), good.size() / 2, good.size() - 1})
    EXPECT_THROW(parse_cm(good.substr(0, n), "short.cm"), CMGeom::IO_error) << n;
  // Modified and resealed: every one either throws IO_error or gives a model that validates.
  std::mt19937 rng(11);
  int refused = 0, accepted = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::string b = good;
    const int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits; ++e) b[rng() % (b.size() - 8)] = char(rng() & 0xffu);
    reseal(b);
    try {
      const Compact_model m = parse_cm(b, "fuzz.cm");
      EXPECT_NO_THROW(m.validate());
      ++accepted;
    } catch (const CMGeom::IO_error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("fuzz.cm"), std::string::npos);
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
}

TEST(CompactModelCompactFile, WrittenAtomicallyAndReadBackByReadCm) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string path = dir + "/compact.cm";
  CM_file_parts parts;
  const std::size_t n = write_compact_cm(path, fandisk().model, Compact_encoding(), &parts);
  EXPECT_EQ(n, parts.total());
  EXPECT_EQ(read_cm(path), quantized_model(fandisk().model));
  EXPECT_EQ(cmgeom_test::count_files(dir), 1u);
  // The reconstruction level (flag bit 3): one byte more, counted with the header, read back.
  ASSERT_EQ(fandisk().model.reconstruction_level, -1);
  Compact_model with_level = fandisk().model;
  with_level.reconstruction_level = 3;
  CM_file_parts level_parts;
  const std::string lb = compact_cm_bytes(with_level, Compact_encoding(), &level_parts);
  EXPECT_EQ(lb.size(), n + 1);
  EXPECT_EQ(level_parts.header, parts.header + 1);
  EXPECT_EQ(level_parts.total(), lb.size());
  const Compact_model read_level = parse_cm(lb);
  EXPECT_EQ(read_level.reconstruction_level, 3);
  Compact_model expected = quantized_model(fandisk().model);
  expected.reconstruction_level = 3;
  EXPECT_EQ(read_level, expected);
  // Bad encodings are refused before anything is written.
  Compact_encoding bad;
  bad.normal_bits = 3;
  EXPECT_THROW(write_compact_cm(dir + "/bad.cm", fandisk().model, bad), CMGeom::Invalid_input);
  bad = Compact_encoding();
  bad.tolerance = -1;
  EXPECT_THROW(write_compact_cm(dir + "/bad.cm", fandisk().model, bad), CMGeom::Invalid_input);
  EXPECT_EQ(cmgeom_test::count_files(dir), 1u);
}

TEST(CompactModelRate, ErrorBoundIsMetAsMeasuredIndependently) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const Built& f = fandisk();
  Rate_target t;
  t.max_error = 0.02;
  Rate_choice c;
  const Compact_model m = build_compact_model_for(f.mesh, t, c);
  ASSERT_TRUE(c.met);
  EXPECT_GE(c.level, 1);
  EXPECT_LE(c.level, 3);
  EXPECT_EQ(compact_cm_bytes(m, c.encoding).size(), c.bytes);
  // the model carries its level into its file (cmgeom cm reconstruct's default)
  EXPECT_EQ(m.reconstruction_level, c.level);
  EXPECT_EQ(parse_cm(compact_cm_bytes(m, c.encoding)).reconstruction_level, c.level);
  // Measured again here with more samples, from the decoded file: within the bound (5 % margin
  // for the sampling).
  CMGeom::Metrics::Error_options o;
  o.samples = 10 * f.mesh.number_of_faces();
  o.seed = 99;
  o.vertex_field = false;
  const Reconstruction r = reconstruct_regular(parse_cm(compact_cm_bytes(m, c.encoding)), c.level);
  const auto e = CMGeom::Metrics::approximation_error(f.mesh, to_surface_mesh(r), o);
  EXPECT_LE(e.hausdorff, 1.05 * t.max_error);
  EXPECT_NEAR(e.rms, c.rms, 0.2 * c.rms);
  // A tighter bound never gives a smaller file.
  Rate_target tight = t;
  tight.max_error = 0.01;
  Rate_choice c2;
  build_compact_model_for(f.mesh, tight, c2);
  if (c2.met) EXPECT_GE(c2.bytes, c.bytes);
}

TEST(CompactModelRate, ByteBoundIsMetAndMoreBytesNeverCostError) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const Built& f = fandisk();
  double last = 1e300;
  for (std::size_t budget : {2000u, 8000u}) {
    Rate_target t;
    t.max_bytes = budget;
    Rate_choice c;
    const Compact_model m = build_compact_model_for(f.mesh, t, c);
    ASSERT_TRUE(c.met) << budget;
    EXPECT_LE(compact_cm_bytes(m, c.encoding).size(), budget);
    EXPECT_EQ(compact_cm_bytes(m, c.encoding).size(), c.bytes);  // (the level byte counted)
    EXPECT_EQ(m.reconstruction_level, c.level);
    EXPECT_LE(c.hausdorff, last * 1.5) << budget;  // sampled: allow the noise of one measure
    last = c.hausdorff;
  }
  Rate_target none;
  Rate_choice c;
  EXPECT_THROW(build_compact_model_for(f.mesh, none, c), CMGeom::Invalid_input);
  Rate_target too_small;
  too_small.max_bytes = 100;
  build_compact_model_for(f.mesh, too_small, c);
  EXPECT_FALSE(c.met);
}
