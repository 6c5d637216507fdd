// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Component pruning (parameters::prune_components, Mesh_simplification_options::prune_components,
// `cmgeom simplify --prune`): small connected components go when their faces are needed, the
// smallest first; never the largest, never below the target; the visitor, the memory's fit and the
// level-of-detail chains (shared atlas included) see the faces removed.
#include "cmgeom_test_config.h"

#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification.h>
#include <CMGeom/Textured_simplification/level_of_detail.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>

#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/boost/graph/copy_face_graph.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cmgeom_test_support.h"
#include "cmgeom_test_surface_meshes.h"
#include "cmgeom_test_textured_grid.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <iostream>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
using Mesh = CMGeom::Surface_mesh;
using Point_3 = CMGeom::Point_3;

// Appends `part`, scaled by `s` and moved by (dx, 0, 0), to `m`.
void append(Mesh& m, const Mesh& part, double s, double dx) {
  Mesh p = part;
  for (auto v : p.vertices()) {
    const Point_3& q = p.point(v);
    p.point(v) = Point_3(s * q.x() + dx, s * q.y(), s * q.z());
  }
  CGAL::copy_face_graph(p, m);
}

// A torus of 2,400 faces (about 2.7 across) and, beside it, six small tori of 96 faces each 0.02 x
// its size and six 0.08 x its size: thirteen closed components of genus 1. A torus cannot be
// collapsed below a few faces, so the small ones alone hold about a hundred faces at their smallest.
Mesh torus_with_small_parts() {
  const Mesh big = cmgeom_test::rippled_torus(40, 30, 0.35, 0.02, 7, 5);
  const Mesh small = cmgeom_test::rippled_torus(8, 6, 0.35, 0.0, 1, 1);
  Mesh m;
  append(m, big, 1.0, 0.0);
  for (int k = 0; k < 6; ++k) append(m, small, 0.02, 2.0 + 0.3 * k);
  for (int k = 0; k < 6; ++k) append(m, small, 0.08, 4.0 + 0.5 * k);
  return m;
}

// The components of `m`: for each, its face count and the width of its bounding box along x.
std::vector<std::pair<std::size_t, double>> components(const Mesh& m) {
  auto fcc = get(CGAL::dynamic_face_property_t<std::size_t>(), m);
  const std::size_t n = CGAL::Polygon_mesh_processing::connected_components(m, fcc);
  std::vector<std::pair<std::size_t, double>> out(n, {0, 0});
  std::vector<double> lo(n, 1e300), hi(n, -1e300);
  for (auto f : m.faces()) {
    const std::size_t c = get(fcc, f);
    ++out[c].first;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
      lo[c] = (std::min)(lo[c], m.point(v).x());
      hi[c] = (std::max)(hi[c], m.point(v).x());
    }
  }
  for (std::size_t c = 0; c < n; ++c) out[c].second = hi[c] - lo[c];
  return out;
}

long euler_characteristic_of(const Mesh& m) {
  return long(m.number_of_vertices()) - long(m.number_of_edges()) + long(m.number_of_faces());
}

