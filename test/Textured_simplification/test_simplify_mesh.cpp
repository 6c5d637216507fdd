// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// simplify_mesh() and its first stage in parts (internal/Mesh_parts.h): cutting a mesh into
// parts and putting them back gives the input again; the locked vertices are exactly the cut
// ones; a simplification in parts keeps the mesh valid, its topology and its target, and its
// error stays close to the simplification of the whole at once.
#include "cmgeom_test_config.h"

#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Textured_simplification.h>

#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <gtest/gtest.h>

#include "cmgeom_test_support.h"
#include "cmgeom_test_surface_meshes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
using Mesh = CMGeom::Surface_mesh;
using Point_3 = CMGeom::Point_3;

// A rippled torus, n x m quads split in two: closed, genus 1, every vertex of degree 6.
Mesh rippled_torus(int n, int m) { return cmgeom_test::rippled_torus(n, m, 0.35, 0.02, 7, 5); }

// A bumpy height field on an n x n grid: one border loop.
Mesh bumpy_sheet(int n) {
  return cmgeom_test::height_field(
      n, [](double x, double y) { return 0.05 * std::sin(9 * x) * std::cos(7 * y) + 0.02 * std::sin(31 * x * y); });
}

long euler_characteristic(const Mesh& m) {
  return long(m.number_of_vertices()) - long(m.number_of_edges()) + long(m.number_of_faces());
}

std::size_t border_loops(const Mesh& m) {
  std::set<Mesh::Halfedge_index> seen;
  std::size_t loops = 0;
  for (auto h : m.halfedges()) {
    if (!m.is_border(h) || seen.count(h)) continue;
    ++loops;
    for (auto g : CGAL::halfedges_around_face(h, m)) seen.insert(g);
  }
  return loops;
}

// The triangles of a mesh as sorted corner-point triples (a representation free of indices).
std::multiset<std::array<std::array<double, 3>, 3>> triangles(const Mesh& m) {
  std::multiset<std::array<std::array<double, 3>, 3>> out;
  for (auto f : m.faces()) {
    std::array<std::array<double, 3>, 3> t;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) {
      const Point_3& p = m.point(v);
      t[std::size_t(k++)] = {p.x(), p.y(), p.z()};
    }
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());  // orientation kept
    out.insert(t);
  }
  return out;
}

TEST(MeshParts, CuttingAndMergingGivesTheInputBack) {
  for (const Mesh& input : {rippled_torus(60, 40), bumpy_sheet(50)}) {
    for (int levels : {1, 2, 3}) {
      std::vector<std::uint32_t> label;
      const auto faces_of = TS::internal::split_faces(input, levels, label);
      ASSERT_EQ(faces_of.size(), std::size_t(1) << levels);
      std::vector<std::uint32_t> corner(input.num_halfedges(), TS::internal::no_index),
          side(input.num_halfedges(), TS::internal::no_index);
      std::vector<TS::internal::Mesh_part<Point_3>> parts;
      std::size_t faces = 0;
      for (std::uint32_t k = 0; k < faces_of.size(); ++k) {
        // the halves differ by one face at most
        EXPECT_LE(faces_of[k].size(), input.number_of_faces() / faces_of.size() + 1);
        parts.push_back(TS::internal::make_part(input, k, faces_of[k], label, corner, side));
        const auto& part = parts.back();
        ASSERT_TRUE(CGAL::is_valid_polygon_mesh(part.mesh)) << "part " << k;
        faces += part.mesh.number_of_faces();
        // a part vertex is locked exactly when its input vertex has faces in another part
        for (auto u : part.mesh.vertices()) {
          const Mesh::Vertex_index v(Mesh::size_type(part.to_input[std::size_t(u)]));
          EXPECT_EQ(part.mesh.point(u), input.point(v));
          bool elsewhere = false;
          for (auto f : CGAL::faces_around_target(input.halfedge(v), input))
            if (f != Mesh::null_face() && label[std::size_t(f)] != k) elsewhere = true;
          EXPECT_EQ(bool(part.locked[std::size_t(u)]), elsewhere);
        }
      }
      EXPECT_EQ(faces, input.number_of_faces());
      const auto merged = TS::internal::merge_parts(parts, input.num_vertices());
      Mesh whole;
      TS::internal::build_triangle_mesh(whole, merged.points, merged.corners, merged.sides, merged.edges);
      ASSERT_TRUE(CGAL::is_valid_polygon_mesh(whole));
      EXPECT_EQ(whole.number_of_vertices(), input.number_of_vertices());
      EXPECT_EQ(whole.number_of_edges(), input.number_of_edges());
      EXPECT_EQ(border_loops(whole), border_loops(input));
      EXPECT_TRUE(triangles(whole) == triangles(input)) << "levels " << levels;
    }
  }
}

