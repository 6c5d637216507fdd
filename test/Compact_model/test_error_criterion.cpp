// Tests of the error-driven adaptive reconstruction (error_criterion.h): the chord estimate,
// vertex budgets, the tolerance on every output edge; the level error table (level_errors.h):
// its codes, its agreement with an independent Metro measure, where it puts the error, its file
// round trips, the exact vertex count of per-face levels, and budgets placed by it.
#include "compact_model_test_util.h"

#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/level_errors.h>

#include <tbb/task_arena.h>

#include <cstring>

namespace {

// ------------------------------------------------------------------ error-driven adaptive
// The chord estimate of error_criterion.h from two samples of the unit sphere theta apart: the
// distance between the chord's midpoint and the sphere is 1 - cos(theta / 2); the estimate is
// first order in theta, so it agrees within a few percent for small theta, and is 0 on a plane.
TEST(CompactModelAdaptive, ChordDeviationMatchesTheSagitta) {
  for (double theta : {0.05, 0.2, 0.4}) {
    const Vec3 a(1, 0, 0), b(std::cos(theta), std::sin(theta), 0);
    const double sagitta = 1 - std::cos(theta / 2);
    const double e = chord_deviation(Sample{a, a}, Sample{b, b});
    EXPECT_NEAR(e, sagitta, 0.03 * sagitta) << theta;
  }
  const Vec3 up(0, 0, 1);
  EXPECT_EQ(chord_deviation(Sample{Vec3(0, 0, 0), up}, Sample{Vec3(3, 1, 0), up}), 0.);
  EXPECT_FALSE(Chord_error_criterion{1e-9}(Sample{Vec3(0, 0, 0), up}, Sample{Vec3(3, 1, 0), up}));
}

// The budget driver stays within the budget, fills most of it, and a larger budget gets a
// smaller tolerance; the output is crack-free with shared vertices like every adaptive one.
TEST(CompactModelAdaptive, VertexBudgetIsMetAndFilled) {
  const Compact_model& m = sphere_model();
  double previous = std::numeric_limits<double>::infinity();
  for (std::size_t budget : {1500u, 4000u, 12000u}) {
    const Vertex_budget_result r = reconstruct_to_vertex_budget(m, budget, 7);
    EXPECT_LE(r.reconstruction.points.size(), budget);
    EXPECT_GE(r.reconstruction.points.size(), std::size_t(0.9 * double(budget)));
    EXPECT_LT(r.tolerance, previous);
    previous = r.tolerance;
    std::string why;
    EXPECT_TRUE(is_closed_and_shared(r.reconstruction, &why)) << why;
  }
  // A budget below the base's vertex count gives the base.
  const Vertex_budget_result base = reconstruct_to_vertex_budget(m, 3, 5);
  EXPECT_EQ(base.reconstruction.points.size(), m.vertices.size());
  EXPECT_THROW(reconstruct_to_vertex_budget(m, 0, 5), CMGeom::Invalid_input);
}

// Every edge of a chord-error adaptive output satisfies the criterion (no edge reached the level
// bound here): its estimated chord deviation is within the tolerance.
TEST(CompactModelAdaptive, EveryOutputEdgeMeetsTheTolerance) {
  const Compact_model& m = sphere_model();
  for (double tol : {1e-3, 2e-4}) {
    const Reconstruction r = reconstruct_adaptive(m, Chord_error_criterion{tol}, 12);
    double worst = 0.;
    for (const auto& t : r.triangles)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        worst = std::max(worst, chord_deviation(Sample{r.points[a], r.normals[a]}, Sample{r.points[b], r.normals[b]}));
      }
    EXPECT_LE(worst, tol);
    EXPECT_GT(r.points.size(), m.vertices.size());
  }
}

