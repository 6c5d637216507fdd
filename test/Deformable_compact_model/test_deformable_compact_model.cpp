// Tests of the Deformable_compact_model package (thesis chapter 6): the local affine maps
// (M = V U^-1 reproduces affine maps, regulariser on planar rings), the transfer into the
// reconstruction (linear reproduction in regular and adaptive subdivision, sharp edges, uvs),
// identity = plain reconstruction bit for bit, parallel == serial, the deformers, and the
// deformable CM against reconstruct-then-deform with a cage.
#include "cmgeom_test_meshes.h"
#include "cmgeom_test_support.h"

#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Compact_model.h>
#include <CMGeom/Deformable_compact_model.h>
#include <CMGeom/Deformable_compact_model/Cage_system_deformer.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <vector>

namespace {

namespace CM = CMGeom::CM;
namespace DCM = CMGeom::DCM;
namespace CD = CMGeom::Cage_deformation;
using CM::Vec3;
using Mat = std::array<std::array<double, 3>, 3>;

CMGeom::Surface_mesh make_icosphere(int level) {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(level, p, f);
  CMGeom::Surface_mesh m;
  std::vector<CMGeom::Surface_mesh::Vertex_index> v;
  for (const auto& q : p) v.push_back(m.add_vertex(CMGeom::Point_3(q[0], q[1], 0.7 * q[2])));  // ellipsoid
  for (const auto& t : f) m.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return m;
}

// Box [-1,1] x [-1,1] x [-h,h], each side an n x n grid of quads split in two.
CMGeom::Surface_mesh make_box(int n, double h = 0.6) {
  CMGeom::Surface_mesh mesh;
  std::map<std::array<long, 3>, CMGeom::Surface_mesh::Vertex_index> index;
  auto vertex = [&](double x, double y, double z) {
    const std::array<long, 3> key = {std::lround(x * 1e6), std::lround(y * 1e6), std::lround(z * 1e6)};
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    return index[key] = mesh.add_vertex(CMGeom::Point_3(x, y, z));
  };
  const double ext[3] = {1., 1., h};
  for (int axis = 0; axis < 3; ++axis)
    for (int side = -1; side <= 1; side += 2) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          auto at = [&](int a, int b) {
            double c[3];
            c[axis] = side * ext[axis];
            c[u] = ext[u] * (-1. + 2. * a / n);
            c[w] = ext[w] * (-1. + 2. * b / n);
            return vertex(c[0], c[1], c[2]);
          };
          auto v00 = at(i, j), v10 = at(i + 1, j), v11 = at(i + 1, j + 1), v01 = at(i, j + 1);
          if (side > 0) {
            mesh.add_face(v00, v10, v11);
            mesh.add_face(v00, v11, v01);
          } else {
            mesh.add_face(v00, v11, v10);
            mesh.add_face(v00, v01, v11);
          }
        }
    }
  return mesh;
}

const CM::Compact_model& ellipsoid_cm() {
  static const CM::Compact_model m = CM::build_compact_model(make_icosphere(3), 120);
  return m;
}

Vec3 apply(const Mat& A, const Vec3& b, const Vec3& p) {
  return Vec3(A[0][0] * p.x + A[0][1] * p.y + A[0][2] * p.z + b.x, A[1][0] * p.x + A[1][1] * p.y + A[1][2] * p.z + b.y,
              A[2][0] * p.x + A[2][1] * p.y + A[2][2] * p.z + b.z);
}

// A general affine map (rotation, shear, non-uniform scale) and a similarity.
const Mat kShear = {{{1.3, 0.4, -0.2}, {0.1, 0.8, 0.5}, {-0.3, 0.2, 1.1}}};
const Vec3 kShift(0.5, -2., 3.);
Mat similarity(double s) {
  const double a = 0.7, c = std::cos(a), si = std::sin(a);  // rotation about (1,1,1)/sqrt3 composed with z
  const Mat Rz = {{{c, -si, 0}, {si, c, 0}, {0, 0, 1}}};
  const Mat Rx = {{{1, 0, 0}, {0, c, -si}, {0, si, c}}};
  Mat R{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) R[i][j] += s * Rz[i][k] * Rx[k][j];
  return R;
}

// (of a point list: a std::vector or a Reconstruction's CM::Output_array)
template <class Points>
double diagonal(const Points& P) {
  Vec3 lo = P[0], hi = P[0];
  for (const Vec3& p : P) {
    lo = Vec3(std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z));
    hi = Vec3(std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z));
  }
  return CM::internal::length(hi - lo);
}

