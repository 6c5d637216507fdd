// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Surface_memory (the memoryful cost of CMGeom's engine): its cost against a value computed by
// hand, the bookkeeping of the points through a whole simplification, and what it buys on the
// shared textured models (Hausdorff and RMS of Metrics, against the quadric alone); the final fit
// of the vertices to the points (fit_vertices): its invariants, measured independently, and its
// RMS against no fit on the shared classic models.
#include "cmgeom_test_config.h"
#include "cmgeom_test_surface_meshes.h"

#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification.h>

#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/squared_distance_3.h>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <string>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
namespace PMP = CGAL::Polygon_mesh_processing;
using Mesh = CMGeom::Surface_mesh;
using Point_3 = CMGeom::Point_3;
using VPM = boost::property_map<Mesh, CGAL::vertex_point_t>::type;
using Memory = TS::Surface_memory<Mesh, VPM>;

// A hexagonal umbrella in z = 0 whose centre is raised to height h.
Mesh umbrella(double h, Mesh::Vertex_index& centre, Mesh::Vertex_index& first) {
  Mesh m;
  centre = m.add_vertex(Point_3(0, 0, h));
  std::vector<Mesh::Vertex_index> ring;
  for (int k = 0; k < 6; ++k) ring.push_back(m.add_vertex(Point_3(std::cos(k * M_PI / 3), std::sin(k * M_PI / 3), 0)));
  for (int k = 0; k < 6; ++k) m.add_face(centre, ring[std::size_t(k)], ring[std::size_t((k + 1) % 6)]);
  first = ring[0];
  return m;
}

TEST(SurfaceMemory, CostIsAreaTimesSquaredDistanceOfThePointsLeftBehind) {
  for (double h : {0.0, 0.1, 0.5}) {
    Mesh::Vertex_index c, n;
    Mesh m = umbrella(h, c, n);
    Memory memory(m, get(CGAL::vertex_point, m));
    ASSERT_EQ(memory.number_of_points(), 7u);
    // every face touches the centre: every point is priced. Collapsing the centre onto the first
    // ring vertex leaves the flat hexagon; the ring points lie on it, the centre is h above it
    // (it projects inside), and its weight is the area of its star.
    const auto hc = CGAL::halfedge(c, n, m).first;
    ASSERT_TRUE(CGAL::halfedge(c, n, m).second);
    const double star_area = PMP::area(m);
    const double expected = star_area * h * h;
    EXPECT_NEAR(memory.cost(m, hc, m.point(n)), expected, 1e-12 * (1 + expected)) << "h = " << h;
    // the placement raised by 0.3: the centre's distance to the tilted star is at most its
    // distance to the kept vertex's... only its bounds are simple: the cost is below the
    // centre's weight times its squared distance to the ring vertex n (a point of the new star)
    // plus the other points' weights times 0.3^2
    const double lift = memory.cost(m, hc, Point_3(1, 0, 0.3));
    EXPECT_GE(lift, 0.);
    const double d_cn = 1 + h * h;  // |c - n|^2
    EXPECT_LE(lift, star_area * d_cn + 6 * star_area * 0.09);
  }
}

