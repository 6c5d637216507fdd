// cmgeom lod <in> -o <out.glb|out.gltf> (--ratios r1,r2,... | --faces n1,n2,... | --max-errors e1,e2,...)
//           [--shared-texture [--no-overflow-charts] [--overflow-colour-tolerance T]]
//           [--policy plain|weighted] [--texture FILE] [--no-texture] [--quantize] [--no-error]
//           [--obj-prefix PREFIX] [--fit-rounds N] [--memory-points N] [--prune] [--no-repair] [--allow-degenerate]
//           [--json]
// A level-of-detail chain from one simplification run (Textured_simplification/level_of_detail.h):
// every level is a snapshot of the same collapse sequence, written as one glTF node per level
// (the finest in the scene, the others listed by its MSFT_lod extension, each node's error in its
// extras). A textured input gets an atlas per level, or with --shared-texture one atlas that every
// level addresses (with a strip of overflow charts for the parts of the input the coarsest level's
// atlas squashes, hides or shows in colours off by more than T, unless --no-overflow-charts). --obj-prefix also writes
// each level as PREFIX_<k>.obj (with its MTL and PNG).
#include "cli_common.h"
#include "collapse_progress.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification/level_of_detail.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;

template <class T>
std::vector<T> parse_list(const std::string& text, const char* option) {
  std::vector<T> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::istringstream is(item);
    T v;
    if (!(is >> v) || !(is >> std::ws).eof())
      throw CMGeom::Invalid_input(std::string(option) + ": '" + item + "' is not a number");
    out.push_back(v);
  }
  if (out.empty()) throw CMGeom::Invalid_input(std::string(option) + ": no value");
  return out;
}

}  // namespace

