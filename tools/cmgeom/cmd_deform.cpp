// cmgeom deform <mesh> --cages <system.json> -o <out> [--json]: deforms a mesh with a cage
// (thesis chapter 5). The cage-system file is JSON:
//   {"cages": [{"rest": "rest.obj", "deformed": "deformed.obj",
//               "coordinates": "mean_value" | "green" | "harmonic",
//               "harmonic": {"resolution": 64, "interpolation": "trilinear" | "tricubic"}}]}
// Paths are relative to the JSON file. Cage polygons are fan-triangulated in file order; the
// deformed cage must have the same vertices (in the same order) as the rest cage and only its
// vertex positions are used, with the rest cage's triangles (so both poses share one split). With
// one cage the result is the plain coordinate deformation; the output keeps the input vertex
// order.
#include "cli_common.h"

#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <filesystem>
#include <fstream>
#include <iostream>

namespace {

namespace CD = CMGeom::Cage_deformation;
using json = nlohmann::ordered_json;

CD::Triangle_cage read_cage(const std::string& path) {
  const CMGeom::Polygon_soup soup = CMGeom::IO::read_polygon_soup(path);
  std::vector<std::vector<std::uint32_t>> faces;  // already fans in file order
  for (std::size_t f = 0; f < soup.number_of_faces(); ++f)
    faces.emplace_back(soup.corner_vertex.begin() + soup.face_start[f],
                       soup.corner_vertex.begin() + soup.face_start[f + 1]);
  return CD::make_triangle_cage(soup.positions, faces);
}

struct Cage_entry {
  std::string rest, deformed, coordinates = "mean_value";
  int resolution = 64;
  std::string interpolation = "tricubic";
};

Cage_entry parse_system(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw CMGeom::IO_error(path, "cannot open the cage-system file");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::parse_error& e) {
    throw CMGeom::IO_error(path, std::string("invalid JSON: ") + e.what());
  }
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  auto rel = [&](const json& v, const char* key) {
    if (!v.contains(key) || !v[key].is_string())
      throw CMGeom::IO_error(path, std::string("cage entry needs a string \"") + key + "\"");
    std::filesystem::path p = v[key].get<std::string>();
    return (p.is_absolute() ? p : dir / p).string();
  };
  if (!j.is_object() || !j.contains("cages") || !j["cages"].is_array() || j["cages"].empty())
    throw CMGeom::IO_error(path, "expected an object with a non-empty array \"cages\"");
  if (j["cages"].size() > 1)
    throw CMGeom::IO_error(path, "several cages need the *Cages join/smooth transformations, "
                                 "which this version does not implement; give one cage");
  const json& c = j["cages"][0];
  Cage_entry e;
  e.rest = rel(c, "rest");
  e.deformed = rel(c, "deformed");
  if (c.contains("coordinates")) {
    if (!c["coordinates"].is_string())
      throw CMGeom::IO_error(path, "\"coordinates\" must be a string");
    e.coordinates = c["coordinates"].get<std::string>();
  }
  if (e.coordinates != "mean_value" && e.coordinates != "green" && e.coordinates != "harmonic")
    throw CMGeom::IO_error(path, "unknown coordinates \"" + e.coordinates +
                                     "\" (expected mean_value, green or harmonic)");
  if (c.contains("harmonic")) {
    const json& h = c["harmonic"];
    if (h.contains("resolution")) {
      if (!h["resolution"].is_number_integer() || h["resolution"].get<int>() < 8 ||
          h["resolution"].get<int>() > 512)
        throw CMGeom::IO_error(path, "\"harmonic.resolution\" must be an integer in [8, 512]");
      e.resolution = h["resolution"].get<int>();
    }
    if (h.contains("interpolation")) {
      e.interpolation = h["interpolation"].is_string() ? h["interpolation"].get<std::string>() : "";
      if (e.interpolation != "trilinear" && e.interpolation != "tricubic")
        throw CMGeom::IO_error(path, "\"harmonic.interpolation\" must be trilinear or tricubic");
    }
  }
  return e;
}

struct Result {
  std::vector<CD::Vec3> positions;
  double bind_seconds = 0, deform_seconds = 0;
  std::size_t weights_bytes = 0, coordinates = 0;
  std::map<std::string, std::size_t> status;
};

template <class Weight, class Coords>
void run(const Coords& coords, const std::vector<CD::Vec3>& points,
         const std::vector<CD::Vec3>& deformed, CD::Weight_storage storage, Result& r) {
  CD::Binding_options opt;
  opt.storage = storage;
  double t0 = cmgeom_cli::now_seconds();
  CD::Cage_binding<Weight> b = CD::bind_points<Weight>(coords, points, opt);
  r.bind_seconds = cmgeom_cli::now_seconds() - t0;
  std::vector<CD::Vec3> basis;
  t0 = cmgeom_cli::now_seconds();
  coords.deformation_rule()(deformed, std::back_inserter(basis));
  b.deform(basis, r.positions);
  r.deform_seconds = cmgeom_cli::now_seconds() - t0;
  r.weights_bytes = b.weights_bytes();
  r.coordinates = b.number_of_coordinates();
  for (auto s : {CD::Coordinate_status::regular, CD::Coordinate_status::on_boundary,
                 CD::Coordinate_status::extended, CD::Coordinate_status::approximate,
                 CD::Coordinate_status::undefined})
    r.status[CD::to_string(s)] = b.count(s);
}

}  // namespace

