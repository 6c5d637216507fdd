// cmgeom deform <mesh> (--cages <system.json> | --grid nx,ny,nz) -o <out> [--json]
//               [--weights double|float] [--storage dense|sparse|grouped] [--write-cages system.json]
//               [--coordinates mean_value|green|harmonic] [--h 0.6] [--margin 0.05] [--piecewise]
// Deforms a mesh with a cage or a *Cages system (thesis chapter 5). The cage-system JSON format
// is read by CMGeom::Cage_deformation::read_cage_system() (Cage_system_io.h, documented in
// doc/Cage_deformation/README.md). One cage without parent links is the plain coordinate
// deformation (dense or sparse weights); several cages are evaluated as the *Cages system of
// §5.3 (join and smooth transformations, multi-level parent links; sparse weights). --grid builds
// a lattice of box cages around the mesh; with --write-cages the system (inline cages, deformed
// = rest) is written for editing, and -o may then be omitted. --piecewise evaluates S_i = T_i
// (no join: the C0 / discontinuous piecewise deformation of Fig. 5.2(a, b), for comparisons).
// The output keeps the input vertex order.
#include "cli_common.h"

#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>

namespace {

namespace CD = CMGeom::Cage_deformation;
using json = nlohmann::ordered_json;

struct Result {
  std::vector<CD::Vec3> positions;
  double setup_seconds = 0, bind_seconds = 0, deform_seconds = 0;
  std::size_t weights_bytes = 0, coordinates = 0, joined = 0, outside = 0;
  std::map<std::string, std::size_t> status;
};

template <class Binding>
void count_status(const Binding& b, Result& r) {
  for (auto s : {CD::Coordinate_status::regular, CD::Coordinate_status::on_boundary,
                 CD::Coordinate_status::extended, CD::Coordinate_status::approximate,
                 CD::Coordinate_status::undefined})
    r.status[CD::to_string(s)] = b.count(s);
}

template <class Weight, class Coords>
void run_single(const Coords& coords, const std::vector<CD::Vec3>& points,
                const std::vector<CD::Vec3>& deformed, CD::Weight_storage storage, Result& r) {
  CD::Binding_options opt;
  opt.storage = storage;
  double t0 = cmgeom_cli::now_seconds();
  cmgeom_cli::Progress bind_stage("bind", double(points.size()), "vertices");
  opt.progress = bind_stage.hook();
  CD::Cage_binding<Weight> b = CD::bind_points<Weight>(coords, points, opt);
  r.bind_seconds = cmgeom_cli::now_seconds() - t0;
  bind_stage.done();
  std::vector<CD::Vec3> basis;
  cmgeom_cli::Progress deform_stage("deform", double(points.size()), "vertices");
  t0 = cmgeom_cli::now_seconds();
  coords.deformation_rule()(deformed, std::back_inserter(basis));
  b.deform(basis, r.positions);
  r.deform_seconds = cmgeom_cli::now_seconds() - t0;
  deform_stage.done();
  r.weights_bytes = b.weights_bytes();
  r.coordinates = b.number_of_coordinates();
  count_status(b, r);
}

template <class Weight, class Fh>
void run_system(const CD::Cage_system& sys, const std::vector<CD::Vec3>& points, const Fh& fh, Result& r) {
  double t0 = cmgeom_cli::now_seconds();
  cmgeom_cli::Progress bind_stage("bind", double(points.size()), "vertices");
  const CD::Cage_system_binding<Weight> b =
      sys.template bind<Weight>(points, CD::Sine_smoothing(), fh, bind_stage.hook());
  r.bind_seconds = cmgeom_cli::now_seconds() - t0;
  bind_stage.done();
  cmgeom_cli::Progress deform_stage("deform", double(points.size()), "vertices");
  t0 = cmgeom_cli::now_seconds();
  b.deform(sys.basis(sys.deformed_leaf_vertices()), r.positions);
  r.deform_seconds = cmgeom_cli::now_seconds() - t0;
  deform_stage.done();
  r.weights_bytes = b.weights_bytes();
  r.coordinates = sys.number_of_coordinates();
  r.joined = b.joined_points();
  r.outside = b.outside();
  count_status(b.weights(), r);
}

}  // namespace