TEST(SurfaceMemory, AVertexPlacedAwayFromThePointsCostsItsGapToThem) {
  // a flat 6 x 6 sheet (spacing s); an interior edge c -> n. Every input vertex is a point.
  const int k = 6;
  const double s = 1.0 / k;
  Mesh m = cmgeom_test::height_field(k, [](double, double) { return 0.0; });
  const auto at = [&](int i, int j) { return Mesh::Vertex_index(Mesh::size_type(i * (k + 1) + j)); };
  const Mesh::Vertex_index c = at(2, 2), n = at(3, 2);
  const auto [h, found] = CGAL::halfedge(c, n, m);
  ASSERT_TRUE(found);
  Memory memory(m, get(CGAL::vertex_point, m));
  // in the plane, onto n: every point lies on the new faces, and n is a point itself
  EXPECT_EQ(memory.cost(m, h, m.point(n)), 0.0);
  // 3s above n: every point is at least 3s away, and the disc a point stands for has a radius of
  // at most s / sqrt(pi) (an interior star: six triangles of s^2 / 2, a third of it is pi r^2).
  // The cost is at least (area of the new star) / 6 x (3s - s / sqrt(pi))^2, whatever the
  // points' own distances to the new faces add.
  const Point_3 x(m.point(n).x(), m.point(n).y(), 3 * s);
  Mesh collapsed = m;
  const auto kept = CGAL::Euler::collapse_edge(CGAL::edge(CGAL::halfedge(c, n, collapsed).first, collapsed), collapsed);
  collapsed.point(kept) = x;
  double star_area = 0;
  for (auto f : CGAL::faces_around_target(collapsed.halfedge(kept), collapsed))
    if (f != Mesh::null_face()) star_area += PMP::face_area(f, collapsed);
  const double gap = 3 * s - s / std::sqrt(M_PI);
  EXPECT_GE(memory.cost(m, h, x), star_area / 6 * gap * gap);
}

TEST(SurfaceMemory, EveryPointStaysOnALiveFaceThroughASimplification) {
  const std::string path = std::string(CMGEOM_DATA_DIR) + "/textured/spot/spot.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data not found: " << path;
  CMGeom::Textured_mesh tm;
  CMGeom::IO::read_mesh(path, tm);
  Mesh& m = tm.mesh();
  const double area3 = 3 * PMP::area(m);
  Memory memory(m, get(CGAL::vertex_point, m));
  EXPECT_EQ(memory.number_of_points(), m.number_of_vertices());
  TS::Area_weighted_quadric_policies<Mesh> policy(m, TS::Quadric_options{false});
  TS::Face_count_stop_predicate<Mesh> stop(m, m.number_of_faces() / 20);
  TS::edge_collapse(
      m, stop,
      CMGeom::parameters::surface_memory(
          &memory, CMGeom::parameters::edge_flips(true, CGAL::parameters::get_cost(policy).get_placement(policy))));
  std::size_t count = 0, dead = 0;
  double area = 0;
  memory.for_each_point([&](Mesh::Face_index f, const auto&, double a) {
    ++count;
    area += a;
    if (f == Mesh::null_face() || m.is_removed(f)) ++dead;
  });
  EXPECT_EQ(count, memory.number_of_points());
  EXPECT_EQ(dead, 0u);
  // the weights are the areas of the input's vertex stars: together three times the input's area
  EXPECT_NEAR(area, area3, 1e-9 * area3);
  EXPECT_LE(m.number_of_faces(), std::size_t(293));
}

TEST(SurfaceMemory, LargeInputsKeepAtMostTheRequestedNumberOfPoints) {
  const std::string path = std::string(CMGEOM_DATA_DIR) + "/textured/DamagedHelmet/DamagedHelmet.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data not found: " << path;
  CMGeom::Textured_mesh tm;
  CMGeom::IO::Read_options ro;
  ro.repair = true;
  CMGeom::IO::read_mesh(path, tm, ro);
  Mesh& m = tm.mesh();
  TS::Surface_memory_options o;
  o.max_points = 1000;
  Memory memory(m, get(CGAL::vertex_point, m), o);
  EXPECT_LE(memory.number_of_points(), 1000u);
  EXPECT_GE(memory.number_of_points(), 900u);
  // the kept points stand for the others: their weights still add up to about 3x the area
  double area = 0;
  memory.for_each_point([&](Mesh::Face_index, const auto&, double a) { area += a; });
  const double area3 = 3 * PMP::area(m);
  EXPECT_NEAR(area, area3, 0.1 * area3);
  // 8.5k vertices: with 1000 points the memory waits until there are at most 2 faces per point
  EXPECT_FALSE(memory.active());
}

