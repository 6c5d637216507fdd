// Tests of the Metrics package: analytic distances, agreement with CGAL's
// approximate_Hausdorff_distance, determinism, vertex fields, texture deviation, image error.
#include <CMGeom/Metrics.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

#include "cmgeom_test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <vector>

#include <tbb/parallel_invoke.h>

#include "cmgeom_test_config.h"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Mesh = CGAL::Surface_mesh<K::Point_3>;
namespace M = CMGeom::Metrics;

Mesh make_mesh(const std::vector<K::Point_3>& pts, const std::vector<std::vector<std::size_t>>& faces) {
  Mesh m;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(pts, faces, m);
  return m;
}

// Icosphere with vertices on the unit sphere: 20 * 4^level faces, inscribed in the sphere.
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

// Smallest distance from the origin to a face plane: 1 - this is how far the inscribed
// polyhedron is below the unit sphere at the worst face centre.
double min_plane_distance(const Mesh& m) {
  double h = HUGE_VAL;
  for (auto f : m.faces()) {
    auto hf = m.halfedge(f);
    const K::Point_3 a = m.point(m.source(hf)), b = m.point(m.target(hf)), c = m.point(m.target(m.next(hf)));
    const K::Plane_3 pl(a, b, c);
    h = std::min(h, std::sqrt(CGAL::squared_distance(K::Point_3(0, 0, 0), pl)));
  }
  return h;
}

// n x n grid of the unit square at height z, triangulated; uv = (x + du, y).
Mesh grid(int n, double z) {
  std::vector<K::Point_3> pts;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) pts.emplace_back(double(i) / n, double(j) / n, z);
  std::vector<std::vector<std::size_t>> faces;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      faces.push_back({a, b, d});
      faces.push_back({a, d, c});
    }
  return make_mesh(pts, faces);
}

TEST(Metrics, MeshAgainstItselfIsZero) {
  const Mesh s = icosphere(3);
  const M::Approximation_error e = M::approximation_error(s, s);
  EXPECT_LT(e.hausdorff, 1e-12);
  EXPECT_LT(e.rms, 1e-12);
  EXPECT_NEAR(e.diagonal, 2. * std::sqrt(3.), 1e-9);  // bbox of the icosphere is [-1,1]^3
}

TEST(Metrics, PlaneAgainstItsOffset) {
  const Mesh a = grid(10, 0.), b = grid(7, 0.1);
  M::Error_options o;
  o.samples = 5000;
  const M::Approximation_error e = M::approximation_error(a, b, o);
  const double diag = std::sqrt(2.);
  EXPECT_NEAR(e.diagonal, diag, 1e-12);
  EXPECT_NEAR(e.hausdorff * diag, 0.1, 1e-12);
  EXPECT_NEAR(e.mean * diag, 0.1, 1e-12);
  EXPECT_NEAR(e.rms * diag, 0.1, 1e-12);
  // Every vertex of either mesh is exactly 0.1 away from the other plane.
  ASSERT_EQ(e.reference_vertex_error.size(), a.number_of_vertices());
  ASSERT_EQ(e.approximation_vertex_error.size(), b.number_of_vertices());
  for (double d : e.reference_vertex_error) EXPECT_NEAR(d, 0.1, 1e-12);
  for (double d : e.approximation_vertex_error) EXPECT_NEAR(d, 0.1, 1e-12);
  // The sample budget is honoured per direction (within rounding of the face subdivisions).
  EXPECT_NEAR(double(e.reference_to_approximation.samples), 5000., 250.);
  EXPECT_NEAR(double(e.approximation_to_reference.samples), 5000., 250.);
  EXPECT_EQ(e.samples, e.reference_to_approximation.samples + e.approximation_to_reference.samples);
  EXPECT_EQ(e.reference_to_approximation.vertex_samples, a.number_of_vertices());
  EXPECT_GT(e.reference_to_approximation.edge_samples, 0u);
  EXPECT_GT(e.reference_to_approximation.face_samples, 0u);
}