template <class A, class B>
double max_distance(const A& a, const B& b) {
  EXPECT_EQ(a.size(), b.size());
  double d = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, CM::internal::length(a[i] - b[i]));
  return d;
}

void expect_bitwise_equal(const CM::Reconstruction& a, const CM::Reconstruction& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  ASSERT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.base_face, b.base_face);
  EXPECT_EQ(a.corner_uvs, b.corner_uvs);
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    ASSERT_EQ(a.points[i], b.points[i]) << "point " << i;
    ASSERT_EQ(a.normals[i], b.normals[i]) << "normal " << i;
  }
}

// ------------------------------------------------------------------ §6.3 local maps
TEST(DeformableCMLocalMaps, LeastSquaresMapIsVUinverseAndReproducesAffineMaps) {
  const CM::Compact_model& m = ellipsoid_cm();
  DCM::Local_deformation_solver solver(m);
  // The ellipsoid's base rings are curved enough: no regularisation, the thesis' plain map.
  EXPECT_EQ(solver.number_of_regularised_vertices(), 0u);
  std::vector<Vec3> def;
  for (const Vec3& p : m.vertices) def.push_back(apply(kShear, kShift, p));
  const auto maps = solver.compute(def);
  for (std::size_t v = 0; v < maps.size(); ++v) {
    EXPECT_FALSE(maps[v].identity);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ASSERT_NEAR(maps[v].M[i][j], kShear[i][j], 1e-12) << v;
  }
  // M = V U^-1 minimises the ring residual: for a non-affine pose, perturbing M increases it.
  std::vector<Vec3> bent;
  for (const Vec3& p : m.vertices) bent.push_back(Vec3(p.x, p.y + 0.3 * p.x * p.x, p.z + 0.2 * p.x * p.y));
  const auto bm = solver.compute(bent);
  for (std::size_t v = 0; v < bm.size(); v += 7) {
    auto residual = [&](const double M[3][3]) {
      double r = 0;
      auto [b, e] = solver.ring(v);
      for (auto it = b; it != e; ++it) {
        const Vec3 a = m.vertices[*it] - m.vertices[v];
        const Vec3 Ma(M[0][0] * a.x + M[0][1] * a.y + M[0][2] * a.z, M[1][0] * a.x + M[1][1] * a.y + M[1][2] * a.z,
                      M[2][0] * a.x + M[2][1] * a.y + M[2][2] * a.z);
        r += CM::internal::squared_length(Ma - (bent[*it] - bent[v]));
      }
      return r;
    };
    const double r0 = residual(bm[v].M);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (double eps : {1e-4, -1e-4}) {
          double M[3][3];
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) M[a][b] = bm[v].M[a][b] + (a == i && b == j ? eps : 0.);
          EXPECT_GT(residual(M), r0);
        }
  }
}

TEST(DeformableCMLocalMaps, PlanarRingsGiveFiniteMapsMappingTheNormal) {
  // A flat 6 x 6 grid CM (boundary included), built by hand: every ring is planar.
  CM::Compact_model m;
  const int n = 6;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back(Vec3(i, j, 0));
  m.normals.push_back(Vec3(0, 0, 1));
  m.surfaces.push_back(CM::Local_surface());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      m.faces.push_back({CM::Corner{a, 0, 0}, CM::Corner{b, 0, 0}, CM::Corner{c, 0, 0}});
      m.faces.push_back({CM::Corner{a, 0, 0}, CM::Corner{c, 0, 0}, CM::Corner{d, 0, 0}});
    }
  m.validate();
  DCM::Local_deformation_solver solver(m);
  EXPECT_EQ(solver.number_of_regularised_vertices(), m.vertices.size());
  EXPECT_EQ(solver.number_of_degenerate_vertices(), 0u);
  // Rigid rotation + scale 2: reproduced exactly although every ring is planar.
  const Mat S = similarity(2.);
  std::vector<Vec3> def;
  for (const Vec3& p : m.vertices) def.push_back(apply(S, kShift, p));
  for (const auto& T : solver.compute(def))
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ASSERT_NEAR(T.M[i][j], S[i][j], 1e-12);
  // A bend: finite maps, tangent plane mapped as the ring says, normal to s n'.
  std::vector<Vec3> bent;
  for (const Vec3& p : m.vertices) bent.push_back(Vec3(p.x, p.y, 0.1 * p.x * p.x));
  const auto maps = solver.compute(bent);
  for (const auto& T : maps)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ASSERT_TRUE(std::isfinite(T.M[i][j]));
  // Interior vertex (3, 3): M e_z is along the deformed normal of the (symmetric) ring.
  const auto& T = maps[3 * (n + 1) + 3];
  const Vec3 Mz(T.M[0][2], T.M[1][2], T.M[2][2]);
  const Vec3 nd = CM::internal::normalized(Vec3(-0.6, 0, 1));  // normal of z = 0.1 x^2 at x = 3
  EXPECT_NEAR(CM::internal::dot(CM::internal::normalized(Mz), nd), 1., 1e-3);
  // The deformed reconstruction is finite everywhere.
  DCM::Deformable_compact_model dcm(m);
  dcm.set_deformed_base(bent);
  const CM::Reconstruction r = dcm.reconstruct_regular(2);
  for (const Vec3& p : r.points) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
  for (const Vec3& q : r.normals) ASSERT_TRUE(std::isfinite(q.x + q.y + q.z));
}

