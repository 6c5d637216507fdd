// Tests of the *Cages system (thesis §5.3): the cage-system file, the structure (borders, join
// cages), C¹ continuity of S across every border (and the jump of piecewise MVC), S = T_i where
// d_i = 1, one cage = plain coordinates, affine reproduction, heterogeneous coordinates, and the
// multi-level propagation (§5.3.4).
#include <CMGeom/Cage_deformation.h>

#include "cmgeom_test_config.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <filesystem>
#include <iostream>
#include <iterator>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

using namespace CMGeom::Cage_deformation;
using CMGeom::Cage_deformation::internal::add;
using CMGeom::Cage_deformation::internal::cross;
using CMGeom::Cage_deformation::internal::dot;
using CMGeom::Cage_deformation::internal::mul;
using CMGeom::Cage_deformation::internal::norm;
using CMGeom::Cage_deformation::internal::sub;

namespace {

using Mat3 = std::array<Vec3, 3>;  // columns

// A smooth, clearly non-affine map of space, applied to the cage vertices.
Vec3 bend(const Vec3& p) {
  return {p[0] + 0.15 * std::sin(1.3 * p[1] + 0.4) + 0.1 * p[2] * p[2],
          p[1] + 0.2 * std::cos(1.1 * p[0]) + 0.05 * p[0] * p[2],
          p[2] + 0.12 * std::sin(0.9 * p[0] + 1.7 * p[1])};
}

void deform_all(Cage_system_description& d, Vec3 (*map)(const Vec3&)) {
  for (auto& c : d.cages)
    for (std::size_t k = 0; k < c.deformed.size(); ++k) c.deformed[k] = map(c.rest.vertices[k]);
}

std::vector<Vec3> random_points(std::mt19937& rng, Vec3 lo, Vec3 hi, int n) {
  std::vector<Vec3> r;
  for (int i = 0; i < n; ++i) {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = std::uniform_real_distribution<double>(lo[a], hi[a])(rng);
    r.push_back(p);
  }
  return r;
}

double max_abs(const Mat3& a) {
  double m = 0;
  for (const Vec3& c : a)
    for (double x : c) m = std::max(m, std::abs(x));
  return m;
}

// Jacobian of S_cage at q (a point of a face with outward unit normal n of `cage`), from that
// cage's side only: tangential central differences on the face, a one-sided second-order
// difference along -n. Returned in the frame (t1, t2, n).
template <class Fh>
Mat3 one_sided_jacobian(const Cage_system& s, std::size_t cage, const std::vector<Vec3>& B, const Vec3& q,
                        const Vec3& n, const Vec3& t1, const Vec3& t2, double delta, const Fh& fh) {
  auto S = [&](const Vec3& p) { return s.evaluate(p, cage, B, Sine_smoothing(), fh); };
  Mat3 J;
  J[0] = mul(1 / (2 * delta), sub(S(add(q, mul(delta, t1))), S(add(q, mul(-delta, t1)))));
  J[1] = mul(1 / (2 * delta), sub(S(add(q, mul(delta, t2))), S(add(q, mul(-delta, t2)))));
  const Vec3 s0 = S(q), s1 = S(add(q, mul(-delta, n))), s2 = S(add(q, mul(-2 * delta, n)));
  // f'(0) along +n from samples at 0, -δ, -2δ: (3 f(0) - 4 f(-δ) + f(-2δ)) / (2δ)
  J[2] = mul(1 / (2 * delta), add(sub(mul(3, s0), mul(4, s1)), s2));
  return J;
}

struct Border_result {
  double max_rel_jump = 0, max_value_gap = 0;
  int probes = 0;
};

// Probes every border face of every leaf cage: the Jacobians of S from both sides.
template <class Fh>
Border_result probe_borders(const Cage_system& s, const std::vector<Vec3>& B, const Fh& fh, std::mt19937& rng) {
  Border_result r;
  const double L = s.union_cage().bbox_diagonal();
  const double delta = 1e-5 * L;
  for (std::size_t i : s.leaf_cages()) {
    const Triangle_cage& ci = s.description().cages[i].rest;
    const auto& gi = s.global_vertices(i);
    for (std::size_t j : s.neighbours(i)) {
      if (j < i) continue;
      const auto& gj = s.global_vertices(j);
      for (const auto& t : ci.triangles) {
        bool shared = true;
        for (int k = 0; k < 3; ++k) shared = shared && std::find(gj.begin(), gj.end(), gi[t[k]]) != gj.end();
        if (!shared) continue;
        const Vec3 a = ci.vertices[t[0]], b = ci.vertices[t[1]], c = ci.vertices[t[2]];
        Vec3 n = cross(sub(b, a), sub(c, a));
        n = mul(1 / norm(n), n);
        Vec3 t1 = mul(1 / norm(sub(b, a)), sub(b, a));
        Vec3 t2 = cross(n, t1);
        for (int probe = 0; probe < 2; ++probe) {
          std::uniform_real_distribution<double> U(0.2, 0.8);
          double u = U(rng), v = U(rng);
          if (u + v > 0.9) {
            u *= 0.5;
            v *= 0.5;
          }
          const Vec3 q = add(a, add(mul(u, sub(b, a)), mul(v, sub(c, a))));
          const Mat3 Ji = one_sided_jacobian(s, i, B, q, n, t1, t2, delta, fh);
          const Mat3 Jj = one_sided_jacobian(s, j, B, q, mul(-1, n), t1, t2, delta, fh);
          Mat3 D;
          // Jj's third column is along -n: flip it back to +n.
          for (int col = 0; col < 2; ++col) D[col] = sub(Ji[col], Jj[col]);
          D[2] = add(Ji[2], Jj[2]);
          r.max_rel_jump = std::max(r.max_rel_jump, max_abs(D) / max_abs(Ji));
          r.max_value_gap = std::max(r.max_value_gap,
                                     norm(sub(s.evaluate(q, i, B, Sine_smoothing(), fh),
                                              s.evaluate(q, j, B, Sine_smoothing(), fh))) / L);
          ++r.probes;
        }
      }
    }
  }
  return r;
}


std::string tmp(const std::string& name) { return std::string(CMGEOM_TEST_TMP_DIR) + "/cage_system_" + name; }

std::string write(const std::string& name, const std::string& text) {
  const std::string p = tmp(name);
  std::ofstream(p) << text;
  return p;
}

const char* cube_json =
    R"({"vertices": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]],
        "faces": [[0,4,6,2],[1,3,7,5],[0,1,5,4],[2,6,7,3],[0,2,3,1],[4,5,7,6]]})";

}  // namespace

