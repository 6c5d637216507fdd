// Deforms points inside a box cage with the three coordinate types of the Cage_deformation
// package and prints where a few of them go.
//
// It shows the CageCoordinates concept at work: one generic function binds any model to a point
// set and deforms it with the model's deformation rule. The cage is a unit cube given by quads
// (fan-triangulated in file order); the pose shears the top face and lifts one corner.
#include <CMGeom/Cage_deformation.h>

#include <cstdio>
#include <vector>

namespace CD = CMGeom::Cage_deformation;

template <class Coordinates>
void deform_and_print(const char* name, const Coordinates& coords, const std::vector<CD::Vec3>& points,
                      const std::vector<CD::Vec3>& deformed_cage) {
  // Bind once (parallel), then deform as often as the cage moves.
  CD::Cage_binding<double> binding = CD::bind_points(coords, points);
  std::vector<CD::Vec3> out;
  binding.deform(coords.deformation_rule(), deformed_cage, out);
  std::printf("%s (%zu coordinates per point, %zu weight bytes)\n", name, binding.number_of_coordinates(),
              binding.weights_bytes());
  for (std::size_t i = 0; i < points.size(); ++i)
    std::printf("  (%.2f %.2f %.2f) -> (%.4f %.4f %.4f)  %s\n", points[i][0], points[i][1], points[i][2], out[i][0],
                out[i][1], out[i][2], CD::to_string(binding.status()[i]));
}

int main() {
  const std::vector<CD::Vec3> corners = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                         {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const std::vector<std::vector<int>> quads = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                               {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  CD::Triangle_cage cage = CD::make_triangle_cage(corners, quads);
  CD::validate_cage(cage, "unit cube");

  std::vector<CD::Vec3> deformed = cage.vertices;
  for (int i = 4; i < 8; ++i) deformed[i][0] += 0.3;  // shear the top face
  deformed[6][2] += 0.5;                              // and lift one of its corners

  const std::vector<CD::Vec3> points = {
      {0.5, 0.5, 0.5}, {0.25, 0.75, 0.9}, {1, 1, 1}, {0.5, 0.5, 1.2}};  // the last one is outside the cage

  deform_and_print("mean value", CD::Mean_value_coordinates_3(cage), points, deformed);
  deform_and_print("Green", CD::Green_coordinates_3(cage), points, deformed);
  CD::Harmonic_options ho;
  ho.resolution = 24;
  deform_and_print("harmonic", CD::Harmonic_coordinates_3(cage, ho), points, deformed);
  return 0;
}
