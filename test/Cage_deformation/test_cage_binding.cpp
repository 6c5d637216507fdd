// Tests of binding points to a cage and of the deformation kernel: dense, sparse and float
// bindings agree and do not depend on the thread count.
#include "cage_coordinates_test_util.h"

// ================================================================== binding and deformation
TEST(CAGE_SUITE(Cage_binding), dense_sparse_float_agree_and_thread_independent) {
  std::mt19937 rng(31);
  Triangle_cage cage = l_cage();
  Mean_value_coordinates_3 mvc(cage);
  Green_coordinates_3 gc(cage);
  std::vector<Vec3> pts = random_points(rng, {0.05, 0.05, 0.05}, {1.95, 0.95, 0.95}, 3000);
  pts.push_back(cage.vertices[2]);  // exact zeros in a sparse row
  std::vector<Vec3> def = cage.vertices;
  std::uniform_real_distribution<double> U(-0.3, 0.3);
  for (Vec3& p : def)
    for (double& c : p) c += U(rng);
  const double L = cage.bbox_diagonal();
  auto check = [&](const auto& coords) {
    auto rule = coords.deformation_rule();
    Cage_binding<double> dd = bind_points(coords, pts);
    Cage_binding<float> df = bind_points<float>(coords, pts);
    Binding_options so;
    so.storage = Weight_storage::sparse;
    Cage_binding<double> sd = bind_points(coords, pts, so);
    so.storage = Weight_storage::grouped;
    Cage_binding<double> gd = bind_points(coords, pts, so);
    std::vector<Vec3> a, b, c, d, e;
    dd.deform(rule, def, a);
    df.deform(rule, def, b);
    sd.deform(rule, def, c);
    gd.deform(rule, def, e);
    EXPECT_EQ(df.weights_bytes() * 2, dd.weights_bytes());
    EXPECT_LE(sd.number_of_stored_weights(), dd.number_of_stored_weights());
    // Grouping keeps every stored weight; rows with exact zeros (if the coordinates give any at
    // the cage vertex) make patterns of their own.
    EXPECT_EQ(gd.number_of_stored_weights(), sd.number_of_stored_weights());
    std::set<std::vector<std::uint32_t>> patterns;
    for (std::size_t i = 0; i < pts.size(); ++i)
      patterns.emplace(sd.columns().begin() + std::ptrdiff_t(sd.row_start()[i]),
                       sd.columns().begin() + std::ptrdiff_t(sd.row_start()[i + 1]));
    EXPECT_EQ(gd.number_of_groups(), patterns.size());
    EXPECT_LT(gd.weights_bytes(), sd.weights_bytes());
    for (std::size_t i : {std::size_t(0), std::size_t(17), pts.size() - 1})
      for (std::size_t k = 0; k < gd.number_of_coordinates(); ++k) EXPECT_EQ(gd.weight(i, k), sd.weight(i, k));
    for (std::size_t i = 0; i < pts.size(); ++i) {
      EXPECT_LT(norm(sub(a[i], b[i])), 1e-6 * L);
      EXPECT_LT(norm(sub(a[i], c[i])), 1e-13 * L);
      EXPECT_LT(norm(sub(a[i], e[i])), 1e-13 * L);
      // against a direct evaluation
      std::vector<double> w = coordinates(coords, pts[i]);
      EXPECT_LT(norm(sub(a[i], combine(w, basis_of(rule, def)))), 1e-12 * L);
    }
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      Cage_binding<double> d1 = bind_points(coords, pts);
      d1.deform(rule, def, d);
      EXPECT_EQ(d1.values(), dd.values());
    }
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_EQ(a[i], d[i]);
  };
  check(mvc);
  check(gc);
}
