// Tests of the bindings of a *Cages system: grouped rows, progress hooks, memory and thread
// independence.
#include "cage_system_test_util.h"

// ------------------------------------------------------------------ grouped rows
TEST(Cage_system, grouped_binding_equals_the_direct_rows) {
  std::mt19937 rng(17);
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 2, 1}, 2, 2, 1, Coordinate_type::mean_value, 0.5);
  d.cages[3].coordinates = Coordinate_type::green;
  deform_all(d, bend);
  const Cage_system s(d);
  const std::vector<Vec3> pts = random_points(rng, {-0.1, -0.1, -0.1}, {2.1, 2.1, 1.1}, 3000);
  const Cage_system_binding<double> b = s.bind(pts);
  EXPECT_EQ(b.weights().storage(), Weight_storage::grouped);
  // Few patterns: per cage, one per set of join terms in use.
  EXPECT_LT(b.weights().number_of_groups(), 200u);
  std::size_t nnz = 0;
  const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
  std::vector<Vec3> out;
  b.deform(B, out);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Cage_system::Point_row r = s.row(pts[i]);
    nnz += r.entries.size();
    Vec3 x{0, 0, 0};
    for (const auto& e : r.entries) x = add(x, mul(e.weight, B[e.column]));
    EXPECT_LT(norm(sub(out[i], x)), 1e-13) << i;
    if (i % 97 == 0)
      for (const auto& e : r.entries) EXPECT_EQ(b.weights().weight(i, e.column), e.weight);
  }
  EXPECT_EQ(b.weights().number_of_stored_weights(), nnz);
  // A weight costs its value, a row one 32-bit index, plus the patterns (sparse rows: value,
  // 32-bit column and 8-byte row start).
  EXPECT_LT(b.weights_bytes(), nnz * 8 + pts.size() * 4 + 64 * 1024);
  EXPECT_LT(b.weights_bytes(), nnz * 12 + pts.size() * 8);
}

// The progress hooks of the bindings (CMGeom/Progress.h): every call from the calling thread
// although the rows are computed on TBB workers, fractions never decreasing and ending at 1, at
// most about 256 calls for 20,000 points, and the same weights as without the hook.
TEST(Cage_system, binding_progress_comes_from_the_calling_thread_and_changes_nothing) {
  std::mt19937 rng(23);
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 2, 1}, 2, 2, 1, Coordinate_type::mean_value, 0.5);
  deform_all(d, bend);
  const Cage_system s(d);
  const std::vector<Vec3> pts = random_points(rng, {0, 0, 0}, {2, 2, 1}, 20000);
  struct Record {
    std::vector<double> fractions;
    bool other_thread = false;
    CMGeom::Progress_callback hook() {
      const std::thread::id caller = std::this_thread::get_id();
      return [this, caller](double f) {
        other_thread = other_thread || std::this_thread::get_id() != caller;
        fractions.push_back(f);
      };
    }
    void check() const {
      ASSERT_FALSE(fractions.empty());
      EXPECT_FALSE(other_thread);
      EXPECT_GE(fractions.front(), 0.);
      EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
      EXPECT_EQ(fractions.back(), 1.);
      EXPECT_LE(fractions.size(), 260u);
    }
  };
  Record system_record;
  const Cage_system_binding<double> hooked = s.bind(pts, Sine_smoothing(), Sine_h_smoothing(), system_record.hook());
  system_record.check();
  EXPECT_EQ(hooked.weights().values(), s.bind(pts).weights().values());
  // One cage's coordinates, dense and sparse rows.
  const Any_cage_coordinates mvc = make_cage_coordinates(Coordinate_type::mean_value, d.cages[0].rest);
  for (const Weight_storage storage : {Weight_storage::dense, Weight_storage::sparse}) {
    Binding_options plain, with;
    plain.storage = with.storage = storage;
    Record record;
    with.progress = record.hook();
    const Cage_binding<double> b = bind_points(mvc, pts, with);
    record.check();
    EXPECT_EQ(b.values(), bind_points(mvc, pts, plain).values());
  }
}

TEST(Cage_system, memory_falls_with_h_and_binding_is_thread_independent) {
  std::mt19937 rng(13);
  const std::vector<Vec3> pts = random_points(rng, {0, 0, 0}, {2, 2, 1}, 2000);
  std::size_t prev_joined = pts.size() + 1, prev_bytes = std::size_t(-1);
  for (double h : {1.0, 0.6, 0.2}) {
    Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 2, 1}, 2, 2, 1, Coordinate_type::mean_value, h);
    deform_all(d, bend);
    const Cage_system s(d);
    std::vector<Vec3> o1, o2;
    Cage_system_binding<double> b1, b2;
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      b1 = s.bind(pts);
    }
    {
      tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
      b2 = s.bind(pts);
    }
    const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
    b1.deform(B, o1);
    b2.deform(B, o2);
    EXPECT_EQ(o1, o2);
    EXPECT_EQ(b1.weights().values(), b2.weights().values());
    EXPECT_LT(b1.joined_points(), prev_joined);
    EXPECT_LT(b1.weights_bytes(), prev_bytes);
    prev_joined = b1.joined_points();
    prev_bytes = b1.weights_bytes();
  }
}