TEST(Metrics, SphereAgainstInscribedIcosphere) {
  // The fine icosphere stands for the unit sphere; the coarse one is inscribed in it. The largest
  // distance in both directions is reached above the centre of the coarse face closest to the
  // origin: 1 - h. The fine mesh itself lies up to eps below the sphere.
  const Mesh sphere = icosphere(5), coarse = icosphere(1);
  const double expected = 1. - min_plane_distance(coarse);
  const double eps = 1. - min_plane_distance(sphere);
  const M::Approximation_error e = M::approximation_error(sphere, coarse);
  const double h = e.hausdorff * e.diagonal;
  EXPECT_GT(h, expected - eps - 1e-4);
  EXPECT_LT(h, expected + 1e-4);
  EXPECT_GT(e.rms, 0.);
  EXPECT_LT(e.rms, e.hausdorff);
  EXPECT_LT(e.mean, e.rms);  // RMS >= mean always, strictly for a non-constant distance
  // Default budget: 10 x max(F) samples per direction.
  const double target = 10. * double(sphere.number_of_faces());
  EXPECT_NEAR(double(e.reference_to_approximation.samples), target, 0.02 * target);
  EXPECT_NEAR(double(e.approximation_to_reference.samples), target, 0.02 * target);
}

TEST(Metrics, DeterministicForSeedWhateverTheThreads) {
  const Mesh a = icosphere(4), b = icosphere(2);
  M::Error_options o;
  o.threads = 1;
  const auto e1 = M::approximation_error(a, b, o);
  o.threads = 2;
  const auto e2 = M::approximation_error(a, b, o);
  const auto e3 = M::approximation_error(a, b, o);
  for (const auto* e : {&e2, &e3}) {
    EXPECT_EQ(e1.hausdorff, e->hausdorff);
    EXPECT_EQ(e1.mean, e->mean);
    EXPECT_EQ(e1.rms, e->rms);
    EXPECT_EQ(e1.samples, e->samples);
    EXPECT_EQ(e1.reference_vertex_error, e->reference_vertex_error);
  }
  o.seed = 7;
  const auto e4 = M::approximation_error(a, b, o);
  EXPECT_NE(e1.rms, e4.rms);  // another seed draws other face subdivisions
  EXPECT_NEAR(e1.rms, e4.rms, 0.02 * e1.rms);
}

void expect_same_error(const M::Approximation_error& a, const M::Approximation_error& b) {
  EXPECT_EQ(a.hausdorff, b.hausdorff);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.rms, b.rms);
  EXPECT_EQ(a.diagonal, b.diagonal);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.reference_to_approximation.max, b.reference_to_approximation.max);
  EXPECT_EQ(a.approximation_to_reference.max, b.approximation_to_reference.max);
  EXPECT_EQ(a.reference_to_approximation.edge_samples, b.reference_to_approximation.edge_samples);
  EXPECT_EQ(a.reference_vertex_error, b.reference_vertex_error);
  EXPECT_EQ(a.approximation_vertex_error, b.approximation_vertex_error);
}