TEST(MeshParts, MergingTheFinestPartsOfAGroupGivesThatGroupAsAPart) {
  // The parts of 2^levels carry, for each coarser level, the runs that glue their locked copies
  // (Mesh_part::run): merged by them, the parts of a group of level L must give the part that
  // cutting the input into 2^L parts makes of that group's faces, the same triangles, the same
  // locked vertices, none glued that should not be (the vertex count).
  for (const Mesh& input : {rippled_torus(60, 40), bumpy_sheet(50)}) {
    for (int levels : {2, 3}) {
      std::vector<std::uint32_t> label;
      const auto faces_of = TS::internal::split_faces(input, levels, label);
      std::vector<std::uint32_t> corner(input.num_halfedges(), TS::internal::no_index),
          side(input.num_halfedges(), TS::internal::no_index);
      std::vector<TS::internal::Mesh_part<Point_3>> parts;
      for (std::uint32_t k = 0; k < faces_of.size(); ++k)
        parts.push_back(TS::internal::make_part(input, k, faces_of[k], label, corner, side, levels));
      for (int level = 1; level < levels; ++level) {
        std::vector<std::uint32_t> coarse_label;
        const auto coarse_faces = TS::internal::split_faces(input, level, coarse_label);
        std::vector<std::uint32_t> coarse_corner(input.num_halfedges(), TS::internal::no_index),
            coarse_side(input.num_halfedges(), TS::internal::no_index);
        const std::size_t per = parts.size() / coarse_faces.size();
        for (std::uint32_t g = 0; g < coarse_faces.size(); ++g) {
          const auto expected =
              TS::internal::make_part(input, g, coarse_faces[g], coarse_label, coarse_corner, coarse_side);
          std::vector<const TS::internal::Mesh_part<Point_3>*> list;
          for (std::size_t k = per * g; k < per * (g + 1); ++k) list.push_back(&parts[k]);
          const auto merged = TS::internal::merge_part_group(list, level);
          Mesh group;
          TS::internal::build_triangle_mesh(group, merged.points, merged.corners, merged.sides, merged.edges);
          ASSERT_TRUE(CGAL::is_valid_polygon_mesh(group)) << "levels " << levels << " level " << level;
          EXPECT_EQ(group.number_of_vertices(), expected.mesh.number_of_vertices());
          EXPECT_EQ(group.number_of_edges(), expected.mesh.number_of_edges());
          EXPECT_TRUE(triangles(group) == triangles(expected.mesh)) << "levels " << levels << " level " << level;
          // locked in the group: a locked copy whose run of that level is cut
          std::set<std::uint32_t> locked_vertices;
          for (std::size_t s = 0; s < list.size(); ++s)
            for (auto u : list[s]->mesh.vertices())
              if (list[s]->locked[std::size_t(u)] && (list[s]->run_cut[std::size_t(u)] >> level & 1u))
                locked_vertices.insert(merged.vertex[s][std::size_t(u)]);
          std::multiset<std::array<double, 3>> locked, expected_locked;
          for (std::uint32_t i : locked_vertices)
            locked.insert({merged.points[i].x(), merged.points[i].y(), merged.points[i].z()});
          for (auto u : expected.mesh.vertices())
            if (expected.locked[std::size_t(u)]) {
              const Point_3& p = expected.mesh.point(u);
              expected_locked.insert({p.x(), p.y(), p.z()});
            }
          EXPECT_TRUE(locked == expected_locked) << "levels " << levels << " level " << level << ": " << locked.size()
                                                 << " locked, expected " << expected_locked.size();
        }
      }
    }
  }
}