// A plane joined to a parabolic fillet (as in JointFitLowersTheErrorAcrossAFillet): at the vertex
// count of regular level 2, the chord-error output puts more than three times as many points on
// the curved half (x > 0.1) as on the flat half (x < -0.1). (The simplified base already leans the
// same way: it has few faces on the flat half.)
TEST(CompactModelAdaptive, ChordErrorRefinesWhereTheSurfaceBends) {
  const Surface_mesh grid = plane_and_fillet(60);
  const Compact_model m = build_compact_model(grid, 60);
  const Reconstruction reg = reconstruct_regular(m, 2);
  const Vertex_budget_result ad = reconstruct_to_vertex_budget(m, reg.points.size(), 5);
  auto count = [](const Reconstruction& r, bool curved) {
    return std::count_if(r.points.begin(), r.points.end(),
                         [&](const Vec3& p) { return curved ? p.x > 0.1 : p.x < -0.1; });
  };
  EXPECT_LE(ad.reconstruction.points.size(), reg.points.size());
  EXPECT_GT(count(ad.reconstruction, true), 3 * count(ad.reconstruction, false));
}

// ------------------------------------------------------------------ level error table
// The unit sphere with a Gaussian bump of height 0.15 around (0, 0, 1).
Surface_mesh bumped_sphere() {
  Surface_mesh s = make_sphere(5);
  for (auto v : s.vertices()) {
    const Point_3 p = s.point(v);
    const double d2 = CGAL::squared_distance(p, Point_3(0, 0, 1));
    s.point(v) = CGAL::ORIGIN + (1. + 0.15 * std::exp(-d2 / 0.02)) * (p - CGAL::ORIGIN);
  }
  return s;
}

// Codes: 0 is 0; a distance comes back within half a step (2^(1/32) - 1 = 2.2 %) inside the range;
// codes grow with the distance.
TEST(CompactModelLevelErrors, CodesRoundTripWithinHalfAStep) {
  const double unit = 1e-6;
  EXPECT_EQ(Level_errors::encode(0., unit), 0);
  EXPECT_EQ(Level_errors::decode(0, unit), 0.);
  int previous = 0;
  for (double x = unit; x < unit * std::exp2(15.8); x *= 1.013) {
    const std::uint8_t c = Level_errors::encode(x, unit);
    EXPECT_GE(int(c), previous);
    previous = c;
    EXPECT_NEAR(Level_errors::decode(c, unit), x, 0.0222 * x) << x;
  }
  EXPECT_EQ(Level_errors::encode(1., unit), 255);
}

// A sphere with a bump: the model's table (i) agrees with an independent measure
// (Metrics::approximation_error, its own random samples) of every regular level: the largest face
// error within 10 % of the Hausdorff distance, the area-weighted RMS within 15 % of the RMS;
// (ii) puts the largest level-2 error on a face near the bump.
TEST(CompactModelLevelErrors, AgreeWithAnIndependentMeasureAndLocateTheError) {
  const Surface_mesh s = bumped_sphere();
  const Vec3 bump(0, 0, 1);
  Compact_model m = build_compact_model(s, 120);
  measure_level_errors(m, s, 3);
  ASSERT_EQ(m.level_errors.depth, 3);
  const std::size_t F = m.faces.size();
  ASSERT_EQ(m.level_errors.rms.size(), 4 * F);
  for (int level = 0; level <= 3; ++level) {
    double mx = 0., s2 = 0., a = 0.;
    for (std::size_t f = 0; f < F; ++f) {
      const Vec3 &p = m.vertices[m.faces[f][0].vertex], &q = m.vertices[m.faces[f][1].vertex],
                 &r = m.vertices[m.faces[f][2].vertex];
      const double area = internal::length(internal::cross(q - p, r - p));
      const double e = m.level_errors.rms_at(level, f, F);
      s2 += area * e * e;
      a += area;
      mx = std::max(mx, m.level_errors.max_at(level, f, F));
    }
    const Surface_mesh rec = to_surface_mesh(reconstruct_regular(m, level));
    const CMGeom::Metrics::Approximation_error ref = CMGeom::Metrics::approximation_error(s, rec);
    EXPECT_NEAR(mx, ref.hausdorff * ref.diagonal, 0.10 * ref.hausdorff * ref.diagonal) << level;
    EXPECT_NEAR(std::sqrt(s2 / a), ref.rms * ref.diagonal, 0.15 * ref.rms * ref.diagonal) << level;
  }
  std::size_t worst = 0;
  for (std::size_t f = 1; f < F; ++f)
    if (m.level_errors.max_at(2, f, F) > m.level_errors.max_at(2, worst, F)) worst = f;
  Vec3 c(0, 0, 0);
  for (const Corner& k : m.faces[worst]) c = c + (1. / 3.) * m.vertices[k.vertex];
  EXPECT_LT(internal::length(c - bump), 0.5);
  EXPECT_THROW(measure_level_errors(m, s, 9), CMGeom::Invalid_input);
}

