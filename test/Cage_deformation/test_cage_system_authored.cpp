// Tests of *Cages systems made of one authored (non-box) cage from the shared data.
#include "cage_system_test_util.h"

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
      std::cout << a.name << " " << to_string(type) << ": " << pts.size() << " points, max |system - plain| " << err
                << " (cage diagonal " << diagonal(d.cages[0].deformed) << ")\n";
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
      for (std::size_t v = 0; v < d.cages[0].deformed.size(); ++v)
        d.cages[0].deformed[v] = map(d.cages[0].rest.vertices[v]);
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