// ------------------------------------------------------------------ file format
TEST(Cage_system_io, reads_inline_and_file_cages_and_round_trips) {
  std::ofstream(tmp("cube.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                                    "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
  const std::string path = write("ok.json", std::string(R"({"h": 0.5, "join_coordinates": "mean_value", "cages": [
      {"name": "a", "rest": )") + cube_json + R"(, "deformed": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,2]]},
      {"name": "b", "rest": "cage_system_cube.obj", "coordinates": "green", "h": 0.25,
       "border_h": [{"cage": "a", "h": 0.125}], "parent": {"cage": "a", "vertices": [0, 7]}}]})");
  const Cage_system_description d = read_cage_system(path);
  ASSERT_EQ(d.cages.size(), 2u);
  EXPECT_EQ(d.cages[0].h, 0.5);
  EXPECT_EQ(d.cages[1].h, 0.25);
  EXPECT_EQ(d.cages[1].coordinates, Coordinate_type::green);
  EXPECT_EQ(d.cages[0].rest.triangles.size(), 12u);
  EXPECT_EQ(d.cages[0].deformed[7][2], 2.0);
  ASSERT_EQ(d.cages[1].parents.size(), 1u);
  EXPECT_EQ(d.cages[1].parents[0].cage, 0u);
  EXPECT_EQ(d.cages[1].parents[0].vertices, (std::vector<std::uint32_t>{0, 7}));
  ASSERT_EQ(d.cages[1].border_h.size(), 1u);
  EXPECT_EQ(d.cages[1].border_h[0].cage, 0u);
  EXPECT_EQ(d.cages[1].border_h[0].h, 0.125);
  EXPECT_TRUE(d.cages[0].border_h.empty());
  // Round trip through the inline writer.
  write_cage_system(tmp("rt.json"), d);
  const Cage_system_description e = read_cage_system(tmp("rt.json"));
  ASSERT_EQ(e.cages.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(e.cages[c].rest.vertices, d.cages[c].rest.vertices);
    EXPECT_EQ(e.cages[c].rest.triangles, d.cages[c].rest.triangles);
    EXPECT_EQ(e.cages[c].deformed, d.cages[c].deformed);
    EXPECT_EQ(e.cages[c].h, d.cages[c].h);
    EXPECT_EQ(e.cages[c].coordinates, d.cages[c].coordinates);
    ASSERT_EQ(e.cages[c].border_h.size(), d.cages[c].border_h.size());
    for (std::size_t k = 0; k < d.cages[c].border_h.size(); ++k) {
      EXPECT_EQ(e.cages[c].border_h[k].cage, d.cages[c].border_h[k].cage);
      EXPECT_EQ(e.cages[c].border_h[k].h, d.cages[c].border_h[k].h);
    }
  }
  EXPECT_EQ(e.cages[1].parents[0].vertices, d.cages[1].parents[0].vertices);
}

TEST(Cage_system_io, errors_name_the_file_and_the_json_pointer) {
  const std::string c = cube_json;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{", "invalid JSON"},
      {"[]", "/: expected a JSON object"},
      {R"({"cages": []})", "/cages: expected a non-empty array"},
      {R"({"cages": [{"rest": )" + c + R"(, "h": 0}]})", "/cages/0/h: must be a number in (0, 1]"},
      {R"({"cages": [{"rest": )" + c + R"(, "hh": 1}]})", "/cages/0/hh: unknown key"},
      {R"({"cages": [{"rest": )" + c + R"(, "coordinates": "wachspress"}]})", "/cages/0/coordinates: unknown coordinates"},
      {R"({"cages": [{"rest": )" + c + R"(, "deformed": [[0,0,0]]}]})", "/cages/0/deformed: has 1 vertices"},
      {R"({"cages": [{"rest": {"vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,"x"]], "faces": [[0,1,2]]}}]})",
       "/cages/0/rest/vertices/3/2: must be a number"},
      {R"({"cages": [{"rest": {"vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]], "faces": [[0,1,2],[0,1,3]]}}]})",
       "/cages/0/rest:"},
      {R"({"cages": [{"rest": {"vertices": [[0,0,0]], "faces": [[0,1,7]]}}]})", "/cages/0/rest/faces/0/1: index out of range"},
      {R"({"cages": [{"rest": )" + c + R"(, "parent": {"cage": 0}}]})", "/cages/0/parent/cage: a cage cannot be its own parent"},
      {R"({"cages": [{"rest": )" + c + R"(, "parent": {"cage": 1}}, {"rest": )" + c + R"(, "parent": {"cage": 0}}]})",
       "the parent links form a cycle"},
      {R"({"cages": [{"rest": )" + c + R"(, "parent": [{"cage": 1, "vertices": [1]}, {"cage": 2, "vertices": [1]}]},
                     {"rest": )" + c + R"(}, {"rest": )" + c + R"(}]})",
       "owned twice"},
      {R"({"cages": [{"rest": "no_such_file.obj"}]})", "/cages/0/rest: "},
      {R"({"join_coordinates": "green", "cages": [{"rest": )" + c + R"(}]})", "/join_coordinates: join cages need C1"},
      {R"({"cages": [{"rest": )" + c + R"(, "harmonic": {"resolution": 4}}]})", "/cages/0/harmonic/resolution"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": {"cage": 1, "h": 0.5}}, {"rest": )" + c + R"(}]})",
       "/cages/0/border_h: must be an array"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": 1, "h": 1.5}]}, {"rest": )" + c + R"(}]})",
       "/cages/0/border_h/0/h: must be a number in (0, 1]"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": "x", "h": 0.5}]}]})",
       "/cages/0/border_h/0/cage: no cage has this name"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": 0, "h": 0.5}]}]})",
       "/cages/0/border_h/0/cage: a cage has no border with itself"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": 1, "h": 0.5}, {"cage": 1, "h": 0.2}]},
                     {"rest": )" + c + R"(}]})",
       "/cages/0/border_h/1/cage: this border is given twice"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"h": 0.5}]}]})", "/cages/0/border_h/0/cage: missing"},
  };
  for (const auto& [text, expect] : cases) {
    const std::string p = write("bad.json", text);
    try {
      read_cage_system(p);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const CMGeom::IO_error& e) {
      const std::string w = e.what();
      EXPECT_NE(w.find(p), std::string::npos) << w;
      EXPECT_NE(w.find(expect), std::string::npos) << w << "\nexpected: " << expect;
      EXPECT_EQ(w.find('\n'), std::string::npos) << w;
    }
  }
}

