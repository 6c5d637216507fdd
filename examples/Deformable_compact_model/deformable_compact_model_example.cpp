// Deformable Compact Model (thesis chapter 6): build the CM of a mesh, deform its base with a
// cage (mean value coordinates of the base vertices only), then with an affine map, and
// reconstruct the deformed model; the per-vertex affine maps of the base carry the deformation
// into every reconstructed point (§6.3-6.4); then animate the cage, reconstructing every frame
// with a Regular_reconstructor (points and normals only after the first frame).
//
// Usage: deformable_compact_model_example [mesh] [base_faces]   (default: the shared fandisk, 250)
#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Compact_model.h>
#include <CMGeom/Deformable_compact_model.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  namespace CM = CMGeom::CM;
  namespace CD = CMGeom::Cage_deformation;
  namespace DCM = CMGeom::DCM;
  const std::string path = argc > 1 ? argv[1] : std::string(CMGEOM_EXAMPLE_DATA_DIR) + "/classic/fandisk.obj";
  const std::size_t faces = argc > 2 ? std::stoul(argv[2]) : 250;
  if (!std::filesystem::exists(path)) {
    std::cout << "model not found: " << path << " (nothing to do)\n";
    return 0;
  }
  CMGeom::Textured_mesh input;
  CMGeom::IO::read_mesh(path, input);
  const CM::Compact_model model = CM::build_compact_model(input.mesh(), faces);
  DCM::Deformable_compact_model dcm(model);  // 1-rings and the rest part of the local maps

  // 1. A cage: the bounding box of the base, 10% larger, as 6 quads (fan-triangulated).
  CM::Vec3 lo = model.vertices[0], hi = lo;
  for (const CM::Vec3& p : model.vertices) {
    lo = CM::Vec3(std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z));
    hi = CM::Vec3(std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z));
  }
  const CM::Vec3 c = 0.5 * (lo + hi), h = 0.55 * (hi - lo);
  std::vector<std::array<double, 3>> corners;
  for (int k = 0; k < 8; ++k)
    corners.push_back({c.x + ((k & 1) ? h.x : -h.x), c.y + ((k & 2) ? h.y : -h.y), c.z + ((k & 4) ? h.z : -h.z)});
  const std::vector<std::vector<std::uint32_t>> quads = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                                         {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  CD::Triangle_cage cage = CD::make_triangle_cage(corners, quads);
  CD::validate_cage(cage, "box cage");
  // The pose: the top of the cage (z > centre) turned by 30 degrees about the vertical axis.
  std::vector<CD::Vec3> pose = cage.vertices;
  for (auto& p : pose)
    if (p[2] > c.z) {
      const double a = 0.5, x = p[0] - c.x, y = p[1] - c.y;
      p = {c.x + std::cos(a) * x - std::sin(a) * y, c.y + std::sin(a) * x + std::cos(a) * y, p[2]};
    }
  DCM::Cage_deformer<CD::Mean_value_coordinates_3> cage_deformer{CD::Mean_value_coordinates_3(cage)};
  cage_deformer.bind(dcm.base_vertices());  // coordinates of the base vertices only
  cage_deformer.set_pose(pose);
  dcm.deform(cage_deformer);  // base pose + local maps T_i
  const CM::Reconstruction twisted = dcm.reconstruct_regular(2);
  std::cout << "cage: " << model.vertices.size() << " base vertices bound (" << cage_deformer.weights_bytes()
            << " bytes of coordinates), " << dcm.solver().number_of_regularised_vertices()
            << " flat 1-rings regularised; level 2: " << twisted.points.size() << " vertices\n";

  // 2. An affine map (a shear): the deformed reconstruction is the sheared plain one (§6.1).
  DCM::Affine_deformer shear({{{1, 0.3, 0}, {0, 1, 0}, {0, 0, 1}}}, CM::Vec3(0, 0, 0));
  shear.bind(dcm.base_vertices());
  dcm.deform(shear);
  CM::Reconstruction sheared = twisted;  // reconstructed into an existing buffer: no allocation
  dcm.reconstruct_regular(2, sheared);
  const CM::Reconstruction plain = CM::reconstruct_regular(model, 2);
  double worst = 0;
  for (std::size_t i = 0; i < plain.points.size(); ++i)
    worst = std::max(worst, CM::internal::length(sheared.points[i] - shear.apply(plain.points[i])));
  std::cout << "affine: largest distance to the sheared plain reconstruction " << worst
            << " (flat rings see the shear only in their tangent plane)\n";

  // 3. An animation: the cage turned further frame by frame. A Regular_reconstructor keeps the
  // base's topology, frames and blend tables of level 2, and the unmapped points of the base edges
  // sharp at an end (Fandisk's creases: each a Newton solve, made once here); after the first frame
  // only the points and normals are written (the triangles do not change), the same bits as
  // reconstruct_regular.
  CM::Reconstruction_options keep_tables;
  keep_tables.vertex_maps = &dcm.vertex_maps();
  const CM::Regular_reconstructor<> rec(model, 2, keep_tables);
  CM::Reconstruction frame;
  bool same = true;
  for (int k = 1; k <= 4; ++k) {
    std::vector<CD::Vec3> turned = cage.vertices;
    for (auto& p : turned)
      if (p[2] > c.z) {
        const double a = 0.15 * k, x = p[0] - c.x, y = p[1] - c.y;
        p = {c.x + std::cos(a) * x - std::sin(a) * y, c.y + std::sin(a) * x + std::cos(a) * y, p[2]};
      }
    cage_deformer.set_pose(turned);
    dcm.deform(cage_deformer);
    if (k == 1)
      dcm.reconstruct_regular(rec, frame);
    else
      dcm.reconstruct_regular_points(rec, frame);
    same = same && frame.points == dcm.reconstruct_regular(2).points;
  }
  std::cout << "animation: 4 frames of " << frame.points.size() << " points (" << rec.number_of_kept_edges()
            << " base edges sharp at an end kept), "
            << (same ? "each the same as a fresh reconstruction" : "DIFFERENT from a fresh reconstruction") << "\n";
  if (!same) return 1;

  CMGeom::Textured_mesh out;
  CM::to_textured_mesh(twisted, out);
  CMGeom::IO::write_mesh("deformable_cm_twisted.off", out);
  // Everything must be finite, and the base vertices must be where the cage sent them.
  for (const CM::Vec3& p : twisted.points)
    if (!std::isfinite(p.x + p.y + p.z)) return 1;
  return 0;
}