TEST(DeformableCMLocalMaps, DegenerateRingIsATranslation) {
  // Face (0,1,2) has zero area (collinear): vertex 0's ring is degenerate.
  CM::Compact_model m;
  m.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  m.normals = {Vec3(0, 0, 1)};
  m.surfaces = {CM::Local_surface()};
  m.faces = {{CM::Corner{0, 0, 0}, CM::Corner{1, 0, 0}, CM::Corner{2, 0, 0}}};
  DCM::Local_deformation_solver solver(m);
  EXPECT_EQ(solver.number_of_degenerate_vertices(), 3u);
  const auto maps = solver.compute({Vec3(0, 0, 1), Vec3(1, 0, 1), Vec3(2, 0, 2)});
  EXPECT_EQ(maps[0].M[0][0], 1.);
  EXPECT_EQ(maps[0].deformed, Vec3(0, 0, 1));
  EXPECT_THROW(solver.compute({Vec3(0, 0, 0)}), CMGeom::Invalid_input);
  EXPECT_THROW(solver.compute({Vec3(0, 0, NAN), Vec3(), Vec3()}), CMGeom::Invalid_input);
}

// ------------------------------------------------------------------ §6.4 transfer
TEST(DeformableCMTransfer, AffineDeformationReproducesTheAffineMapOfTheReconstruction) {
  const CM::Compact_model& m = ellipsoid_cm();
  DCM::Deformable_compact_model dcm(m);
  DCM::Affine_deformer affine(kShear, kShift);
  affine.bind(dcm.base_vertices());
  dcm.deform(affine);
  for (int level : {1, 3}) {
    const CM::Reconstruction plain = CM::reconstruct_regular(m, level);
    const CM::Reconstruction def = dcm.reconstruct_regular(level);
    ASSERT_EQ(def.triangles, plain.triangles);
    std::vector<Vec3> expected;
    for (const Vec3& p : plain.points) expected.push_back(apply(kShear, kShift, p));
    EXPECT_LT(max_distance(def.points, expected), 1e-12 * diagonal(expected)) << "level " << level;
    // Normals follow the cofactor of A.
    for (std::size_t i = 0; i < plain.points.size(); i += 13) {
      const Vec3 n = plain.normals[i];
      const Vec3 r0(kShear[0][0], kShear[0][1], kShear[0][2]), r1(kShear[1][0], kShear[1][1], kShear[1][2]),
          r2(kShear[2][0], kShear[2][1], kShear[2][2]);
      const Vec3 cn(CM::internal::dot(CM::internal::cross(r1, r2), n),
                    CM::internal::dot(CM::internal::cross(r2, r0), n),
                    CM::internal::dot(CM::internal::cross(r0, r1), n));
      EXPECT_NEAR(CM::internal::dot(CM::internal::normalized(cn), def.normals[i]), 1., 1e-12);
    }
  }
}