// The table is the same on one thread and on four (its searches start from fixed blocks' previous
// results, so not even the round-off depends on how the work was shared).
TEST(CompactModelLevelErrors, DoNotDependOnTheThreadCount) {
  const Surface_mesh s = bumped_sphere();
  const Compact_model base = build_compact_model(s, 120);
  std::vector<Compact_model> m(2, base);
  for (int k = 0; k < 2; ++k) {
    tbb::task_arena arena(k == 0 ? 1 : 4);
    arena.execute([&] { measure_level_errors(m[std::size_t(k)], s, 3); });
  }
  EXPECT_EQ(m[0].level_errors.unit, m[1].level_errors.unit);
  EXPECT_EQ(m[0].level_errors.rms, m[1].level_errors.rms);
  EXPECT_EQ(m[0].level_errors.max, m[1].level_errors.max);
}

// The table survives both file versions: version 2 exactly, version 3 per face (its faces are
// stored in decoding order: the multiset of per-face code rows is the same). A table that does not
// match the faces is refused, and a truncated one is a one-line IO_error.
TEST(CompactModelLevelErrors, SurviveTheFileFormats) {
  Compact_model m = sphere_model();
  const Surface_mesh s = make_sphere(5);
  measure_level_errors(m, s, 2);
  const std::string v2 = cm_bytes(m);
  EXPECT_EQ(parse_cm(v2), m);
  EXPECT_THROW(parse_cm(v2.substr(0, v2.size() - 20) + v2.substr(v2.size() - 8)), CMGeom::IO_error);
  const Compact_model q = quantized_model(m);
  ASSERT_EQ(q.level_errors.depth, 2);
  EXPECT_EQ(q.level_errors.unit, m.level_errors.unit);
  auto rows = [](const Compact_model& x) {
    const std::size_t F = x.faces.size();
    std::vector<std::vector<int>> r(F);
    for (std::size_t f = 0; f < F; ++f)
      for (int l = 0; l <= x.level_errors.depth; ++l) {
        r[f].push_back(x.level_errors.rms[std::size_t(l) * F + f]);
        r[f].push_back(x.level_errors.max[std::size_t(l) * F + f]);
      }
    std::sort(r.begin(), r.end());
    return r;
  };
  EXPECT_EQ(rows(q), rows(m));
  CMGeom::CM::CM_file_parts parts;
  const std::string v3 = compact_cm_bytes(m, Compact_encoding(), &parts);
  EXPECT_GT(parts.level_errors, 0u);
  EXPECT_EQ(parts.total(), v3.size());
  // Version 3 stores the codes delta-coded (flag bit 2); a file with the codes as they are (flag
  // bit 1 alone, the first layout of the table) still reads, to the same table.
  const Compact_model d = parse_cm(v3);
  EXPECT_EQ(rows(d), rows(m));
  EXPECT_EQ(static_cast<unsigned char>(v3[12]), 6u);
  std::string plain = v3.substr(0, v3.size() - 8);
  std::size_t at = 69;
  for (int k = 0; k < 6; ++k) {  // skip the six streams before the table's
    std::uint32_t stored = 0;
    std::memcpy(&stored, plain.data() + at + 5, 4);
    at += 9 + stored;
  }
  std::string raw(1, char(d.level_errors.depth));
  const float unit = float(d.level_errors.unit);
  raw.append(reinterpret_cast<const char*>(&unit), 4);
  raw.append(d.level_errors.rms.begin(), d.level_errors.rms.end());
  raw.append(d.level_errors.max.begin(), d.level_errors.max.end());
  const std::uint32_t n = std::uint32_t(raw.size());
  plain.resize(at);
  plain += '\0';  // method 0: raw
  plain.append(reinterpret_cast<const char*>(&n), 4);
  plain.append(reinterpret_cast<const char*>(&n), 4);
  plain += raw;
  const auto with_flags = [&](char flags) {  // (and the checksum of the bytes with them)
    std::string out = plain;
    out[12] = flags;
    const std::uint64_t hash =
        CMGeom::CM::internal::fnv1a64(reinterpret_cast<const unsigned char*>(out.data()), out.size());
    out.append(reinterpret_cast<const char*>(&hash), 8);
    return out;
  };
  EXPECT_EQ(parse_cm(with_flags(2)), d);
  const Compact_model twice = parse_cm(with_flags(6));  // the raw codes read as deltas: another table
  EXPECT_NE(twice.level_errors.rms, d.level_errors.rms);
  EXPECT_THROW(parse_cm(with_flags(4)), CMGeom::IO_error);  // delta-coded codes without a table
  Compact_model bad = m;
  bad.level_errors.max.pop_back();
  EXPECT_THROW(cm_bytes(bad), CMGeom::Invalid_input);
}