// By default every vertex of a large input is a point (none is left unseen), and the cost waits
// to price collapses until there are at most two faces per 65,536 points (pricing_points).
TEST(SurfaceMemory, EveryVertexIsAPointAndPricingWaitsOnLargeInputs) {
  Mesh m = cmgeom_test::rippled_torus(400, 200, 0.3, 0.02, 5, 3);  // 80,000 vertices, 160,000 faces
  ASSERT_EQ(m.number_of_vertices(), 80000u);
  const Memory memory(m, get(CGAL::vertex_point, m));
  EXPECT_EQ(memory.number_of_points(), m.number_of_vertices());
  double area = 0;
  memory.for_each_point([&](Mesh::Face_index, const auto&, double a) { area += a; });
  EXPECT_NEAR(area, 3 * PMP::area(m), 1e-9 * 3 * PMP::area(m));
  EXPECT_FALSE(memory.active());  // 160,000 faces > 2 x 65,536 + 8
  TS::Surface_memory_options o;
  o.pricing_points = 0;  // every point counts: prices from the start
  EXPECT_TRUE(Memory(m, get(CGAL::vertex_point, m), o).active());
  o.pricing_points = 80000;
  EXPECT_TRUE(Memory(m, get(CGAL::vertex_point, m), o).active());
  o.pricing_points = 79995;  // 2 x 79,995 + 8 < 160,000
  EXPECT_FALSE(Memory(m, get(CGAL::vertex_point, m), o).active());
}

// On every shared textured model at 10 % and 2 %: the memory's Hausdorff and RMS against the
// quadric alone, both without the final fit (manual, Textured_simplification, "The memoryful
// cost"). Measured: RMS lower in 15 of the 16 cases (WaterBottle at 2 %: 0.8 % higher); Hausdorff
// lower in 10, at most 1.53x higher (WaterBottle, 2 %), and on fuze at 10 %, whose base rim the
// quadric alone cuts off, 0.0164 instead of 0.0297. (Before the cost saw the new vertex's distance
// to the points: RMS lower in 16, Hausdorff at most 1.37x higher; over the 93 configurations of the
// shared meshes with the final fit, that distance halves the cases above 1.25x CGAL GH's Hausdorff.)
TEST(SurfaceMemory, LowersTheErrorOfTheQuadricOnTheSharedTexturedModels) {
  const char* const models[][2] = {{"spot", "spot.obj"},
                                   {"bob", "bob_tri.obj"},
                                   {"fuze", "fuze.obj"},
                                   {"DamagedHelmet", "DamagedHelmet.obj"},
                                   {"WaterBottle", "WaterBottle.obj"},
                                   {"Duck", "Duck.obj"},
                                   {"bunny10k_textured", "bunny10k_textured.obj"},
                                   {"texturedknot", "texturedknot.obj"}};
  int ran = 0, rms_lower = 0, cases = 0;
  double h_ratio_max = 0, fuze_h[2] = {0, 0};
  for (const auto& model : models) {
    const std::string path = std::string(CMGEOM_DATA_DIR) + "/textured/" + model[0] + "/" + model[1];
    if (!std::filesystem::exists(path)) continue;
    ++ran;
    CMGeom::Textured_mesh input;
    CMGeom::IO::Read_options ro;
    ro.repair = true;
    CMGeom::IO::read_mesh(path, input, ro);
    for (double ratio : {0.1, 0.02}) {
      CMGeom::Metrics::Approximation_error e[2];
      for (int with = 0; with < 2; ++with) {
        Mesh m = input.mesh();
        TS::Area_weighted_quadric_policies<Mesh> policy(m, TS::Quadric_options{false});
        TS::Face_count_stop_predicate<Mesh> stop(m, std::size_t(ratio * double(input.mesh().number_of_faces())));
        std::optional<Memory> memory;
        if (with) memory.emplace(m, get(CGAL::vertex_point, m));
        TS::edge_collapse(m, stop,
                          CMGeom::parameters::surface_memory(memory ? &*memory : nullptr,
                                                             CGAL::parameters::get_cost(policy).get_placement(policy)));
        m.collect_garbage();
        e[with] = CMGeom::Metrics::approximation_error(input.mesh(), m);
      }
      ++cases;
      rms_lower += e[1].rms < e[0].rms;
      h_ratio_max = std::max(h_ratio_max, e[1].hausdorff / e[0].hausdorff);
      if (std::string(model[0]) == "fuze" && ratio == 0.1) {
        fuze_h[0] = e[0].hausdorff;
        fuze_h[1] = e[1].hausdorff;
      }
      std::cout << model[0] << " at " << ratio * 100 << " %: Hausdorff " << e[0].hausdorff << " -> " << e[1].hausdorff
                << ", RMS " << e[0].rms << " -> " << e[1].rms << "\n";
    }
  }
  if (ran == 0) GTEST_SKIP() << "shared data not found: " << CMGEOM_DATA_DIR << "/textured";
  EXPECT_GE(rms_lower, cases - 1);
  EXPECT_LT(h_ratio_max, 1.6);
  if (fuze_h[0] > 0) EXPECT_LT(fuze_h[1], 0.75 * fuze_h[0]);
}

