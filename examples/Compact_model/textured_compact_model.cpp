// The Compact Model of a textured mesh (thesis §4.5.4): the base is simplified under the chart
// constraints of chapter 3, so it carries per-corner texture coordinates and a new atlas made
// through the index texture. Writes the CM and its atlas together (both files or neither), reads
// the CM back, and reconstructs it at level 2 as a textured OBJ.
//
//   textured_compact_model [mesh.obj] [ratio]     (default: data/spot/spot.obj, 0.1)
// Writes textured.cm, textured.png and textured_level2.obj (+ .mtl, texture) in the current
// directory.
#include <CMGeom/Compact_model.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>

#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  namespace CM = CMGeom::CM;
  const std::string path = argc > 1 ? argv[1] : "data/spot/spot.obj";
  const double ratio = argc > 2 ? std::atof(argv[2]) : 0.1;
  try {
    CMGeom::Textured_mesh input;
    CMGeom::IO::read_textured_mesh(path, input);  // validated mesh + decoded texture
    const std::size_t target = std::size_t(ratio * double(input.mesh().number_of_faces()));

    CM::Textured_build_result textured;
    CM::Build_statistics st;
    CM::Compact_model model = CM::build_textured_compact_model(input, target, CM::Build_options(),
                                                               CM::Quadric_surface_traits(), &textured, &st);
    std::cout << path << ": base " << st.base_vertices << " vertices, " << st.base_faces << " faces, charts "
              << textured.simplification.charts_in << " -> " << textured.simplification.charts_out << "\n";

    // The CM names its atlas relative to its own directory; both files appear on commit().
    std::size_t bytes = 0;
    {
      CMGeom::IO::Atomic_output out;
      if (!textured.texture.empty()) {
        CMGeom::IO::write_image("textured.png", textured.texture, out);
        model.texture = "textured.png";
      }
      bytes = CM::write_cm("textured.cm", model, out);
      out.commit();
    }
    CM::Compact_model back = CM::read_cm("textured.cm");
    std::cout << "textured.cm: " << bytes << " bytes, read back identical: " << (back == model ? "yes" : "NO")
              << ", texture " << CM::texture_path(back, "textured.cm") << "\n";
    back.texture = CM::texture_path(back, "textured.cm");

    const CM::Reconstruction r = CM::reconstruct_regular(back, 2);
    CMGeom::Textured_mesh out;
    CM::to_textured_mesh(r, out, back.texture);
    CMGeom::IO::write_mesh("textured_level2.obj", out);  // OBJ + MTL + texture, atomically
    std::cout << "level 2: " << r.points.size() << " vertices, " << r.triangles.size() << " faces, "
              << r.corner_uvs.size() / 3 << " textured\n";
    const bool ok = back == model && textured.simplification.charts_out == textured.simplification.charts_in &&
                    r.corner_uvs.size() == 3 * r.triangles.size();
    return ok ? EXIT_SUCCESS : EXIT_FAILURE;
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }
}