TEST(PruneComponents, SmallPartsGiveTheirFacesToTheRestSmallestFirst) {
  const Mesh input = torus_with_small_parts();
  ASSERT_EQ(components(input).size(), 13u);
  const std::size_t target = 60;
  // without pruning the small tori hold their faces: the run stops above the target
  Mesh kept = input;
  const TS::Mesh_simplification_result rk = TS::simplify_mesh(kept, target);
  EXPECT_EQ(rk.stopped_by, TS::Stop_reason::no_collapse);
  EXPECT_GT(kept.number_of_faces(), target + 40);
  EXPECT_EQ(components(kept).size(), 13u);
  // with it the target is reached, and the torus keeps the faces the small ones gave up
  Mesh pruned = input;
  TS::Mesh_simplification_options o;
  o.prune_components = true;
  const TS::Removed_faces_visitor counter;
  const TS::Mesh_simplification_result rp = TS::simplify_mesh(pruned, target, o, counter);
  EXPECT_EQ(rp.stopped_by, TS::Stop_reason::target);
  EXPECT_LE(pruned.number_of_faces(), target);
  EXPECT_GE(pruned.number_of_faces() + 2, target);
  EXPECT_EQ(counter.removed(), input.number_of_faces() - pruned.number_of_faces());
  ASSERT_TRUE(CGAL::is_valid_polygon_mesh(pruned));
  EXPECT_TRUE(CGAL::is_closed(pruned));
  const auto left = components(pruned);
  ASSERT_GE(left.size(), 1u);
  // the torus is there (the widest component), with more faces than without pruning
  const auto widest =
      *std::max_element(left.begin(), left.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  EXPECT_GT(widest.second, 2.0);
  std::size_t torus_kept = 0;
  for (const auto& c : components(kept))
    if (c.second > 2.0) torus_kept = c.first;
  EXPECT_GT(widest.first, torus_kept);
  // every component left is still a closed torus (Euler characteristic 0 each)
  EXPECT_EQ(euler_characteristic_of(pruned), 0);
  // the tiny tori went before any of the larger small ones
  int tiny = 0, small = 0;
  for (const auto& c : left) {
    if (c.second > 2.0) continue;
    (c.second < 0.1 ? tiny : small) += 1;
  }
  EXPECT_TRUE(small == 6 || tiny == 0) << tiny << " tiny and " << small << " small tori left";
  EXPECT_LT(tiny + small, 12);
  // at the face count the run without pruning stops at, pruning is closer to the input (RMS, both
  // ways): the faces the small tori held at their smallest shape the torus instead
  Mesh same = input;
  TS::simplify_mesh(same, kept.number_of_faces(), o);
  EXPECT_LE(same.number_of_faces(), kept.number_of_faces());
  const double e_pruned = CMGeom::Metrics::approximation_error(input, same).rms;
  const double e_kept = CMGeom::Metrics::approximation_error(input, kept).rms;
  std::cout << kept.number_of_faces() << " faces: RMS " << e_pruned << " with pruning, " << e_kept << " without\n";
  EXPECT_LT(e_pruned, e_kept);
}

TEST(PruneComponents, NeverBelowTheTargetNorTheLargestComponent) {
  const Mesh big = cmgeom_test::rippled_torus(40, 30, 0.35, 0.02, 7, 5);
  const Mesh small = cmgeom_test::rippled_torus(8, 6, 0.35, 0.0, 1, 1);
  Mesh m;
  append(m, big, 1.0, 0.0);
  append(m, small, 0.05, 3.0);
  TS::Mesh_simplification_options o;
  o.prune_components = true;
  // removing the small torus would go below the target: it stays
  const std::size_t near = m.number_of_faces() - 20;
  Mesh a = m;
  TS::simplify_mesh(a, near, o);
  EXPECT_EQ(components(a).size(), 2u);
  EXPECT_LE(a.number_of_faces(), near);
  // far below: the small one goes, the torus never does (it holds the faces left)
  Mesh b = m;
  TS::simplify_mesh(b, 24, o);
  const auto left = components(b);
  ASSERT_EQ(left.size(), 1u);
  EXPECT_GT(left[0].second, 2.0);
  EXPECT_LE(b.number_of_faces(), 24u);
  // a single component: pruning changes nothing, vertex for vertex
  Mesh c = big, d = big;
  TS::simplify_mesh(c, 300, o);
  TS::simplify_mesh(d, 300);
  ASSERT_EQ(c.number_of_vertices(), d.number_of_vertices());
  for (auto v : c.vertices()) EXPECT_EQ(c.point(v), d.point(v));
}

TEST(PruneComponents, OptionsAreChecked) {
  Mesh m = torus_with_small_parts();
  TS::Mesh_simplification_options o;
  o.prune_components = true;
  TS::Mesh_simplification_options e = o;
  e.max_error = 0.01;
  e.target_faces = 100;
  EXPECT_THROW(TS::simplify_mesh(m, e), std::invalid_argument);
  TS::Mesh_simplification_options c = o;
  c.max_cost = 1.0;
  EXPECT_THROW(TS::simplify_mesh(m, c), std::invalid_argument);  // no face target
  TS::Mesh_simplification_options g = o;
  g.engine = TS::Simplification_engine::cgal;
  g.surface_memory = false;
  g.target_faces = 100;
  EXPECT_THROW(TS::simplify_mesh(m, g), std::invalid_argument);
  EXPECT_EQ(m.number_of_faces(), torus_with_small_parts().number_of_faces());  // left as it was
  // the textured path refuses them as invalid input, before anything changes
  CMGeom::Textured_mesh tm = cmgeom_test::two_chart_grid(16, 64);
  const std::size_t faces = tm.mesh().number_of_faces();
  TS::Textured_simplification_options to;
  to.prune_components = true;
  to.target_faces = 50;
  to.max_error = 0.01;
  EXPECT_THROW(TS::simplify_textured_mesh(tm, to), CMGeom::Invalid_input);
  to.max_error.reset();
  to.keep_charts = true;
  EXPECT_THROW(TS::simplify_textured_mesh(tm, to), CMGeom::Invalid_input);
  EXPECT_EQ(tm.mesh().number_of_faces(), faces);
}

TEST(PruneComponents, LevelOfDetailChainsPruneInTheRunsOrder) {
  const CMGeom::Textured_mesh input(torus_with_small_parts());
  TS::Level_of_detail_options o;
  o.prune_components = true;
  const std::size_t n = input.mesh().number_of_faces();
  o.target_faces = {n, 600, 200, 60};
  const TS::Level_of_detail_result r = TS::simplify_to_levels(input, o);
  ASSERT_EQ(r.levels.size(), 4u);
  std::size_t previous = n + 1, parts = 14;
  for (std::size_t i = 0; i < r.levels.size(); ++i) {
    const Mesh& l = r.levels[i].mesh.mesh();
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(l));
    EXPECT_LE(l.number_of_faces(), o.target_faces[i]);
    EXPECT_LT(l.number_of_faces(), previous);
    previous = l.number_of_faces();
    // components only go: a coarser level never has more
    const std::size_t k = components(l).size();
    EXPECT_LE(k, parts);
    parts = k;
  }
  EXPECT_LT(parts, 13u);
  // the coarsest level is the mesh simplify_mesh() gives with pruning to its target
  Mesh alone = input.mesh();
  TS::Mesh_simplification_options so;
  so.parts_min_faces = 0;
  so.prune_components = true;
  so.quadric = o.quadric;
  so.memory = o.memory;
  TS::simplify_mesh(alone, o.target_faces.back(), so);
  const Mesh& last = r.levels.back().mesh.mesh();
  ASSERT_EQ(alone.number_of_faces(), last.number_of_faces());
  std::multiset<std::array<double, 3>> pa, pl;
  for (auto v : alone.vertices()) pa.insert({alone.point(v).x(), alone.point(v).y(), alone.point(v).z()});
  for (auto v : last.vertices()) pl.insert({last.point(v).x(), last.point(v).y(), last.point(v).z()});
  EXPECT_TRUE(pa == pl);
}