TEST(Metrics, ReferencePreparedOnceGivesTheSameNumbers) {
  // Error_reference keeps the reference's tree and samples across calls; each call must give what
  // approximation_error() gives for that pair, bit for bit: coarser approximations (the reference's
  // samples reused), a finer one (with the default budget its samples are drawn again), a fixed
  // budget, and calls from two threads at once.
  const Mesh ref = icosphere(3), fine = icosphere(4);
  const Mesh coarse[] = {icosphere(1), icosphere(2), grid(6, 0.3)};
  for (std::size_t budget : {std::size_t(0), std::size_t(3000)}) {
    SCOPED_TRACE("samples " + std::to_string(budget));
    M::Error_options o;
    o.samples = budget;
    const M::Error_reference prepared(ref, o);
    for (const Mesh& c : coarse) expect_same_error(prepared.error(c), M::approximation_error(ref, c, o));
    const M::Approximation_error f = prepared.error(fine);
    expect_same_error(f, M::approximation_error(ref, fine, o));
    if (budget == 0)  // 10 x the finer mesh's faces, not the reference's
      EXPECT_NEAR(double(f.reference_to_approximation.samples), 10. * double(fine.number_of_faces()),
                  0.02 * 10. * double(fine.number_of_faces()));
    M::Approximation_error side_by_side[2];
    tbb::parallel_invoke([&] { side_by_side[0] = prepared.error(coarse[0]); },
                         [&] { side_by_side[1] = prepared.error(coarse[1]); });
    expect_same_error(side_by_side[0], M::approximation_error(ref, coarse[0], o));
    expect_same_error(side_by_side[1], M::approximation_error(ref, coarse[1], o));
  }
  // each approximation is checked as approximation_error() checks it
  const M::Error_reference square(grid(3, 0.));
  EXPECT_THROW(square.error(Mesh()), CMGeom::Invalid_input);
}

TEST(Metrics, LowerBoundIsAtMostTheErrorAndReachesItAtAVertex) {
  // Error_reference::hausdorff_lower_bound() measures subsets of the samples error() measures:
  // never above its Hausdorff distance; with stride 1 at least the reference side's maximum; equal
  // to the whole when the farthest point of either surface is a vertex of the approximation (here
  // a vertex pushed 0.5 out of the unit sphere, which the fine icosphere stands for).
  const Mesh ref = icosphere(4);
  Mesh spike = icosphere(2);
  const auto top = *spike.vertices().begin();
  spike.point(top) = K::Point_3(1.5 * spike.point(top).x(), 1.5 * spike.point(top).y(), 1.5 * spike.point(top).z());
  const Mesh approximations[] = {icosphere(1), icosphere(2), grid(6, 0.3), spike};
  for (std::size_t budget : {std::size_t(0), std::size_t(3000)})
    for (bool vertices : {true, false}) {
      SCOPED_TRACE("samples " + std::to_string(budget) + (vertices ? ", vertices sampled" : ", no vertex samples"));
      M::Error_options o;
      o.samples = budget;
      o.sample_vertices = vertices;
      o.vertex_field = false;
      const M::Error_reference prepared(ref, o);
      for (const Mesh& a : approximations) {
        const M::Approximation_error e = prepared.error(a);
        const double whole = prepared.hausdorff_lower_bound(a, 1);
        EXPECT_LE(whole, e.hausdorff * (1 + 1e-12));
        EXPECT_GE(whole, e.reference_to_approximation.max / e.diagonal * (1 - 1e-12));
        for (std::size_t stride : {2, 16, 100000}) {
          const double part = prepared.hausdorff_lower_bound(a, stride);
          EXPECT_GE(part, 0.);
          EXPECT_LE(part, whole * (1 + 1e-12)) << "stride " << stride;
        }
      }
      if (vertices) {  // (without vertex samples no sample lies on the spike's apex)
        const M::Approximation_error e = prepared.error(spike);
        EXPECT_NEAR(e.hausdorff * e.diagonal, 0.5, 0.01);  // 0.5 above a sphere the fine mesh hugs
        EXPECT_NEAR(prepared.hausdorff_lower_bound(spike, 1), e.hausdorff, 1e-12 * e.hausdorff);
      }
    }
  const M::Error_reference prepared(ref);
  EXPECT_THROW((void)prepared.hausdorff_lower_bound(icosphere(1), 0), CMGeom::Invalid_input);
  EXPECT_THROW((void)prepared.hausdorff_lower_bound(Mesh(), 4), CMGeom::Invalid_input);
}