// A torus with bumps (no symmetry the collapses could keep exactly).
Mesh bumpy_torus(int n, int m) { return cmgeom_test::rippled_torus(n, m, 0.35, 0.35 * 0.15, 5, 3); }

// Per point: the squared distance to the face it is attached to (CGAL's, not the memory's).
std::vector<double> attached_distances(const Mesh& m, const Memory& memory) {
  std::vector<double> d;
  memory.for_each_point([&](Mesh::Face_index f, const auto& p, double) {
    const auto h = m.halfedge(f);
    const CMGeom::Kernel::Triangle_3 t(m.point(m.source(h)), m.point(m.target(h)), m.point(m.target(m.next(h))));
    d.push_back(CGAL::squared_distance(t, Point_3(p.x, p.y, p.z)));
  });
  return d;
}

std::vector<std::array<std::uint32_t, 3>> face_corners(const Mesh& m) {
  std::vector<std::array<std::uint32_t, 3>> out;
  for (auto f : m.faces()) {
    const auto h = m.halfedge(f);
    out.push_back({std::uint32_t(m.source(h)), std::uint32_t(m.target(h)), std::uint32_t(m.target(m.next(h)))});
  }
  return out;
}

TEST(SurfaceMemoryFit, LowersThePointEnergyKeepsConnectivityAndNeverMovesAPointFarther) {
  const Mesh input = bumpy_torus(120, 48);  // 11,520 faces
  Mesh m = input;
  Memory memory(m, get(CGAL::vertex_point, m));
  TS::Area_weighted_quadric_policies<Mesh> policy(m, TS::Quadric_options{false});
  TS::Face_count_stop_predicate<Mesh> stop(m, 500);
  TS::edge_collapse(
      m, stop, CMGeom::parameters::surface_memory(&memory, CGAL::parameters::get_cost(policy).get_placement(policy)));
  // before the fit: the energy and the worst point, from CGAL's point-triangle distances
  const std::vector<double> d0 = attached_distances(m, memory);
  std::vector<double> area;
  memory.for_each_point([&](Mesh::Face_index, const auto&, double a) { area.push_back(a); });
  double e0 = 0;
  for (std::size_t i = 0; i < d0.size(); ++i) e0 += area[i] * d0[i];
  const double worst0 = *std::max_element(d0.begin(), d0.end());
  const auto corners0 = face_corners(m);
  std::vector<CMGeom::Kernel::Vector_3> normals0;
  for (auto f : m.faces()) normals0.push_back(PMP::compute_face_normal(f, m));

  TS::Surface_fit_options fo;
  // where the fit would move the vertices, asked first: neither the mesh nor the points change
  std::vector<Point_3> before;
  for (auto v : m.vertices()) before.push_back(m.point(v));
  const std::vector<Point_3> would = memory.fitted_positions(m, fo, [&](auto v) { return policy.quadric(v); });
  {
    std::size_t i = 0;
    for (auto v : m.vertices()) ASSERT_EQ(m.point(v), before[i++]);
    EXPECT_EQ(attached_distances(m, memory), d0);
  }
  // the same, its input copied now and the fit made later (a level of a chain, fitted beside the
  // collapses): what it gives does not depend on what the mesh and the memory go through meanwhile
  // (here, the fit itself)
  const auto later = memory.fitted_positions_later(m, fo, [&](auto v) { return policy.quadric(v); });
  const std::size_t moves = memory.fit_vertices(m, fo, [&](auto v) { return policy.quadric(v); });
  EXPECT_GT(moves, std::size_t(m.number_of_vertices()));  // most vertices move in every round
  // the fit made is the one foretold, exactly
  for (auto v : m.vertices()) ASSERT_EQ(m.point(v), would[std::size_t(v)]);
  const std::vector<Point_3> made_later = later();
  ASSERT_EQ(made_later.size(), would.size());
  for (auto v : m.vertices()) ASSERT_EQ(made_later[std::size_t(v)], would[std::size_t(v)]);

  const std::vector<double> d1 = attached_distances(m, memory);
  ASSERT_EQ(d1.size(), d0.size());
  std::vector<double> area1;
  memory.for_each_point([&](Mesh::Face_index, const auto&, double a) { area1.push_back(a); });
  double e1 = 0;
  for (std::size_t i = 0; i < d1.size(); ++i) e1 += area1[i] * d1[i];
  const double worst1 = *std::max_element(d1.begin(), d1.end());
  std::cout << "points' energy " << e0 << " -> " << e1 << ", worst squared distance " << worst0 << " -> " << worst1
            << ", " << moves << " moves\n";
  EXPECT_LT(e1, 0.8 * e0);
  EXPECT_LE(worst1, worst0 * (1 + 1e-9));
  // the same faces on the same vertices, none turned by more than max_turn, none flipped
  EXPECT_EQ(face_corners(m), corners0);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  std::size_t k = 0;
  for (auto f : m.faces()) {
    const auto n = PMP::compute_face_normal(f, m);
    EXPECT_GE(n * normals0[k++], std::cos(fo.max_turn) - 1e-9);
  }
  // and against the input surface itself (not only its vertices): closer in RMS
  Mesh unfitted = input;
  {
    Memory again(unfitted, get(CGAL::vertex_point, unfitted));
    TS::Area_weighted_quadric_policies<Mesh> p2(unfitted, TS::Quadric_options{false});
    TS::Face_count_stop_predicate<Mesh> s2(unfitted, 500);
    TS::edge_collapse(unfitted, s2,
                      CMGeom::parameters::surface_memory(&again, CGAL::parameters::get_cost(p2).get_placement(p2)));
  }
  unfitted.collect_garbage();
  m.collect_garbage();
  const auto e_unfitted = CMGeom::Metrics::approximation_error(input, unfitted);
  const auto e_fitted = CMGeom::Metrics::approximation_error(input, m);
  std::cout << "RMS " << e_unfitted.rms << " -> " << e_fitted.rms << ", Hausdorff " << e_unfitted.hausdorff << " -> "
            << e_fitted.hausdorff << "\n";
  EXPECT_LT(e_fitted.rms, 0.95 * e_unfitted.rms);
}