// ------------------------------------------------------------------ structure
TEST(Cage_system, grid_structure_borders_and_join_cages) {
  const Cage_system s(make_grid_cage_system({0, 0, 0}, {2, 2, 1}, 2, 2, 1));
  ASSERT_EQ(s.leaf_cages().size(), 4u);
  EXPECT_EQ(s.leaf_vertices().size(), 18u);  // 3 x 3 x 2 lattice
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(s.neighbours(c).size(), 2u);  // diagonal cells touch along an edge only
    for (std::size_t o : s.neighbours(c)) EXPECT_EQ(s.border_size(c, o), 2u);
    EXPECT_EQ(s.boundary_vertices(c).size(), 6u);
  }
  // Classes: the central edge (2 vertices, 4 cages) and 4 face-middle edges (2 vertices, 2 cages).
  ASSERT_EQ(s.number_of_join_cages(), 5u);
  std::size_t total = 0;
  for (std::size_t k = 0; k < s.number_of_join_cages(); ++k) {
    total += s.join_class(k).size();
    EXPECT_EQ(s.join_class(k).size(), 2u);
    Triangle_cage jc = s.join_cage(k);
    EXPECT_FALSE(validate_cage(jc, "join cage", Cage_orientation::require_outward));
    EXPECT_NEAR(jc.signed_volume(), double(s.join_class_cages(k).size()), 1e-12);
  }
  EXPECT_EQ(total, 10u);
  Triangle_cage u = s.union_cage();
  EXPECT_FALSE(validate_cage(u, "union", Cage_orientation::require_outward));
  EXPECT_NEAR(u.signed_volume(), 4.0, 1e-12);
  // Overlapping cages are rejected.
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {1, 1, 1}, 1, 1, 1);
  d.cages.push_back(d.cages[0]);
  EXPECT_THROW(Cage_system{d}, CMGeom::Invalid_input);
}

// ------------------------------------------------------------------ C¹ across borders
TEST(Cage_system, C1_across_every_border_and_jump_of_piecewise_mvc) {
  std::mt19937 rng(7);
  for (const std::array<int, 3> g : {std::array<int, 3>{2, 1, 1}, std::array<int, 3>{2, 2, 1}, std::array<int, 3>{1, 1, 3},
                                       std::array<int, 3>{2, 2, 2}, std::array<int, 3>{3, 3, 3}}) {
    Cage_system_description d = make_grid_cage_system({-1, -0.8, -0.6}, {1.1, 0.9, 0.7}, g[0], g[1], g[2],
                                                      Coordinate_type::mean_value, 0.6);
    deform_all(d, bend);
    const Cage_system s(d);
    const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
    const Border_result star = probe_borders(s, B, Sine_h_smoothing(), rng);
    EXPECT_GT(star.probes, 0);
    EXPECT_LT(star.max_rel_jump, 1e-6) << g[0] << "x" << g[1] << "x" << g[2];
    EXPECT_LT(star.max_value_gap, 1e-12);
    const Border_result piecewise = probe_borders(s, B, Piecewise_smoothing(), rng);
    std::cout << g[0] << "x" << g[1] << "x" << g[2] << ": " << star.probes
              << " probes, Jacobian jump *Cages " << star.max_rel_jump << ", piecewise MVC "
              << piecewise.max_rel_jump << "\n";
    EXPECT_GT(piecewise.max_rel_jump, 1e-2) << "piecewise MVC should show a Jacobian jump";
    EXPECT_LT(piecewise.max_value_gap, 1e-12) << "piecewise MVC is C0";
  }
}

TEST(Cage_system, heterogeneous_coordinates_stay_C1) {
  std::mt19937 rng(11);
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {3, 1, 1}, 3, 1, 1, Coordinate_type::mean_value, 0.6);
  d.cages[1].coordinates = Coordinate_type::green;
  d.cages[2].coordinates = Coordinate_type::harmonic;
  d.cages[2].harmonic.resolution = 24;
  deform_all(d, bend);
  const Cage_system s(d);
  const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
  const Border_result r = probe_borders(s, B, Sine_h_smoothing(), rng);
  EXPECT_EQ(r.probes, 2 * 2 * 2);
  EXPECT_LT(r.max_rel_jump, 1e-6);
  EXPECT_LT(r.max_value_gap, 1e-12);
  // Without the join, the Green cage is discontinuous across its faces.
  const Border_result p = probe_borders(s, B, Piecewise_smoothing(), rng);
  std::cout << "MVC+Green+harmonic: Jacobian jump " << r.max_rel_jump << ", value gap without join "
            << p.max_value_gap << "\n";
  EXPECT_GT(p.max_value_gap, 1e-4);
}

// ------------------------------------------------------------------ reductions
TEST(Cage_system, S_equals_T_where_d_is_one) {
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1, 1}, 2, 1, 1, Coordinate_type::mean_value, 0.2);
  deform_all(d, bend);
  const Cage_system s(d);
  const std::vector<Vec3> leaf = s.deformed_leaf_vertices();
  const std::vector<Vec3> B = s.basis(leaf);
  std::mt19937 rng(3);
  int with_d1 = 0;
  for (const Vec3& p : random_points(rng, {0, 0, 0}, {2, 1, 1}, 400)) {
    const auto [c, inside] = s.locate(p);
    ASSERT_TRUE(inside);
    EXPECT_EQ(c, p[0] < 1 ? 0u : 1u);
    if (s.distance(p, c) < 1) continue;
    ++with_d1;
    Mean_value_coordinates_3 mvc(d.cages[c].rest);
    std::vector<double> w(8);
    mvc(p, w.begin());
    Vec3 t{0, 0, 0};
    for (int k = 0; k < 8; ++k) t = add(t, mul(w[k], leaf[s.global_vertices(c)[k]]));
    EXPECT_LT(norm(sub(s.evaluate(p, c, B), t)), 1e-14);
    EXPECT_EQ(s.row(p, c).entries.size(), 8u) << "no join data where d = 1";
  }
  EXPECT_GT(with_d1, 100);
}