TEST(DeformableCMTransfer, AdaptiveReconstructionFollowsTheDeformedSurface) {
  const CM::Compact_model& m = ellipsoid_cm();
  DCM::Deformable_compact_model dcm(m);
  const double s = 1.7;
  const Mat S = similarity(s);
  DCM::Affine_deformer sim(S, kShift);
  sim.bind(dcm.base_vertices());
  dcm.deform(sim);
  // Edge-length criterion on the deformed surface with the threshold scaled: same decisions.
  const CM::Reconstruction plain = CM::reconstruct_adaptive(m, CM::Edge_length_criterion{0.08}, 5);
  const CM::Reconstruction def = dcm.reconstruct_adaptive(CM::Edge_length_criterion{0.08 * s}, 5);
  ASSERT_EQ(def.triangles, plain.triangles);
  std::vector<Vec3> expected;
  for (const Vec3& p : plain.points) expected.push_back(apply(S, kShift, p));
  EXPECT_LT(max_distance(def.points, expected), 1e-12 * diagonal(expected));
  // A stretch along x makes the deformed criterion refine more (it reads the deformation).
  DCM::Affine_deformer stretch({{{3, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, Vec3(0, 0, 0));
  stretch.bind(dcm.base_vertices());
  dcm.deform(stretch);
  EXPECT_GT(dcm.reconstruct_adaptive(CM::Edge_length_criterion{0.08}, 5).triangles.size(),
            plain.triangles.size() + plain.triangles.size() / 2);
}

// A map that flattens the model (a singular linear part) or holds a non-finite entry is refused,
// whatever its scale; a tiny invertible one is not, and the deformer keeps its last valid map.
TEST(DeformableCMAffine, SingularOrNonFiniteMapsAreRefused) {
  using A3 = std::array<std::array<double, 3>, 3>;
  const Vec3 zero(0, 0, 0);
  EXPECT_THROW(DCM::Affine_deformer(A3{}, zero), CMGeom::Invalid_input);
  EXPECT_THROW(DCM::Affine_deformer(A3{{{1, 2, 3}, {2, 4, 6}, {0, 0, 1}}}, zero), CMGeom::Invalid_input);  // rank 2
  EXPECT_THROW(DCM::Affine_deformer(A3{{{1e-9, 0, 0}, {0, 1e-9, 0}, {0, 0, 0}}}, zero), CMGeom::Invalid_input);
  EXPECT_THROW(DCM::Affine_deformer(A3{{{1, 0, 0}, {0, std::nan(""), 0}, {0, 0, 1}}}, zero), CMGeom::Invalid_input);
  EXPECT_THROW(DCM::Affine_deformer(A3{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}, Vec3(0, HUGE_VAL, 0)),
               CMGeom::Invalid_input);
  DCM::Affine_deformer tiny(A3{{{1e-9, 0, 0}, {0, 1e-9, 0}, {0, 0, 1e-9}}}, zero);
  tiny.bind({Vec3(1, 2, 3)});
  EXPECT_THROW(tiny.set_map(A3{}, zero), CMGeom::Invalid_input);
  std::vector<Vec3> out;
  tiny.deform(out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].z, 3e-9);
}

TEST(DeformableCMTransfer, SharpEdgesAndTextureCoordinatesAreCarried) {
  CM::Build_statistics st;
  CM::Compact_model m = CM::build_compact_model(make_box(8), 150, CM::Build_options(), CM::Quadric_surface_traits(),
                                                CM::Weighted_quadric_simplifier(), &st);
  ASSERT_GT(st.sharp_edges, 0u);
  m.uvs.resize(m.faces.size());
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Vec3& p = m.vertices[m.faces[f][c].vertex];
      m.uvs[f][c] = {float(0.5 + 0.25 * p.x), float(0.5 + 0.25 * p.y)};
    }
  DCM::Deformable_compact_model dcm(m);
  const Mat S = similarity(0.5);
  DCM::Affine_deformer rigid(S, kShift);
  rigid.bind(dcm.base_vertices());
  dcm.deform(rigid);
  const CM::Reconstruction plain = CM::reconstruct_regular(m, 3);
  const CM::Reconstruction def = dcm.reconstruct_regular(3);
  ASSERT_EQ(def.triangles, plain.triangles);
  EXPECT_EQ(def.corner_uvs, plain.corner_uvs);
  ASSERT_FALSE(def.corner_uvs.empty());
  std::vector<Vec3> expected;
  for (const Vec3& p : plain.points) expected.push_back(apply(S, kShift, p));
  // Sharp-edge points (intersections of two sector surfaces) included: box rings are planar
  // on the sides (regularised) and the map is a similarity, reproduced on every ring.
  EXPECT_LT(max_distance(def.points, expected), 1e-12 * diagonal(expected));
}

TEST(DeformableCMTransfer, IdentityGivesThePlainReconstructionBitForBit) {
  const CM::Compact_model& m = ellipsoid_cm();
  DCM::Deformable_compact_model dcm(m);  // rest pose
  expect_bitwise_equal(dcm.reconstruct_regular(3), CM::reconstruct_regular(m, 3));
  expect_bitwise_equal(dcm.reconstruct_adaptive(CM::Edge_length_criterion{0.05}, 5),
                       CM::reconstruct_adaptive(m, CM::Edge_length_criterion{0.05}, 5));
  DCM::Affine_deformer id;
  id.bind(dcm.base_vertices());
  dcm.deform(id);
  expect_bitwise_equal(dcm.reconstruct_regular(2), CM::reconstruct_regular(m, 2));
  // Moving one vertex leaves every triangle outside the faces of its 1-ring untouched.
  DCM::Vertex_moves_deformer moves;
  moves.bind(dcm.base_vertices());
  moves.move(5, m.vertices[5] + Vec3(0, 0, 0.2));
  dcm.deform(moves);
  const CM::Reconstruction plain = CM::reconstruct_regular(m, 2), def = dcm.reconstruct_regular(2);
  auto [b, e] = dcm.solver().ring(5);
  std::vector<bool> near(m.vertices.size(), false);
  near[5] = true;
  for (auto it = b; it != e; ++it) near[*it] = true;
  std::size_t same = 0, moved = 0;
  for (std::size_t t = 0; t < plain.triangles.size(); ++t) {
    const auto& F = m.faces[plain.base_face[t]];
    const bool touched = near[F[0].vertex] || near[F[1].vertex] || near[F[2].vertex];
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t i = plain.triangles[t][c];
      if (!touched) {
        ASSERT_EQ(def.points[i], plain.points[i]);
        ++same;
      } else if (def.points[i] != plain.points[i]) {
        ++moved;
      }
    }
  }
  EXPECT_GT(same, 0u);
  EXPECT_GT(moved, 0u);
  EXPECT_EQ(def.points[5], m.vertices[5] + Vec3(0, 0, 0.2));
}