TEST(PruneComponents, SharedAtlasChainOfAModelInManyParts) {
  const std::string path = std::string(CMGEOM_DATA_DIR) + "/textured/DamagedHelmet/DamagedHelmet.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data not found: " << path;
  CMGeom::Textured_mesh input;
  CMGeom::IO::Read_options ro;
  ro.repair = true;  // (7 non-manifold edges, as `cmgeom` repairs them)
  CMGeom::IO::read_textured_mesh(path, input, ro);
  const std::size_t n = input.mesh().number_of_faces();
  TS::Level_of_detail_options o;
  o.target_faces = {n, n / 20, n / 100};
  o.shared_texture = true;
  o.measure_error = false;
  TS::Level_of_detail_options p = o;
  p.prune_components = true;
  const TS::Level_of_detail_result without = TS::simplify_to_levels(input, o);
  const TS::Level_of_detail_result with = TS::simplify_to_levels(input, p);
  // without pruning the helmet's 60-odd loose parts stop the run above 1 %; with it the target is met
  EXPECT_GT(without.levels.back().mesh.mesh().number_of_faces(), o.target_faces.back());
  EXPECT_LE(with.levels.back().mesh.mesh().number_of_faces(), o.target_faces.back());
  const CMGeom::Image& atlas = with.levels.back().mesh.materials().at(0).diffuse_image;
  ASSERT_FALSE(atlas.empty());
  for (const auto& l : with.levels) {
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(l.mesh.mesh()));
    EXPECT_TRUE(l.mesh.materials().at(0).diffuse_image == atlas);
    for (auto h : l.mesh.mesh().halfedges()) {
      if (l.mesh.mesh().is_border(h)) continue;
      const CMGeom::Point_2 t = l.mesh.uv(h);
      ASSERT_TRUE(t.x() > -0.01 && t.x() < 1.01 && t.y() > -0.01 && t.y() < 1.01) << "UV " << t << " off the atlas";
    }
  }
  // the coarsest level spends its faces on the helmet rather than on the bolts: closer to the input
  // (geometric RMS, both directions; measured 0.015 against 0.031 of the diagonal)
  const double e_with = CMGeom::Metrics::approximation_error(input.mesh(), with.levels.back().mesh.mesh()).rms;
  const double e_without = CMGeom::Metrics::approximation_error(input.mesh(), without.levels.back().mesh.mesh()).rms;
  std::cout << "DamagedHelmet at 1 %: RMS " << e_with << " with pruning, " << e_without << " without\n";
  EXPECT_LT(e_with, e_without);
}

TEST(PruneComponents, CommandLine) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built: " << CMGEOM_CMGEOM_EXE;
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string in = dir + "/parts.off", out = dir + "/parts_out.off";
  Mesh parts = torus_with_small_parts();
  ASSERT_TRUE(CGAL::IO::write_polygon_mesh(in, parts, CGAL::parameters::stream_precision(17)));
  const cmgeom_test::Cli_result r =
      cmgeom_test::run_cli("simplify '" + in + "' -o '" + out + "' --faces 60 --prune --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["prune"].get<bool>());
  EXPECT_EQ(j["stopped_by"].get<std::string>(), "target");
  EXPECT_LE(j["faces_out"].get<std::size_t>(), 60u);
  Mesh m;
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(out, m));
  EXPECT_LT(components(m).size(), 13u);
  // refused combinations: exit code 1, a message naming --prune, nothing written
  const std::size_t files = cmgeom_test::count_files(dir);
  for (const std::string bad :
       {" --max-error 0.01", " --faces 60 --max-error 0.01", " --faces 60 --engine cgal", " --max-cost 1"}) {
    const cmgeom_test::Cli_result e =
        cmgeom_test::run_cli("simplify '" + in + "' -o '" + dir + "/never.off' --prune" + bad, dir);
    EXPECT_EQ(e.exit_code, 1) << bad;
    EXPECT_NE(e.err.find("--prune"), std::string::npos) << bad << ": " << e.err;
  }
  EXPECT_EQ(cmgeom_test::count_files(dir), files);
}

}  // namespace