// ------------------------------------------------------------------ h per border (§5.5)
TEST(Cage_system, h_per_border_is_C1_and_acts_near_its_border_only) {
  std::mt19937 rng(13);
  // Three cells along x; the middle cell (1) has borders with 0 (x = 1) and 2 (x = 2).
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {3, 1, 1}, 3, 1, 1, Coordinate_type::mean_value, 0.5);
  deform_all(d, bend);
  const Cage_system plain(d);
  d.cages[1].border_h.push_back({0, 0.1});
  d.cages[0].border_h.push_back({1, 0.3});  // the other side of the same border, its own value
  const Cage_system own(d);
  EXPECT_EQ(own.border_h(1, 0), 0.1);
  EXPECT_EQ(own.border_h(1, 2), 0.5);
  EXPECT_EQ(own.border_h(0, 1), 0.3);
  // Reference: d_1 = f_0.5(1 − w_12) · f_0.1(1 − w_10), with w_1j the mean value coordinates of
  // cage 1 summed over the 4 vertices of the shared face (computed here from the rest cage).
  Mean_value_coordinates_3 mvc(d.cages[1].rest);
  const Sine_h_smoothing fh;
  int near0_plain = 0, near0_own = 0, near2_plain = 0, near2_own = 0;
  for (const Vec3& p : random_points(rng, {1.02, 0.02, 0.02}, {1.98, 0.98, 0.98}, 2000)) {
    std::vector<double> w(8);
    mvc(p, w.begin());
    double w10 = 0, w12 = 0;
    for (int k = 0; k < 8; ++k) (d.cages[1].rest.vertices[k][0] < 1.5 ? w10 : w12) += w[k];
    const double ref = fh(1 - w12, 0.5) * fh(1 - w10, 0.1);
    EXPECT_NEAR(own.distance(p, 1), ref, 1e-12);
    EXPECT_NEAR(plain.distance(p, 1), fh((1 - w10) * (1 - w12), 0.5), 1e-12);
    const bool near0 = p[0] < 1.5;
    (near0 ? near0_plain : near2_plain) += plain.distance(p, 1) < 1;
    (near0 ? near0_own : near2_own) += own.distance(p, 1) < 1;
  }
  // A small h on the border with cage 0 frees most of that half from join data; the half near
  // cage 2 keeps its transition zone.
  std::cout << "points with d < 1, half near cage 0: " << near0_plain << " -> " << near0_own
            << ", half near cage 2: " << near2_plain << " -> " << near2_own << "\n";
  EXPECT_GT(near0_plain, 800);
  EXPECT_LT(near0_own, near0_plain / 2);
  EXPECT_GT(near2_own, near2_plain * 8 / 10);
  // d = 0 on the borders and S stays C¹ across every border (both sides with their own h).
  const std::vector<Vec3> B = own.basis(own.deformed_leaf_vertices());
  const Border_result r = probe_borders(own, B, Sine_h_smoothing(), rng);
  EXPECT_GT(r.probes, 0);
  EXPECT_LT(r.max_rel_jump, 1e-6);
  EXPECT_LT(r.max_value_gap, 1e-12);
  EXPECT_NEAR(own.distance({1.0 + 1e-12, 0.5, 0.5}, 1), 0.0, 1e-9);
  // A border h naming a cage that is no neighbour is refused.
  Cage_system_description bad = d;
  bad.cages[0].border_h = {{2, 0.5}};
  EXPECT_THROW(Cage_system{bad}, CMGeom::Invalid_input);
  bad.cages[0].border_h = {{1, 0.0}};
  EXPECT_THROW(Cage_system{bad}, CMGeom::Invalid_input);
  // Errors name the file the description came from.
  bad.source = "system.json";
  try {
    Cage_system{bad};
    ADD_FAILURE() << "a border h of 0 was accepted";
  } catch (const CMGeom::Invalid_input& e) {
    EXPECT_EQ(std::string(e.what()), "system.json: cage 0: border h for cage 1: h must be in (0, 1]");
  }
}

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

TEST(Cage_system, one_cage_is_the_plain_coordinates) {
  std::mt19937 rng(5);
  for (Coordinate_type type : {Coordinate_type::mean_value, Coordinate_type::green}) {
    Cage_system_description d = make_grid_cage_system({0, 0, 0}, {1, 2, 1}, 1, 1, 1, type, 0.5);
    deform_all(d, bend);
    const Cage_system s(d);
    EXPECT_EQ(s.number_of_join_cages(), 0u);
    const std::vector<Vec3> pts = random_points(rng, {-0.2, -0.2, -0.2}, {1.2, 2.2, 1.2}, 300);
    const Cage_system_binding<double> b = s.bind(pts);
    std::vector<Vec3> out;
    b.deform(s.basis(s.deformed_leaf_vertices()), out);
    const Any_cage_coordinates plain = make_cage_coordinates(type, d.cages[0].rest);
    const Cage_binding<double> pb = bind_points(plain, pts);
    std::vector<Vec3> ref;
    pb.deform(plain.deformation_rule(), d.cages[0].deformed, ref);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      EXPECT_EQ(b.influence()[i], 1.0f);
      EXPECT_LT(norm(sub(out[i], ref[i])), 1e-13) << to_string(type);
    }
  }
}

TEST(Cage_system, global_affine_map_is_reproduced) {
  std::mt19937 rng(9);
  const double A[3][4] = {{1.1, 0.3, -0.2, 0.5}, {-0.1, 0.9, 0.4, -1}, {0.2, 0.1, 1.3, 2}};
  auto affine = [&](const Vec3& p) {
    Vec3 r;
    for (int a = 0; a < 3; ++a) r[a] = A[a][0] * p[0] + A[a][1] * p[1] + A[a][2] * p[2] + A[a][3];
    return r;
  };
  for (const std::array<int, 3> g : {std::array<int, 3>{2, 1, 1}, std::array<int, 3>{2, 2, 1}, std::array<int, 3>{3, 3, 3}}) {
    Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1.5, 1}, g[0], g[1], g[2],
                                                      Coordinate_type::mean_value, 0.6);
    for (auto& c : d.cages)
      for (std::size_t k = 0; k < 8; ++k) c.deformed[k] = affine(c.rest.vertices[k]);
    const Cage_system s(d);
    const std::vector<Vec3> pts = random_points(rng, {0, 0, 0}, {2, 1.5, 1}, 500);
    const Cage_system_binding<double> b = s.bind(pts);
    EXPECT_EQ(b.outside(), 0u);
    EXPECT_GT(b.joined_points(), 0u);
    std::vector<Vec3> out;
    b.deform(s.basis(s.deformed_leaf_vertices()), out);
    for (std::size_t i = 0; i < pts.size(); ++i) EXPECT_LT(norm(sub(out[i], affine(pts[i]))), 1e-9);
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