// One direction of our measure against CGAL's, with the same numbers of vertex, edge and face
// samples (CGAL samples at random, we sample regularly: both approach the same supremum).
void expect_agrees_with_cgal(const Mesh& a, const Mesh& b, double rel_tol) {
  M::Error_options o;
  o.vertex_field = false;
  const auto ours = M::approximation_error(a, b, o);
  const auto& one = ours.reference_to_approximation;
  namespace PMP = CGAL::Polygon_mesh_processing;
  const double cgal = PMP::approximate_Hausdorff_distance<CGAL::Parallel_if_available_tag>(
      a, b,
      CGAL::parameters::number_of_points_on_faces(one.face_samples)
          .number_of_points_on_edges(one.edge_samples)
          .random_seed(1),
      CGAL::parameters::default_values());
  EXPECT_GT(one.max, 0.);
  EXPECT_NEAR(one.max, cgal, rel_tol * cgal) << "ours " << one.max << " CGAL " << cgal;
}

TEST(Metrics, AgreesWithCGALApproximateHausdorff) {
  expect_agrees_with_cgal(icosphere(5), icosphere(1), 0.01);
  expect_agrees_with_cgal(icosphere(1), icosphere(5), 0.01);
  const std::string path = std::string(CMGEOM_DATA_DIR) + "/classic/bunny.off";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data not found: " << path;
  Mesh bunny;
  ASSERT_TRUE(CGAL::IO::read_polygon_mesh(path, bunny));
  // A bumpy copy: every vertex pushed by a smooth function of its position.
  Mesh bumpy = bunny;
  for (auto v : bumpy.vertices()) {
    const auto p = bumpy.point(v);
    const double s = 0.002 * std::sin(60 * p.x()) * std::sin(50 * p.y()) * std::sin(40 * p.z());
    bumpy.point(v) = K::Point_3(p.x() + s, p.y() + s, p.z() - s);
  }
  expect_agrees_with_cgal(bunny, bumpy, 0.05);
}

// The error's closest-point search (internal::Triangle_tree::closest_point: CGAL's tree, our
// traversal and point-triangle test) against every triangle one by one, from hints near and far,
// on a closed sphere, an open folded grid (boundary edges and corners) and a flat grid with
// zero-area faces.
TEST(Metrics, ClosestPointEqualsTheNearestTriangleByBruteForce) {
  Mesh folded = grid(12, 0.);
  for (auto v : folded.vertices()) {
    const auto p = folded.point(v);
    folded.point(v) = K::Point_3(p.x(), p.y(), 0.3 * std::sin(5 * p.x()) * p.y());
  }
  const Mesh sphere = icosphere(2);
  // a flat grid with zero-area faces: a vertex moved onto the midpoint of an edge of its face
  // (coordinates in eighths: the three corners exactly collinear)
  Mesh flattened = grid(8, 0.);
  {
    auto corner = [&](double x, double y) {
      for (auto v : flattened.vertices())
        if (flattened.point(v) == K::Point_3(x, y, 0.)) return v;
      return Mesh::null_vertex();
    };
    flattened.point(corner(0.5, 0.5)) = K::Point_3(0.4375, 0.375, 0.);
    flattened.point(corner(0.25, 0.75)) = K::Point_3(0.1875, 0.625, 0.);
  }
  for (const Mesh* m : std::array<const Mesh*, 3>{&folded, &sphere, &flattened}) {
    const Mesh& mesh = *m;
    const M::internal::Flat_mesh flat = M::internal::make_flat_mesh(mesh, mesh.points(), "test");
    const M::internal::Triangle_tree tree(flat);
    using P = M::internal::Distance_kernel::Point_3;
    std::vector<bool> zero_area;  // per triangle: its corners collinear
    for (const auto& t : tree.triangles) zero_area.push_back(CGAL::collinear(t.vertex(0), t.vertex(1), t.vertex(2)));
    EXPECT_EQ(std::count(zero_area.begin(), zero_area.end(), true), m == &flattened ? 2 : 0);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    for (int i = 0; i < 2000; ++i) {
      const P q(u(rng), u(rng), u(rng));
      double brute = HUGE_VAL;  // (a zero-area triangle: the nearest of its sides)
      for (std::size_t f = 0; f < tree.triangles.size(); ++f) {
        const auto& t = tree.triangles[f];
        if (zero_area[f])
          for (int k = 0; k < 3; ++k)
            brute = std::min(brute, CGAL::squared_distance(q, M::internal::Distance_kernel::Segment_3(
                                                                  t.vertex(k), t.vertex((k + 1) % 3))));
        else
          brute = std::min(brute, CGAL::squared_distance(q, t));
      }
      // a hint on the surface: a corner of some triangle, near the query or anywhere
      const auto& t = tree.triangles[std::size_t(rng() % tree.triangles.size())];
      const P hint = i % 2 ? t.vertex(int(rng() % 3)) : tree.tree.closest_point(q);
      const P x = tree.closest_point(q, hint);
      EXPECT_NEAR(CGAL::squared_distance(q, x), brute, 1e-12) << "query " << q;
      double on_surface = HUGE_VAL;  // the point returned lies on the surface
      for (std::size_t f = 0; f < tree.triangles.size(); ++f)
        if (!zero_area[f]) on_surface = std::min(on_surface, CGAL::squared_distance(x, tree.triangles[f]));
      EXPECT_LT(on_surface, 1e-20);
    }
  }
}