TEST(MeshParts, MergeNumbersAsOnePassOverThePartsInOrder) {
  // merge_parts() numbers on all cores; its numbers are those of one pass over the parts in order,
  // written here plainly: a part's live vertices, a shared (locked) one where first met; its live
  // edges but the cut ones, which come last in the order of their end vertices; its live faces.
  // The parts have removed elements (some collapses inside each), as after a simplification.
  for (const Mesh& input : {rippled_torus(60, 40), bumpy_sheet(50)}) {
    std::vector<std::uint32_t> label;
    const auto faces_of = TS::internal::split_faces(input, 3, label);
    std::vector<std::uint32_t> corner(input.num_halfedges(), TS::internal::no_index),
        side(input.num_halfedges(), TS::internal::no_index);
    std::vector<TS::internal::Mesh_part<Point_3>> parts;
    std::size_t collapsed = 0;
    for (std::uint32_t k = 0; k < faces_of.size(); ++k) {
      parts.push_back(TS::internal::make_part(input, k, faces_of[k], label, corner, side));
      Mesh& pm = parts.back().mesh;
      const auto& locked = parts.back().locked;
      for (std::size_t e = 0; e < pm.num_edges(); e += 7) {
        const Mesh::Edge_index ed{Mesh::size_type(e)};
        if (pm.is_removed(ed)) continue;
        const auto h = pm.halfedge(ed);
        if (locked[std::size_t(pm.source(h))] || locked[std::size_t(pm.target(h))] || pm.is_border(ed) ||
            pm.is_border(pm.source(h)) || pm.is_border(pm.target(h)) ||
            !CGAL::Euler::does_satisfy_link_condition(ed, pm))
          continue;
        CGAL::Euler::collapse_edge(ed, pm);
        ++collapsed;
      }
    }
    ASSERT_GT(collapsed, 100u);
    const auto merged = TS::internal::merge_parts(parts, input.num_vertices());
    // the plain pass
    std::vector<Point_3> points;
    std::vector<std::uint32_t> input_vertex, corners, sides;
    std::vector<std::vector<std::uint32_t>> vertex(parts.size()), face(parts.size()), edge(parts.size());
    std::map<std::uint32_t, std::uint32_t> shared;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const auto& part = parts[k];
      vertex[k].assign(part.mesh.num_vertices(), TS::internal::no_index);
      for (auto u : part.mesh.vertices()) {
        const std::uint32_t v = part.to_input[std::size_t(u)];
        if (part.locked[std::size_t(u)] && shared.count(v)) {
          vertex[k][std::size_t(u)] = shared[v];
          continue;
        }
        vertex[k][std::size_t(u)] = std::uint32_t(points.size());
        if (part.locked[std::size_t(u)]) shared[v] = std::uint32_t(points.size());
        points.push_back(part.mesh.point(u));
        input_vertex.push_back(part.locked[std::size_t(u)] ? v : TS::internal::no_index);
      }
    }
    std::uint32_t edges = 0;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::pair<std::size_t, std::size_t>>> cut;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const auto& pm = parts[k].mesh;
      edge[k].assign(pm.num_edges(), TS::internal::no_index);
      for (auto e : pm.edges()) {
        const auto a = pm.vertex(e, 0), b = pm.vertex(e, 1);
        if (pm.is_border(e) && parts[k].locked[std::size_t(a)] && parts[k].locked[std::size_t(b)]) {
          const std::uint32_t x = vertex[k][std::size_t(a)], y = vertex[k][std::size_t(b)];
          cut[{(std::min)(x, y), (std::max)(x, y)}].push_back({k, std::size_t(e)});
        } else {
          edge[k][std::size_t(e)] = edges++;
        }
      }
    }
    for (const auto& [ends, sides_of_edge] : cut) {
      ASSERT_LE(sides_of_edge.size(), 2u);
      for (const auto& [k, e] : sides_of_edge) edge[k][e] = edges;
      ++edges;
    }
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const auto& pm = parts[k].mesh;
      face[k].assign(pm.num_faces(), TS::internal::no_index);
      for (auto f : pm.faces()) {
        face[k][std::size_t(f)] = std::uint32_t(corners.size() / 3);
        for (auto h : CGAL::halfedges_around_face(pm.halfedge(f), pm)) {
          corners.push_back(vertex[k][std::size_t(pm.source(h))]);
          sides.push_back(edge[k][std::size_t(pm.edge(h))]);
        }
      }
    }
    EXPECT_TRUE(merged.points == points);
    EXPECT_EQ(merged.input_vertex, input_vertex);
    EXPECT_EQ(merged.vertex, vertex);
    EXPECT_EQ(merged.edges, std::size_t(edges));
    EXPECT_EQ(merged.corners, corners);
    EXPECT_EQ(merged.sides, sides);
    EXPECT_EQ(merged.face, face);
    Mesh whole;
    TS::internal::build_triangle_mesh(whole, merged.points, merged.corners, merged.sides, merged.edges);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(whole));
    EXPECT_EQ(whole.number_of_faces(), input.number_of_faces() - 2 * collapsed);
  }
}

