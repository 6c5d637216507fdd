// cmgeom cm build <in> -o <model.cm> (--faces N | --ratio r) [--sharp-angle deg] [--cubic]
//                 [--texture image | --no-texture] [--joint-fit] [--error-bound x [--error-rounds n] [--error-level L]]
//                 [--json]
// cmgeom cm reconstruct <model.cm> -o <out> [--level L | --edge-length x | --roi x,y,z,r |
//                       --silhouette x,y,z] [--max-level L] [--projection normal|closest] [--json]
// cmgeom cm deform <model.cm> (--cages <system.json> | --affine a11,...,a34) -o <out>
//                  [--level L | --edge-length x | --roi x,y,z,r | --silhouette x,y,z] [--max-level L]
//                  [--projection normal|closest] [--flatness f] [--json]
// Compact Models (thesis chapter 4): build writes the CM file of a mesh (§4.3-4.4, error control
// §4.5.3); reconstruct rebuilds a mesh from it, regularly or adaptively (§4.5); deform deforms
// the CM base with a cage, a *Cages system or an affine map and reconstructs the deformed model
// (Deformable CMs, thesis chapter 6). The cage-system file is the one of `cmgeom deform`
// (Cage_deformation/Cage_system_io.h): one cage deforms with its own coordinates, several with
// the *Cages join (§5.3). Outputs are written atomically.
#include "cli_common.h"

#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Cage_deformation/Any_cage_coordinates.h>
#include <CMGeom/Cage_deformation/Cage_system.h>
#include <CMGeom/Cage_deformation/Cage_system_io.h>
#include <CMGeom/Compact_model.h>
#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/error_criterion.h>
#include <CMGeom/Compact_model/level_errors.h>
#include <CMGeom/Compact_model/rate_distortion.h>
#include <CMGeom/Compact_model/select_compact_model.h>
#include <CMGeom/Deformable_compact_model.h>
#include <CMGeom/Deformable_compact_model/Cage_system_deformer.h>
#include <CMGeom/Error.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace CM = CMGeom::CM;

std::vector<double> parse_numbers(const std::string& s, std::size_t n, const std::string& option) {
  std::vector<double> r;
  std::stringstream ss(s);
  std::string tok;
  while (std::getline(ss, tok, ',')) {
    char* end = nullptr;
    const double v = std::strtod(tok.c_str(), &end);
    if (tok.empty() || *end != 0 || !std::isfinite(v))
      throw CMGeom::Invalid_input(option + ": not a number: '" + tok + "'");
    r.push_back(v);
  }
  if (r.size() != n)
    throw CMGeom::Invalid_input(option + " needs " + std::to_string(n) + " comma-separated numbers, got '" + s + "'");
  return r;
}

namespace CD = CMGeom::Cage_deformation;
namespace DCM = CMGeom::DCM;

// Reconstructs with `run(options)` as the progress stage "reconstruct"; its count is the
// regular reconstruction's triangles, known in advance (`regular_triangles`, 0 for an adaptive
// one, which shows the time left and counts its triangles at the end).
template <class Run>
CM::Reconstruction reconstruct_with_progress(CM::Reconstruction_options options, std::size_t regular_triangles,
                                             const Run& run) {
  cmgeom_cli::Progress stage("reconstruct");
  if (regular_triangles > 0) stage.set_total(double(regular_triangles), "triangles");
  options.progress = stage.hook();
  CM::Reconstruction out = run(options);
  stage.set_total(double(out.triangles.size()), "triangles");
  return out;
}

// Writes a reconstruction as the progress stage "write <file name>".
void write_reconstruction(const CM::Reconstruction& out, const std::string& texture, const std::string& path) {
  cmgeom_cli::Progress stage("write " + std::filesystem::path(path).filename().string(), double(out.triangles.size()),
                             "triangles");
  CMGeom::Textured_mesh tm;
  CM::to_textured_mesh(out, tm, texture);
  CMGeom::IO::write_mesh(path, tm);
}

}  // namespace