// A box cage around the ellipsoid, and a smooth pose of it (top face twisted and lifted).
CD::Triangle_cage box_cage(double e) {
  std::vector<std::array<double, 3>> P;
  for (int k = 0; k < 8; ++k) P.push_back({(k & 1) ? e : -e, (k & 2) ? e : -e, (k & 4) ? e : -e});
  const std::vector<std::vector<std::uint32_t>> quads = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  CD::Triangle_cage c = CD::make_triangle_cage(P, quads);
  CD::validate_cage(c);
  return c;
}
std::vector<CD::Vec3> cage_pose(const CD::Triangle_cage& c) {
  std::vector<CD::Vec3> P = c.vertices;
  for (auto& p : P)
    if (p[2] > 0) {
      const double a = 0.4, x = p[0], y = p[1];
      p = {std::cos(a) * x - std::sin(a) * y + 0.3, std::sin(a) * x + std::cos(a) * y, p[2] * 1.3};
    }
  return P;
}

TEST(DeformableCMTransfer, ParallelEqualsSerial) {
  const CM::Compact_model& m = ellipsoid_cm();
  const CD::Triangle_cage cage = box_cage(1.5);
  DCM::Cage_deformer<CD::Mean_value_coordinates_3> cd{CD::Mean_value_coordinates_3(cage)};
  cd.set_pose(cage_pose(cage));
  DCM::Local_deformation_options serial;
  serial.parallel = false;
  DCM::Deformable_compact_model par(m), ser(m, serial);
  cd.bind(par.base_vertices());
  par.deform(cd);
  ser.deform(cd);
  for (std::size_t v = 0; v < m.vertices.size(); ++v)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ASSERT_EQ(par.vertex_maps()[v].M[i][j], ser.vertex_maps()[v].M[i][j]);
  CM::Reconstruction_options one;
  one.parallel = false;
  expect_bitwise_equal(par.reconstruct_regular(3), ser.reconstruct_regular(3, one));
  expect_bitwise_equal(par.reconstruct_adaptive(CM::Edge_length_criterion{0.05}, 5),
                       ser.reconstruct_adaptive(CM::Edge_length_criterion{0.05}, 5, one));
}