TEST(MeshParts, BuildRefusesAnEdgeWithThreeSides) {
  // three triangles on one edge (0, 1)
  const std::vector<Point_3> p = {Point_3(0, 0, 0), Point_3(1, 0, 0), Point_3(0, 1, 0), Point_3(0, -1, 0),
                                  Point_3(0, 0, 1)};
  const std::vector<std::uint32_t> corners = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  const std::vector<std::uint32_t> sides = {0, 1, 2, 0, 3, 4, 0, 5, 6};
  Mesh m;
  EXPECT_THROW(TS::internal::build_triangle_mesh(m, p, corners, sides, 7), std::logic_error);
}

// Parts forced on a small mesh (the defaults start at 262,144 faces).
TS::Mesh_simplification_options small_parts() {
  TS::Mesh_simplification_options o;
  o.quadric.weighted = false;
  o.parts_min_faces = 4096;
  o.part_faces = 1024;
  return o;
}

/// `m` with every face split in four at its edges' midpoints (flat: the surface is unchanged).
Mesh midpoint_subdivision(const Mesh& m) {
  std::vector<Point_3> points;
  std::vector<std::array<std::size_t, 3>> faces;
  for (auto v : m.vertices()) points.push_back(m.point(v));  // (m has no removed vertex)
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> middle;
  auto mid = [&](std::size_t a, std::size_t b) {
    const auto key = std::minmax(a, b);
    const auto it = middle.find(key);
    if (it != middle.end()) return it->second;
    points.push_back(CGAL::midpoint(points[a], points[b]));
    return middle[key] = points.size() - 1;
  };
  for (auto f : m.faces()) {
    const auto h = m.halfedge(f);
    const std::size_t a = m.source(h), b = m.target(h), c = m.target(m.next(h));
    const std::size_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    faces.push_back({a, ab, ca});
    faces.push_back({ab, b, bc});
    faces.push_back({ca, bc, c});
    faces.push_back({ab, bc, ca});
  }
  Mesh out;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, faces, out);
  return out;
}

// A mesh subdivided flat and simplified back to more faces than it had is recovered: the quadrics
// find its vertices, and the final fit must not move them. The fit's points are re-attached to
// their nearest faces first: a point the collapses left on a face it no longer lies over used to
// loosen the fit's distance bound for every point (the twice-subdivided ogre to 10 %: Hausdorff
// 5.0e-5 of the diagonal with the fit, 2.5e-8 without).
TEST(SimplifyMesh, FlatSubdivisionIsRecoveredWithTheFit) {
  const Mesh coarse = rippled_torus(24, 12);
  const Mesh fine = midpoint_subdivision(midpoint_subdivision(coarse));
  ASSERT_EQ(fine.number_of_faces(), 16 * coarse.number_of_faces());
  for (std::size_t target : {2 * coarse.number_of_faces(), coarse.number_of_faces() + coarse.number_of_faces() / 2}) {
    Mesh fitted = fine, unfitted = fine;
    TS::Mesh_simplification_options o;
    // the memory prices no collapse here (as on inputs of more than 65,536 vertices until two
    // faces per point are left): the points move only with the two faces a collapse removes
    o.memory.pricing_points = 16;
    const TS::Mesh_simplification_result r = TS::simplify_mesh(fitted, target, o);
    EXPECT_GT(r.fit_moves, 0u);
    o.memory.fit.rounds = 0;
    TS::simplify_mesh(unfitted, target, o);
    const auto ef = CMGeom::Metrics::approximation_error(fine, fitted);
    const auto eu = CMGeom::Metrics::approximation_error(fine, unfitted);
    // (Hausdorff distances as fractions of the diagonal)
    std::cout << target << " faces: Hausdorff with the fit " << ef.hausdorff << ", without " << eu.hausdorff << '\n';
    // recovered without the fit (the quadrics' exact vertices), and the fit keeps it so
    EXPECT_LT(eu.hausdorff, 1e-7) << target;
    EXPECT_LT(ef.hausdorff, 1e-6) << target;
  }
}