CMGEOM_CLI_COMMAND(
    cm,
    "Compact Models (thesis chapters 4 and 6): 'cm build' a CM file, 'cm reconstruct' a mesh from it, 'cm deform' it") {
  app.require_subcommand(1);
  // ------------------------------------------------------------------ cm build
  struct Build_args {
    std::string input, output;
    std::size_t faces = 0;
    double ratio = 0, sharp_angle = 40, error_bound = 0;
    int error_rounds = 2, error_level = 2;
    bool cubic = false, joint_fit = false, json = false, no_texture = false, no_repair = false, compact = false,
         allow_degenerate = false, drop_repeated = false, no_input_creases = false, optimal_placement = false;
    std::string fit = "auto";
    int select_level = 3;
    int texture_size = 0, normal_bits = 12, max_level = 3, level_errors = -1;
    double tolerance = 0, max_error = 0;
    std::size_t max_bytes = 0;
    std::string texture;
  };
  auto b = std::make_shared<Build_args>();
  CLI::App* build = app.add_subcommand("build", "Build the Compact Model of a triangle mesh (thesis §4.3–4.4)");
  build->add_option("input", b->input, "Input mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  build->add_option("-o,--output", b->output, "Output CM file")->required();
  auto* faces = build->add_option("--faces", b->faces, "Faces of the base (simplified) mesh");
  auto* ratio = build->add_option("--ratio", b->ratio, "Base faces as a fraction of the input faces, in (0, 1]");
  auto* max_error =
      build->add_option("--max-error", b->max_error,
                        "Rate-distortion: the smallest model whose reconstruction is within this symmetric "
                        "Hausdorff distance, a fraction of the bounding-box diagonal (chooses base size, "
                        "quantization and level; writes the compact file)");
  auto* max_bytes =
      build->add_option("--bytes", b->max_bytes,
                        "Rate-distortion: the lowest-error model whose compact file fits in this many bytes "
                        "(with --max-error: the smallest within both)");
  auto* rate_level = build->add_option("--max-level", b->max_level,
                                       "Rate-distortion: highest reconstruction level considered, 1-6 (default 3)");
  faces->excludes(ratio);
  ratio->excludes(faces);
  for (CLI::Option* o : {max_error, max_bytes}) {
    o->excludes(faces);
    o->excludes(ratio);
  }
  build->add_option("--sharp-angle", b->sharp_angle, "Sharp-edge threshold in degrees (thesis §4.4.2; default 40)");
  build->add_option("--error-bound", b->error_bound,
                    "Error control (thesis §4.5.3): absolute distance bound, 0 = off (default)");
  build->add_option("--error-rounds", b->error_rounds,
                    "Most rounds of error control (default 2; a round that does not lower the error is undone)");
  build->add_option(
      "--error-level", b->error_level,
      "Reconstruction level at which error control measures (default 2; use the level you will reconstruct at)");
  auto* fit =
      build
          ->add_option("--fit", b->fit,
                       "How the local surfaces are fitted: auto (default, CMGeom addition: builds the thesis' model "
                       "and the joint refit on optimally placed base vertices, with quadrics at a 25-degree "
                       "sharp threshold and with cubics, and keeps the lowest measured Hausdorff error at "
                       "--select-level; about 8 times the time of --fit thesis), thesis (the independent "
                       "fits of §4.4.3, base vertices on input vertices), joint (the joint refit)")
          ->check(CLI::IsMember({"auto", "thesis", "joint"}));
  auto* select_level = build->add_option("--select-level", b->select_level,
                                         "--fit auto: reconstruction level at which the candidates are measured, "
                                         "1-6 (default 3; use the level you will reconstruct at)");
  build->add_flag("--cubic", b->cubic,
                  "Cubic local surfaces instead of the thesis' quadrics (one build: --fit thesis unless joint)");
  build->add_flag("--joint-fit", b->joint_fit,
                  "Refit all local surfaces together so that their blend follows the input (CMGeom addition; "
                  "the same as --fit joint)");
  build->add_flag("--optimal-placement", b->optimal_placement,
                  "Place base vertices optimally (weighted quadrics), then snap them to the input (§4.3), "
                  "instead of keeping them on input vertices (geometry-only builds with --faces or --ratio; one "
                  "build: --fit thesis unless joint)");
  build->add_flag("--no-input-creases", b->no_input_creases,
                  "Sharp edges from the thesis' fits alone (§4.4.2), without CMGeom's rule that a base edge "
                  "along a path of input creases is sharp too");
  build->add_flag("--no-texture", b->no_texture, "Geometry only even for an input with texture coordinates");
  build->add_option("--texture", b->texture, "Diffuse texture for an input whose file names none (e.g. spot.obj)");
  cmgeom_cli::add_repair_by_default_options(*build, b->no_repair);
  cmgeom_cli::add_allow_degenerate_option(*build, b->allow_degenerate);
  cmgeom_cli::add_drop_repeated_option(*build, b->drop_repeated);
  build->add_option("--texture-size", b->texture_size,
                    "Textured input: texels per UV unit of the base's new atlas (default: the input texture's size)");
  build->add_flag("--compact", b->compact,
                  "Write the compact, quantized CM file (format version 3: positions on a grid, normals and "
                  "coefficients quantized, entropy coded; CMGeom addition)");
  auto* tolerance =
      build->add_option("--tolerance", b->tolerance,
                        "Compact file: grid step of the positions and twice the coefficient tolerance, as a "
                        "fraction of the input's bounding-box diagonal (default 1e-4)");
  auto* normal_bits =
      build->add_option("--normal-bits", b->normal_bits,
                        "Compact file: bits per octahedral coordinate of the frame normals, 6-20 (default 12)");
  auto* level_errors =
      build
          ->add_option(
              "--level-errors", b->level_errors,
              "Measure the regular reconstruction's error against the input per base face at levels 0-N (0-8) "
              "and store it in the CM file, for `cm reconstruct --vertices` (CMGeom addition; about 2 bytes per "
              "face and level)")
          ->check(CLI::Range(0, 8));
  level_errors->excludes(max_bytes);
  build->add_flag("--json", b->json, "Print a JSON report on stdout");

  // ------------------------------------------------------------------ cm reconstruct
  struct Rec_args {
    std::string input, output, roi, silhouette, projection = "closest";
    int level = 2, max_level = 6;
    double edge_length = 0;
    std::size_t vertices = 0;
    bool json = false;
  };
  auto r = std::make_shared<Rec_args>();
  CLI::App* rec = app.add_subcommand("reconstruct", "Reconstruct a mesh from a CM file (thesis §4.5)");
  rec->add_option("input", r->input, "CM file")->required();
  rec->add_option("-o,--output", r->output, "Output mesh (.obj, .off, .ply, .stl)")->required();
  auto* level = rec->add_option(
      "--level", r->level,
      "Regular subdivision level (default: the level the file was built for by cm build --max-error or --bytes, "
      "else 2)");
  auto* edge = rec->add_option("--edge-length", r->edge_length, "Adaptive: split edges longer than this");
  auto* roi = rec->add_option("--roi", r->roi, "Adaptive: region of interest x,y,z,radius");
  auto* sil = rec->add_option("--silhouette", r->silhouette, "Adaptive: refine the silhouette seen from x,y,z");
  auto* budget = rec->add_option(
      "--vertices", r->vertices,
      "Adaptive: at most this many output vertices, placed by the CM's level error table where it has one "
      "(cm build --level-errors), by the estimated chord error otherwise");
  level->excludes(edge)->excludes(roi)->excludes(sil)->excludes(budget);
  edge->excludes(roi)->excludes(sil)->excludes(budget);
  roi->excludes(sil)->excludes(budget);
  sil->excludes(budget);
  rec->add_option("--max-level", r->max_level, "Adaptive: maximum halvings of a base edge (default 6)");
  rec->add_option("--projection", r->projection, "Projection onto local surfaces: closest (Newton) or normal")
      ->check(CLI::IsMember({"closest", "normal"}));
  rec->add_flag("--json", r->json, "Print a JSON report on stdout");

  // ------------------------------------------------------------------ cm deform
  struct Def_args {
    cmgeom_cli::Cage_source cages;  // --cages only
    std::string input, output, affine, roi, silhouette, projection = "closest";
    int level = 2, max_level = 6;
    double edge_length = 0, flatness = 0.01;
    bool json = false;
  };
  auto d = std::make_shared<Def_args>();
  CLI::App* def =
      app.add_subcommand("deform", "Deform a CM's base and reconstruct the deformed model (thesis chapter 6)");
  def->add_option("input", d->input, "CM file")->required();
  auto* d_cages = cmgeom_cli::add_cage_source_options(*def, d->cages, cmgeom_cli::Cage_grid_options::none);
  auto* d_affine =
      def->add_option("--affine", d->affine, "Affine map instead of a cage: a11,a12,a13,b1,a21,...,b3 (12 numbers)");
  d_cages->excludes(d_affine);
  d_affine->excludes(d_cages);
  def->add_option("-o,--output", d->output, "Output mesh (.obj, .off, .ply, .stl)")->required();
  auto* d_level = def->add_option(
      "--level", d->level,
      "Regular subdivision level (default: the level the file was built for by cm build --max-error or --bytes, "
      "else 2)");
  auto* d_edge =
      def->add_option("--edge-length", d->edge_length, "Adaptive: split edges longer than this (deformed lengths)");
  auto* d_roi = def->add_option("--roi", d->roi, "Adaptive: region of interest x,y,z,radius (deformed space)");
  auto* d_sil =
      def->add_option("--silhouette", d->silhouette, "Adaptive: refine the deformed silhouette seen from x,y,z");
  d_level->excludes(d_edge)->excludes(d_roi)->excludes(d_sil);
  d_edge->excludes(d_roi)->excludes(d_sil);
  d_roi->excludes(d_sil);
  def->add_option("--max-level", d->max_level, "Adaptive: maximum halvings of a base edge (default 6)");
  def->add_option("--projection", d->projection, "Projection onto local surfaces: closest (Newton) or normal")
      ->check(CLI::IsMember({"closest", "normal"}));
  def->add_option(
      "--flatness", d->flatness,
      "Local maps: regularise 1-rings flatter than this (default 0.01; 0 = never, planar 1-rings then only translate)");
  def->add_flag("--json", d->json, "Print a JSON report on stdout");

  return [build, rec, def, b, r, d, faces, ratio, level, edge, roi, sil, d_cages, d_affine, d_edge, d_roi, d_sil,
          tolerance, normal_bits, max_error, max_bytes, rate_level, fit, select_level, level_errors, budget,
          d_level]() -> int {
    if (def->parsed()) {
      const double t_command = cmgeom_cli::now_seconds();
      if (d_cages->count() == 0 && d_affine->count() == 0)
        throw CMGeom::Invalid_input("one of --cages or --affine is required");
      if (d->max_level < 0 || d->max_level > 20) throw CMGeom::Invalid_input("--max-level must be in [0, 20]");
      if (!(d->flatness >= 0 && d->flatness <= 1)) throw CMGeom::Invalid_input("--flatness must be in [0, 1]");
      CM::Compact_model model = CM::read_cm(d->input);
      model.texture = CM::texture_path(model, d->input);
      DCM::Local_deformation_options lo;
      lo.flatness = d->flatness;
      DCM::Deformable_compact_model dcm(model, lo);
      nlohmann::ordered_json j;
      j["input"] = d->input;
      j["output"] = d->output;
      std::vector<CM::Vec3> deformed;
      double bind_seconds = 0, deform_seconds = 0, setup_seconds = 0;
      std::size_t weights_bytes = 0;
      if (d_affine->count()) {
        const auto a = parse_numbers(d->affine, 12, "--affine");
        DCM::Affine_deformer af;
        try {
          af.set_map({{{a[0], a[1], a[2]}, {a[4], a[5], a[6]}, {a[8], a[9], a[10]}}}, CM::Vec3(a[3], a[7], a[11]));
        } catch (const CMGeom::Invalid_input& e) {
          throw CMGeom::Invalid_input(std::string("--affine ") + d->affine + ": " + e.what());
        }
        af.bind(dcm.base_vertices());
        const double t0 = cmgeom_cli::now_seconds();
        af.deform(deformed);
        deform_seconds = cmgeom_cli::now_seconds() - t0;
        j["deformer"] = "affine";
      } else {
        const CD::Cage_system_description desc = CD::read_cage_system(d->cages.file);
        for (const auto& c : desc.cages) cmgeom_cli::print_warnings("cm deform", c.warnings);
        std::size_t undefined = 0;
        auto run = [&](auto& deformer) {
          double t0 = cmgeom_cli::now_seconds();
          {
            cmgeom_cli::Progress stage("bind", double(dcm.base_vertices().size()), "base vertices");
            deformer.bind(dcm.base_vertices());
          }
          bind_seconds = cmgeom_cli::now_seconds() - t0;
          t0 = cmgeom_cli::now_seconds();
          deformer.deform(deformed);
          deform_seconds = cmgeom_cli::now_seconds() - t0;
          weights_bytes = deformer.weights_bytes();
        };
        std::string coordinates;
        std::size_t cage_vertices = 0;
        for (const auto& c : desc.cages) {
          const std::string t = CD::to_string(c.coordinates);
          if (coordinates.find(t) == std::string::npos) coordinates += (coordinates.empty() ? "" : "+") + t;
          cage_vertices += c.rest.vertices.size();
        }
        const double t_setup = cmgeom_cli::now_seconds();
        // The coordinates' set-up (a grid solve per cage for harmonic coordinates) has no hook:
        // its stage reports its end only.
        auto setup_stage = std::make_unique<cmgeom_cli::Progress>("cage setup", double(desc.cages.size()), "cages");
        if (desc.cages.size() == 1) {
          const CD::Cage_description& c = desc.cages[0];
          DCM::Cage_deformer<CD::Any_cage_coordinates> cd(CD::make_cage_coordinates(c.coordinates, c.rest, c.harmonic));
          setup_seconds = cmgeom_cli::now_seconds() - t_setup;
          setup_stage.reset();
          cd.set_pose(c.deformed);
          run(cd);
          undefined = cd.binding().count(CD::Coordinate_status::undefined);
        } else {
          const CD::Cage_system sys(desc);
          setup_seconds = cmgeom_cli::now_seconds() - t_setup;
          setup_stage.reset();
          DCM::Cage_system_deformer<> cs(sys);
          run(cs);
          undefined = cs.binding().weights().count(CD::Coordinate_status::undefined);
        }
        if (undefined)
          throw CMGeom::Invalid_input(d->input + ": " + std::to_string(undefined) + " of " +
                                      std::to_string(model.vertices.size()) +
                                      " base vertices lie outside the cages, where harmonic coordinates are undefined "
                                      "(give those cages \"harmonic\": {\"outside\": \"mean_value\"} to use mean "
                                      "value coordinates there, or \"coordinates\": \"mean_value\" or \"green\", "
                                      "which are defined there, or use cages that enclose the model)");
        j["deformer"] = desc.cages.size() == 1 ? "cage" : "cage_system";
        j["coordinates"] = coordinates;
        j["cages"] = desc.cages.size();
        j["cage_vertices"] = cage_vertices;
      }
      double t0 = cmgeom_cli::now_seconds();
      dcm.set_deformed_base(deformed);
      const double maps_seconds = cmgeom_cli::now_seconds() - t0;
      CM::Reconstruction_options ro;
      ro.projection = d->projection == "normal" ? CM::Projection::along_normal : CM::Projection::closest_point;
      std::string mode = "regular";
      t0 = cmgeom_cli::now_seconds();
      CM::Reconstruction out;
      if (d_edge->count()) {
        if (!(d->edge_length > 0)) throw CMGeom::Invalid_input("--edge-length must be > 0");
        mode = "edge-length";
        out = reconstruct_with_progress(ro, 0, [&](const CM::Reconstruction_options& o) {
          return dcm.reconstruct_adaptive(CM::Edge_length_criterion{d->edge_length}, d->max_level, o);
        });
      } else if (d_roi->count()) {
        const auto v = parse_numbers(d->roi, 4, "--roi");
        if (!(v[3] > 0)) throw CMGeom::Invalid_input("--roi radius must be > 0");
        mode = "roi";
        out = reconstruct_with_progress(ro, 0, [&](const CM::Reconstruction_options& o) {
          return dcm.reconstruct_adaptive(CM::Region_of_interest_criterion{CM::Vec3(v[0], v[1], v[2]), v[3]},
                                          d->max_level, o);
        });
      } else if (d_sil->count()) {
        const auto v = parse_numbers(d->silhouette, 3, "--silhouette");
        mode = "silhouette";
        out = reconstruct_with_progress(ro, 0, [&](const CM::Reconstruction_options& o) {
          return dcm.reconstruct_adaptive(CM::Silhouette_criterion{CM::Vec3(v[0], v[1], v[2]), 0.2}, d->max_level, o);
        });
      } else {
        if (d->level < 0 || d->level > 12) throw CMGeom::Invalid_input("--level must be in [0, 12]");
        if (d_level->count() == 0 && model.reconstruction_level >= 0) d->level = model.reconstruction_level;
        out = reconstruct_with_progress(
            ro, model.faces.size() << (2 * d->level),
            [&](const CM::Reconstruction_options& o) { return dcm.reconstruct_regular(d->level, o); });
      }
      const double reconstruct_seconds = cmgeom_cli::now_seconds() - t0;  // the library call alone
      write_reconstruction(out, model.texture, d->output);
      const double command_seconds = cmgeom_cli::now_seconds() - t_command;  // reading and writing included
      if (d->json) {
        j["mode"] = mode;
        if (mode == "regular") j["level"] = d->level;
        j["projection"] = d->projection;
        j["base_vertices"] = model.vertices.size();
        j["base_faces"] = model.faces.size();
        j["regularised_vertices"] = dcm.solver().number_of_regularised_vertices();
        j["degenerate_vertices"] = dcm.solver().number_of_degenerate_vertices();
        j["vertices"] = out.points.size();
        j["faces"] = out.triangles.size();
        if (d_cages->count()) j["setup_seconds"] = setup_seconds;
        j["bind_seconds"] = bind_seconds;
        j["base_deform_seconds"] = deform_seconds;
        j["local_maps_seconds"] = maps_seconds;
        j["deform_seconds"] = deform_seconds + maps_seconds;
        j["reconstruct_seconds"] = reconstruct_seconds;
        j["seconds"] = command_seconds;
        j["weights_bytes"] = weights_bytes;
        j["local_maps_bytes"] = dcm.bytes();
        cmgeom_cli::print_json(j);
      }
      return 0;
    }
    if (build->parsed()) {
      const bool rate = max_error->count() || max_bytes->count();
      if (faces->count() == 0 && ratio->count() == 0 && !rate)
        throw CMGeom::Invalid_input("one of --faces, --ratio, --max-error or --bytes is required");
      if (max_error->count() && !(b->max_error > 0 && b->max_error < 1))
        throw CMGeom::Invalid_input("--max-error must be in (0, 1) (a fraction of the bounding-box diagonal)");
      if (max_bytes->count() && b->max_bytes < 64) throw CMGeom::Invalid_input("--bytes must be at least 64");
      if (rate_level->count() && !rate) throw CMGeom::Invalid_input("--max-level applies to --max-error and --bytes");
      if (b->max_level < 1 || b->max_level > 6) throw CMGeom::Invalid_input("--max-level must be in [1, 6]");
      if (rate && tolerance->count())
        throw CMGeom::Invalid_input("--tolerance is chosen by --max-error and --bytes: give one or the other");
      // --fit: an explicit auto excludes the options naming one configuration; without --fit they
      // choose one build
      const bool fit_given = fit->count() > 0;
      if (b->joint_fit) {
        if (fit_given && b->fit != "joint")
          throw CMGeom::Invalid_input("--joint-fit contradicts --fit " + b->fit + " (it means --fit joint)");
        b->fit = "joint";
      }
      if (b->fit == "auto" && (b->cubic || b->optimal_placement)) {
        if (fit_given)
          throw CMGeom::Invalid_input(
              "--cubic and --optimal-placement name one build configuration: use them with --fit thesis or joint");
        b->fit = "thesis";
      }
      if (select_level->count() && b->fit != "auto")
        throw CMGeom::Invalid_input("--select-level applies to --fit auto");
      if (b->select_level < 1 || b->select_level > 6) throw CMGeom::Invalid_input("--select-level must be in [1, 6]");
      if (rate && (b->error_bound > 0))
        throw CMGeom::Invalid_input("--error-bound (error control) cannot be combined with --max-error or --bytes");
      if (ratio->count() && !(b->ratio > 0 && b->ratio <= 1))
        throw CMGeom::Invalid_input("--ratio must be in (0, 1], got " + std::to_string(b->ratio));
      if (faces->count() && b->faces < 2) throw CMGeom::Invalid_input("--faces must be at least 2");
      if (!(b->sharp_angle > 0 && b->sharp_angle < 180))
        throw CMGeom::Invalid_input("--sharp-angle must be in (0, 180) degrees");
      if (!(b->error_bound >= 0)) throw CMGeom::Invalid_input("--error-bound must be >= 0");
      if (b->error_rounds < 0 || b->error_rounds > 100)
        throw CMGeom::Invalid_input("--error-rounds must be in [0, 100]");
      if (b->error_level < 0 || b->error_level > 8) throw CMGeom::Invalid_input("--error-level must be in [0, 8]");
      if (b->texture_size < 0 || b->texture_size > 16384)
        throw CMGeom::Invalid_input("--texture-size must be in [0, 16384]");
      if ((tolerance->count() || normal_bits->count()) && !b->compact)
        throw CMGeom::Invalid_input("--tolerance and --normal-bits apply to the compact file: add --compact");
      if (tolerance->count() && !(b->tolerance > 0 && b->tolerance < 1))
        throw CMGeom::Invalid_input("--tolerance must be in (0, 1) (a fraction of the bounding-box diagonal)");
      if (b->normal_bits < 6 || b->normal_bits > 20) throw CMGeom::Invalid_input("--normal-bits must be in [6, 20]");
      CMGeom::Textured_mesh tm;
      CMGeom::IO::Read_options read_options;
      read_options.repair = !b->no_repair;  // (repaired by default, as simplify and lod do)
      read_options.allow_degenerate_faces = b->allow_degenerate;
      read_options.drop_repeated_vertex_faces = b->drop_repeated;
      std::vector<std::string> warnings;
      read_options.warnings = &warnings;
      cmgeom_cli::read_mesh_with_progress(b->input, tm, read_options);
      cmgeom_cli::print_warnings("cm build", warnings);
      CMGeom::Surface_mesh& mesh = tm.mesh();
      if (!CGAL::is_triangle_mesh(mesh)) throw CMGeom::Invalid_input(b->input + ": not a triangle mesh");
      if (!b->no_texture) {
        cmgeom_cli::apply_texture_option(tm, b->input, b->texture);
        cmgeom_cli::refuse_unnamed_texture(tm, b->input, "for a textured Compact Model");
      }
      // A textured input gives a textured CM (thesis §4.5.4): the base is simplified under the
      // chart constraints of chapter 3 and, when the texture can be decoded, gets a new atlas
      // written next to the CM file as <output stem>.png.
      // (as simplify: texture coordinates without a texture make a geometry-only model, UVs dropped)
      const bool textured = tm.has_uvs() && cmgeom_cli::names_a_texture(tm) && !b->no_texture;
      if (tm.has_uvs() && !textured) {
        if (!b->no_texture)
          std::cerr << "cmgeom cm build: note: " << b->input
                    << " names no texture: texture coordinates are dropped (geometry-only model)\n";
        tm.set_has_uvs(false);
      }
      // the rate-distortion search and textured builds make one configuration's models
      if (b->fit == "auto" && (textured || rate)) {
        if (fit_given)
          throw CMGeom::Invalid_input(b->input + (rate ? ": --fit auto does not combine with --max-error or --bytes"
                                                       : ": --fit auto applies to geometry-only builds (textured "
                                                         "input: use --fit thesis or joint, or --no-texture)"));
        b->fit = "thesis";
      }
      // (the textured base keeps its vertices on input vertices; the rate search builds the default base)
      if (b->optimal_placement && (textured || rate))
        throw CMGeom::Invalid_input(b->input +
                                    ": --optimal-placement applies to geometry-only builds with --faces or "
                                    "--ratio");
      if (textured && rate)
        throw CMGeom::Invalid_input(b->input +
                                    ": --max-error and --bytes build geometry-only models: add --no-texture");
      if (textured) {
        cmgeom_cli::Progress stage("load textures", double(tm.materials().size()), "materials");
        CMGeom::IO::load_textures(tm);
      }
      // a ratio's face count is simplify_mesh()'s (target_faces_for_ratio), at least 2
      const std::size_t target = faces->count()
                                     ? b->faces
                                     : std::max<std::size_t>(2, CMGeom::Textured_simplification::target_faces_for_ratio(
                                                                    mesh.number_of_faces(), rate ? 1.0 : b->ratio));
      CM::Build_options opt;
      opt.sharp_angle = b->sharp_angle;
      opt.error_bound = b->error_bound;
      opt.error_control_rounds = b->error_rounds;
      opt.error_control_level = b->error_level;
      opt.joint_fit = b->fit == "joint";
      opt.input_creases = !b->no_input_creases;
      CM::Build_statistics st;
      CM::Textured_build_result tr;
      // The rate counts the input's faces (the build's work grows with them); a textured build
      // spends part of its simplification share on the index texture, which has no hook of its own.
      cmgeom_cli::Progress stage("cm build", double(mesh.number_of_faces()), "faces");
      opt.progress = stage.hook();
      const double t0 = cmgeom_cli::now_seconds();
      CM::Compact_model model;
      CM::Rate_choice choice;
      CM::Selection_result selection;
      if (rate) {
        CM::Rate_target rt;
        rt.max_error = b->max_error;
        rt.max_bytes = b->max_bytes;
        rt.max_level = b->max_level;
        rt.progress = stage.hook();
        opt.progress = nullptr;
        model = b->cubic ? CM::build_compact_model_for(mesh, rt, choice, opt, CM::Cubic_surface_traits())
                         : CM::build_compact_model_for(mesh, rt, choice, opt, CM::Quadric_surface_traits());
        if (!choice.met) {
          std::ostringstream m;
          m << "no model meets the target: the closest has a " << choice.base_faces << "-face base, " << choice.bytes
            << " bytes, Hausdorff " << choice.hausdorff << " of the diagonal at level " << choice.level
            << " (nothing written)";
          throw CMGeom::Invalid_input(m.str());
        }
        st.base_vertices = model.vertices.size();
        st.base_faces = model.faces.size();
        st.sharp_edges = model.sharp_edges().size();
        st.cone_vertices = model.cone_vertices().size();
      } else if (textured) {
        CMGeom::Textured_simplification::Textured_simplification_options to = CM::textured_base_options();
        to.texture_size = b->texture_size;
        model = b->cubic
                    ? CM::build_textured_compact_model(tm, target, opt, CM::Cubic_surface_traits(), &tr, &st, to)
                    : CM::build_textured_compact_model(tm, target, opt, CM::Quadric_surface_traits(), &tr, &st, to);
      } else if (b->fit == "auto") {
        CM::Selection_options so;
        so.level = b->select_level;
        so.progress = stage.hook();
        opt.progress = nullptr;
        model = CM::build_selected_compact_model(mesh, target, opt, so, &selection, &st);
      } else {
        const CM::Fit_configuration c{b->fit, b->optimal_placement, b->fit == "joint", b->cubic, 0.};
        model = CM::build_configured_compact_model(mesh, target, opt, c, &st);
      }
      const double seconds = cmgeom_cli::now_seconds() - t0;
      stage.done();
      // (a textured base keeps the input's charts, §4.5.4, and may stop above its target)
      if (textured && tr.simplification.faces_out > target)
        std::cerr << "cmgeom cm build: the base stopped at " << tr.simplification.faces_out << " faces for a target of "
                  << target
                  << " (chart limit: no collapse left that keeps the input's charts; --no-texture builds a "
                     "geometry-only model to the target)\n";
      double level_errors_seconds = 0.;
      if (level_errors->count()) {
        cmgeom_cli::Progress le_stage("level errors");
        CM::Reconstruction_options lo;
        lo.progress = le_stage.hook();
        const double t1 = cmgeom_cli::now_seconds();
        CM::measure_level_errors(model, mesh, b->level_errors, lo);  // (any traits evaluate every stored surface)
        level_errors_seconds = cmgeom_cli::now_seconds() - t1;
        le_stage.done();
      }
      std::size_t bytes = 0;
      CM::CM_file_parts parts;
      std::string atlas;
      {
        // the CM and its atlas appear together or not at all
        CMGeom::IO::Atomic_output out;
        if (!tr.texture.empty()) {
          const std::filesystem::path cm_path(b->output);
          atlas = (cm_path.parent_path() / (cm_path.stem().string() + ".png")).string();
          CMGeom::IO::write_image(atlas, tr.texture, out);
          model.texture = cm_path.stem().string() + ".png";  // relative to the CM file's directory
        }
        if (rate) {
          bytes = CM::write_compact_cm(b->output, model, choice.encoding, out, &parts);
        } else if (b->compact) {
          CM::Compact_encoding enc;
          const CGAL::Bbox_3 box = CGAL::Polygon_mesh_processing::bbox(mesh);
          const double diagonal =
              std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                        CGAL::square(box.zmax() - box.zmin()));
          enc.tolerance = (tolerance->count() ? b->tolerance : 1e-4) * diagonal;
          enc.normal_bits = b->normal_bits;
          bytes = CM::write_compact_cm(b->output, model, enc, out, &parts);
        } else {
          bytes = CM::write_cm(b->output, model, out);
        }
        out.commit();
      }
      if (b->json) {
        nlohmann::ordered_json j;
        j["input"] = b->input;
        j["output"] = b->output;
        j["input_vertices"] = mesh.number_of_vertices();
        j["input_faces"] = mesh.number_of_faces();
        j["base_vertices"] = st.base_vertices;
        j["base_faces"] = st.base_faces;
        if (!rate) j["base_target_faces"] = target;
        if (textured) j["base_stopped_by"] = CMGeom::Textured_simplification::to_string(tr.simplification.stopped_by);
        j["surfaces"] = model.surfaces.size();
        j["sharp_edges"] = st.sharp_edges;
        j["dart_promotions"] = st.dart_promotions;
        j["cone_vertices"] = st.cone_vertices;
        j["error_control_points"] = st.error_control_points;
        j["error_control_rejected_rounds"] = st.error_control_rejected_rounds;
        j["joint_fit"] = st.joint_fit;
        if (b->fit == "auto") {
          const CM::Fit_configuration& c = selection.candidates[selection.chosen].configuration;
          j["fit"] = c.name;
          j["cubic"] = c.cubic;
          j["optimal_placement"] = c.optimal_placement;
          nlohmann::ordered_json cs = nlohmann::ordered_json::array();
          for (const auto& k : selection.candidates)
            cs.push_back(
                {{"fit", k.configuration.name}, {"hausdorff", k.hausdorff}, {"rms", k.rms}, {"seconds", k.seconds}});
          j["selection"] = {{"level", b->select_level}, {"candidates", cs}};
        } else {
          j["fit"] = b->fit;
          j["cubic"] = b->cubic;
          j["optimal_placement"] = b->optimal_placement;
        }
        j["textured"] = model.has_uvs();
        if (textured) {
          j["charts_in"] = tr.simplification.charts_in;
          j["charts_out"] = tr.simplification.charts_out;
          j["texture"] = model.texture;
          if (!atlas.empty()) j["atlas"] = atlas;
        }
        j["bytes"] = bytes;
        if (level_errors->count()) j["level_errors"] = {{"depth", b->level_errors}, {"seconds", level_errors_seconds}};
        if (rate) {
          j["rate"] = {{"max_error", b->max_error},
                       {"max_bytes", b->max_bytes},
                       {"base_faces_target", choice.base_faces},
                       {"level", choice.level},
                       {"tolerance", choice.encoding.tolerance},
                       {"hausdorff", choice.hausdorff},
                       {"rms", choice.rms},
                       {"candidates", choice.candidates}};
        }
        if (b->compact || rate) {
          j["format_version"] = 3;
          j["bytes_per_part"] = {{"header", parts.header},    {"connectivity", parts.connectivity},
                                 {"sectors", parts.sectors},  {"positions", parts.positions},
                                 {"normals", parts.normals},  {"coefficients", parts.coefficients},
                                 {"uvs", parts.uvs},          {"level_errors", parts.level_errors},
                                 {"checksum", parts.checksum}};
        }
        j["seconds"] = seconds;
        cmgeom_cli::print_json(j);
      }
      return 0;
    }
    // reconstruct
    const double t_command = cmgeom_cli::now_seconds();
    if (r->max_level < 0 || r->max_level > 20) throw CMGeom::Invalid_input("--max-level must be in [0, 20]");
    CM::Compact_model model = CM::read_cm(r->input);
    model.texture = CM::texture_path(model, r->input);
    CM::Reconstruction_options ro;
    ro.projection = r->projection == "normal" ? CM::Projection::along_normal : CM::Projection::closest_point;
    std::string mode = "regular";
    const double t0 = cmgeom_cli::now_seconds();
    CM::Reconstruction out;
    CM::Vertex_budget_result vb;
    if (budget->count()) {
      if (r->vertices == 0) throw CMGeom::Invalid_input("--vertices must be at least 1");
      mode = "vertex-budget";
      cmgeom_cli::Progress stage("reconstruct");
      vb = CM::reconstruct_to_vertex_budget(model, r->vertices, r->max_level, ro);
      stage.done();
      out = std::move(vb.reconstruction);
    } else if (edge->count()) {
      if (!(r->edge_length > 0)) throw CMGeom::Invalid_input("--edge-length must be > 0");
      mode = "edge-length";
      out = reconstruct_with_progress(ro, 0, [&](const CM::Reconstruction_options& o) {
        return CM::reconstruct_adaptive(model, CM::Edge_length_criterion{r->edge_length}, r->max_level, o);
      });
    } else if (roi->count()) {
      const auto v = parse_numbers(r->roi, 4, "--roi");
      if (!(v[3] > 0)) throw CMGeom::Invalid_input("--roi radius must be > 0");
      mode = "roi";
      out = reconstruct_with_progress(ro, 0, [&](const CM::Reconstruction_options& o) {
        return CM::reconstruct_adaptive(model, CM::Region_of_interest_criterion{CM::Vec3(v[0], v[1], v[2]), v[3]},
                                        r->max_level, o);
      });
    } else if (sil->count()) {
      const auto v = parse_numbers(r->silhouette, 3, "--silhouette");
      mode = "silhouette";
      out = reconstruct_with_progress(ro, 0, [&](const CM::Reconstruction_options& o) {
        return CM::reconstruct_adaptive(model, CM::Silhouette_criterion{CM::Vec3(v[0], v[1], v[2]), 0.2}, r->max_level,
                                        o);
      });
    } else {
      if (r->level < 0 || r->level > 12) throw CMGeom::Invalid_input("--level must be in [0, 12]");
      if (level->count() == 0 && model.reconstruction_level >= 0) r->level = model.reconstruction_level;
      out = reconstruct_with_progress(
          ro, model.faces.size() << (2 * r->level),
          [&](const CM::Reconstruction_options& o) { return CM::reconstruct_regular(model, r->level, o); });
    }
    const double reconstruct_seconds = cmgeom_cli::now_seconds() - t0;  // the library call alone
    write_reconstruction(out, model.texture, r->output);
    const double seconds = cmgeom_cli::now_seconds() - t_command;  // reading and writing included
    if (r->json) {
      nlohmann::ordered_json j;
      j["input"] = r->input;
      j["output"] = r->output;
      j["mode"] = mode;
      if (mode == "regular") j["level"] = r->level;
      j["projection"] = r->projection;
      j["base_vertices"] = model.vertices.size();
      j["base_faces"] = model.faces.size();
      j["vertices"] = out.points.size();
      j["faces"] = out.triangles.size();
      if (budget->count()) {
        j["budget"] = r->vertices;
        j["placed_by"] = vb.level_errors ? "level errors" : "chord error";
        if (vb.level_errors) {
          j["regular_level"] = vb.face_levels.regular_level;
          j["regular"] = vb.face_levels.regular;
          j["estimated_rms"] = vb.face_levels.estimated_rms;
          j["estimated_max"] = vb.face_levels.estimated_max;
          j["regular_estimated_rms"] = vb.face_levels.regular_estimated_rms;
          j["regular_estimated_max"] = vb.face_levels.regular_estimated_max;
        } else {
          j["tolerance"] = vb.tolerance;
        }
      }
      j["reconstruct_seconds"] = reconstruct_seconds;
      j["seconds"] = seconds;
      cmgeom_cli::print_json(j);
    }
    return 0;
  };
}