CMGEOM_CLI_COMMAND(deform, "Deform a mesh with a cage or a *Cages system (mean value, Green, harmonic)") {
  struct Args {
    std::string input, system, output, grid, write_cages, weights = "double", storage = "dense",
        coordinates = "mean_value";
    double h = 1.0, margin = 0.05;
    bool as_json = false, piecewise = false;
  };
  auto a = std::make_shared<Args>();
  app.add_option("mesh", a->input, "Mesh to deform (.obj, .off, .ply, .gltf, .glb)")->required();
  auto* cages = app.add_option("--cages", a->system, "Cage-system JSON file");
  auto* grid = app.add_option("--grid", a->grid, "Build a grid of nx,ny,nz box cages around the mesh");
  cages->excludes(grid);
  app.add_option("-o,--output", a->output, "Deformed mesh (same vertex order as the input)");
  app.add_option("--write-cages", a->write_cages, "Write the cage system (inline cages) to this JSON file");
  app.add_option("--coordinates", a->coordinates, "With --grid: coordinates of every cage")
      ->check(CLI::IsMember({"mean_value", "green", "harmonic"}));
  app.add_option("--h", a->h, "With --grid: h of every cage, in (0, 1] (default 1)");
  app.add_option("--margin", a->margin, "With --grid: margin around the mesh, times its bbox diagonal (default 0.05)");
  app.add_option("--weights", a->weights, "Weight precision: double or float")
      ->check(CLI::IsMember({"double", "float"}));
  app.add_option("--storage", a->storage,
                 "Weight storage of a single cage: dense, sparse or grouped (rows sharing a column pattern)")
      ->check(CLI::IsMember({"dense", "sparse", "grouped"}));
  app.add_flag("--piecewise", a->piecewise,
               "Several cages: apply each cage's own coordinates alone (no join; for comparisons)");
  app.add_flag("--json", a->as_json, "Print timings and counts as JSON");
  return [a]() -> int {
    if (a->system.empty() && a->grid.empty()) throw CMGeom::Invalid_input("give --cages <system.json> or --grid nx,ny,nz");
    if (a->output.empty() && a->write_cages.empty()) throw CMGeom::Invalid_input("give -o <output> (or --write-cages)");
    if (!(a->h > 0 && a->h <= 1)) throw CMGeom::Invalid_input("--h must be in (0, 1]");

    CMGeom::Textured_mesh tm;
    cmgeom_cli::read_mesh_with_progress(a->input, tm);
    auto& mesh = tm.mesh();
    std::vector<CD::Vec3> points;
    points.reserve(mesh.number_of_vertices());
    for (auto v : mesh.vertices()) {
      const auto& p = mesh.point(v);
      points.push_back({p.x(), p.y(), p.z()});
    }

    CD::Cage_system_description desc;
    if (!a->grid.empty()) {
      int n[3];
      char extra = 0;
      if (std::sscanf(a->grid.c_str(), "%d,%d,%d%c", &n[0], &n[1], &n[2], &extra) != 3)
        throw CMGeom::Invalid_input("bad --grid '" + a->grid + "': expected nx,ny,nz, e.g. 2,2,1");
      const CD::Coordinate_type type = a->coordinates == "green"      ? CD::Coordinate_type::green
                                       : a->coordinates == "harmonic" ? CD::Coordinate_type::harmonic
                                                                      : CD::Coordinate_type::mean_value;
      desc = CD::make_grid_cage_system(points, n[0], n[1], n[2], a->margin, type, a->h);
    } else {
      desc = CD::read_cage_system(a->system);
    }
    for (const auto& c : desc.cages)
      for (const std::string& w : c.warnings) std::cerr << "cmgeom deform: warning: " << w << "\n";
    if (!a->write_cages.empty()) CD::write_cage_system(a->write_cages, desc);
    if (a->output.empty()) return 0;

    const bool use_float = a->weights == "float";
    const bool single = desc.cages.size() == 1;
    Result r;
    std::string coordinates;
    const double t_setup = cmgeom_cli::now_seconds();
    // The coordinates' set-up (a grid solve per cage for harmonic coordinates) has no hook: its
    // stage reports its end only.
    auto setup_stage = std::make_unique<cmgeom_cli::Progress>("cage setup", double(desc.cages.size()), "cages");
    if (single) {
      const CD::Cage_description& c = desc.cages[0];
      coordinates = CD::to_string(c.coordinates);
      const auto st = a->storage == "sparse"    ? CD::Weight_storage::sparse
                      : a->storage == "grouped" ? CD::Weight_storage::grouped
                                                : CD::Weight_storage::dense;
      const CD::Any_cage_coordinates coords = CD::make_cage_coordinates(c.coordinates, c.rest, c.harmonic);
      r.setup_seconds = cmgeom_cli::now_seconds() - t_setup;
      setup_stage.reset();
      if (use_float)
        run_single<float>(coords, points, c.deformed, st, r);
      else
        run_single<double>(coords, points, c.deformed, st, r);
    } else {
      std::set<std::string> types;
      for (const auto& c : desc.cages) types.insert(CD::to_string(c.coordinates));
      for (const std::string& t : types) coordinates += (coordinates.empty() ? "" : "+") + t;
      const CD::Cage_system sys(desc);
      r.setup_seconds = cmgeom_cli::now_seconds() - t_setup;
      setup_stage.reset();
      if (use_float && a->piecewise)
        run_system<float>(sys, points, CD::Piecewise_smoothing(), r);
      else if (use_float)
        run_system<float>(sys, points, CD::Sine_h_smoothing(), r);
      else if (a->piecewise)
        run_system<double>(sys, points, CD::Piecewise_smoothing(), r);
      else
        run_system<double>(sys, points, CD::Sine_h_smoothing(), r);
    }
    if (const std::size_t bad = r.status["undefined"])
      throw CMGeom::Invalid_input(a->input + ": " + std::to_string(bad) + " of " + std::to_string(points.size()) +
                                  " vertices lie outside the cage" + (single ? " " + desc.cages[0].rest_source : "s") +
                                  ", where harmonic coordinates are undefined");
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
      j["joined_vertices"] = r.joined;
      j["outside_vertices"] = r.outside;
    }
    j["setup_seconds"] = r.setup_seconds;
    j["bind_seconds"] = r.bind_seconds;
    j["deform_seconds"] = r.deform_seconds;
    j["weights_bytes"] = r.weights_bytes;
    json s;
    for (const auto& [k, n] : r.status) s[k] = n;
    j["vertex_status"] = s;
    if (a->as_json) {
      cmgeom_cli::print_json(j);
    } else {
      std::cout << "deformed " << points.size() << " vertices with " << desc.cages.size() << " cage"
                << (single ? "" : "s") << " (" << coordinates << ", " << cage_vertices
                << " cage vertices): bind " << r.bind_seconds << " s, deform " << r.deform_seconds
                << " s, weights " << r.weights_bytes << " bytes -> " << a->output << "\n";
    }
    return 0;
  };
}