TEST(SimplifyMesh, InPartsKeepsTopologyTargetAndError) {
  for (const Mesh& input : {rippled_torus(120, 80), bumpy_sheet(100)}) {
    for (double ratio : {0.05, 0.02}) {
      const std::size_t target = std::size_t(ratio * double(input.number_of_faces()));
      // the parts put back together at once, the finer cuts' strips left for the whole
      Mesh at_once = input;
      TS::Mesh_simplification_options flat = small_parts();
      flat.parts_whole_levels = 4;
      const TS::Mesh_simplification_result a = TS::simplify_mesh(at_once, target, flat);
      ASSERT_TRUE(CGAL::is_valid_polygon_mesh(at_once));
      EXPECT_LE(at_once.number_of_faces(), target);
      EXPECT_EQ(euler_characteristic(at_once), euler_characteristic(input));
      EXPECT_EQ(border_loops(at_once), border_loops(input));
      // pairwise (the default)
      Mesh parts = input, whole = input;
      const TS::Mesh_simplification_result r = TS::simplify_mesh(parts, target, small_parts());
      EXPECT_LT(r.faces_after_parts, a.faces_after_parts);  // only the first cut's strip left
      TS::Mesh_simplification_options o = small_parts();
      o.parts_min_faces = 0;
      const TS::Mesh_simplification_result w = TS::simplify_mesh(whole, target, o);
      EXPECT_EQ(r.parts, 16u);  // 19,200 and 20,000 faces: four halvings of at least 1,024
      EXPECT_EQ(w.parts, 0u);
      EXPECT_GT(r.faces_after_parts, target);
      EXPECT_LT(r.faces_after_parts, input.number_of_faces() / 2);  // the parts did most of the work
      ASSERT_TRUE(CGAL::is_valid_polygon_mesh(parts));
      EXPECT_TRUE(CGAL::is_triangle_mesh(parts));
      EXPECT_FALSE(parts.has_garbage());
      // a collapse removes two faces (one on a border): the target or one below
      EXPECT_LE(parts.number_of_faces(), target);
      EXPECT_GE(parts.number_of_faces() + 1, target);
      EXPECT_EQ(r.faces_out, parts.number_of_faces());
      EXPECT_LE(whole.number_of_faces(), target);
      EXPECT_GE(whole.number_of_faces() + 1, target);
      EXPECT_EQ(euler_characteristic(parts), euler_characteristic(input));
      EXPECT_EQ(border_loops(parts), border_loops(input));
      const auto ep = CMGeom::Metrics::approximation_error(input, parts);
      const auto ea = CMGeom::Metrics::approximation_error(input, at_once);
      const auto ew = CMGeom::Metrics::approximation_error(input, whole);
      // the cuts cost little: measured on these two (16 parts of about 1,200 faces, far smaller than
      // the defaults allow), pairwise Hausdorff 0.81-1.24x, RMS 0.98-1.06x that of the whole at once,
      // the parts put back at once 0.77-1.06x and 1.00-1.03x (printed)
      std::cout << "in parts / whole, " << input.number_of_faces() << " faces to " << target << ": Hausdorff "
                << ep.hausdorff / ew.hausdorff << ", RMS " << ep.rms / ew.rms
                << " (parts put back at once: " << ea.hausdorff / ew.hausdorff << ", " << ea.rms / ew.rms << ")\n";
      EXPECT_LE(ep.hausdorff, 1.5 * ew.hausdorff) << "ratio " << ratio;
      EXPECT_LE(ep.rms, 1.2 * ew.rms) << "ratio " << ratio;
      EXPECT_LE(ea.hausdorff, 1.5 * ew.hausdorff) << "ratio " << ratio;
      EXPECT_LE(ea.rms, 1.2 * ew.rms) << "ratio " << ratio;
    }
  }
}

TEST(SimplifyMesh, ReleasingTheInputDuringThePartsChangesNothing) {
  // release_input_in_parts frees the input once cut, and the parts' quadrics are the input's
  // either way: the output is the same, point for point, with before_changing_input called once
  for (const Mesh& input : {rippled_torus(120, 80), bumpy_sheet(100)}) {
    const std::size_t target = input.number_of_faces() / 40;
    Mesh kept = input, released = input;
    TS::Mesh_simplification_options o = small_parts();
    int calls_kept = 0, calls_released = 0;
    o.before_changing_input = [&] {
      ++calls_kept;
      EXPECT_EQ(kept.number_of_faces(), input.number_of_faces());  // not changed yet
    };
    const TS::Mesh_simplification_result rk = TS::simplify_mesh(kept, target, o);
    o.release_input_in_parts = true;
    o.before_changing_input = [&] {
      ++calls_released;
      EXPECT_EQ(released.number_of_faces(), input.number_of_faces());
    };
    const TS::Mesh_simplification_result rr = TS::simplify_mesh(released, target, o);
    EXPECT_EQ(calls_kept, 1);
    EXPECT_EQ(calls_released, 1);
    EXPECT_EQ(rk.parts, 16u);
    EXPECT_EQ(rr.parts, 16u);
    EXPECT_EQ(rr.faces_after_parts, rk.faces_after_parts);
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(released));
    EXPECT_EQ(released.number_of_faces(), kept.number_of_faces());
    EXPECT_TRUE(triangles(released) == triangles(kept));
  }
}

