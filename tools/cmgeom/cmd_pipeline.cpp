// cmgeom pipeline [--model <mesh> [--texture <image>]] [--cages <system.json>] -o <dir>: the whole framework of the
// thesis on one model, as the README's main job. Each stage runs the corresponding sub-command
// in-process (so it gets exactly the validation, atomic output and JSON report of the command a
// user would type), prints its progress on stderr (unless --quiet; the stages' own progress
// lines appear under it), and the run ends with report.md and
// report.html (the same content; the HTML embeds the pictures) listing every command, number
// and picture. A failing stage stops the run with a one-line message; the outputs of the
// stages that finished stay in place and the report says where the run stopped.
#include "cli_common.h"
#include "pipeline_report.h"

#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <CGAL/bounding_box.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using cmgeom_cli::Report;

// Where the bundled default model is: next to an installed binary (share/CMGeom/data), or in
// the source tree the binary was built from.
std::string default_model() {
  std::vector<fs::path> candidates;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share/CMGeom/data/spot/spot.obj");
#ifdef CMGEOM_SOURCE_DATA_DIR
  candidates.push_back(fs::path(CMGEOM_SOURCE_DATA_DIR) / "spot/spot.obj");
#endif
  for (const auto& c : candidates)
    if (fs::exists(c)) return c.string();
  throw std::runtime_error("the bundled model data/spot/spot.obj was not found; give one with --model");
}

struct Stage_failed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string quoted(const std::string& s) {
  if (s.find_first_of(" \t'\"$\\;&|") == std::string::npos && !s.empty()) return s;
  std::string q = "'";
  for (char c : s) q += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

class Pipeline {
public:
  Pipeline(fs::path out, int stages) : out_(std::move(out)), stages_(stages) {}

  // Runs one sub-command; returns its JSON output when it printed one. The command line
  // recorded in the report uses paths relative to the output directory.
  json run(const std::vector<std::string>& args) {
    // Outputs are shown relative to the output directory, where the report is.
    const std::string prefix = out_.string() + "/";
    std::string line = "cmgeom";
    for (const auto& a : args)
      line += " " + quoted(a.compare(0, prefix.size(), prefix) == 0 ? a.substr(prefix.size()) : a);
    commands_.push_back(line);
    const auto r = cmgeom_cli::run_captured(args);
    if (r.exit_code != 0)
      throw Stage_failed("'" + line +
                         "' failed: " + (r.error.empty() ? "exit code " + std::to_string(r.exit_code) : r.error));
    if (r.output.empty() || r.output.front() != '{') return json();
    try {
      return json::parse(r.output);
    } catch (const json::parse_error&) {
      return json();
    }
  }

  std::string path(const std::string& name) const { return (out_ / name).string(); }

  void begin(const std::string& title) {
    ++current_;
    title_ = title;
    commands_.clear();
    start_ = cmgeom_cli::now_seconds();
    if (!cmgeom_cli::Progress::quiet())
      std::cerr << "[" << current_ << "/" << stages_ << "] " << title << " ..." << std::endl;
  }
  double end() {
    const double s = cmgeom_cli::now_seconds() - start_;
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.2f", s);
    if (!cmgeom_cli::Progress::quiet())
      std::cerr << "[" << current_ << "/" << stages_ << "] " << title_ << ": done in " << buf << " s" << std::endl;
    return s;
  }
  const std::vector<std::string>& commands() const { return commands_; }
  const std::string& title() const { return title_; }

private:
  fs::path out_;
  int stages_, current_ = 0;
  std::string title_;
  double start_ = 0;
  std::vector<std::string> commands_;
};

std::string fmt(double v, int digits = 3) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}
std::string general(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}
std::string pct(const json& v) { return v.is_number() ? fmt(100.0 * v.get<double>(), 4) + " %" : "-"; }
std::string ms(const json& v) { return v.is_number() ? fmt(1000.0 * v.get<double>(), 2) : "-"; }
std::string num(const json& v) {
  if (v.is_number_integer() || v.is_number_unsigned()) return std::to_string(v.get<long long>());
  if (v.is_number()) return fmt(v.get<double>());
  return "-";
}