// reconstruct_face_levels() outputs exactly the points the level topology counts, without cracks,
// for random per-face levels; uniform levels give the regular reconstruction's count and, bit for
// bit, the adaptive reconstruction that splits every edge.
TEST(CompactModelLevelErrors, PerFaceLevelsGiveTheCountedVerticesWithoutCracks) {
  const Compact_model& m = sphere_model();
  const internal::Face_level_topology topo(m);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 4; ++trial) {
    std::vector<std::uint8_t> levels(m.faces.size());
    for (auto& l : levels) l = std::uint8_t(rng() % 5);
    const Reconstruction r = reconstruct_face_levels(m, levels);
    EXPECT_EQ(r.points.size(), topo.count(m.vertices.size(), levels));
    std::string why;
    EXPECT_TRUE(is_closed_and_shared(r, &why)) << why;
  }
  for (int l = 0; l <= 3; ++l) {
    const std::vector<std::uint8_t> levels(m.faces.size(), std::uint8_t(l));
    EXPECT_EQ(topo.count(m.vertices.size(), levels), reconstruct_regular(m, l).points.size());
    EXPECT_TRUE(same(reconstruct_face_levels(m, levels), reconstruct_adaptive(m, Always_split(), l)));
  }
  EXPECT_THROW(reconstruct_face_levels(m, std::vector<std::uint8_t>(3, 1)), CMGeom::Invalid_input);
}

// Budgets placed by the table: within the budget, never an estimate worse than the regular
// level that fits, and, measured independently against the input (Metro), an RMS no larger than
// that regular level's and a Hausdorff distance no larger up to the measure's sampling (2 %), on
// the bumped sphere and on the plane with a fillet.
TEST(CompactModelLevelErrors, BudgetsPlacedByTheTableAreNoWorseThanRegular) {
  std::vector<std::pair<Surface_mesh, std::size_t>> cases;
  cases.emplace_back(bumped_sphere(), 120);
  cases.emplace_back(plane_and_fillet(60), 60);
  for (auto& [mesh, faces] : cases) {
    Compact_model m = build_compact_model(mesh, faces);
    measure_level_errors(m, mesh, 4);
    for (int level = 1; level <= 3; ++level) {
      const Reconstruction reg = reconstruct_regular(m, level);
      const Vertex_budget_result ad = reconstruct_to_vertex_budget(m, reg.points.size(), 4);
      ASSERT_TRUE(ad.level_errors);
      EXPECT_EQ(ad.face_levels.regular_level, level);
      EXPECT_LE(ad.reconstruction.points.size(), reg.points.size());
      EXPECT_EQ(ad.reconstruction.points.size(), ad.face_levels.vertices);
      EXPECT_LE(ad.face_levels.estimated_rms, ad.face_levels.regular_estimated_rms);
      EXPECT_LE(ad.face_levels.estimated_max, ad.face_levels.regular_estimated_max);
      const auto er = CMGeom::Metrics::approximation_error(mesh, to_surface_mesh(reg));
      const auto ea = CMGeom::Metrics::approximation_error(mesh, to_surface_mesh(ad.reconstruction));
      EXPECT_LE(ea.rms, er.rms) << level;
      EXPECT_LE(ea.hausdorff, er.hausdorff * 1.02) << level;
    }
  }
  Compact_model none = sphere_model();
  EXPECT_THROW(face_levels_for_budget(none, 1000, 3), CMGeom::Invalid_input);
}

}  // namespace