// The part-side rule for two locked copies of one input vertex (a part whose faces around that
// vertex make two runs): on a strip of three quads, p0 and p3 copies of input vertex 7. Without
// the twin marks the filter lets the bottom edge p1-p2 go, which would join p0 and p3 (one vertex
// once the parts are glued) by two edges; with them it refuses that and the collapse of p2 onto
// p3 (p3 would become the neighbour of p1, next to p0), and still accepts the top edge q1-q2.
TEST(MeshParts, TwinCopiesOfAnInputVertexAreNeverJoinedTwice) {
  TS::internal::Mesh_part<Point_3> part;
  Mesh& m = part.mesh;
  std::vector<Mesh::Vertex_index> p, q;
  for (int i = 0; i < 4; ++i) p.push_back(m.add_vertex(Point_3(i, 0, 0)));
  for (int i = 0; i < 4; ++i) q.push_back(m.add_vertex(Point_3(i, 1, 0)));
  for (std::size_t i = 0; i < 3; ++i) {
    ASSERT_NE(m.add_face(p[i], p[i + 1], q[i + 1]), Mesh::null_face());
    ASSERT_NE(m.add_face(p[i], q[i + 1], q[i]), Mesh::null_face());
  }
  part.locked.assign(m.num_vertices(), 0);
  part.to_input.assign(m.num_vertices(), TS::internal::no_index);
  for (auto v : {p[0], p[3]}) {
    part.locked[std::size_t(v)] = 1;
    part.to_input[std::size_t(v)] = 7;
  }
  part.locked[std::size_t(q[0])] = 1;  // a locked vertex of its own (no twin)
  part.to_input[std::size_t(q[0])] = 9;
  const std::vector<std::uint8_t> twin = TS::internal::locked_twins(part);
  ASSERT_EQ(twin.size(), m.num_vertices());
  for (auto v : m.vertices()) EXPECT_EQ(twin[std::size_t(v)] != 0, v == p[0] || v == p[3]) << std::size_t(v);
  struct Profile {
    const Mesh* mesh;
    Mesh::Vertex_index a, b;
    const Mesh& surface_mesh() const { return *mesh; }
    Mesh::Vertex_index v0() const { return a; }
    Mesh::Vertex_index v1() const { return b; }
  };
  const std::optional<Point_3> at(Point_3(1.5, 0, 0));
  auto accepts = [&](const std::vector<std::uint8_t>* marks, Mesh::Vertex_index a, Mesh::Vertex_index b) {
    return TS::internal::Locked_vertex_filter<Point_3>{&part, marks}(Profile{&m, a, b}, at).has_value();
  };
  EXPECT_TRUE(accepts(nullptr, p[1], p[2]));  // what the filter let through before
  EXPECT_FALSE(accepts(&twin, p[1], p[2]));
  EXPECT_FALSE(accepts(&twin, p[2], p[1]));
  EXPECT_FALSE(accepts(&twin, p[2], p[3]));
  EXPECT_FALSE(accepts(&twin, p[3], p[2]));
  EXPECT_TRUE(accepts(&twin, q[1], q[2]));
  EXPECT_TRUE(accepts(&twin, q[2], q[3]));
  // a part with no twin has no marks
  part.to_input[std::size_t(p[3])] = 8;
  EXPECT_TRUE(TS::internal::locked_twins(part).empty());
}