TEST(DeformableCMTransfer, CachedRestReconstructionGivesTheSameBits) {
  const CM::Compact_model& m = ellipsoid_cm();
  const CD::Triangle_cage cage = box_cage(1.5);
  DCM::Cage_deformer<CD::Mean_value_coordinates_3> cd{CD::Mean_value_coordinates_3(cage)};
  DCM::Deformable_compact_model dcm(m);
  cd.bind(dcm.base_vertices());
  // A level the reconstruction refuses is refused before anything is built.
  EXPECT_THROW(DCM::Deformable_reconstruction(m, -1), CMGeom::Invalid_input);
  EXPECT_THROW(DCM::Deformable_reconstruction(m, 13), CMGeom::Invalid_input);
  // Levels 0 and 1 have no face points (0 also no edge points), level 2's edges and faces hold 3
  // (mapped four edges or faces at a time), level 5's faces 465 (four points at a time).
  for (const int level : {0, 1, 2, 3, 5}) {
    SCOPED_TRACE("level " + std::to_string(level));
    const DCM::Deformable_reconstruction cache(m, level);
    CM::Reconstruction out;
    // Two poses in a row (the second reuses `out`), then the cage's rest pose (coordinates
    // reproduce it only to rounding, so the maps are not exact identities).
    std::vector<CD::Vec3> pose = cage_pose(cage);
    for (int k = 0; k < 3; ++k) {
      if (k == 1)
        for (auto& p : pose) p[0] += 0.1 * p[2];
      cd.set_pose(k == 2 ? cage.vertices : pose);
      dcm.deform(cd);
      cache.deform(dcm, out);
      expect_bitwise_equal(out, dcm.reconstruct_regular(level));
    }
    // Only the base vertices with x > 0 moved: the others whose ring did not move keep exact
    // identity maps, so some faces and edges mix moving and still corners, some are still.
    std::vector<CM::Vec3> half = m.vertices;
    std::size_t moved = 0;
    for (auto& v : half)
      if (v.x > 0.) {
        v = CM::Vec3(1.1 * v.x + 0.05 * v.y, v.y, v.z + 0.1 * v.x);
        ++moved;
      }
    ASSERT_GT(moved, 0u);
    ASSERT_LT(moved, half.size());
    dcm.set_deformed_base(half);
    std::size_t still = 0;
    for (const auto& T : dcm.vertex_maps()) still += T.identity;
    EXPECT_GT(still, 0u);
    EXPECT_LT(still, half.size());
    cache.deform(dcm, out);
    expect_bitwise_equal(out, dcm.reconstruct_regular(level));
    // The exact rest pose (identity maps) gives the plain reconstruction back.
    dcm.set_deformed_base(m.vertices);
    cache.deform(dcm, out);
    expect_bitwise_equal(out, CM::reconstruct_regular(m, level));
    // Nothing per point but the rest point and normal: 48 bytes each, plus the base edges (8 bytes),
    // faces (12) and the weight tables (n - 1 edge points x 16, (n - 1)(n - 2) / 2 face points x 24
    // bytes, n = 2^level). The ellipsoid's base is closed and of genus 0: E = V + F - 2.
    const std::size_t E = m.vertices.size() + m.faces.size() - 2, n = std::size_t(1) << level;
    EXPECT_EQ(cache.number_of_points(), m.vertices.size() + E * (n - 1) + m.faces.size() * (n - 1) * (n - 2) / 2);
    EXPECT_EQ(cache.bytes(),
              cache.number_of_points() * 48 + 8 * E + 12 * m.faces.size() + (n - 1) * 16 + (n - 1) * (n - 2) / 2 * 24);
    // Maps for another base are refused, `out` left as it was.
    const CM::Reconstruction before = out;
    std::vector<CM::Vertex_affine_map> wrong(m.vertices.size() + 1);
    EXPECT_THROW(cache.deform(wrong, out), CMGeom::Invalid_input);
    expect_bitwise_equal(out, before);
  }
}