TEST(SurfaceMemoryFit, GivesTheSameMeshOnOneThreadAndOnAll) {
  // 23,040 vertices: the fit's blocks of vertex indices (Surface_memory::fit_block) are three,
  // whose inner vertices move at once on all cores
  const Mesh input = bumpy_torus(240, 96);
  ASSERT_GT(input.number_of_vertices(), 2 * Memory::fit_block);
  Mesh out[2];
  for (int k = 0; k < 2; ++k) {
    tbb::task_arena arena(k == 0 ? 1 : tbb::task_arena::automatic);
    arena.execute([&] {
      out[k] = input;
      TS::Mesh_simplification_options o;
      o.target_faces = 4000;
      TS::simplify_mesh(out[k], o);
    });
  }
  ASSERT_EQ(out[0].number_of_vertices(), out[1].number_of_vertices());
  for (auto v : out[0].vertices()) EXPECT_EQ(out[0].point(v), out[1].point(v));
}

TEST(SurfaceMemoryFit, RefusesInvalidOptions) {
  const auto bad = [](auto change) {
    TS::Surface_fit_options o;
    change(o);
    return o;
  };
  const TS::Surface_fit_options invalid[] = {bad([](auto& o) { o.rounds = -1; }),
                                             bad([](auto& o) { o.damping = -0.1; }),
                                             bad([](auto& o) { o.damping = NAN; }),
                                             bad([](auto& o) { o.quadric_weight = -1; }),
                                             bad([](auto& o) { o.quadric_weight = INFINITY; }),
                                             bad([](auto& o) { o.max_turn = 0; }),
                                             bad([](auto& o) { o.max_turn = 3.5; }),
                                             bad([](auto& o) { o.min_points_per_face = -1; }),
                                             bad([](auto& o) { o.min_points_per_face = NAN; })};
  for (const auto& o : invalid) {
    EXPECT_THROW(TS::check_fit_options(o), std::invalid_argument);
    Mesh m = bumpy_torus(12, 8);
    TS::Mesh_simplification_options so;
    so.target_faces = 50;
    so.memory.fit = o;
    EXPECT_THROW(TS::simplify_mesh(m, so), std::invalid_argument);
    EXPECT_EQ(m.number_of_faces(), 192u);  // refused before any change
  }
  EXPECT_NO_THROW(TS::check_fit_options(TS::Surface_fit_options()));
  // the memory's own option, refused by the memory and by simplify_mesh before any change (also
  // on the path in parts, which builds its memories after taking the input apart)
  for (double w : {-1.0, double(NAN), double(INFINITY)}) {
    Mesh m = bumpy_torus(12, 8);
    TS::Surface_memory_options mo;
    mo.vertex_gap_weight = w;
    EXPECT_THROW(Memory(m, get(CGAL::vertex_point, m), mo), std::invalid_argument);
    for (std::size_t parts_min_faces : {std::size_t(0), std::size_t(64)}) {
      TS::Mesh_simplification_options so;
      so.target_faces = 40;
      so.parts_min_faces = parts_min_faces;  // 64: in parts of about 32 faces
      so.part_faces = 32;
      so.memory.vertex_gap_weight = w;
      EXPECT_THROW(TS::simplify_mesh(m, so), std::invalid_argument);
      EXPECT_EQ(m.number_of_faces(), 192u);
    }
  }
}