// The open, non-manifold ogre of the shared data (44 components, borders, 3 non-manifold vertices
// the reader repairs, zero-area faces), cut into small parts: its fans cross the cuts more than
// once, and the parts put back together used to hold two edges between the same two vertices
// (simplify_mesh threw "the simplified parts do not make a valid mesh"). The output is valid, its
// topology that of the input, and no two edges join the same two vertices.
TEST(SimplifyMesh, InPartsOnAnOpenNonManifoldScanStaysValid) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string path = cmgeom_test::shared_mesh("classic/ogre.obj.gz", dir);
  ASSERT_FALSE(path.empty());
  CMGeom::IO::Read_options ro;
  ro.repair = true;
  ro.allow_degenerate_faces = true;
  std::vector<std::string> warnings;
  ro.warnings = &warnings;
  Mesh input;
  CMGeom::IO::read_mesh(path, input, ro);
  ASSERT_EQ(input.number_of_faces(), 124008u);
  for (double ratio : {0.2, 0.05}) {
    Mesh m = input;
    TS::Mesh_simplification_options o;
    o.target_ratio = ratio;
    o.parts_min_faces = 4096;
    o.part_faces = 2048;
    TS::Mesh_simplification_result r;
    ASSERT_NO_THROW(r = TS::simplify_mesh(m, o)) << ratio;
    EXPECT_EQ(r.parts, 16u) << ratio;  // (four halvings at most)
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m)) << ratio;
    EXPECT_TRUE(CGAL::is_triangle_mesh(m));
    EXPECT_LE(m.number_of_faces(), r.target_faces) << ratio;
    EXPECT_EQ(euler_characteristic(m), euler_characteristic(input)) << ratio;
    EXPECT_EQ(border_loops(m), border_loops(input)) << ratio;
    std::set<std::pair<std::size_t, std::size_t>> ends;
    for (auto e : m.edges()) {
      std::size_t a = std::size_t(m.vertex(e, 0)), b = std::size_t(m.vertex(e, 1));
      if (a > b) std::swap(a, b);
      EXPECT_TRUE(ends.emplace(a, b).second) << "two edges join vertices " << a << " and " << b << ", ratio " << ratio;
    }
  }
}

TEST(SimplifyMesh, SmallInputsAndLowRatiosSkipTheParts) {
  TS::Mesh_simplification_options o = small_parts();
  // asked for more than 1 / (4 x parts_stop_factor) of the faces: one stage; less: parts
  Mesh t = rippled_torus(120, 80);
  Mesh t2 = t;
  EXPECT_EQ(TS::simplify_mesh(t, t.number_of_faces() / 3, o).parts, 0u);
  EXPECT_GT(TS::simplify_mesh(t2, t2.number_of_faces() / 5, o).parts, 0u);
  // below parts_min_faces: one stage
  Mesh s = rippled_torus(40, 40);
  EXPECT_EQ(TS::simplify_mesh(s, s.number_of_faces() / 20, o).parts, 0u);
  o.parts_stop_factor = 0.5;
  EXPECT_THROW(TS::simplify_mesh(s, 10, o), std::invalid_argument);
  // a quad is refused, and the mesh is left as it was
  Mesh q;
  const auto a = q.add_vertex(Point_3(0, 0, 0)), b = q.add_vertex(Point_3(1, 0, 0)), c = q.add_vertex(Point_3(1, 1, 0)),
             d = q.add_vertex(Point_3(0, 1, 0));
  q.add_face(a, b, c, d);
  EXPECT_THROW(TS::simplify_mesh(q, 1), CMGeom::Invalid_input);
  EXPECT_EQ(q.number_of_faces(), 1u);
  EXPECT_EQ(q.number_of_vertices(), 4u);
  // nothing to do: the mesh is unchanged
  Mesh u = rippled_torus(20, 10);
  const auto before = triangles(u);
  EXPECT_EQ(TS::simplify_mesh(u, u.number_of_faces()).faces_out, u.number_of_faces());
  EXPECT_TRUE(triangles(u) == before);
}

