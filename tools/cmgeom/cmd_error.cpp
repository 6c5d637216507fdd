// cmgeom error <reference> <approximation> [--samples N] [--seed S] [--threads T] [--field out.ply]
//              [--field-on reference|approximation] [--json]
// Metro-style geometric error (Metrics/approximation_error.h): symmetric Hausdorff, mean and RMS
// as fractions of the reference's bounding-box diagonal, plus texture deviation when both meshes
// have texture coordinates. --field writes the per-vertex distance (absolute units) as a PLY with
// a "quality" vertex property (or one value per line for .txt), ready for `cmgeom render --field`.
#include "cli_common.h"

#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Metrics/soup_metrics.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>

namespace {

std::string shortest(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  for (int p = 1; p <= 17; ++p) {  // shortest form that reads back to the same double
    char b2[40];
    std::snprintf(b2, sizeof b2, "%.*g", p, v);
    if (std::strtod(b2, nullptr) == v) return b2;
  }
  return buf;
}

// Positions and polygons of `soup` with the per-vertex field (file vertex order).
void write_field(const std::string& path, const CMGeom::Polygon_soup& soup, const std::vector<double>& field) {
  std::ostringstream out;
  if (CMGeom::IO::extension(path) == ".txt") {
    out << "# per-vertex distance to the other mesh, one value per vertex in file order\n";
    for (double d : field) out << shortest(d) << "\n";
  } else if (CMGeom::IO::extension(path) == ".ply") {
    out << "ply\nformat ascii 1.0\ncomment per-vertex distance to the other mesh in 'quality'\n"
        << "element vertex " << soup.positions.size() << "\nproperty double x\nproperty double y\n"
        << "property double z\nproperty double quality\nelement face " << soup.number_of_faces()
        << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (std::size_t i = 0; i < soup.positions.size(); ++i) {
      const auto& p = soup.positions[i];
      out << shortest(p[0]) << " " << shortest(p[1]) << " " << shortest(p[2]) << " " << shortest(field[i]) << "\n";
    }
    for (std::size_t f = 0; f < soup.number_of_faces(); ++f) {
      out << soup.face_size(f);
      for (std::uint32_t c = soup.face_start[f]; c < soup.face_start[f + 1]; ++c) out << " " << soup.corner_vertex[c];
      out << "\n";
    }
  } else {
    throw CMGeom::IO_error(path, "unsupported field file extension (use .ply or .txt)");
  }
  CMGeom::IO::write_file_atomically(path, out.str());
}

nlohmann::ordered_json one_sided(const CMGeom::Metrics::One_sided_error& e) {
  nlohmann::ordered_json j;
  j["max"] = e.max;
  j["mean"] = e.mean;
  j["rms"] = e.rms;
  j["samples"] = e.samples;
  j["vertex_samples"] = e.vertex_samples;
  j["edge_samples"] = e.edge_samples;
  j["face_samples"] = e.face_samples;
  return j;
}

}  // namespace