CMGEOM_CLI_COMMAND(deform, "Deform a mesh with a cage (mean value, Green or harmonic coordinates)") {
  auto input = std::make_shared<std::string>();
  auto system = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto weights = std::make_shared<std::string>("double");
  auto storage = std::make_shared<std::string>("dense");
  auto as_json = std::make_shared<bool>(false);
  app.add_option("mesh", *input, "Mesh to deform (.obj, .off, .ply, .gltf, .glb)")->required();
  app.add_option("--cages", *system, "Cage-system JSON file")->required();
  app.add_option("-o,--output", *output, "Deformed mesh (same vertex order as the input)")->required();
  app.add_option("--weights", *weights, "Weight precision: double or float")
      ->check(CLI::IsMember({"double", "float"}));
  app.add_option("--storage", *storage, "Weight storage: dense or sparse")
      ->check(CLI::IsMember({"dense", "sparse"}));
  app.add_flag("--json", *as_json, "Print timings and counts as JSON");
  return [=]() -> int {
    const Cage_entry e = parse_system(*system);
    CD::Triangle_cage rest = read_cage(e.rest);
    const CD::Triangle_cage def = read_cage(e.deformed);
    if (def.vertices.size() != rest.vertices.size())
      throw CMGeom::IO_error(e.deformed, "the deformed cage has " + std::to_string(def.vertices.size()) +
                                             " vertices and the rest cage " + e.rest + " has " +
                                             std::to_string(rest.vertices.size()) +
                                             ": they must have the same vertices");
    // Only vertex positions are taken from the deformed cage: the triangles are the rest cage's
    // (same split for both poses), so a file that lists the faces differently is accepted.
    if (def.triangles != rest.triangles)
      std::cerr << "cmgeom deform: warning: " << e.deformed
                << ": faces differ from the rest cage's; the rest cage's triangles are used\n";
    const bool flipped = CD::validate_cage(rest, e.rest);
    std::vector<CD::Vec3> deformed = def.vertices;

    CMGeom::Textured_mesh tm;
    CMGeom::IO::read_mesh(*input, tm);
    auto& mesh = tm.mesh();
    std::vector<CD::Vec3> points;
    points.reserve(mesh.number_of_vertices());
    for (auto v : mesh.vertices()) {
      const auto& p = mesh.point(v);
      points.push_back({p.x(), p.y(), p.z()});
    }

    const auto st = *storage == "sparse" ? CD::Weight_storage::sparse : CD::Weight_storage::dense;
    const bool use_float = *weights == "float";
    Result r;
    double setup_seconds = 0;
    auto dispatch = [&](const auto& coords) {
      if (use_float)
        run<float>(coords, points, deformed, st, r);
      else
        run<double>(coords, points, deformed, st, r);
    };
    if (e.coordinates == "mean_value") {
      dispatch(CD::Mean_value_coordinates_3(rest));
    } else if (e.coordinates == "green") {
      dispatch(CD::Green_coordinates_3(rest));
    } else {
      const double t0 = cmgeom_cli::now_seconds();
      CD::Harmonic_options ho;
      ho.resolution = e.resolution;
      ho.interpolation = e.interpolation == "tricubic" ? CD::Harmonic_interpolation::tricubic
                                                       : CD::Harmonic_interpolation::trilinear;
      CD::Harmonic_coordinates_3 hc(rest, ho);
      setup_seconds = cmgeom_cli::now_seconds() - t0;
      dispatch(hc);
    }
    if (const std::size_t bad = r.status["undefined"])
      throw CMGeom::Invalid_input(*input + ": " + std::to_string(bad) + " of " +
                                  std::to_string(points.size()) +
                                  " vertices lie outside the cage " + e.rest +
                                  ", where harmonic coordinates are undefined");
    std::size_t i = 0;
    for (auto v : mesh.vertices()) {
      const CD::Vec3& p = r.positions[i++];
      mesh.point(v) = CMGeom::Point_3(p[0], p[1], p[2]);
    }
    CMGeom::IO::write_mesh(*output, tm);

    json j;
    j["input"] = *input;
    j["output"] = *output;
    j["coordinates"] = e.coordinates;
    j["vertices"] = points.size();
    j["cage_vertices"] = rest.vertices.size();
    j["cage_triangles"] = rest.triangles.size();
    j["cage_reoriented"] = flipped;
    j["coordinates_per_vertex"] = r.coordinates;
    j["weights"] = *weights;
    j["storage"] = *storage;
    if (e.coordinates == "harmonic") j["harmonic_solve_seconds"] = setup_seconds;
    j["bind_seconds"] = r.bind_seconds;
    j["deform_seconds"] = r.deform_seconds;
    j["weights_bytes"] = r.weights_bytes;
    json s;
    for (const auto& [k, n] : r.status) s[k] = n;
    j["vertex_status"] = s;
    if (*as_json) {
      cmgeom_cli::print_json(j);
    } else {
      std::cout << "deformed " << points.size() << " vertices with " << e.coordinates
                << " coordinates (" << rest.vertices.size() << " cage vertices): bind "
                << r.bind_seconds << " s, deform " << r.deform_seconds << " s, weights "
                << r.weights_bytes << " bytes -> " << *output << "\n";
    }
    return 0;
  };
}