// Vertices in no face (scans carry them: the Stanford bunny's OBJ has 1,113) are no part of the
// simplified surface: dropped by the run on the whole, on CGAL's engine and in parts alike, the
// faces' vertices kept.
TEST(SimplifyMesh, IsolatedVerticesOfTheInputAreDropped) {
  Mesh input = rippled_torus(120, 80);
  for (int i = 0; i < 3; ++i) input.add_vertex(Point_3(10 + i, 0, 0));
  auto referenced = [](const Mesh& m) {
    std::size_t n = 0;
    for (auto v : m.vertices()) n += !m.is_isolated(v);
    return n;
  };
  const TS::Mesh_simplification_options in_parts = small_parts();
  TS::Mesh_simplification_options cgal;
  cgal.engine = TS::Simplification_engine::cgal;
  cgal.surface_memory = false;
  for (const auto& [name, o, ratio] : {std::make_tuple("whole", TS::Mesh_simplification_options(), 3),
                                       std::make_tuple("cgal", cgal, 3), std::make_tuple("parts", in_parts, 5)}) {
    SCOPED_TRACE(name);
    Mesh m = input;
    const TS::Mesh_simplification_result r = TS::simplify_mesh(m, input.number_of_faces() / ratio, o);
    EXPECT_EQ(r.parts > 0, std::string(name) == "parts");
    EXPECT_EQ(referenced(m), m.number_of_vertices());
    EXPECT_FALSE(m.has_garbage());
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_LE(m.number_of_faces(), input.number_of_faces() / ratio);
  }
}

TEST(SimplifyMesh, RemovedFacesVisitorCountsWhatTheCollapsesRemove) {
  // one stage (below parts_min_faces): the visitor sees every collapse. A closed mesh loses two
  // faces per collapse; the callback gets the count after every 1024th collapse.
  Mesh m = rippled_torus(50, 40);  // 4,000 faces (parts_min_faces: 4,096)
  const std::size_t faces_in = m.number_of_faces();
  std::vector<std::size_t> reported;
  const TS::Removed_faces_visitor visitor([&](std::size_t removed) { reported.push_back(removed); });
  const TS::Removed_faces_visitor copy = visitor;  // copies share the count
  const TS::Mesh_simplification_result r = TS::simplify_mesh(m, 200, small_parts(), copy);
  ASSERT_EQ(r.parts, 0u);
  EXPECT_EQ(r.faces_out, m.number_of_faces());
  EXPECT_EQ(visitor.removed(), faces_in - r.faces_out);
  EXPECT_EQ(visitor.collapses(), visitor.removed() / 2);
  ASSERT_EQ(reported.size(), visitor.collapses() / 1024);
  for (std::size_t k = 0; k < reported.size(); ++k) EXPECT_EQ(reported[k], 2 * 1024 * (k + 1));
  // an open sheet: a border collapse removes one face
  Mesh s = bumpy_sheet(40);
  const std::size_t sheet_in = s.number_of_faces();
  const TS::Removed_faces_visitor counter;  // no callback
  const TS::Mesh_simplification_result rs = TS::simplify_mesh(s, 100, small_parts(), counter);
  ASSERT_EQ(rs.parts, 0u);
  EXPECT_EQ(counter.removed(), sheet_in - rs.faces_out);
  EXPECT_LE(counter.collapses(), counter.removed());
  EXPECT_GE(2 * counter.collapses(), counter.removed());
}

TEST(SimplifyMesh, RemovedFacesVisitorCountsTheCollapsesOfTheParts) {
  // in parts (16 of them): the parts' collapses, on every core, are counted too, and reported
  // during that stage from the caller's thread; the count ends at the faces removed in all
  Mesh m = rippled_torus(200, 160);  // 64,000 faces
  const std::size_t faces_in = m.number_of_faces();
  std::vector<std::size_t> reported;
  const std::thread::id caller = std::this_thread::get_id();
  bool other_thread = false;
  const TS::Removed_faces_visitor visitor([&](std::size_t removed) {
    other_thread |= std::this_thread::get_id() != caller;
    reported.push_back(removed);
  });
  const TS::Mesh_simplification_result r = TS::simplify_mesh(m, 1000, small_parts(), visitor);
  ASSERT_GT(r.parts, 0u);
  EXPECT_FALSE(other_thread);
  EXPECT_EQ(visitor.removed(), faces_in - r.faces_out);
  EXPECT_EQ(visitor.removed_in_parts(), faces_in - r.faces_after_parts);
  EXPECT_EQ(visitor.collapses(), (r.faces_after_parts - r.faces_out) / 2);  // (closed: two faces each)
  ASSERT_FALSE(reported.empty());
  EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
  EXPECT_LE(reported.back(), visitor.removed());
  // reports came during the parts' stage, before its final count
  const std::size_t in_parts = faces_in - r.faces_after_parts;
  EXPECT_GE(std::count_if(reported.begin(), reported.end(), [&](std::size_t k) { return k < in_parts; }), 1);
  EXPECT_GE(std::count(reported.begin(), reported.end(), in_parts), 1);
}

}  // namespace