// The fit is made only where the memory holds at least min_points_per_face points per face of the
// result (default 3): the torus' 5,760 vertices are its points, so 1,920 faces (3 per face) are
// fitted and 1,922 are not; the boundary is the same for simplify_mesh() and for the memory itself.
TEST(SurfaceMemoryFit, IsMadeOnlyWithEnoughPointsPerFace) {
  const Mesh input = bumpy_torus(120, 48);  // 11,520 faces, 5,760 vertices
  ASSERT_EQ(input.number_of_vertices(), 5760u);
  ASSERT_EQ(TS::Surface_fit_options().min_points_per_face, 3.0);
  std::map<std::pair<std::size_t, double>, Mesh> out;
  for (std::size_t target : {std::size_t(5760), std::size_t(1922), std::size_t(1920), std::size_t(1152)}) {
    for (double min_points : {3.0, 0.0}) {
      SCOPED_TRACE(std::to_string(target) + " faces, at least " + std::to_string(min_points) + " points per face");
      Mesh m = input;
      TS::Mesh_simplification_options o;
      o.parts_min_faces = 0;
      o.memory.fit.min_points_per_face = min_points;
      const TS::Mesh_simplification_result r = TS::simplify_mesh(m, target, o);
      ASSERT_EQ(r.faces_out, target);
      const bool enough = min_points == 0 || 5760 >= 3 * target;
      EXPECT_EQ(r.fit_moves > 0, enough);
      out[{target, min_points}] = m;
    }
    // without the fit, the result is the collapsed mesh: the same as the run without fit rounds
    Mesh unfitted = input;
    TS::Mesh_simplification_options o;
    o.parts_min_faces = 0;
    o.memory.fit.rounds = 0;
    TS::simplify_mesh(unfitted, target, o);
    const Mesh& d = out[{target, 3.0}];
    const bool same =
        std::equal(d.points().begin(), d.points().end(), unfitted.points().begin(), unfitted.points().end());
    EXPECT_EQ(same, 5760 < 3 * target) << target;
  }
  // the memory's own answer, on a mesh collapsed to 1,922 and then to 1,920 faces
  Mesh m = input;
  Memory memory(m, get(CGAL::vertex_point, m));
  TS::Area_weighted_quadric_policies<Mesh> policy(m, TS::Quadric_options{false});
  for (std::size_t faces : {std::size_t(1922), std::size_t(1920)}) {
    TS::Face_count_stop_predicate<Mesh> stop(m, faces);
    TS::edge_collapse(
        m, stop, CMGeom::parameters::surface_memory(&memory, CGAL::parameters::get_cost(policy).get_placement(policy)));
    ASSERT_EQ(m.number_of_faces(), faces);
    TS::Surface_fit_options fo;
    EXPECT_EQ(memory.fit_applies(m, fo), faces == 1920);
    fo.rounds = 0;
    EXPECT_FALSE(memory.fit_applies(m, fo));
  }
}

