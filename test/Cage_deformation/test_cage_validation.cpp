// Tests of cage validation: fan triangulation of polygonal cages, open, mixed and inward cages,
// cages from a Surface_mesh, duplicated vertices.
#include "cage_coordinates_test_util.h"

// ================================================================== cage validation
TEST(CAGE_SUITE(Cage_validation), fan_triangulation_in_file_order) {
  std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}};
  std::vector<std::vector<int>> f = {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  Triangle_cage c = make_triangle_cage(p, f);
  ASSERT_EQ(c.triangles.size(), 6u);
  EXPECT_EQ(c.triangles[0], (std::array<std::uint32_t, 3>{0, 3, 2}));
  EXPECT_EQ(c.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 1}));
  EXPECT_FALSE(validate_cage(c));
  EXPECT_NEAR(c.signed_volume(), 1.0 / 3.0, 1e-15);
}

TEST(CAGE_SUITE(Cage_validation), rejects_open_mixed_and_flips_inward) {
  Triangle_cage c = cube_cage();
  Triangle_cage open = c;
  open.triangles.pop_back();
  EXPECT_THROW(validate_cage(open), CMGeom::Invalid_input);
  Triangle_cage mixed = c;
  std::swap(mixed.triangles[0][1], mixed.triangles[0][2]);
  EXPECT_THROW(validate_cage(mixed), CMGeom::Invalid_input);
  Triangle_cage inward = c;
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  EXPECT_THROW(validate_cage(inward, "c", Cage_orientation::require_outward), CMGeom::Invalid_input);
  EXPECT_TRUE(validate_cage(inward));
  EXPECT_GT(inward.signed_volume(), 0);
  Triangle_cage nan = c;
  nan.vertices[3][1] = std::nan("");
  EXPECT_THROW(validate_cage(nan), CMGeom::Invalid_input);
}

TEST(CAGE_SUITE(Cage_validation), from_surface_mesh_and_flipped_orientation) {
  // make_triangle_cage on a CGAL FaceGraph gives the same cage as from the polygons.
  Triangle_cage c = cube_cage();
  CGAL::Surface_mesh<CGAL::Epick::Point_3> sm;
  std::vector<CGAL::Surface_mesh<CGAL::Epick::Point_3>::Vertex_index> vi;
  for (const Vec3& p : c.vertices) vi.push_back(sm.add_vertex(CGAL::Epick::Point_3(p[0], p[1], p[2])));
  for (const auto& t : c.triangles) sm.add_face(vi[t[0]], vi[t[1]], vi[t[2]]);
  Triangle_cage d = make_triangle_cage(sm);
  EXPECT_EQ(d.vertices, c.vertices);
  EXPECT_EQ(d.triangles.size(), c.triangles.size());
  EXPECT_FALSE(validate_cage(d));
  // MVC do not depend on the orientation; an inward cage is flipped back by validate_cage.
  Triangle_cage l = l_cage(), f = l;
  for (auto& t : f.triangles) std::swap(t[1], t[2]);
  Mean_value_coordinates_3 a(l), b(f);
  std::mt19937 rng(2);
  for (const Vec3& x : random_points(rng, {-0.5, -0.5, -0.5}, {2.5, 2.5, 1.5}, 100)) {
    std::vector<double> wa = coordinates(a, x), wb = coordinates(b, x);
    for (std::size_t k = 0; k < wa.size(); ++k) EXPECT_NEAR(wa[k], wb[k], 1e-12);
  }
}

TEST(CAGE_SUITE(Cage_validation), duplicated_vertices_still_closed) {
  // Split vertex 6 of the cube into two coincident copies used by different faces.
  Triangle_cage c = cube_cage();
  const std::uint32_t dup = std::uint32_t(c.vertices.size());
  c.vertices.push_back(c.vertices[6]);
  int changed = 0;
  for (auto& t : c.triangles)
    for (auto& i : t)
      if (i == 6 && changed < 2) {
        i = dup;
        ++changed;
        break;
      }
  EXPECT_NO_THROW(validate_cage(c));
  Mean_value_coordinates_3 mvc(c);
  std::vector<double> w = coordinates(mvc, {0.3, 0.6, 0.7});
  EXPECT_NEAR(sum_of(w, w.size()), 1.0, 1e-13);
  Vec3 r = combine(w, c.vertices);
  EXPECT_LT(norm(sub(r, {0.3, 0.6, 0.7})), 1e-13);
}