CMGEOM_CLI_COMMAND(error, "Metro-style geometric error (Hausdorff, mean, RMS) between two meshes") {
  auto reference = std::make_shared<std::string>();
  auto approximation = std::make_shared<std::string>();
  auto field = std::make_shared<std::string>();
  auto field_on = std::make_shared<std::string>("approximation");
  auto samples = std::make_shared<std::size_t>(0);
  auto seed = std::make_shared<std::uint64_t>(CMGeom::Metrics::Error_options().seed);
  auto threads = std::make_shared<int>(0);
  auto json = std::make_shared<bool>(false);
  app.add_option("reference", *reference, "Reference (original) mesh")->required();
  app.add_option("approximation", *approximation, "Approximating mesh")->required();
  app.add_option("--samples", *samples, "Samples per direction (default 10 x max faces)");
  app.add_option("--seed", *seed, "Seed of the face sampling");
  app.add_option("--threads", *threads, "Worker threads (0 = all cores; results do not depend on it)");
  app.add_option("--field", *field, "Write the per-vertex distance to this .ply (quality property) or .txt");
  app.add_option("--field-on", *field_on, "Mesh that carries the field")
      ->check(CLI::IsMember({"reference", "approximation"}));
  app.add_flag("--json", *json, "Print a JSON object instead of text");
  return [=]() -> int {
    // The measure is defined on any set of triangles: the files are measured as they are
    // (polygon soups), without the manifold repair a halfedge mesh would need.
    if (!field->empty()) {
      const std::string ext = CMGeom::IO::extension(*field);
      if (ext != ".ply" && ext != ".txt")
        throw CMGeom::IO_error(*field, "unsupported field file extension (use .ply or .txt)");
    }
    const CMGeom::Polygon_soup ref = cmgeom_cli::read_polygon_soup_with_progress(*reference);
    const CMGeom::Polygon_soup app_mesh = cmgeom_cli::read_polygon_soup_with_progress(*approximation);
    for (const auto* s : {&ref, &app_mesh}) cmgeom_cli::print_warnings("error", s->warnings);
    CMGeom::Metrics::Error_options o;
    o.samples = *samples;
    o.seed = *seed;
    o.threads = *threads;
    o.vertex_field = !field->empty();
    // The measure has no hook: its stage reports its end only.
    auto stage = std::make_unique<cmgeom_cli::Progress>("measure distances");
    const double t0 = cmgeom_cli::now_seconds();
    const auto e = CMGeom::Metrics::approximation_error(ref, app_mesh, o);
    const double t1 = cmgeom_cli::now_seconds();
    stage->set_total(double(e.samples), "samples");
    stage.reset();
    const bool textured = ref.has_uvs() && app_mesh.has_uvs();
    CMGeom::Metrics::Texture_deviation td;
    if (textured) td = CMGeom::Metrics::texture_deviation(ref, app_mesh, o);
    if (!field->empty()) {
      const bool on_ref = *field_on == "reference";
      write_field(*field, on_ref ? ref : app_mesh, on_ref ? e.reference_vertex_error : e.approximation_vertex_error);
    }
    nlohmann::ordered_json j;
    j["reference"] = *reference;
    j["approximation"] = *approximation;
    j["hausdorff"] = e.hausdorff;
    j["mean"] = e.mean;
    j["rms"] = e.rms;
    j["diagonal"] = e.diagonal;
    j["samples"] = e.samples;
    j["seed"] = *seed;
    j["absolute"] = {
        {"hausdorff", e.hausdorff * e.diagonal}, {"mean", e.mean * e.diagonal}, {"rms", e.rms * e.diagonal}};
    j["reference_to_approximation"] = one_sided(e.reference_to_approximation);
    j["approximation_to_reference"] = one_sided(e.approximation_to_reference);
    if (textured) {
      j["texture_deviation"] = td.deviation;
      j["texture_deviation_absolute"] = td.absolute;
      j["texture_samples_matched"] = td.matched_samples;
      j["texture_samples"] = td.samples;
    }
    if (!field->empty()) j["field"] = *field;
    j["seconds"] = t1 - t0;
    if (*json) {
      cmgeom_cli::print_json(j);
      return 0;
    }
    char buf[512];
    std::cout << "reference      " << *reference << " (" << ref.number_of_faces() << " faces)\n"
              << "approximation  " << *approximation << " (" << app_mesh.number_of_faces() << " faces)\n";
    std::snprintf(buf, sizeof buf,
                  "samples        %zu (%zu on the reference, %zu on the approximation)\n"
                  "diagonal       %.6g\n"
                  "hausdorff      %.6g of the diagonal (%.4f %%, %.6g absolute)\n"
                  "mean           %.6g of the diagonal (%.4f %%, %.6g absolute)\n"
                  "rms            %.6g of the diagonal (%.4f %%, %.6g absolute)\n"
                  "one-sided max  reference->approximation %.6g, approximation->reference %.6g (absolute)\n",
                  e.samples, e.reference_to_approximation.samples, e.approximation_to_reference.samples, e.diagonal,
                  e.hausdorff, 100 * e.hausdorff, e.hausdorff * e.diagonal, e.mean, 100 * e.mean, e.mean * e.diagonal,
                  e.rms, 100 * e.rms, e.rms * e.diagonal, e.reference_to_approximation.max,
                  e.approximation_to_reference.max);
    std::cout << buf;
    if (textured) {
      std::snprintf(buf, sizeof buf,
                    "texture dev.   %.6g of the diagonal (%.4f %%, %.6g absolute; %zu of %zu samples matched)\n",
                    td.deviation, 100 * td.deviation, td.absolute, td.matched_samples, td.samples);
      std::cout << buf;
    }
    std::snprintf(buf, sizeof buf, "time           %.3f s\n", t1 - t0);
    std::cout << buf;
    if (!field->empty()) std::cout << "field          " << *field << " (on the " << *field_on << ")\n";
    return 0;
  };
}
