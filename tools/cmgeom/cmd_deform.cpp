// cmgeom deform <mesh> (--cages <system.json> | --grid nx,ny,nz) -o <out> [--json]
//               [--weights double|float] [--storage dense|sparse|grouped] [--write-cages system.json]
//               [--coordinates mean_value|green|harmonic] [--h 0.6] [--margin 0.05] [--piecewise]
// Deforms a mesh with a cage or a *Cages system (thesis chapter 5). The cage-system JSON format
// is read by CMGeom::Cage_deformation::read_cage_system() (Cage_system_io.h, documented in
// doc/Cage_deformation/README.md). One cage without parent links is the plain coordinate
// deformation (dense or sparse weights); several cages are evaluated as the *Cages system of
// §5.3 (join and smooth transformations, multi-level parent links; sparse weights): the library's
// CMGeom::Cage_deformation::deform() (deform.h) makes that choice. --grid builds
// a lattice of box cages around the mesh; with --write-cages the system (inline cages, deformed
// = rest) is written for editing, and -o may then be omitted. --piecewise evaluates S_i = T_i
// (no join: the C0 / discontinuous piecewise deformation of Fig. 5.2(a, b), for comparisons).
// The output keeps the input vertex order.
#include "cli_common.h"

#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Cage_deformation/deform.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>