TEST(DeformableCMTransfer, ReconstructorGivesTheSameBitsPoseAfterPose) {
  // A textured box with sharp edges (sharp-edge points, uvs) and the smooth ellipsoid.
  CM::Compact_model box = CM::build_compact_model(make_box(8), 150);
  box.uvs.resize(box.faces.size());
  for (std::size_t f = 0; f < box.faces.size(); ++f)
    for (int c = 0; c < 3; ++c) {
      const Vec3& p = box.vertices[box.faces[f][c].vertex];
      box.uvs[f][c] = {float(0.5 + 0.25 * p.x), float(0.5 + 0.25 * p.y)};
    }
  for (const CM::Compact_model* m : {&ellipsoid_cm(), static_cast<const CM::Compact_model*>(&box)})
    for (const CM::Projection proj : {CM::Projection::closest_point, CM::Projection::along_normal})
      for (const int level : {0, 1, 2, 3, 5}) {
        SCOPED_TRACE("model of " + std::to_string(m->faces.size()) + " faces, projection " + std::to_string(int(proj)) +
                     ", level " + std::to_string(level));
        DCM::Deformable_compact_model dcm(*m);
        CM::Reconstruction_options opt;
        opt.projection = proj;
        CM::Reconstruction_options with_maps = opt;
        with_maps.vertex_maps = &dcm.vertex_maps();
        // One reconstructor keeping the blend's tables, one without them (each call then makes its own).
        const CM::Regular_reconstructor<> kept(*m, level, with_maps), plain(*m, level, opt);
        EXPECT_EQ(kept.number_of_triangles(), m->faces.size() << (2 * level));
        // the blend's tables: 2 weights per edge point (none at level 0) and 3 per face point,
        // along N again in the four-lane layout of the face kernel (12 per group of four points)
        const std::size_t n = std::size_t(1) << level, face_points = n > 1 ? (n - 1) * (n - 2) / 2 : 0;
        const std::size_t lanes = proj == CM::Projection::along_normal ? 12 * ((face_points + 3) / 4) : 0;
        EXPECT_EQ(kept.bytes() - plain.bytes(), sizeof(double) * (2 * (n - 1) + 3 * face_points + lanes));
        // Without maps: the plain reconstruction.
        CM::Reconstruction out;
        plain.reconstruct(out, opt);
        expect_bitwise_equal(out, CM::reconstruct_regular(*m, level, opt));
        // Three poses: the first writes everything, the next only the points and normals.
        CM::Reconstruction out_kept, out_plain;
        for (int k = 0; k < 3; ++k) {
          std::vector<CM::Vec3> pose = m->vertices;
          for (auto& v : pose) v = CM::Vec3(v.x + 0.1 * (k + 1) * v.z * v.z, v.y - 0.05 * k * v.x, v.z);
          dcm.set_deformed_base(pose);
          const CM::Reconstruction expected = dcm.reconstruct_regular(level, opt);
          if (k == 0) {
            dcm.reconstruct_regular(kept, out_kept, opt);
            dcm.reconstruct_regular(plain, out_plain, opt);
          } else {
            dcm.reconstruct_regular_points(kept, out_kept, opt);
            dcm.reconstruct_regular_points(plain, out_plain, opt);
          }
          expect_bitwise_equal(out_kept, expected);
          expect_bitwise_equal(out_plain, expected);
        }
        // An output of another level is refused and left as it was; so is a reconstructor of
        // another model, and options of another projection.
        CM::Reconstruction other = CM::reconstruct_regular(*m, level + 1);
        const CM::Reconstruction before = other;
        EXPECT_THROW(dcm.reconstruct_regular_points(kept, other, opt), CMGeom::Invalid_input);
        expect_bitwise_equal(other, before);
        const CM::Compact_model copy = *m;
        const CM::Regular_reconstructor<> of_copy(copy, level, opt);
        EXPECT_THROW(dcm.reconstruct_regular(of_copy, out, opt), CMGeom::Invalid_input);
        CM::Reconstruction_options other_projection = opt;
        other_projection.projection =
            proj == CM::Projection::along_normal ? CM::Projection::closest_point : CM::Projection::along_normal;
        EXPECT_THROW(kept.reconstruct(out, other_projection), CMGeom::Invalid_input);
        EXPECT_THROW(kept.reconstruct_points(out_kept, other_projection), CMGeom::Invalid_input);
        // Maps for another base: refused by both calls, the output left as it was.
        const std::vector<CM::Vertex_affine_map> wrong(m->vertices.size() + 1);
        CM::Reconstruction_options wrong_maps = opt;
        wrong_maps.vertex_maps = &wrong;
        CM::Reconstruction other_level = CM::reconstruct_regular(*m, level + 1, opt);
        const CM::Reconstruction other_before = other_level;
        EXPECT_THROW(kept.reconstruct(other_level, wrong_maps), CMGeom::Invalid_input);
        expect_bitwise_equal(other_level, other_before);
        const CM::Reconstruction kept_before = out_kept;
        EXPECT_THROW(kept.reconstruct_points(out_kept, wrong_maps), CMGeom::Invalid_input);
        expect_bitwise_equal(out_kept, kept_before);
      }
  EXPECT_THROW(CM::Regular_reconstructor<>(ellipsoid_cm(), 13), CMGeom::Invalid_input);
  EXPECT_THROW(CM::Regular_reconstructor<>(ellipsoid_cm(), -1), CMGeom::Invalid_input);
}

