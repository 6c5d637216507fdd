// Builds the Compact Model of a mesh, writes and reads it back, and reconstructs it regularly and
// adaptively (region of interest around the first base vertex; a vertex budget placed by the
// model's level error table, measured against the input), swapping the local-surface
// traits (thesis quadrics, then cubics) to show the policy, and compares the thesis' independent
// fits with the joint refit (Build_options::joint_fit) and with the joint refit of cubic surfaces
// under error control (§4.5.3: Build_options::error_bound) by their Metro error; then lets
// build_selected_compact_model() choose among its default configurations by measurement (what
// `cmgeom cm build` does by default).
//
// Usage: compact_model_example [mesh] [base_faces]   (default: the shared fandisk, 250 faces)
#include <CMGeom/Compact_model.h>
#include <CMGeom/Compact_model/error_criterion.h>
#include <CMGeom/Compact_model/level_errors.h>
#include <CMGeom/Compact_model/select_compact_model.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Metrics/approximation_error.h>

#include <CGAL/Polygon_mesh_processing/bbox.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <utility>

int main(int argc, char** argv) {
  namespace CM = CMGeom::CM;
  const std::string path = argc > 1 ? argv[1] : std::string(CMGEOM_EXAMPLE_DATA_DIR) + "/classic/fandisk.obj";
  const std::size_t faces = argc > 2 ? std::stoul(argv[2]) : 250;
  if (!std::filesystem::exists(path)) {
    std::cout << "model not found: " << path << " (nothing to do)\n";
    return 0;
  }
  CMGeom::Textured_mesh input;
  CMGeom::IO::read_mesh(path, input);

  CM::Build_statistics st;
  const CM::Compact_model model = CM::build_compact_model(
      input.mesh(), faces, CM::Build_options(), CM::Quadric_surface_traits(), CM::Weighted_quadric_simplifier(), &st);
  std::cout << "base: " << st.base_vertices << " vertices, " << st.base_faces << " faces, " << st.sharp_edges
            << " sharp edges, " << st.cone_vertices << " cone-type vertices\n";

  const std::size_t bytes = CM::write_cm("example.cm", model);
  const CM::Compact_model back = CM::read_cm("example.cm");
  std::cout << "CM file: " << bytes << " bytes, read back identical: " << (back == model ? "yes" : "NO") << "\n";

  const CM::Reconstruction regular = CM::reconstruct_regular(back, 2);
  const CM::Vec3 c = back.vertices.front();
  const CM::Reconstruction roi = CM::reconstruct_adaptive(back, CM::Region_of_interest_criterion{c, 0.1}, 4);
  std::cout << "regular level 2: " << regular.points.size() << " vertices; adaptive (ROI): " << roi.points.size()
            << " vertices\n";

  // The level error table (a CMGeom addition): the error of regular levels 0-3 against the input,
  // per base face, kept in the model; a vertex budget is then spent where it lowers that error.
  CM::Compact_model tabled = back;
  CM::measure_level_errors(tabled, input.mesh(), 3);
  const CM::Vertex_budget_result budget = CM::reconstruct_to_vertex_budget(tabled, regular.points.size(), 3);
  std::cout << "budget of " << regular.points.size()
            << " vertices placed by the level error table: " << budget.reconstruction.points.size()
            << " vertices, estimated RMS " << budget.face_levels.estimated_rms << " (regular level "
            << budget.face_levels.regular_level << ": " << budget.face_levels.regular_estimated_rms << ")\n";

  // Another traits class: cubic local surfaces where they fit better.
  const CM::Compact_model cubic =
      CM::build_compact_model(input.mesh(), faces, CM::Build_options(), CM::Cubic_surface_traits());
  std::size_t cubics = 0;
  for (const auto& s : cubic.surfaces) cubics += s.model == CM::CUBIC_MODEL;
  std::cout << "cubic traits: " << cubics << " of " << cubic.surfaces.size() << " surfaces are cubic\n";

  // The joint refit: same base, all surfaces fitted together so that their blend follows the input.
  CM::Build_options joint_options;
  joint_options.joint_fit = true;
  const CM::Compact_model joint = CM::build_compact_model(input.mesh(), faces, joint_options);
  // Error control on top: reconstructed points farther than the bound (0.3 % of the diagonal)
  // from the input, and input points that far from the reconstruction, measured at level 2, join
  // the joint refit; rounds that do not lower the largest distance are undone.
  const auto box = CGAL::Polygon_mesh_processing::bbox(input.mesh());
  CM::Build_options controlled_options = joint_options;
  controlled_options.error_bound =
      0.003 * std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                        CGAL::square(box.zmax() - box.zmin()));
  controlled_options.error_control_level = 2;
  controlled_options.error_control_rounds = 4;
  CM::Build_statistics controlled_st;
  const CM::Compact_model controlled =
      CM::build_compact_model(input.mesh(), faces, controlled_options, CM::Cubic_surface_traits(),
                              CM::Weighted_quadric_simplifier(), &controlled_st);
  std::cout << "error control: " << controlled_st.error_control_points << " points added, "
            << controlled_st.error_control_rejected_rounds << " rounds undone\n";
  const std::pair<const CM::Compact_model*, const char*> variants[] = {
      {&model, "thesis fits"}, {&joint, "joint refit"}, {&controlled, "joint refit, cubic, error control"}};
  for (const auto& [m, name] : variants) {
    const CMGeom::Metrics::Approximation_error e =
        CMGeom::Metrics::approximation_error(input.mesh(), CM::to_surface_mesh(CM::reconstruct_regular(*m, 2)));
    std::cout << name << ", level 2: Hausdorff " << 100 * e.hausdorff << " %, RMS " << 100 * e.rms
              << " % of the diagonal\n";
  }

  // The fits chosen by measurement: every default configuration built and measured at level 3.
  CM::Selection_result selection;
  const CM::Compact_model selected =
      CM::build_selected_compact_model(input.mesh(), faces, CM::Build_options(), CM::Selection_options(), &selection);
  for (const auto& k : selection.candidates)
    std::cout << "candidate " << k.configuration.name << ", level 3: Hausdorff " << 100 * k.hausdorff << " %, RMS "
              << 100 * k.rms << " %, built in " << k.seconds << " s\n";
  std::cout << "chosen: " << selection.candidates[selection.chosen].configuration.name << " ("
            << selected.vertices.size() << " base vertices)\n";

  CMGeom::Textured_mesh out;
  CM::to_textured_mesh(regular, out);
  CMGeom::IO::write_mesh("example_level2.off", out);
  return back == model ? 0 : 1;
}