CMGEOM_CLI_COMMAND(deform, "Deform a mesh with a cage or a *Cages system (mean value, Green, harmonic)") {
  namespace CD = CMGeom::Cage_deformation;
  using json = nlohmann::ordered_json;
  struct Args {
    cmgeom_cli::Cage_source cages;
    std::string input, output, write_cages, weights = "double", storage = "dense";
    bool as_json = false, piecewise = false, allow_degenerate = false, drop_repeated = false, repair = false;
  };
  auto a = std::make_shared<Args>();
  app.add_option("mesh", a->input, "Mesh to deform (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  cmgeom_cli::add_cage_source_options(app, a->cages, cmgeom_cli::Cage_grid_options::any_coordinates);
  app.add_option("-o,--output", a->output, "Deformed mesh (same vertex order as the input)");
  app.add_option("--write-cages", a->write_cages, "Write the cage system (inline cages) to this JSON file");
  app.add_option("--weights", a->weights, "Weight precision: double or float")
      ->check(CLI::IsMember({"double", "float"}));
  app.add_option("--storage", a->storage,
                 "Weight storage of a single cage: dense, sparse or grouped (rows sharing a column pattern)")
      ->check(CLI::IsMember({"dense", "sparse", "grouped"}));
  app.add_flag("--piecewise", a->piecewise,
               "Several cages: apply each cage's own coordinates alone (no join; for comparisons)");
  app.add_flag("--json", a->as_json, "Print timings and counts as JSON");
  cmgeom_cli::add_repair_option(app, a->repair);
  cmgeom_cli::add_allow_degenerate_option(app, a->allow_degenerate);
  cmgeom_cli::add_drop_repeated_option(app, a->drop_repeated);
  return [a]() -> int {
    a->cages.require();
    if (a->output.empty() && a->write_cages.empty()) throw CMGeom::Invalid_input("give -o <output> (or --write-cages)");
    a->cages.check_h();

    CMGeom::Textured_mesh tm;
    CMGeom::IO::Read_options read_options;
    read_options.allow_degenerate_faces = a->allow_degenerate;
    read_options.drop_repeated_vertex_faces = a->drop_repeated;
    read_options.repair = a->repair;
    std::vector<std::string> warnings;
    read_options.warnings = &warnings;
    cmgeom_cli::read_mesh_with_progress(a->input, tm, read_options);
    cmgeom_cli::print_warnings("deform", warnings);
    auto& mesh = tm.mesh();
    std::vector<CD::Vec3> points;
    points.reserve(mesh.number_of_vertices());
    for (auto v : mesh.vertices()) {
      const auto& p = mesh.point(v);
      points.push_back({p.x(), p.y(), p.z()});
    }

    const CD::Cage_system_description desc = a->cages.description(points);
    for (const auto& c : desc.cages) cmgeom_cli::print_warnings("deform", c.warnings);
    if (!a->write_cages.empty()) CD::write_cage_system(a->write_cages, desc);
    if (a->output.empty()) return 0;

    const bool single = desc.cages.size() == 1;
    std::string coordinates;
    if (single) {
      coordinates = CD::to_string(desc.cages[0].coordinates);
    } else {
      std::set<std::string> types;
      for (const auto& c : desc.cages) types.insert(CD::to_string(c.coordinates));
      for (const std::string& t : types) coordinates += (coordinates.empty() ? "" : "+") + t;
    }
    CD::Deform_options options;
    options.storage = a->storage == "sparse"    ? CD::Weight_storage::sparse
                      : a->storage == "grouped" ? CD::Weight_storage::grouped
                                                : CD::Weight_storage::dense;
    options.piecewise = a->piecewise;
    // One progress stage per stage of deform(); the coordinates' set-up (a grid solve per cage
    // for harmonic coordinates) and the product have no hook: they report their end only.
    std::unique_ptr<cmgeom_cli::Progress> stage;
    options.stage = [&](CD::Deform_stage s) {
      stage.reset();
      if (s == CD::Deform_stage::setup)
        stage = std::make_unique<cmgeom_cli::Progress>("cage setup", double(desc.cages.size()), "cages");
      else
        stage = std::make_unique<cmgeom_cli::Progress>(s == CD::Deform_stage::bind ? "bind" : "deform",
                                                       double(points.size()), "vertices");
    };
    options.progress = [&](double fraction) {
      if (stage) stage->update(fraction);
    };
    const CD::Deform_result r =
        a->weights == "float" ? CD::deform<float>(points, desc, options) : CD::deform<double>(points, desc, options);
    stage.reset();
    if (const std::size_t bad = r.count(CD::Coordinate_status::undefined))
      throw CMGeom::Invalid_input(a->input + ": " + std::to_string(bad) + " of " + std::to_string(points.size()) +
                                  " vertices lie outside the cage" + (single ? " " + desc.cages[0].rest_source : "s") +
                                  ", where harmonic coordinates are undefined (give the cage \"harmonic\": "
                                  "{\"outside\": \"mean_value\"} to use mean value coordinates there, or "
                                  "\"coordinates\": \"mean_value\" or \"green\", which are defined there, or use a "
                                  "cage that encloses the mesh)");
    std::size_t i = 0;
    for (auto v : mesh.vertices()) {
      const CD::Vec3& p = r.positions[i++];
      mesh.point(v) = CMGeom::Point_3(p[0], p[1], p[2]);
    }
    {
      cmgeom_cli::Progress stage("write " + std::filesystem::path(a->output).filename().string(),
                                 double(mesh.number_of_faces()), "faces");
      CMGeom::IO::write_mesh(a->output, tm);
    }

    std::size_t cage_vertices = 0, cage_triangles = 0;
    bool reoriented = false;
    for (const auto& c : desc.cages) {
      cage_vertices += c.rest.vertices.size();
      cage_triangles += c.rest.triangles.size();
      reoriented = reoriented || c.reoriented;
    }
    json j;
    j["input"] = a->input;
    j["output"] = a->output;
    j["coordinates"] = coordinates;
    j["vertices"] = points.size();
    j["cages"] = desc.cages.size();
    j["cage_vertices"] = cage_vertices;
    j["cage_triangles"] = cage_triangles;
    j["cage_reoriented"] = reoriented;
    j["coordinates_per_vertex"] = r.coordinates;
    j["weights"] = a->weights;
    j["storage"] = single ? a->storage : "grouped";
    if (!single) {
      j["piecewise"] = a->piecewise;
      j["joined_vertices"] = r.joined_points;
      j["outside_vertices"] = r.outside_points;
    }
    j["setup_seconds"] = r.setup_seconds;
    j["bind_seconds"] = r.bind_seconds;
    j["deform_seconds"] = r.deform_seconds;
    j["weights_bytes"] = r.weights_bytes;
    std::map<std::string, std::size_t> status;  // by name
    for (auto st : {CD::Coordinate_status::regular, CD::Coordinate_status::on_boundary, CD::Coordinate_status::extended,
                    CD::Coordinate_status::approximate, CD::Coordinate_status::undefined})
      status[CD::to_string(st)] = r.count(st);
    json s;
    for (const auto& [k, n] : status) s[k] = n;
    j["vertex_status"] = s;
    if (a->as_json) {
      cmgeom_cli::print_json(j);
    } else {
      std::cout << "deformed " << points.size() << " vertices with " << desc.cages.size() << " cage"
                << (single ? "" : "s") << " (" << coordinates << ", " << cage_vertices << " cage vertices): bind "
                << r.bind_seconds << " s, deform " << r.deform_seconds << " s, weights " << r.weights_bytes
                << " bytes -> " << a->output << "\n";
    }
    return 0;
  };
}