TEST(Metrics, RejectsNonTriangleFaces) {
  std::vector<K::Point_3> pts = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const Mesh quad = make_mesh(pts, {{0, 1, 2, 3}});
  const Mesh tri = grid(1, 0.);
  EXPECT_THROW(M::approximation_error(quad, tri), CMGeom::Invalid_input);
  EXPECT_THROW(M::approximation_error(tri, quad), CMGeom::Invalid_input);
  EXPECT_THROW(M::approximation_error(Mesh(), tri), CMGeom::Invalid_input);
}

TEST(Metrics, TextureDeviation) {
  using UV = K::Point_2;
  auto with_uv = [](Mesh& m, double du) {
    auto uv = m.add_property_map<Mesh::Halfedge_index, UV>("h:uv", UV(0, 0)).first;
    for (auto h : m.halfedges())
      if (!m.is_border(h)) uv[h] = UV(m.point(m.target(h)).x() + du, m.point(m.target(h)).y());
    return uv;
  };
  Mesh a = grid(8, 0.), b = grid(3, 0.), c = grid(3, 0.25), d = grid(5, 0.);
  auto ua = with_uv(a, 0.), ub = with_uv(b, 0.), uc = with_uv(c, 0.), ud = with_uv(d, 0.1);
  // Same parameterisation of the same plane: no deviation, whatever the triangulation.
  const auto t0 = M::texture_deviation(a, ua, b, ub);
  EXPECT_LT(t0.absolute, 1e-12);
  EXPECT_GT(t0.matched_samples, 0u);
  // Lifted by 0.25: every (u,v) moves by exactly 0.25.
  const auto t1 = M::texture_deviation(a, ua, c, uc);
  EXPECT_NEAR(t1.absolute, 0.25, 1e-12);
  EXPECT_NEAR(t1.deviation, 0.25 / std::sqrt(2.), 1e-12);
  EXPECT_EQ(t1.matched_samples, t1.samples);
  // UVs shifted by 0.1 in u: the point with (u,v) moves by 0.1 in x, where (u,v) exists on both.
  const auto t2 = M::texture_deviation(a, ua, d, ud);
  EXPECT_NEAR(t2.absolute, 0.1, 1e-9);
  EXPECT_LT(t2.matched_samples, t2.samples);  // u in [0, 0.1) only exists on one side
  // Mirrored charts (both halves share one UV region): every (u,v) has two preimages; a mesh
  // against itself is still 0, and against a lifted copy it is the lift.
  auto mirrored = [](Mesh& m) {
    auto uv = m.add_property_map<Mesh::Halfedge_index, UV>("h:uv", UV(0, 0)).first;
    for (auto h : m.halfedges())
      if (!m.is_border(h)) uv[h] = UV(std::abs(m.point(m.target(h)).x() - 0.5), m.point(m.target(h)).y());
    return uv;
  };
  Mesh e = grid(6, 0.), f = grid(6, 0.25);
  auto ue = mirrored(e), uf = mirrored(f);
  EXPECT_LT(M::texture_deviation(e, ue, e, ue).absolute, 1e-12);
  EXPECT_NEAR(M::texture_deviation(e, ue, f, uf).absolute, 0.25, 1e-12);
}