// ------------------------------------------------------------------ multi-level (§5.3.4)
TEST(Cage_system, moving_an_internal_cage_moves_only_its_descendants) {
  // Leaves: 3 cells in a row. Internal P owns every vertex of cell 2; top Q owns every vertex of P.
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {3, 1, 1}, 3, 1, 1);
  Cage_description P = make_grid_cage_system({1.6, -0.5, -0.5}, {3.5, 1.5, 1.5}, 1, 1, 1).cages[0];
  Cage_description Q = make_grid_cage_system({1.4, -1, -1}, {4, 2, 2}, 1, 1, 1).cages[0];
  P.name = "P";
  Q.name = "Q";
  d.cages.push_back(P);  // 3
  d.cages.push_back(Q);  // 4
  d.cages[2].parents.push_back({3, {0, 1, 2, 3, 4, 5, 6, 7}});
  d.cages[3].parents.push_back({4, {0, 1, 2, 3, 4, 5, 6, 7}});
  const Cage_system s(d);
  EXPECT_EQ(s.leaf_cages(), (std::vector<std::size_t>{0, 1, 2}));
  const std::vector<Vec3> rest = s.leaf_vertices();
  auto poses = [&]() {
    std::vector<std::vector<Vec3>> p;
    for (const auto& c : d.cages) p.push_back(c.rest.vertices);
    return p;
  };
  std::set<std::uint32_t> desc(s.global_vertices(2).begin(), s.global_vertices(2).end());
  // Translate Q: its descendants (P, then cell 2's vertices) translate; nothing else moves.
  const Vec3 shift{0.3, -0.2, 0.5};
  auto pose = poses();
  for (Vec3& v : pose[4]) v = add(v, shift);
  std::vector<Vec3> moved = s.deformed_leaf_vertices(pose);
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    if (desc.count(v))
      EXPECT_LT(norm(sub(moved[v], add(rest[v], shift))), 1e-12);
    else
      EXPECT_EQ(moved[v], rest[v]);
  }
  // Moving a leaf vertex directly does not move its parents; moving P afterwards keeps the
  // vertex's offset (rotation about P's centre: the offset rotates with it).
  pose = poses();
  const std::uint32_t k = 7;  // corner (3,1,1) of cell 2
  const Vec3 t{0.1, 0.05, -0.02};
  pose[2][k] = add(pose[2][k], t);
  moved = s.deformed_leaf_vertices(pose);
  EXPECT_LT(norm(sub(moved[s.global_vertices(2)[k]], add(rest[s.global_vertices(2)[k]], t))), 1e-12);
  const Vec3 ctr{2.55, 0.5, 0.5};
  auto rot = [&](const Vec3& p) {
    const Vec3 q = sub(p, ctr);
    return add(ctr, Vec3{-q[1], q[0], q[2]});  // 90° about z
  };
  for (Vec3& v : pose[3]) v = rot(v);
  moved = s.deformed_leaf_vertices(pose);
  for (std::uint32_t v = 0; v < rest.size(); ++v) {
    if (!desc.count(v)) {
      EXPECT_EQ(moved[v], rest[v]);
      continue;
    }
    const Vec3 expect = v == s.global_vertices(2)[k] ? rot(add(rest[v], t)) : rot(rest[v]);
    EXPECT_LT(norm(sub(moved[v], expect)), 1e-12);
  }
}

// A hand-made description (not read from a file, so not checked by the reader) with a bad
// parent link is refused before anything indexes with it.
TEST(Cage_system, bad_parent_links_of_a_hand_made_description_are_refused) {
  const Cage_system_description base = [] {
    Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1, 1}, 2, 1, 1);
    d.cages.push_back(make_grid_cage_system({-0.5, -0.5, -0.5}, {2.5, 1.5, 1.5}, 1, 1, 1).cages[0]);
    return d;
  }();
  auto refused = [](const Cage_system_description& d, const std::string& what) {
    try {
      const Cage_system s(d);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const CMGeom::Invalid_input& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  Cage_system_description d = base;
  d.cages[0].parents.push_back({7, {0, 1}});
  refused(d, "bad parent link to cage 7");
  d = base;
  d.cages[1].parents.push_back({1, {0}});
  refused(d, "bad parent link to cage 1");
  d = base;
  d.cages[0].parents.push_back({2, {0, 1, 100000}});
  refused(d, "owns vertex 100000");
  d = base;  // a valid link still builds
  d.cages[0].parents.push_back({2, {0, 1, 2, 3, 4, 5, 6, 7}});
  EXPECT_NO_THROW(Cage_system s(d));
}

TEST(Cage_system, harmonic_parent_uses_the_lambda_rule_outside) {
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {1, 1, 1}, 1, 1, 1);
  Cage_description P = make_grid_cage_system({-0.25, -0.25, -0.25}, {1.25, 1.25, 1.25}, 1, 1, 1,
                                             Coordinate_type::harmonic).cages[0];
  P.harmonic.resolution = 16;
  d.cages.push_back(P);
  d.cages[0].parents.push_back({1, {0, 1, 2, 3, 4, 5, 6, 7}});
  const Cage_system s(d);
  std::vector<std::vector<Vec3>> pose{d.cages[0].rest.vertices, d.cages[1].rest.vertices};
  const Vec3 t{0.6, 0.4, 0.5}, shift{1, 2, 3};
  pose[0][7] = add(pose[0][7], t);  // (1,1,1) + t is outside P: harmonic coordinates undefined
  for (Vec3& v : pose[1]) v = add(v, shift);
  const std::vector<Vec3> moved = s.deformed_leaf_vertices(pose);
  const std::uint32_t g = s.global_vertices(0)[7];
  EXPECT_LT(norm(sub(moved[g], add(add(s.leaf_vertices()[g], t), shift))), 1e-9);
  EXPECT_LT(norm(sub(moved[s.global_vertices(0)[0]], add(s.leaf_vertices()[s.global_vertices(0)[0]], shift))), 1e-9);
}