// The default deformation of the pipeline: a smooth bend of the rest cages. A point at signed
// position t in [-1, 1] along axis `along` (from the centre of `box`, clamped) is rotated by
// angle * t in the plane of `along` and `across`, about the centre, which curves the model like
// a U (both ends move the same way along `across`). The map depends only on the position, so
// vertices shared by neighbouring grid cages stay shared. When `mixed` is set, the odd-numbered
// cages switch to Green coordinates (the heterogeneous *Cages systems of thesis §5.3.3).
json bent_cage_system(const json& rest, const CGAL::Bbox_3& box, int along, int across, double angle_degrees,
                      bool mixed) {
  double c[3];
  for (int i = 0; i < 3; ++i) c[i] = 0.5 * (box.min(i) + box.max(i));
  const double half = 0.5 * (box.max(along) - box.min(along));
  const double radians_per_t = angle_degrees * std::acos(-1.0) / 180.0;
  json system = rest;
  int index = 0;
  for (auto& cage : system["cages"]) {
    json deformed = json::array();
    for (const auto& v : cage["rest"]["vertices"]) {
      double p[3] = {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
      const double t = std::max(-1.0, std::min(1.0, (p[along] - c[along]) / half));
      const double phi = radians_per_t * t;
      const double da = p[along] - c[along], db = p[across] - c[across];
      p[along] = c[along] + std::cos(phi) * da - std::sin(phi) * db;
      p[across] = c[across] + std::sin(phi) * da + std::cos(phi) * db;
      deformed.push_back({p[0], p[1], p[2]});
    }
    cage["deformed"] = deformed;
    if (mixed && index % 2 == 1) cage["coordinates"] = "green";
    ++index;
  }
  return system;
}

}  // namespace