// A soup straight from arrays: positions, triangles, optional per-corner UVs = (x + du, y).
CMGeom::Polygon_soup soup_grid(int n, double z, bool uv, double du = 0.) {
  CMGeom::Polygon_soup s;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      s.positions.push_back({{double(i) / n, double(j) / n, z}});
      if (uv) s.uvs.push_back({{double(i) / n + du, double(j) / n}});
    }
  auto tri = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    for (std::uint32_t v : {a, b, c}) {
      s.corner_vertex.push_back(v);
      s.corner_uv.push_back(uv ? v : CMGeom::Polygon_soup::no_index);
    }
    s.face_start.push_back(std::uint32_t(s.corner_vertex.size()));
    s.face_material.push_back(0);
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      tri(a, b, d);
      tri(a, d, c);
    }
  return s;
}

TEST(Metrics, PolygonSoupsWithoutHalfedgeMesh) {
  CMGeom::Polygon_soup a = soup_grid(10, 0., true), b = soup_grid(7, 0.1, true);
  // A non-manifold extra: a fin sharing an edge of b with two other faces is measured as it is.
  b.positions.push_back({{0., 0., 0.1}});
  b.positions.push_back({{1. / 7., 0., 0.1}});
  b.positions.push_back({{0.5 / 7., 0., 0.1}});
  const auto e = M::approximation_error(a, b);
  EXPECT_NEAR(e.hausdorff * e.diagonal, 0.1, 1e-12);
  EXPECT_NEAR(e.rms * e.diagonal, 0.1, 1e-12);
  ASSERT_EQ(e.approximation_vertex_error.size(), b.positions.size());
  EXPECT_EQ(e.approximation_to_reference.vertex_samples, 64u);  // the 3 unused positions are not sampled
  const auto t = M::texture_deviation(a, b);
  EXPECT_NEAR(t.absolute, 0.1, 1e-12);
  const auto t2 = M::texture_deviation(a, soup_grid(4, 0., true, 0.2));
  EXPECT_NEAR(t2.absolute, 0.2, 1e-9);
  EXPECT_THROW(M::texture_deviation(a, soup_grid(4, 0., false)), CMGeom::Invalid_input);  // no UVs
}

TEST(Metrics, ImageError) {
  CMGeom::Image a(4, 4, 4), b(4, 4, 4);
  EXPECT_EQ(M::image_error(a, b).pixels, 0u);  // nothing covered
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 2; ++x) {
      a.bytes()[a.index(x, y, 3)] = 255;
      b.bytes()[b.index(x, y, 3)] = 255;
    }
  auto e = M::image_error(a, b);
  EXPECT_EQ(e.pixels, 8u);
  EXPECT_EQ(e.rmse, 0.);
  EXPECT_TRUE(std::isinf(e.psnr));
  b.bytes()[b.index(1, 1, 0)] = 30;   // one channel of one covered pixel differs by 30
  a.bytes()[a.index(3, 3, 3)] = 255;  // one more pixel covered in a only, equal colour (black)
  e = M::image_error(a, b);
  EXPECT_EQ(e.pixels, 9u);
  EXPECT_NEAR(e.rmse, std::sqrt(900. / 27.), 1e-12);
  EXPECT_NEAR(e.psnr, 20. * std::log10(255. / std::sqrt(900. / 27.)), 1e-12);
  EXPECT_NEAR(e.mean_squared_rgb, (30. / 255.) * (30. / 255.) / 9., 1e-15);
  EXPECT_THROW(M::image_error(a, CMGeom::Image(2, 2, 4)), CMGeom::Invalid_input);
}

}  // namespace