// ------------------------------------------------------------------ authored (non-box) cages
// Cage systems made of one artist's cage from the shared data (QMVC and PGC cages: concave,
// many-sided, the elephant's with vertices repeated at one position, which the system welds).
namespace {
std::string data_dir() { return CMGEOM_DATA_DIR; }

struct Authored_cage {
  std::string name, mesh, cage, deformed;  // deformed: "" when the data set gives no pose
};

std::vector<Authored_cage> authored_cages() {
  const std::string d = data_dir() + "/cages/";
  return {{"ManHead", d + "qmvc/ManHead.obj", d + "qmvc/ManHead_Cage.obj", d + "qmvc/ManHead_Cage_Deformed.obj"},
          {"Beast", d + "qmvc/Beast.obj", d + "qmvc/Beast_Cage.obj", d + "qmvc/Beast_Cage_Deformed.obj"},
          {"hand", d + "pgc/hand/hand.obj", d + "pgc/hand/cage.obj", ""},
          {"elephant", d + "pgc/elephant/elephant.obj", d + "pgc/elephant/cage.obj", ""}};
}

std::vector<Vec3> read_points(const std::string& path) {
  std::vector<Vec3> p;
  std::vector<std::vector<std::uint32_t>> f;
  read_polygons(path, p, f);
  return p;
}

// Every k-th vertex of the model, at most about `max` of them (binding a whole model through the
// system's per-point rows would take most of a test's time budget on a loaded 2-core machine).
std::vector<Vec3> model_sample(const std::string& path, std::size_t max) {
  const std::vector<Vec3> all = read_points(path);
  std::vector<Vec3> r;
  for (std::size_t v = 0; v < all.size(); v += all.size() / max + 1) r.push_back(all[v]);
  return r;
}

// A system of the one authored cage, deformed = rest. Harmonic coordinates at resolution 32 (the
// default 64 costs seconds per cage).
Cage_system_description one_cage_system(const Authored_cage& a, Coordinate_type type) {
  Cage_description c;
  c.name = a.name;
  c.rest_source = a.cage;
  c.rest = read_triangle_cage(a.cage);
  c.reoriented = validate_cage(c.rest, a.cage);
  c.deformed = c.rest.vertices;
  c.coordinates = type;
  c.harmonic.resolution = 32;
  Cage_system_description d;
  d.cages.push_back(std::move(c));
  d.source = a.cage;
  return d;
}

double diagonal(const std::vector<Vec3>& pts) {
  Vec3 lo = pts[0], hi = pts[0];
  for (const Vec3& p : pts)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  return norm(sub(hi, lo));
}

// A non-affine pose for the cages that come without one: `bend` in the cage's own frame (centre
// of its bounding box, lengths in units of its diagonal).
std::vector<Vec3> bent_pose(const Triangle_cage& cage) {
  Vec3 lo = cage.vertices[0], hi = lo;
  for (const Vec3& p : cage.vertices)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  const Vec3 c = mul(0.5, add(lo, hi));
  const double L = norm(sub(hi, lo));
  std::vector<Vec3> r;
  for (const Vec3& p : cage.vertices) r.push_back(add(c, mul(L, bend(mul(1 / L, sub(p, c))))));
  return r;
}

// The coordinate types tested on a cage: mean value and Green on all, harmonic on the small
// ManHead cage only (12 vertices; a solve per coordinate).
std::vector<Coordinate_type> types_for(const Authored_cage& a) {
  if (a.name == "ManHead") return {Coordinate_type::mean_value, Coordinate_type::green, Coordinate_type::harmonic};
  return {Coordinate_type::mean_value, Coordinate_type::green};
}
}  // namespace

// A system of one cage has no border (d = 1 everywhere), so S = T: the same points as binding
// the cage's own coordinates with bind_points() and deforming with its deformation rule, for the
// authored pose (QMVC) or a bent one (PGC). The authored poses also give finite points.
TEST(Cage_system, one_authored_cage_is_the_plain_coordinates) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  for (const Authored_cage& a : authored_cages()) {
    const std::vector<Vec3> pts = model_sample(a.mesh, 3000);
    for (Coordinate_type type : types_for(a)) {
      Cage_system_description d = one_cage_system(a, type);
      d.cages[0].deformed = a.deformed.empty() ? bent_pose(d.cages[0].rest) : read_points(a.deformed);
      ASSERT_EQ(d.cages[0].deformed.size(), d.cages[0].rest.vertices.size()) << a.name;
      const Cage_system s(d);
      EXPECT_EQ(s.leaf_cages().size(), 1u);
      EXPECT_TRUE(s.neighbours(0).empty());
      EXPECT_EQ(s.number_of_join_cages(), 0u);
      const Cage_system_binding<double> b = s.bind(pts);
      std::vector<Vec3> out;
      b.deform(s.basis(s.deformed_leaf_vertices()), out);
      const Any_cage_coordinates plain = make_cage_coordinates(type, d.cages[0].rest, d.cages[0].harmonic);
      const Cage_binding<double> pb = bind_points(plain, pts);
      std::vector<Vec3> ref;
      pb.deform(plain.deformation_rule(), d.cages[0].deformed, ref);
      // Both sides sum the same products; the system may add the weights of welded duplicate
      // vertices before multiplying, a few ulps of the deformed cage's size.
      const double tol = 1e-12 * diagonal(d.cages[0].deformed);
      double err = 0;
      std::size_t finite = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        EXPECT_EQ(b.influence()[i], 1.0f);
        // Same status, except that the system marks points outside its leaf cages `extended`.
        Coordinate_status expect = pb.status()[i];
        if (!s.locate(pts[i]).second && expect < Coordinate_status::extended) expect = Coordinate_status::extended;
        EXPECT_EQ(b.weights().status()[i], expect) << a.name << " " << to_string(type) << " " << i;
        err = std::max(err, norm(sub(out[i], ref[i])));
        finite += std::isfinite(out[i][0]) && std::isfinite(out[i][1]) && std::isfinite(out[i][2]);
      }
      EXPECT_LT(err, tol) << a.name << " " << to_string(type);
      EXPECT_EQ(b.joined_points(), 0u);
      // Every point is finite (harmonic points outside the cage, status undefined, get zero
      // weights and go to the origin, still finite).
      EXPECT_EQ(finite, pts.size()) << a.name << " " << to_string(type);
      std::cout << a.name << " " << to_string(type) << ": " << pts.size() << " points, max |system - plain| "
                << err << " (cage diagonal " << diagonal(d.cages[0].deformed) << ")\n";
    }
  }
}

// Binding the model's vertices and deforming with the rest cage gives the vertices back. Mean
// value and harmonic coordinates (with mean value boundary data) reproduce linear functions and
// sum to 1, Green coordinates reproduce similarities (the identity among them, inside and through
// the exterior extension), so the only error is rounding: K products of coordinates of size
// O(1) with positions of size O(L + |centre|), a few hundred ulps of L for the cages here
// (K ≤ 452). The bound is the single-cage rest-pose bound, 1e-9 L (measured: at most 5e-13 L,
// except 1.3e-10 L for mean value coordinates on the elephant). Harmonic points outside the
// cage (status undefined) are left out.
TEST(Cage_system, authored_cage_at_rest_reproduces_the_model) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  for (const Authored_cage& a : authored_cages()) {
    const std::vector<Vec3> pts = model_sample(a.mesh, 3000);
    for (Coordinate_type type : types_for(a)) {
      const Cage_system s(one_cage_system(a, type));
      const double L = s.union_cage().bbox_diagonal();
      const Cage_system_binding<double> b = s.bind(pts);
      std::vector<Vec3> out;
      b.deform(s.basis(s.leaf_vertices()), out);
      double err = 0;
      std::size_t used = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if (b.weights().status()[i] == Coordinate_status::undefined) continue;
        err = std::max(err, norm(sub(out[i], pts[i])));
        ++used;
      }
      EXPECT_GT(used, pts.size() * 9 / 10) << a.name << " " << to_string(type);
      EXPECT_LT(err, 1e-9 * L) << a.name << " " << to_string(type);
      std::cout << a.name << " " << to_string(type) << " at rest: max error " << err / L << " L over " << used
                << " points\n";
    }
  }
}