CMGEOM_CLI_COMMAND(pipeline,
                   "Run the whole framework on a model (default: the bundled Spot) and write report.md/.html") {
  struct Options {
    std::string model, output, cages, size = "768x768", texture;
    double ratio = 0.1, cm_ratio = 0.05;
    int level = 2;
    bool allow_degenerate = false;
  };
  auto o = std::make_shared<Options>();
  app.add_option(
      "--model", o->model,
      "Input mesh, textured or not (default: the bundled Spot model); non-manifold or inconsistently oriented input is "
      "repaired while reading, as 'cmgeom simplify' does");
  app.add_option("-o,--output", o->output, "Output directory (created; existing files of the same name are replaced)")
      ->required();
  app.add_option("--ratio", o->ratio, "Simplification target as a fraction of the input faces (default 0.1)")
      ->check(CLI::Range(1e-6, 1.0));
  app.add_option("--cm-ratio", o->cm_ratio, "Compact Model base faces as a fraction of the input (default 0.05)")
      ->check(CLI::Range(1e-6, 1.0));
  app.add_option("--level", o->level, "Regular reconstruction level of the Compact Model (default 2)")
      ->check(CLI::Range(0, 6));
  app.add_option("--cages", o->cages,
                 "Cage-system JSON file (see 'cmgeom deform') for the deformation stages (default: a grid of two "
                 "box cages around the model, mean value and Green coordinates, bent by 30 degrees)");
  app.add_option("--size", o->size, "Picture size WxH (default 768x768)");
  app.add_option("--texture", o->texture, "Diffuse texture for a model whose file names none (e.g. spot.obj)");
  cmgeom_cli::add_allow_degenerate_option(app, o->allow_degenerate);

  return [o]() -> int {
    const std::string model = o->model.empty() ? default_model() : o->model;
    if (!o->cages.empty() && !fs::is_regular_file(o->cages))
      throw CMGeom::IO_error(o->cages, "no such cage-system file");
    cmgeom_cli::parse_picture_size(o->size);  // checked before anything is written
    // Read once here (before anything is created) for the facts the stages' parameters depend on.
    CMGeom::Textured_mesh mesh;
    CMGeom::IO::Read_options read_options;
    read_options.repair = true;  // as the stages read it (each is given --repair below)
    read_options.allow_degenerate_faces = o->allow_degenerate;
    cmgeom_cli::read_mesh_with_progress(model, mesh, read_options);
    // a texture is never guessed (as simplify, lod and cm build refuse it), before anything is written
    cmgeom_cli::apply_texture_option(mesh, model, o->texture);
    cmgeom_cli::refuse_unnamed_texture(mesh, model, "to run the pipeline on it textured", false);
    // the stages that build a mesh from the model read it as the read above does
    const auto reading_model = [&](std::vector<std::string> cmd) {
      if (o->allow_degenerate) cmd.push_back("--allow-degenerate");
      cmd.push_back("--repair");
      return cmd;
    };
    // and those that read its texture get the one given
    const auto texturing_model = [&](std::vector<std::string> cmd) {
      if (!o->texture.empty()) cmd.insert(cmd.end(), {"--texture", o->texture});
      return cmd;
    };
    const fs::path out = o->output;
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec || !fs::is_directory(out))
      throw CMGeom::IO_error(out.string(), "cannot create the output directory: " + ec.message());
    const auto box = CGAL::bounding_box(mesh.mesh().points().begin(), mesh.mesh().points().end());
    const double diagonal = std::sqrt(CGAL::squared_distance(box.min(), box.max()));
    const bool textured = mesh.has_uvs();
    // Box axes from the shortest to the longest. The default cages are split across the longest
    // and bent in the plane of the two longest; the deformation pictures look along the shortest.
    int axis[3] = {0, 1, 2};
    std::stable_sort(axis, axis + 3, [&](int a, int b) {
      return box.max_coord(a) - box.min_coord(a) < box.max_coord(b) - box.min_coord(b);
    });
    const std::string view = axis[0] == 0 ? "right" : axis[0] == 1 ? "top" : "front";

    Report report("CMGeom pipeline on " + fs::path(model).filename().string());
    const int stages = 6;
    Pipeline p(out, stages);
    auto section = [&](double seconds) -> Report::Section& {
      auto& s = report.add_section(p.title(), seconds);
      s.commands = p.commands();
      return s;
    };

    try {
      p.begin("Input model");
      const json info = p.run({"info", model, "--json"});
      {
        std::vector<std::string> args = {
            "render", model,   "-o",        p.path("input.png"),
            "--size", o->size, "--caption", textured ? "input: chart boundaries in red" : "input"};
        if (textured) args.insert(args.end(), {"--charts", "--atlas", p.path("input_atlas.png")});
        p.run(texturing_model(args));
      }
      if (textured) p.run({"render", model, "-o", p.path("input_shaded.png"), "--size", o->size, "--no-texture"});
      {
        auto& s = section(p.end());
        s.table = {{"vertices", "faces", "charts", "genus", "components", "closed"},
                   {{num(info["referenced_vertices"]), num(info["faces"]), num(info["charts"]), num(info["genus"]),
                     num(info["components"]), info["closed"].dump()}}};
        s.pictures.push_back({"input.png", textured ? "Input model, chart boundaries in red" : "Input model"});
        if (textured) {
          s.pictures.push_back({"input_shaded.png", "Input geometry"});
          s.pictures.push_back({"input_atlas.png", "Input texture atlas with its UV layout"});
        }
      }

      p.begin(textured
                  ? "Simplification (thesis chapter 3): new atlas (plain and area-weighted quadrics) and the thesis' "
                    "chart-preserving method"
                  : "Simplification (thesis chapter 3): area-weighted quadric vs plain Garland-Heckbert");
      {
        Report::Table table{{"run", "faces in", "faces out", "charts in", "charts out", "seconds", "Hausdorff (% diag)",
                             "RMS (% diag)", "image RMSE (26 views)"},
                            {}};
        std::vector<Report::Picture> pictures;
        struct Run {
          std::string tag, caption;
          std::vector<std::string> args;
        };
        std::vector<Run> runs = {{"weighted", "weighted quadric", {"--policy", "weighted"}},
                                 {"plain", "plain quadric", {"--policy", "plain"}}};
        if (textured)  // the thesis' own method: weighted quadrics, charts kept, index texture
          runs.push_back({"charts_kept",
                          "weighted quadric, charts kept (thesis §3.5)",
                          {"--policy", "weighted", "--keep-charts"}});
        for (const Run& run : runs) {
          const std::string mesh_out = p.path("simplified_" + run.tag + ".obj");
          std::vector<std::string> cmd = {"simplify", model, "-o", mesh_out, "--ratio", general(o->ratio), "--json"};
          cmd.insert(cmd.end(), run.args.begin(), run.args.end());
          const json js = p.run(texturing_model(reading_model(cmd)));
          const json je = p.run({"error", model, mesh_out, "--json"});
          const json jc = p.run(texturing_model(
              {"compare", model, mesh_out, "--json", "-o", p.path("compare_" + run.tag + ".png"), "--size", "256"}));
          std::vector<std::string> render = {
              "render",      mesh_out,    "-o",       p.path("simplified_" + run.tag + ".png"), "--size", o->size,
              "--wireframe", "--caption", run.caption};
          if (textured)  // chart boundaries in red, and the new atlas (thesis Fig. 3.8-3.13)
            render.insert(render.end(), {"--charts", "--atlas", p.path("simplified_" + run.tag + "_atlas.png")});
          p.run(render);
          table.rows.push_back({run.caption, num(js["faces_in"]), num(js["faces_out"]),
                                num(js.value("charts_in", json())), num(js.value("charts_out", json())),
                                num(js["seconds"]), pct(je["hausdorff"]), pct(je["rms"]), num(jc["rmse"])});
          pictures.push_back({"simplified_" + run.tag + ".png", run.caption + ", " + num(js["faces_out"]) + " faces" +
                                                                    (textured ? ", chart boundaries in red" : "")});
          if (textured) pictures.push_back({"simplified_" + run.tag + "_atlas.png", run.caption + ": texture atlas"});
          pictures.push_back({"compare_" + run.tag + ".png",
                              run.caption + ": reference / simplified / difference over 6 of the 26 views"});
        }
        auto& s = section(p.end());
        s.table = table;
        s.pictures = pictures;
      }

      p.begin("Compact Model (thesis chapter 4): build, regular and adaptive reconstruction");
      {
        const json jb = p.run(texturing_model(reading_model(
            {"cm", "build", model, "-o", p.path("model.cm"), "--ratio", general(o->cm_ratio), "--json"})));
        Report::Table table{
            {"reconstruction", "vertices", "faces", "seconds (library call)", "Hausdorff (% diag)", "RMS (% diag)"},
            {}};
        std::vector<Report::Picture> pictures;
        struct Variant {
          std::string name, caption;
          std::vector<std::string> args;
        };
        const std::vector<Variant> variants = {
            {"regular", "regular, level " + std::to_string(o->level), {"--level", std::to_string(o->level)}},
            {"adaptive", "adaptive, edges below 1 % of the diagonal", {"--edge-length", general(0.01 * diagonal)}}};
        for (const auto& v : variants) {
          const std::string mesh_out = p.path("cm_" + v.name + ".ply");
          std::vector<std::string> args = {"cm", "reconstruct", p.path("model.cm"), "-o", mesh_out, "--json"};
          args.insert(args.end(), v.args.begin(), v.args.end());
          const json jr = p.run(args);
          const std::string field = p.path("cm_" + v.name + "_error.txt");
          const json je = p.run({"error", model, mesh_out, "--json", "--field", field, "--field-on", "approximation"});
          p.run({"render", mesh_out, "-o", p.path("cm_" + v.name + ".png"), "--size", o->size, "--wireframe",
                 "--caption", "CM " + v.caption});
          p.run({"render", mesh_out, "-o", p.path("cm_" + v.name + "_error.png"), "--size", o->size, "--field", field,
                 "--label", "distance to the input"});
          table.rows.push_back({v.caption, num(jr["vertices"]), num(jr["faces"]), num(jr["reconstruct_seconds"]),
                                pct(je["hausdorff"]), pct(je["rms"])});
          pictures.push_back({"cm_" + v.name + ".png", "CM reconstruction, " + v.caption});
          pictures.push_back({"cm_" + v.name + "_error.png", "distance to the input, " + v.caption});
        }
        auto& s = section(p.end());
        s.text = "Base: " + num(jb["base_vertices"]) + " vertices, " + num(jb["base_faces"]) + " faces, " +
                 num(jb["sharp_edges"]) + " sharp edges, " + num(jb["cone_vertices"]) + " cone vertices; " +
                 num(jb["bytes"]) + " bytes; built in " + num(jb["seconds"]) + " s." +
                 (jb.value("textured", false)
                      ? " A textured CM (thesis §4.5.4): the base was simplified under the chart constraints of "
                        "chapter 3 (" +
                            num(jb["charts_out"]) +
                            " charts kept) and carries per-corner texture "
                            "coordinates" +
                            std::string(jb.contains("atlas") ? " and a new atlas, model.png" : "") +
                            "; the deformable CM below wears the texture."
                      : std::string());
        s.table = table;
        s.pictures = pictures;
      }

      p.begin("*Cages deformation (thesis chapter 5): cages, coordinates, influence map");
      std::string system = o->cages;
      {
        std::string text;
        Report::Table table{
            {"cage system", "cages", "coordinates", "set-up ms", "bind ms", "deform ms", "weights (bytes)"}, {}};
        std::vector<Report::Picture> pictures;
        struct System {
          std::string name, file;
        };
        std::vector<System> systems;
        p.run(texturing_model({"render", model, "-o", p.path("rest_side.png"), "--size", o->size, "--view", view,
                               "--caption", "rest pose"}));
        pictures.push_back({"rest_side.png", "the input in its rest pose, seen along its shortest axis"});
        if (system.empty()) {
          // A grid of two box cages split across the longest axis, bent 30 degrees; once with
          // mean value coordinates in both cages, once with Green coordinates in the second.
          std::string grid;
          for (int i = 0; i < 3; ++i) grid += std::string(i ? "," : "") + (i == axis[2] ? "2" : "1");
          p.run(reading_model({"deform", model, "--grid", grid, "--write-cages", p.path("rest_cages.json")}));
          std::ifstream in(p.path("rest_cages.json"));
          const json rest = json::parse(in);
          for (const bool mixed : {false, true}) {
            const std::string name = mixed ? "cages.json" : "cages_mean_value.json";
            CMGeom::IO::write_file_atomically(
                p.path(name), bent_cage_system(rest, box.bbox(), axis[2], axis[1], 30.0, mixed).dump(1) + "\n");
            systems.push_back(
                {mixed ? "grid " + grid + ", mean value + Green" : "grid " + grid + ", mean value", p.path(name)});
          }
          system = p.path("cages.json");
          text =
              "Cages: a grid of box cages around the model (rest_cages.json, written by the first command), "
              "deformed by the pipeline's default bend: rotation about the shortest box axis by 30 degrees "
              "times the position along the longest axis (cages_mean_value.json, cages.json).";
        } else {
          systems.push_back({fs::path(system).filename().string(), system});
        }
        for (std::size_t i = 0; i < systems.size(); ++i) {
          const bool main_system = systems[i].file == system;
          const std::string stem = main_system ? "deformed" : "deformed_mean_value";
          const json jd = p.run(
              reading_model({"deform", model, "--cages", systems[i].file, "-o", p.path(stem + ".obj"), "--json"}));
          p.run({"render", p.path(stem + ".obj"), "-o", p.path(stem + ".png"), "--size", o->size, "--view", view,
                 "--caption", "*Cages: " + systems[i].name});
          std::string coordinates =
              jd["coordinates"].is_string() ? jd["coordinates"].get<std::string>() : jd["coordinates"].dump();
          table.rows.push_back({systems[i].name, num(jd["cages"]), coordinates, ms(jd["setup_seconds"]),
                                ms(jd["bind_seconds"]), ms(jd["deform_seconds"]), num(jd["weights_bytes"])});
          pictures.push_back({stem + ".png", "deformed by " + systems[i].name});
        }
        const json ji =
            p.run({"influence", model, "--cages", system, "-o", p.path("influence.png"), "--size", o->size, "--json"});
        pictures.push_back({"influence.png",
                            "influence map d (thesis §5.3.3): 1 where a cage's own transformation acts alone, 0 on the "
                            "cage borders where the join cage takes over"});
        auto& s = section(p.end());
        s.text = text + (text.empty() ? "" : " ") + "Influence: " + num(ji["joined_vertices"]) + " of " +
                 num(ji["vertices"]) +
                 " vertices are blended with the join cage (d < 1), mean d = " + num(ji["mean_influence"]) + ".";
        s.table = table;
        s.pictures = pictures;
      }

      p.begin("Deformable Compact Model (thesis chapter 6): the CM deformed by the cages and by an affine map");
      {
        Report::Table table{{"deformer", "base vertices", "faces", "deform ms", "reconstruct ms",
                             "Hausdorff to the deformed mesh (% diag)", "RMS (% diag)"},
                            {}};
        std::vector<Report::Picture> pictures;
        const json jc = p.run({"cm", "deform", p.path("model.cm"), "--cages", system, "-o", p.path("dcm_cages.obj"),
                               "--level", std::to_string(o->level), "--json"});
        const json je = p.run({"error", p.path("deformed.obj"), p.path("dcm_cages.obj"), "--json"});
        p.run({"render", p.path("dcm_cages.obj"), "-o", p.path("dcm_cages.png"), "--size", o->size, "--view", view,
               "--wireframe", "--caption", "deformable CM, cages"});
        table.rows.push_back({"cages (" + fs::path(system).filename().string() + ")", num(jc["base_vertices"]),
                              num(jc["faces"]), ms(jc["deform_seconds"]), ms(jc["reconstruct_seconds"]),
                              pct(je["hausdorff"]), pct(je["rms"])});
        pictures.push_back({"dcm_cages.png", "deformable CM deformed by the cages, level " + std::to_string(o->level)});
        // The affine map: the shear x' = x + 0.3 z (y and z unchanged).
        const double shear = 0.3;
        const json ja =
            p.run({"cm", "deform", p.path("model.cm"), "--affine", "1,0," + general(shear) + ",0,0,1,0,0,0,0,1,0", "-o",
                   p.path("dcm_affine.obj"), "--level", std::to_string(o->level), "--json"});
        p.run({"render", p.path("dcm_affine.obj"), "-o", p.path("dcm_affine.png"), "--size", o->size, "--wireframe",
               "--caption", "deformable CM, affine shear"});
        table.rows.push_back({"affine shear x += " + general(shear) + " z", num(ja["base_vertices"]), num(ja["faces"]),
                              ms(ja["deform_seconds"]), ms(ja["reconstruct_seconds"]), "-", "-"});
        pictures.push_back({"dcm_affine.png", "deformable CM under the shear x += " + general(shear) + " z"});
        auto& s = section(p.end());
        s.text =
            "Only the CM base is deformed; the local surfaces follow through their local frames "
            "(thesis §6.3) and the reconstruction is compared with the full-resolution mesh deformed by "
            "the same cages.";
        s.table = table;
        s.pictures = pictures;
      }

      p.begin("Report");
      report.finish(out, "");
      p.end();
    } catch (const Stage_failed& e) {
      report.finish(out, "stopped at stage '" + p.title() + "': " + e.what());
      throw std::runtime_error("stage '" + p.title() + "' failed; outputs of the finished stages are in " +
                               out.string() + ": " + e.what());
    }
    if (!cmgeom_cli::Progress::quiet())
      std::cerr << "results: " << (out / "report.md").string() << ", " << (out / "report.html").string() << std::endl;
    return 0;
  };
}