CMGEOM_CLI_COMMAND(lod, "Write a level-of-detail chain (glTF/GLB, one node per level) from one simplification run") {
  struct Options {
    std::string input, output, ratios, faces, max_errors, policy = "plain", texture, obj_prefix;
    bool shared_texture = false, no_overflow_charts = false, no_texture = false, no_error = false, json = false,
         no_repair = false, allow_degenerate = false, drop_repeated = false, prune = false;
    int fit_rounds = 3;
    double fit_min_points = TS::Surface_fit_options().min_points_per_face;
    std::size_t memory_points = 0;
    double overflow_colour_tolerance =
        CMGeom::Textured_simplification::Level_of_detail_options().overflow_colour_tolerance;
    CMGeom::IO::Gltf_options gltf;
  };
  auto o = std::make_shared<Options>();
  app.add_option("input", o->input, "Input mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  app.add_option("-o,--output", o->output, "Output scene (.glb or .gltf)")->required();
  auto* ratios =
      app.add_option("--ratios", o->ratios,
                     "Levels as fractions of the input's faces, decreasing, comma-separated (e.g. 1,0.25,0.05,0.01)");
  auto* faces = app.add_option("--faces", o->faces, "Levels as face counts, decreasing, comma-separated");
  auto* errors =
      app.add_option("--max-errors", o->max_errors,
                     "Levels by error bound instead: symmetric Hausdorff distances as fractions of the bounding-box "
                     "diagonal, increasing, comma-separated (e.g. 0,0.002,0.01,0.05; 0 is the input); each level "
                     "is guaranteed within its bound (as simplify's --max-error: the run goes on from one bound to "
                     "the next until no collapse within it is left; levels not fitted; not with --prune)");
  ratios->excludes(faces);
  faces->excludes(ratios);
  errors->excludes(ratios);
  errors->excludes(faces);
  ratios->excludes(errors);
  faces->excludes(errors);
  app.add_flag("--shared-texture", o->shared_texture,
               "Textured input: one atlas (made for the coarsest level) that every level addresses");
  app.add_flag("--no-overflow-charts", o->no_overflow_charts,
               "With --shared-texture: parts of the input that the shared atlas squashes or hides keep their place "
               "in it instead of getting charts of their own in a strip under the atlas");
  auto* colour_tolerance =
      app.add_option("--overflow-colour-tolerance", o->overflow_colour_tolerance,
                     "With --shared-texture: the input faces whose colours from the shared atlas are off from their "
                     "own, and the input under a finer level's face whose colours from it are off from a bake's, by "
                     "more than this (RMS, colours in [0, 1]) also get charts of their own, "
                     "and faces take them only where they show nearer colours there; 0: geometric tests alone")
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
  app.add_option("--policy", o->policy, "Cost: plain (Garland-Heckbert, the default) or weighted (thesis §3.4.2)")
      ->check(CLI::IsMember({"weighted", "plain"}));
  app.add_option("--texture", o->texture, "Diffuse texture for an input whose file names none (e.g. spot.obj)");
  app.add_flag("--no-texture", o->no_texture, "Geometry only even for a textured input");
  app.add_option(
         "--fit-rounds", o->fit_rounds,
         "Rounds of the fit of each level's vertices to the input's points (as simplify's --fit-rounds: a "
         "level is the mesh simplify gives for its face count, and a level with fewer input points per face than "
         "--fit-min-points is not fitted); 0 = none. Default 3")
      ->check(CLI::Range(0, 100));
  cmgeom_cli::add_fit_min_points_option(app, o->fit_min_points);
  cmgeom_cli::add_memory_points_option(app, o->memory_points);
  app.add_flag("--no-error", o->no_error, "Do not measure the levels' errors (no 'error' in the nodes' extras)");
  app.add_option("--obj-prefix", o->obj_prefix, "Also write every level as PREFIX_<k>.obj (+ MTL + PNG)");
  cmgeom_cli::add_repair_by_default_options(app, o->no_repair);
  cmgeom_cli::add_allow_degenerate_option(app, o->allow_degenerate);
  cmgeom_cli::add_drop_repeated_option(app, o->drop_repeated);
  app.add_flag("--prune", o->prune,
               "Remove whole connected components (small parts, debris) when that costs less than the next "
               "collapse, never below the smallest level; gives their faces to the rest");
  app.add_flag("--json", o->json, "Print a JSON report on stdout");
  cmgeom_cli::add_gltf_options(app, o->gltf);

  return [o, ratios, faces, errors, colour_tolerance]() -> int {
    if (ratios->count() == 0 && faces->count() == 0 && errors->count() == 0)
      throw CMGeom::Invalid_input("one of --ratios, --faces or --max-errors is required");
    const std::string ext = CMGeom::IO::extension(o->output);
    if (ext != ".glb" && ext != ".gltf")
      throw CMGeom::Invalid_input(o->output + ": a level-of-detail chain is written as .glb or .gltf");

    CMGeom::Textured_mesh tm;
    CMGeom::IO::Read_options ro;
    ro.repair = !o->no_repair;
    ro.allow_degenerate_faces = o->allow_degenerate;
    ro.drop_repeated_vertex_faces = o->drop_repeated;
    std::vector<std::string> warnings;
    ro.warnings = &warnings;
    const double read_start = cmgeom_cli::now_seconds();
    CMGeom::IO::read_mesh(o->input, tm, ro);
    const double seconds_read = cmgeom_cli::now_seconds() - read_start;
    cmgeom_cli::print_warnings("lod", warnings);
    if (!CGAL::is_triangle_mesh(tm.mesh())) throw CMGeom::Invalid_input(o->input + ": not a triangle mesh");
    if (!o->no_texture) {
      cmgeom_cli::apply_texture_option(tm, o->input, o->texture);
      cmgeom_cli::refuse_unnamed_texture(tm, o->input, "for textured levels");
    }
    if (o->no_texture) {
      tm.set_has_uvs(false);
      tm.materials().clear();
    } else {
      CMGeom::IO::load_textures(tm);
    }
    bool has_image = false;
    for (const auto& m : tm.materials()) has_image |= !m.diffuse_image.empty();
    const bool textured = tm.has_uvs() && has_image;
    if (o->no_overflow_charts && !o->shared_texture)
      throw CMGeom::Invalid_input("--no-overflow-charts applies to --shared-texture only");
    if (colour_tolerance->count() > 0 && (!o->shared_texture || o->no_overflow_charts))
      throw CMGeom::Invalid_input("--overflow-colour-tolerance applies to --shared-texture with overflow charts only");
    if (o->shared_texture && !textured)
      throw CMGeom::Invalid_input(o->input +
                                  ": --shared-texture needs a textured input (UVs and a texture; see --texture)");
    if (tm.has_uvs() && !textured)
      std::cerr << "cmgeom lod: note: the input names no texture: texture coordinates are dropped\n";

    const std::size_t faces_in = tm.mesh().number_of_faces();
    TS::Level_of_detail_options lo;
    std::vector<double> ratio_list;
    if (ratios->count()) {
      ratio_list = parse_list<double>(o->ratios, "--ratios");
      for (double r : ratio_list) {
        if (!(r > 0 && r <= 1)) {
          std::ostringstream m;
          m << "--ratios: every ratio must be in (0, 1], got " << r;
          throw CMGeom::Invalid_input(m.str());
        }
        lo.target_faces.push_back(std::max<std::size_t>(1, std::size_t(std::llround(r * double(faces_in)))));
      }
    } else if (errors->count()) {
      if (o->prune) throw CMGeom::Invalid_input("--prune cannot be combined with --max-errors");
      lo.max_errors = parse_list<double>(o->max_errors, "--max-errors");
      for (std::size_t i = 0; i < lo.max_errors.size(); ++i) {
        if (!(lo.max_errors[i] >= 0)) throw CMGeom::Invalid_input("--max-errors: every bound must be >= 0");
        if (i > 0 && lo.max_errors[i] <= lo.max_errors[i - 1])
          throw CMGeom::Invalid_input("--max-errors: the bounds must increase strictly");
      }
    } else {
      for (long long n : parse_list<long long>(o->faces, "--faces")) {
        if (n < 1) throw CMGeom::Invalid_input("--faces: every face count must be at least 1");
        lo.target_faces.push_back(std::size_t(n));  // at least the input's count: the input itself
      }
    }
    for (std::size_t i = 1; i < lo.target_faces.size(); ++i)
      if (lo.target_faces[i] >= lo.target_faces[i - 1])
        throw CMGeom::Invalid_input(
            "the levels must decrease strictly (in faces: " + std::to_string(lo.target_faces[i - 1]) + " then " +
            std::to_string(lo.target_faces[i]) + ")");
    lo.quadric.weighted = o->policy == "weighted";
    lo.shared_texture = o->shared_texture;
    lo.overflow_charts = !o->no_overflow_charts;
    lo.overflow_colour_tolerance = o->overflow_colour_tolerance;
    lo.measure_error = !o->no_error;
    lo.memory.fit.rounds = o->fit_rounds;
    lo.memory.fit.min_points_per_face = o->fit_min_points;
    lo.memory.max_points = o->memory_points;
    lo.prune_components = o->prune;

    // (levels by error: the run's end is not known in advance; the bar counts towards one face, and
    // its final line gives the faces actually removed)
    const std::size_t last = lo.max_errors.empty() ? lo.target_faces.back() : 1;
    cmgeom_cli::Progress bar("lod", double(faces_in > last ? faces_in - last : 0), "faces removed");
    cmgeom_cli::Collapse_progress state{&bar, double(faces_in > last ? faces_in - last : 0)};
    const double t0 = cmgeom_cli::now_seconds();
    TS::Level_of_detail_result r = TS::simplify_to_levels(std::move(tm), lo, state.visitor());  // (tm not read after)
    state.done(faces_in, r.levels.empty() ? faces_in : r.levels.back().mesh.mesh().number_of_faces());
    const double seconds = cmgeom_cli::now_seconds() - t0;
    if (o->shared_texture && r.shared_texture_hidden > 0.05)
      std::cerr
          << "cmgeom lod: warning: the shared atlas hides " << std::lround(100 * r.shared_texture_hidden)
          << " % of the input's texture (parts of the input fold onto one place of the coarsest level, which is too "
             "coarse for one atlas): raise the smallest ratio, or drop --shared-texture\n";

    if (lo.max_errors.empty())
      for (std::size_t i = 0; i < r.levels.size(); ++i) {
        const std::size_t faces = r.levels[i].mesh.mesh().number_of_faces();
        if (r.levels[i].is_input || faces <= r.levels[i].target_faces) continue;
        std::cerr << "cmgeom lod: level " << i << " stopped at " << faces << " faces for a target of "
                  << r.levels[i].target_faces << " ("
                  << cmgeom_cli::no_collapse_reason(r.levels[i].mesh.mesh(), !o->prune) << ")\n";
      }

    std::vector<CMGeom::IO::Gltf_level> levels;
    for (std::size_t i = 0; i < r.levels.size(); ++i) {
      CMGeom::IO::Gltf_level g;
      g.mesh = &r.levels[i].mesh;
      g.name = "lod" + std::to_string(i);
      g.error = r.levels[i].hausdorff;
      g.ratio = double(r.levels[i].mesh.mesh().number_of_faces()) / double(faces_in);
      levels.push_back(g);
    }
    const double tw = cmgeom_cli::now_seconds();
    {
      // the scene and the OBJ levels appear together or not at all (a missing --obj-prefix
      // directory must not leave the scene behind)
      CMGeom::IO::Atomic_output out;
      CMGeom::IO::write_textured_gltf(o->output, levels, out, o->gltf);
      if (!o->obj_prefix.empty())
        for (std::size_t i = 0; i < r.levels.size(); ++i)
          CMGeom::IO::write_textured_mesh(o->obj_prefix + "_" + std::to_string(i) + ".obj", r.levels[i].mesh, out);
      out.commit();
    }
    const double seconds_write = cmgeom_cli::now_seconds() - tw;

    if (o->json) {
      nlohmann::ordered_json j;
      j["input"] = o->input;
      j["output"] = o->output;
      j["faces_in"] = faces_in;
      j["textured"] = textured;
      j["shared_texture"] = o->shared_texture;
      j["policy"] = o->policy;
      j["fit_rounds"] = lo.max_errors.empty() ? o->fit_rounds : 0;  // (levels by bound are not fitted)
      j["fit_min_points"] = o->fit_min_points;
      j["memory_points"] = o->memory_points;
      j["prune"] = o->prune;
      if (o->shared_texture) {
        j["shared_texture_hidden"] = r.shared_texture_hidden;
        j["shared_texture_relocated"] = r.shared_texture_relocated;
        j["shared_texture_overflow"] = r.shared_texture_overflow;
      }
      if (!lo.max_errors.empty()) j["max_errors"] = lo.max_errors;
      auto& arr = j["levels"] = nlohmann::ordered_json::array();
      for (std::size_t i = 0; i < r.levels.size(); ++i) {
        const auto& l = r.levels[i];
        nlohmann::ordered_json e;
        e["level"] = i;
        if (lo.max_errors.empty())
          e["target_faces"] = l.target_faces;
        else
          e["max_error"] = lo.max_errors[i];
        e["faces"] = l.mesh.mesh().number_of_faces();
        // (the vertices in a face: those the GLB stores; an input read with vertices in no face keeps them)
        const auto& lm = l.mesh.mesh();
        e["vertices"] =
            std::size_t(std::count_if(lm.vertices().begin(), lm.vertices().end(),
                                      [&](CMGeom::Surface_mesh::Vertex_index v) { return !lm.is_isolated(v); }));
        e["is_input"] = l.is_input;
        if (l.hausdorff >= 0) {
          e["hausdorff"] = l.hausdorff;
          e["rms"] = l.rms;
        }
        if (textured && l.is_input && !o->shared_texture) {
          // (the input itself, with its own texture and charts)
          const CMGeom::Image* image = nullptr;
          for (const auto& m : l.mesh.materials())
            if (!image && !m.diffuse_image.empty()) image = &m.diffuse_image;
          e["texture_width"] = image ? image->width() : 0;
          e["texture_height"] = image ? image->height() : 0;
          std::vector<int> chart(l.mesh.mesh().num_faces(), -1);
          e["charts"] = CMGeom::compute_chart_ids(
              l.mesh.mesh(), l.mesh.uv_map(),
              boost::make_iterator_property_map(chart.begin(), get(boost::face_index, l.mesh.mesh())));
        } else if (textured) {
          e["texture_width"] = l.atlas.texture_width;
          e["texture_height"] = l.atlas.texture_height;
          e["charts"] = l.atlas.charts;
          // the making of the atlas, on the level it was made for (the coarsest, for a shared one)
          if (!l.is_input && (!o->shared_texture || i + 1 == r.levels.size())) {
            e["texels_in_charts"] = l.atlas.texels_baked;
            e["texels_painted"] = l.atlas.texels_painted;
            e["seconds_charts"] = l.atlas.seconds_charts;
            e["seconds_paint"] = l.atlas.seconds_paint;
            e["seconds_bake"] = l.atlas.seconds_bake;
          }
        }
        arr.push_back(e);
      }
      j["seconds"] = seconds;
      j["seconds_collapse"] = r.seconds_collapse;
      j["parts"] = r.parts;
      if (r.parts > 0) j["faces_after_parts"] = r.faces_after_parts;
      j["runs_in_parts"] = r.runs_in_parts;
      j["seconds_texture"] = r.seconds_texture;
      j["seconds_error"] = r.seconds_error;
      j["seconds_read"] = seconds_read;
      j["seconds_write"] = seconds_write;
      cmgeom_cli::print_json(j);
    } else {
      std::cout << o->input << ": " << r.levels.size() << " levels (";
      for (std::size_t i = 0; i < r.levels.size(); ++i)
        std::cout << (i ? ", " : "") << r.levels[i].mesh.mesh().number_of_faces();
      std::cout << " faces) in " << seconds << " s"
                << (textured ? (o->shared_texture ? ", one shared atlas" : ", an atlas per level") : "") << " -> "
                << o->output << "\n";
    }
    return 0;
  };
}