// Linear precision: moving the cage by an affine map moves every point by the same map, for
// mean value and harmonic coordinates with a general (shearing, non-uniform) map, for Green
// coordinates with a similarity (rotation, uniform scale, translation), the maps they
// reproduce. Tolerance as at rest, relative to the moved cage's diagonal.
TEST(Cage_system, authored_cage_reproduces_affine_maps) {
  if (!std::filesystem::exists(data_dir() + "/cages"))
    GTEST_SKIP() << "shared data not found: " << data_dir() << "/cages";
  const double A[3][3] = {{1.1, 0.3, -0.2}, {-0.1, 0.9, 0.4}, {0.2, 0.1, 1.3}};
  const double c = std::cos(0.7), sn = std::sin(0.7), k = 1.3;
  const double R[3][3] = {{k * c, -k * sn, 0}, {k * sn, k * c, 0}, {0, 0, k}};  // 0.7 rad about z, scale 1.3
  const Vec3 t{0.5, -1, 2};
  for (const Authored_cage& a : authored_cages()) {
    const std::vector<Vec3> pts = model_sample(a.mesh, 2000);
    for (Coordinate_type type : types_for(a)) {
      const auto& M = type == Coordinate_type::green ? R : A;
      const double scale = diagonal(pts);  // translation in units of the model's size
      auto map = [&](const Vec3& p) {
        Vec3 r;
        for (int i = 0; i < 3; ++i) r[i] = M[i][0] * p[0] + M[i][1] * p[1] + M[i][2] * p[2] + t[i] * scale;
        return r;
      };
      Cage_system_description d = one_cage_system(a, type);
      for (std::size_t v = 0; v < d.cages[0].deformed.size(); ++v) d.cages[0].deformed[v] = map(d.cages[0].rest.vertices[v]);
      const Cage_system s(d);
      const Cage_system_binding<double> b = s.bind(pts);
      std::vector<Vec3> out;
      b.deform(s.basis(s.deformed_leaf_vertices()), out);
      const double L = diagonal(d.cages[0].deformed);
      double err = 0;
      std::size_t used = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if (b.weights().status()[i] == Coordinate_status::undefined) continue;
        err = std::max(err, norm(sub(out[i], map(pts[i]))));
        ++used;
      }
      EXPECT_GT(used, pts.size() * 9 / 10) << a.name << " " << to_string(type);
      EXPECT_LT(err, 1e-9 * L) << a.name << " " << to_string(type);
    }
  }
}

// ------------------------------------------------------------------ harmonic join cages
namespace {
// A grid system under the `bend` pose whose join cages have harmonic coordinates (tricubic
// lookup, resolution 20: a solve per join cage in well under a second).
Cage_system_description harmonic_join_grid(int nx, int ny, int nz, Coordinate_type join) {
  Cage_system_description d = make_grid_cage_system({-1, -0.8, -0.6}, {1.1, 0.9, 0.7}, nx, ny, nz,
                                                    Coordinate_type::mean_value, 0.6);
  d.join_coordinates = join;
  d.join_harmonic.resolution = 20;
  deform_all(d, bend);
  return d;
}
}  // namespace

// Join cages with harmonic coordinates (`join_coordinates: harmonic`): J is then built from grid
// harmonic coordinates of the union of the incident cages. They sum to 1 and reproduce affine
// maps (mean value boundary data), so every row of S sums to 1 and S reproduces a global affine
// map and the rest pose; the join must really differ from the mean value one (else nothing new
// is tested). In a 2x1x1 grid the one join cage is the union, the border lies inside it, and S
// is C¹ there as with the mean value join.
TEST(Cage_system, harmonic_join_cages_sum_to_one_and_reproduce_affine_maps) {
  std::mt19937 rng(29);
  const double A[3][4] = {{1.1, 0.3, -0.2, 0.5}, {-0.1, 0.9, 0.4, -1}, {0.2, 0.1, 1.3, 2}};
  auto affine = [&](const Vec3& p) {
    Vec3 r;
    for (int a = 0; a < 3; ++a) r[a] = A[a][0] * p[0] + A[a][1] * p[1] + A[a][2] * p[2] + A[a][3];
    return r;
  };
  for (const std::array<int, 3> g : {std::array<int, 3>{2, 1, 1}, std::array<int, 3>{2, 2, 1}}) {
    const Cage_system_description d = harmonic_join_grid(g[0], g[1], g[2], Coordinate_type::harmonic);
    const Cage_system s(d), m(harmonic_join_grid(g[0], g[1], g[2], Coordinate_type::mean_value));
    const std::string grid = std::to_string(g[0]) + "x" + std::to_string(g[1]) + "x" + std::to_string(g[2]);
    const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
    if (g[1] == 1) {
      const Border_result r = probe_borders(s, B, Sine_h_smoothing(), rng);
      EXPECT_GT(r.probes, 0);
      EXPECT_LT(r.max_rel_jump, 1e-6) << grid;
      EXPECT_LT(r.max_value_gap, 1e-12) << grid;
    }
    // Partition of unity of the rows (to the solver's 1e-12 relative residual, summed over the
    // coordinates), and a join different from the mean value one.
    const std::vector<Vec3> pts = random_points(rng, {-1, -0.8, -0.6}, {1.1, 0.9, 0.7}, 400);
    double max_sum_err = 0, max_diff = 0;
    std::size_t joined = 0;
    for (const Vec3& p : pts) {
      const Cage_system::Point_row row = s.row(p);
      double sum = 0;
      for (const auto& e : row.entries) sum += e.weight;
      max_sum_err = std::max(max_sum_err, std::abs(sum - 1));
      if (row.d < 1) {
        ++joined;
        max_diff = std::max(max_diff, norm(sub(s.evaluate(p, row.cage, B), m.evaluate(p, row.cage, B))));
      }
    }
    std::cout << grid << " harmonic join: |sum of a row - 1| <= " << max_sum_err
              << ", max |S with harmonic join - S with mean value join| " << max_diff << "\n";
    EXPECT_LT(max_sum_err, 1e-9) << grid;
    EXPECT_GT(joined, 50u) << grid;
    EXPECT_GT(max_diff, 1e-6) << grid;
    // A global affine map of the cages moves every point by the same map (1e-9, as for the
    // harmonic coordinates of one cage).
    Cage_system_description moved = d;
    for (auto& c : moved.cages)
      for (std::size_t k = 0; k < c.deformed.size(); ++k) c.deformed[k] = affine(c.rest.vertices[k]);
    const Cage_system sa(moved);
    const Cage_system_binding<double> b = sa.bind(pts);
    EXPECT_EQ(b.joined_points(), joined) << grid;  // d depends on the rest cages only
    std::vector<Vec3> out;
    b.deform(sa.basis(sa.deformed_leaf_vertices()), out);
    double err = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) err = std::max(err, norm(sub(out[i], affine(pts[i]))));
    EXPECT_LT(err, 1e-9) << grid;
    // At rest the points stay where they are.
    s.bind(pts).deform(s.basis(s.leaf_vertices()), out);
    err = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) err = std::max(err, norm(sub(out[i], pts[i])));
    EXPECT_LT(err, 1e-9) << grid;
  }
}