// simplify_mesh() with its default fit against no fit, on the shared classic models at 10 % and
// 2 %, errors by Metrics (dense sampling, both ways): RMS lower in every case, Hausdorff at most
// 1.25x (manual, Textured_simplification, "Fitting the vertices to the points").
TEST(SurfaceMemoryFit, LowersTheRmsOnTheSharedClassicModels) {
  const char* const models[] = {"fandisk.obj", "decimated-max.obj", "bunny.off",
                                "cow.obj",     "horse.ply",         "trim-star.off"};
  int ran = 0, cases = 0, rms_lower = 0;
  double h_ratio_max = 0;
  for (const char* model : models) {
    const std::string path = std::string(CMGEOM_DATA_DIR) + "/classic/" + model;
    if (!std::filesystem::exists(path)) continue;
    ++ran;
    CMGeom::Textured_mesh input;
    CMGeom::IO::Read_options ro;
    ro.repair = true;  // cow.obj has a non-manifold vertex
    CMGeom::IO::read_mesh(path, input, ro);
    for (double ratio : {0.1, 0.02}) {
      CMGeom::Metrics::Approximation_error e[2];
      for (int fit = 0; fit < 2; ++fit) {
        Mesh m = input.mesh();
        TS::Mesh_simplification_options o;  // as `cmgeom simplify`: plain quadrics
        o.quadric.weighted = false;
        o.target_ratio = ratio;
        if (!fit) o.memory.fit.rounds = 0;
        const TS::Mesh_simplification_result r = TS::simplify_mesh(m, o);
        EXPECT_EQ(r.fit_moves > 0, fit == 1);
        e[fit] = CMGeom::Metrics::approximation_error(input.mesh(), m);
      }
      ++cases;
      rms_lower += e[1].rms < e[0].rms;
      h_ratio_max = std::max(h_ratio_max, e[1].hausdorff / e[0].hausdorff);
      std::cout << model << " at " << ratio * 100 << " %: RMS " << e[0].rms << " -> " << e[1].rms << ", Hausdorff "
                << e[0].hausdorff << " -> " << e[1].hausdorff << "\n";
    }
  }
  if (ran == 0) GTEST_SKIP() << "shared data not found: " << CMGEOM_DATA_DIR << "/classic";
  EXPECT_EQ(rms_lower, cases);
  EXPECT_LE(h_ratio_max, 1.25);
}

}  // namespace