TEST(DeformableCMTransfer, CageDeformationOfTheBaseApproximatesDeformingTheReconstruction) {
  const CM::Compact_model& m = ellipsoid_cm();
  const CD::Triangle_cage cage = box_cage(1.5);
  const CD::Mean_value_coordinates_3 mvc(cage);
  const std::vector<CD::Vec3> pose = cage_pose(cage);
  DCM::Cage_deformer<CD::Mean_value_coordinates_3> cd(mvc);
  cd.set_pose(pose);
  DCM::Deformable_compact_model dcm(m);
  cd.bind(dcm.base_vertices());
  EXPECT_EQ(cd.weights_bytes(), m.vertices.size() * 8 * sizeof(double));
  dcm.deform(cd);
  // The base vertices go exactly where the cage sends them (T_i(v_i) = v'_i).
  const CM::Reconstruction def = dcm.reconstruct_regular(2);
  for (std::size_t i = 0; i < m.vertices.size(); ++i) EXPECT_EQ(def.points[i], dcm.deformed_base()[i]);
  // Reconstruct-then-deform (thesis Fig. 6.4 "CM reconstruction") with the same cage.
  const CM::Reconstruction plain = CM::reconstruct_regular(m, 2);
  std::vector<CD::Vec3> pts;
  for (const Vec3& p : plain.points) pts.push_back({p.x, p.y, p.z});
  const auto b = CD::bind_points(mvc, pts);
  std::vector<CD::Vec3> out;
  b.deform(mvc.deformation_rule(), pose, out);
  std::vector<Vec3> ref;
  for (const auto& p : out) ref.push_back(Vec3(p[0], p[1], p[2]));
  const double diag = diagonal(ref), err = max_distance(def.points, ref);
  // The deformation moves points by ~30% of the diagonal; the transfer stays within 1%.
  EXPECT_GT(max_distance(plain.points, ref), 0.1 * diag);
  EXPECT_LT(err, 0.01 * diag);
}

TEST(DeformableCMDeformers, CageSystemDrivesTheBase) {
  // A *Cages system of 2 x 1 x 1 box cells around the ellipsoid (mean value, joined).
  const CM::Compact_model& m = ellipsoid_cm();
  std::vector<CD::Vec3> pts;
  for (const Vec3& p : m.vertices) pts.push_back({p.x, p.y, p.z});
  const CD::Cage_system sys(CD::make_grid_cage_system(pts, 2, 1, 1, 0.1, CD::Coordinate_type::mean_value, 0.6));
  DCM::Cage_system_deformer<> cs(sys);
  DCM::Deformable_compact_model dcm(m);
  cs.bind(dcm.base_vertices());
  EXPECT_GT(cs.weights_bytes(), 0u);
  // A translation of every cage vertex moves the base (and the reconstruction) by it.
  const CD::Vec3 t = {0.3, -0.2, 0.5};
  std::vector<std::vector<CD::Vec3>> pose;
  for (const auto& c : sys.description().cages) {
    pose.emplace_back();
    for (const auto& v : c.rest.vertices) pose.back().push_back({v[0] + t[0], v[1] + t[1], v[2] + t[2]});
  }
  cs.set_pose(pose);
  dcm.deform(cs);
  const CM::Reconstruction plain = CM::reconstruct_regular(m, 2), def = dcm.reconstruct_regular(2);
  std::vector<Vec3> expected;
  for (const Vec3& p : plain.points) expected.push_back(p + Vec3(t[0], t[1], t[2]));
  EXPECT_LT(max_distance(def.points, expected), 1e-9 * diagonal(expected));
  // A bend of the cells: the deformable CM stays close to deforming the reconstruction itself.
  for (auto& c : pose)
    for (auto& v : c) v = {v[0], v[1] + 0.3 * v[0] * v[0], v[2]};
  cs.set_pose(pose);
  dcm.deform(cs);
  const CM::Reconstruction bent = dcm.reconstruct_regular(2);
  std::vector<CD::Vec3> rp;
  for (const Vec3& p : plain.points) rp.push_back({p.x, p.y, p.z});
  const auto b = sys.bind<double>(rp);
  std::vector<CD::Vec3> out;
  b.deform(sys.basis(sys.deformed_leaf_vertices(pose)), out);
  std::vector<Vec3> ref;
  for (const auto& p : out) ref.push_back(Vec3(p[0], p[1], p[2]));
  EXPECT_LT(max_distance(bent.points, ref), 0.01 * diagonal(ref));
  EXPECT_THROW(cs.set_pose({}), CMGeom::Invalid_input);
}

TEST(DeformableCMDeformers, ModelsOfTheConcept) {
  const std::vector<Vec3> rest = {Vec3(0, 0, 0), Vec3(1, 2, 3)};
  DCM::Vertex_moves_deformer mv;
  mv.bind(rest);
  mv.move(1, Vec3(5, 5, 5));
  std::vector<Vec3> out;
  mv.deform(out);
  EXPECT_EQ(out[0], rest[0]);
  EXPECT_EQ(out[1], Vec3(5, 5, 5));
  mv.move(7, Vec3());
  EXPECT_THROW(mv.deform(out), CMGeom::Invalid_input);
  auto twist = [](const Vec3& p) { return Vec3(p.x, p.y, p.z + p.x); };
  DCM::Pointwise_deformer<decltype(twist)> pw(twist);
  pw.bind(rest);
  pw.deform(out);
  EXPECT_EQ(out[1], Vec3(1, 2, 4));
  EXPECT_EQ(pw.weights_bytes(), 0u);
}

}  // namespace