// With several join classes per cage (2x2x1), a border B_ij lies on the surface of the join
// cages of the classes that contain only one of C_i, C_j; the C¹ argument of §5.3.2 needs their
// W̄ to vanish there, with f'(0) = 0. The manual states that harmonic join cages (tricubic
// lookup) keep S C¹: checked with the same probes and bound as the mean value join.
// With several join classes a border can lie on the surface of another class's join cage, where
// that class's harmonic weight should vanish; the grid-sampled harmonic coordinates leave it at
// about 1e-4 with a non-zero slope, so the deformation is continuous there but only approximately
// C1 (Jacobian jump measured 1e-7 of the diagonal off the shared face: 1.2e-3 relative at grid
// resolution 20, 5.2e-4 at 40; it shrinks with the resolution). The mean value join is C1 there
// (C1_across_every_border_and_jump_of_piecewise_mvc); the manual states both.
TEST(Cage_system, harmonic_join_cages_are_continuous_with_several_join_classes) {
  std::mt19937 rng(31);
  const Cage_system s(harmonic_join_grid(2, 2, 1, Coordinate_type::harmonic));
  const std::vector<Vec3> B = s.basis(s.deformed_leaf_vertices());
  const Border_result r = probe_borders(s, B, Sine_h_smoothing(), rng);
  std::cout << "2x2x1 harmonic join: " << r.probes << " probes, Jacobian jump " << r.max_rel_jump << ", value gap "
            << r.max_value_gap << "\n";
  EXPECT_EQ(r.probes, 16);
  EXPECT_LT(r.max_value_gap, 1e-12);
}

// ------------------------------------------------------------------ command line
namespace {
int run_cli(const std::string& args, std::string* out, std::string* err) {
  const std::string o = tmp("cli_stdout.txt"), e = tmp("cli_stderr.txt");
  const int rc = std::system((std::string(CMGEOM_CMGEOM_EXE) + " " + args + " > " + o + " 2> " + e).c_str());
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  if (out) *out = slurp(o);
  if (err) *err = slurp(e);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}
}  // namespace

TEST(Cage_system_cli, deform_and_influence_of_a_two_cage_system) {
  if (!std::filesystem::exists(CMGEOM_CMGEOM_EXE)) GTEST_SKIP() << "cmgeom not built";
  // An octahedron straddling the border of a 2x1x1 system whose cages move by one affine map.
  const std::vector<Vec3> mv = {{1.0, 0.5, 0.9}, {0.3, 0.5, 0.5}, {1.0, 0.1, 0.5},
                                {1.7, 0.5, 0.5}, {1.0, 0.9, 0.5}, {1.0, 0.5, 0.1}};
  {
    std::ofstream o(tmp("octa.obj"));
    o.precision(17);
    for (const Vec3& p : mv) o << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    o << "f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 6 3 2\nf 6 4 3\nf 6 5 4\nf 6 2 5\n";
  }
  auto affine = [](const Vec3& p) {
    return Vec3{1.2 * p[0] + 0.3 * p[2] + 1, 0.9 * p[1] - 0.2 * p[0], 1.1 * p[2] + 0.1 * p[1] - 2};
  };
  Cage_system_description d = make_grid_cage_system({0, 0, 0}, {2, 1, 1}, 2, 1, 1, Coordinate_type::mean_value, 0.6);
  for (auto& c : d.cages)
    for (std::size_t k = 0; k < 8; ++k) c.deformed[k] = affine(c.rest.vertices[k]);
  write_cage_system(tmp("two.json"), d);
  std::string so, se;
  ASSERT_EQ(run_cli("deform " + tmp("octa.obj") + " --cages " + tmp("two.json") + " -o " + tmp("two_out.obj") + " --json",
                    &so, &se), 0) << se;
  EXPECT_NE(so.find("\"joined_vertices\""), std::string::npos) << so;
  std::vector<Vec3> pts;
  std::vector<std::vector<std::uint32_t>> polys;
  read_polygons(tmp("two_out.obj"), pts, polys);
  ASSERT_EQ(pts.size(), mv.size());
  for (std::size_t i = 0; i < mv.size(); ++i) EXPECT_LT(norm(sub(pts[i], affine(mv[i]))), 1e-9) << i;
  // Influence values: the library's d_i, in vertex order.
  ASSERT_EQ(run_cli("influence " + tmp("octa.obj") + " --cages " + tmp("two.json") + " --values " + tmp("d.txt"), &so, &se), 0) << se;
  const Cage_system s(read_cage_system(tmp("two.json")));
  const Cage_system_binding<float> b = s.bind<float>(mv);
  std::ifstream in(tmp("d.txt"));
  for (std::size_t i = 0; i < mv.size(); ++i) {
    double x = -1;
    ASSERT_TRUE(in >> x);
    EXPECT_NEAR(x, b.influence()[i], 1e-7);
    EXPECT_GE(x, 0);
    EXPECT_LE(x, 1);
  }
  EXPECT_LT(b.influence()[0], 0.01);  // (1, 0.5, 0.9) is on the border: d = 0
  // --grid --write-cages writes an editable system that reads back with the same cages.
  ASSERT_EQ(run_cli("deform " + tmp("octa.obj") + " --grid 2,2,1 --h 0.5 --write-cages " + tmp("grid.json"), &so, &se), 0) << se;
  const Cage_system_description g = read_cage_system(tmp("grid.json"));
  EXPECT_EQ(g.cages.size(), 4u);
  EXPECT_EQ(g.cages[3].h, 0.5);
  // Errors: one line, exit code 1, no output file.
  Cage_system_description bad = d;
  bad.cages.push_back(bad.cages[0]);  // overlapping cages
  bad.cages.back().name = "copy";
  write_cage_system(tmp("bad.json"), bad);
  std::filesystem::remove(tmp("bad_out.obj"));
  EXPECT_EQ(run_cli("deform " + tmp("octa.obj") + " --cages " + tmp("bad.json") + " -o " + tmp("bad_out.obj"), &so, &se), 1);
  EXPECT_NE(se.find("overlap"), std::string::npos) << se;
  EXPECT_EQ(std::count(se.begin(), se.end(), '\n'), 1) << se;
  EXPECT_FALSE(std::filesystem::exists(tmp("bad_out.obj")));
  EXPECT_EQ(run_cli("deform " + tmp("octa.obj") + " --grid 2,x,1 -o " + tmp("bad_out.obj"), &so, &se), 1);
  EXPECT_NE(se.find("--grid"), std::string::npos) << se;
}
