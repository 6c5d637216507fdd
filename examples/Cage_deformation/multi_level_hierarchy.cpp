// A multi-level *Cages hierarchy (thesis §5.3.4): an "arm" of points enclosed by four leaf cages
// in a row, and one upper-level cage, the forearm cage, that owns the far vertices of the last two
// leaves. Posing the forearm cage bends the arm at the elbow; a leaf-level edit made on top of it
// (widening the hand) is carried along by the parent. Changes flow downwards only: the leaves the
// forearm does not own stay where they are.
//
// Usage: multi_level_hierarchy     (prints what moved; exit 1 on a failed check)
#include <CMGeom/Cage_deformation.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace CD = CMGeom::Cage_deformation;

static double distance(const CD::Vec3& a, const CD::Vec3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

int main() {
  const double pi = 3.14159265358979323846;
  // The model: points filling the arm [0.05, 3.95] x [0, 1] x [0, 1].
  std::vector<CD::Vec3> points;
  for (int i = 0; i <= 78; ++i)
    for (int j = 0; j <= 10; ++j)
      for (int k = 0; k <= 10; ++k) points.push_back({0.05 + 0.05 * i, 0.1 * j, 0.1 * k});

  // Level 0: four box cages in a row (cells 0..3 along x), mean value coordinates, h = 0.5.
  CD::Cage_system_description desc = CD::make_grid_cage_system(CD::Vec3{0, -0.2, -0.2}, CD::Vec3{4, 1.2, 1.2}, 4, 1, 1,
                                                               CD::Coordinate_type::mean_value, 0.5);

  // Level 1: the forearm cage, a box around the last one and a half cells. It owns every leaf
  // vertex with x >= 3 (the face shared by cells 2 and 3, and the hand face x = 4): a parent
  // link per child cage lists the child's vertices it owns.
  CD::Cage_description forearm =
      CD::make_grid_cage_system(CD::Vec3{2.4, -0.6, -0.6}, CD::Vec3{4.5, 1.6, 1.6}, 1, 1, 1).cages[0];
  forearm.name = "forearm";
  const std::size_t forearm_index = desc.cages.size();
  for (std::size_t c : {std::size_t(2), std::size_t(3)}) {
    CD::Cage_parent_link link{forearm_index, {}};
    for (std::uint32_t k = 0; k < desc.cages[c].rest.vertices.size(); ++k)
      if (desc.cages[c].rest.vertices[k][0] >= 3.0) link.vertices.push_back(k);
    desc.cages[c].parents.push_back(link);
  }
  desc.cages.push_back(forearm);
  const CD::Cage_system system(desc);  // validates the links: no cycle, owned vertices inside
  std::cout << system.leaf_cages().size() << " leaf cages, 1 upper-level cage\n";

  // Pose 1: rotate the forearm cage by 50 degrees about the y axis through the elbow (2.5, *, 0.5).
  const double a = 50. * pi / 180.;
  auto bend = [&](const CD::Vec3& p) {
    const double x = p[0] - 2.5, z = p[2] - 0.5;
    return CD::Vec3{2.5 + std::cos(a) * x - std::sin(a) * z, p[1], 0.5 + std::sin(a) * x + std::cos(a) * z};
  };
  std::vector<std::vector<CD::Vec3>> pose;
  for (const auto& c : desc.cages) pose.push_back(c.rest.vertices);
  for (CD::Vec3& v : pose[forearm_index]) v = bend(v);

  const auto binding = system.bind<double>(points);  // once; every pose is a sparse product
  std::vector<CD::Vec3> bent;
  binding.deform(system.basis(system.deformed_leaf_vertices(pose)), bent);

  // Pose 2: the same, plus a leaf-level edit: widen the hand face (x = 4) of cell 3 by 40 % in y
  // and z. The displacement is given in the leaf's own rest frame; the parent carries it.
  for (CD::Vec3& v : pose[3]) {
    if (v[0] < 4.0) continue;
    v[1] = 0.5 + 1.4 * (v[1] - 0.5);
    v[2] = 0.5 + 1.4 * (v[2] - 0.5);
  }
  std::vector<CD::Vec3> widened;
  binding.deform(system.basis(system.deformed_leaf_vertices(pose)), widened);

  // What moved.
  double still = 0., rigid = 0., hand_before = 0., hand_after = 0.;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const CD::Vec3& p = points[i];
    if (p[0] <= 1.0) still = std::max(still, std::max(distance(bent[i], p), distance(widened[i], p)));
    // Deep inside cell 3 (d = 1: its own transform only), all of whose vertices the forearm
    // moved rigidly in pose 1: mean value coordinates reproduce that rotation exactly.
    if (p[0] >= 3.6 && p[0] <= 3.8 && p[1] >= 0.3 && p[1] <= 0.7 && p[2] >= 0.3 && p[2] <= 0.7)
      rigid = std::max(rigid, distance(bent[i], bend(p)));
    if (p[0] >= 3.9) {  // the hand: its extent along y
      hand_before = std::max(hand_before, std::abs(bent[i][1] - 0.5));
      hand_after = std::max(hand_after, std::abs(widened[i][1] - 0.5));
    }
  }
  std::cout << "largest move of the upper arm (x <= 1):           " << still << "\n"
            << "deep in the forearm, distance to the rotation:    " << rigid << "\n"
            << "hand half-width along y, bent / bent and widened: " << hand_before << " / " << hand_after << "\n";
  const bool ok = still < 1e-9 && rigid < 1e-9 && hand_after > 1.2 * hand_before;
  return ok ? 0 : 1;
}
