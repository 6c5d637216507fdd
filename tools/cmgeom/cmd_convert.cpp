// cmgeom convert <in> -o <out> [--quantize]: read, validate, write another format (atomically); a
// textured input written to OFF, PLY or STL loses its texture, with a warning.
#include "cli_common.h"

#include <CMGeom/Mesh_IO/textured_mesh_io.h>

CMGEOM_CLI_COMMAND(convert, "Convert a mesh between OBJ(+MTL+textures), OFF, PLY, STL, glTF and GLB") {
  auto input = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto opts = std::make_shared<CMGeom::IO::Read_options>();
  app.add_option("input", *input, "Input mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  app.add_option("-o,--output", *output, "Output mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  auto gltf = std::make_shared<CMGeom::IO::Gltf_options>();
  cmgeom_cli::add_gltf_options(app, *gltf);
  cmgeom_cli::add_repair_option(app, opts->repair);
  cmgeom_cli::add_allow_degenerate_option(app, opts->allow_degenerate_faces);
  cmgeom_cli::add_drop_repeated_option(app, opts->drop_repeated_vertex_faces);
  app.add_flag("--remove-unreferenced", opts->remove_unreferenced_vertices, "Drop vertices no face uses");
  return [=]() -> int {
    CMGeom::Textured_mesh tm;
    std::vector<std::string> warnings;
    CMGeom::IO::Read_options o = *opts;
    o.warnings = &warnings;
    CMGeom::IO::read_mesh(*input, tm, o);
    const std::string ext = CMGeom::IO::extension(*output);
    if (tm.has_uvs() && (ext == ".off" || ext == ".ply" || ext == ".stl"))
      warnings.push_back(*output + ": " + ext.substr(1) +
                         " output stores the geometry only: the texture coordinates and materials are not written");
    cmgeom_cli::print_warnings("convert", warnings);
    CMGeom::IO::write_textured_mesh(*output, tm, *gltf);
    return 0;
  };
}
