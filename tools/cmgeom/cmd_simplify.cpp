// cmgeom simplify <in> -o <out> (--faces N | --ratio r | --max-cost c | --max-error E) [--policy weighted|plain]
//                 [--merge thesis|sum] [--flips] [--engine cmgeom|cgal] [--json]
//                 [--texture-backend cpu|osmesa] [--texture-size N] [--texture FILE]
//                 [--no-texture] [--keep-charts] [--freeze-seams] [--bake-lookups] [--no-repair] [--memoryless]
//                 [--fit-rounds N] [--memory-points N] [--prune] [--allow-degenerate]
// Edge-collapse simplification with plain Garland-Heckbert quadrics (or, --policy weighted, the
// weighted quadrics of thesis §3.4), on
// CMGeom's engine or CGAL's; on CMGeom's engine the quadric cost is completed by the memoryful
// term of Surface_memory.h (the input's points kept on the faces) unless --memoryless, and the
// vertices are then fitted to those points (--fit-rounds rounds; not with --max-error). A
// textured input (UVs and a texture image) is written as OBJ + MTL + PNG or as glTF/GLB: by default its
// collapses ignore the charts (any target is reached) and a new atlas is painted from the input
// followed down the collapses, the texels left looked up on it (rebuild_atlas.h); with --keep-charts it goes through
// the texture part of chapter 3 (chart constraints §3.5, index texture §3.3/§3.6), which stops where the charts allow
// no more collapses. Anything else is simplified as geometry only, UVs dropped. A non-manifold or inconsistently
// oriented input is repaired (a one-line warning says what changed) unless --no-repair. --max-error E guarantees a
// Hausdorff distance of at most E (a fraction of the input's diagonal) between output and input (Hausdorff_bound.h).
// Outputs are written atomically. The geometry is simplified by one call of simplify_mesh() (the target, the ratio's
// rounding and the engine are its own).
#include "cli_common.h"
#include "collapse_progress.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>
#ifdef CMGEOM_HAS_OSMESA
#include <CMGeom/Textured_simplification/Osmesa_index_texture_resampler.h>
#endif

#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
using Mesh = CMGeom::Surface_mesh;

}  // namespace

CMGEOM_CLI_COMMAND(simplify,
                   "Simplify a triangle mesh by quadric edge collapse (plain quadrics and the memoryful cost; --policy "
                   "weighted: the weighted quadrics of thesis §3.4)") {
  struct Options {
    std::string input, output, policy = "plain", engine = "cmgeom", merge = "thesis";
    std::string texture_backend = "cpu", texture;
    std::size_t faces = 0;
    double ratio = 0, max_cost = 0, max_error = 0;
    int texture_size = 0, fit_rounds = 3;
    double fit_min_points = TS::Surface_fit_options().min_points_per_face;
    std::size_t memory_points = 0;
    bool flips = false, json = false, no_repair = false, allow_degenerate = false, drop_repeated = false,
         no_texture = false, freeze_seams = false, memoryless = false, prune = false;
    bool keep_charts = false, bake_lookups = false;
    CMGeom::IO::Gltf_options gltf;
  };
  auto o = std::make_shared<Options>();
  app.add_option("input", o->input, "Input mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  app.add_option("-o,--output", o->output, "Output mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  cmgeom_cli::add_gltf_options(app, o->gltf);
  auto* faces = app.add_option("--faces", o->faces, "Target number of faces");
  auto* ratio = app.add_option("--ratio", o->ratio, "Target fraction of the input faces, in (0, 1]");
  faces->excludes(ratio);
  ratio->excludes(faces);
  auto* max_cost = app.add_option("--max-cost", o->max_cost,
                                  "Geometry only: stop when the cheapest collapse left costs more than this (quadric "
                                  "error: area x squared distance, see the manual); with --faces or --ratio, whichever "
                                  "comes first");
  auto* max_error = app.add_option(
      "--max-error", o->max_error,
      "Guaranteed bound on the Hausdorff distance between output and input (both ways), as a fraction of the "
      "input's bounding-box diagonal, e.g. 0.005: collapses that could exceed it are refused. Alone: simplify as "
      "far as the bound allows; with --faces or --ratio, whichever comes first. With --keep-charts the run "
      "also ends where no collapse keeps the charts");
  app.add_option("--policy", o->policy,
                 "Cost: plain (Garland-Heckbert, the default: lowest measured error) or weighted (thesis §3.4.2)")
      ->check(CLI::IsMember({"weighted", "plain"}));
  app.add_option("--merge", o->merge,
                 "Weighted policy's quadric merge: thesis ((w_i Q_i + w_j Q_j)/(w_i + w_j), 3.4.2) or sum "
                 "(Q_i + Q_j: lower global error, weaker feature preservation)")
      ->check(CLI::IsMember({"thesis", "sum"}));
  app.add_option("--engine", o->engine, "Collapse engine: cmgeom (fast) or cgal (CGAL's edge_collapse)")
      ->check(CLI::IsMember({"cmgeom", "cgal"}));
  app.add_flag("--flips", o->flips, "Flip-test the edges around each collapse (thesis §3.5.1; cmgeom engine)");
  app.add_flag("--prune", o->prune,
               "Remove whole connected components (small parts, debris) when that costs less than the next "
               "collapse, never below the target; gives their faces to the rest. Needs --faces or --ratio; not "
               "with --max-error, --max-cost, --keep-charts or --engine cgal");
  app.add_flag("--json", o->json, "Print a JSON report on stdout");
  cmgeom_cli::add_repair_by_default_options(app, o->no_repair);
  cmgeom_cli::add_allow_degenerate_option(app, o->allow_degenerate);
  cmgeom_cli::add_drop_repeated_option(app, o->drop_repeated);
  auto* backend = app.add_option("--texture-backend", o->texture_backend,
                                 "Index-texture resampling backend (textured input): cpu (reference) or osmesa")
                      ->check(CLI::IsMember({"cpu", "osmesa"}));
  auto* tsize =
      app.add_option("--texture-size", o->texture_size,
                     "Texels per UV unit of the index and output textures (default: the input texture's size)");
  app.add_option("--texture", o->texture, "Diffuse texture for an input whose file names none (e.g. spot.obj)");
  app.add_flag("--no-texture", o->no_texture, "Geometry only even for a textured input (UVs dropped)");
  app.add_flag("--memoryless", o->memoryless,
               "Quadric cost alone: no memoryful term (the input's points kept on the faces, Surface_memory.h)");
  app.add_option(
         "--fit-rounds", o->fit_rounds,
         "Rounds of the final fit of the vertices to the input's points (least squares, with the memoryful "
         "term; 0 = none; not with --max-error, whose bound holds for the collapsed positions; not when the output "
         "has fewer input points per face than --fit-min-points: by default above about 1/6 of the input's faces). "
         "Default 3")
      ->check(CLI::Range(0, 100));
  cmgeom_cli::add_fit_min_points_option(app, o->fit_min_points);
  auto* memory_points = cmgeom_cli::add_memory_points_option(app, o->memory_points);
  app.add_flag("--keep-charts", o->keep_charts,
               "Textured input: keep the input's charts (thesis §3.5; stops where no collapse keeps them) instead of "
               "baking a new atlas");
  app.add_flag("--bake-lookups", o->bake_lookups,
               "Textured input: look up every texel of the new atlas on the input (the closest facing point) instead "
               "of painting it from the input followed down the collapses (slower; for comparison)");
  app.add_flag("--freeze-seams", o->freeze_seams,
               "Textured input, with --keep-charts: never move chart-boundary vertices (baseline)");

  return [o, faces, ratio, max_cost, max_error, backend, tsize, memory_points]() -> int {
    if (faces->count() == 0 && ratio->count() == 0 && max_cost->count() == 0 && max_error->count() == 0)
      throw CMGeom::Invalid_input("one of --faces, --ratio, --max-cost or --max-error is required");
    if (max_error->count() && !(o->max_error > 0 && std::isfinite(o->max_error)))
      throw CMGeom::Invalid_input("--max-error must be finite and > 0, got " + std::to_string(o->max_error));
    if (ratio->count() && !(o->ratio > 0 && o->ratio <= 1))
      throw CMGeom::Invalid_input("--ratio must be in (0, 1], got " + std::to_string(o->ratio));
    if (faces->count() && o->faces == 0) throw CMGeom::Invalid_input("--faces must be at least 1");
    if (max_cost->count() && !(o->max_cost >= 0 && std::isfinite(o->max_cost)))
      throw CMGeom::Invalid_input("--max-cost must be finite and >= 0, got " + std::to_string(o->max_cost));
    if (o->flips && o->engine == "cgal")
      throw CMGeom::Invalid_input("--flips needs --engine cmgeom (CGAL's engine has no flip hook)");
    if (o->prune && faces->count() == 0 && ratio->count() == 0)
      throw CMGeom::Invalid_input("--prune needs a face target (--faces or --ratio)");
    if (o->prune && (max_error->count() || max_cost->count()))
      throw CMGeom::Invalid_input("--prune cannot be combined with --max-error or --max-cost");
    if (o->prune && o->engine == "cgal") throw CMGeom::Invalid_input("--prune needs --engine cmgeom");
    if (memory_points->count() && (o->memoryless || o->engine == "cgal"))
      throw CMGeom::Invalid_input(
          "--memory-points applies to the memoryful term (not with --memoryless or --engine cgal)");

    // A file without texture coordinates (or read with --no-texture) is read as geometry alone:
    // its mesh has no corner UV and face material maps (on a 1M-face mesh the UVs alone are
    // 51 MB, a fifth of the memory at the reading's peak).
    CMGeom::Textured_mesh tm;
    Mesh geometry;
    CMGeom::IO::Read_options ro;
    ro.repair = !o->no_repair;
    ro.allow_degenerate_faces = o->allow_degenerate;
    ro.drop_repeated_vertex_faces = o->drop_repeated;
    std::vector<std::string> warnings;
    const double read_start = cmgeom_cli::now_seconds();
    bool file_uvs = false, geometry_only = false;
    {
      const CMGeom::Polygon_soup soup = CMGeom::IO::read_polygon_soup(o->input);
      warnings = soup.warnings;
      ro.warnings = &warnings;
      file_uvs = soup.faces_have_uvs();  // as the reader decides
      geometry_only = !file_uvs || o->no_texture;
      if (geometry_only)
        CMGeom::IO::build_surface_mesh(soup, geometry, ro);
      else
        CMGeom::IO::build_textured_mesh(soup, tm, ro);
    }
    const double seconds_read = cmgeom_cli::now_seconds() - read_start;
    cmgeom_cli::print_warnings("simplify", warnings);
    Mesh& mesh = geometry_only ? geometry : tm.mesh();
    if (!CGAL::is_triangle_mesh(mesh)) throw CMGeom::Invalid_input(o->input + ": not a triangle mesh");
    if (!o->no_texture) {
      cmgeom_cli::apply_texture_option(tm, o->input, o->texture);
      cmgeom_cli::refuse_unnamed_texture(tm, o->input, "to simplify it textured");
    }
    const bool textured = tm.has_uvs() && cmgeom_cli::names_a_texture(tm) && !o->no_texture;
    if (o->keep_charts && !textured)
      throw CMGeom::Invalid_input(o->input +
                                  ": --keep-charts needs a textured input (UVs and a texture; see --texture)");
    if (o->freeze_seams && !o->keep_charts) throw CMGeom::Invalid_input("--freeze-seams needs --keep-charts");
    if (backend->count() && !o->keep_charts)
      throw CMGeom::Invalid_input("--texture-backend selects the index-texture resampler of --keep-charts");
    if ((backend->count() || tsize->count() || o->freeze_seams) && !textured)
      throw CMGeom::Invalid_input(o->input +
                                  ": texture options need a textured input (UVs and a texture; see --texture)");

    const std::size_t faces_in = mesh.number_of_faces();
    // the face target (none with --max-cost or --max-error alone: the progress bar then counts towards
    // a single face, and its final line gives the faces actually removed)
    const bool has_target = faces->count() || ratio->count();
    const std::size_t target = faces->count()   ? o->faces
                               : ratio->count() ? TS::target_faces_for_ratio(faces_in, o->ratio)
                                                : std::size_t(1);

    TS::Quadric_options qo;
    qo.weighted = o->policy == "weighted";
    qo.merge = o->merge == "sum" ? TS::Quadric_merge::sum : TS::Quadric_merge::weighted_average;
    // the merge actually used, for the report: plain quadrics always sum
    const std::string merge_used = qo.weighted ? o->merge : std::string("sum");
    cmgeom_cli::Progress bar("simplify", double(faces_in > target ? faces_in - target : 0), "faces removed");
    if (textured) {
      if (o->engine != "cmgeom") throw CMGeom::Invalid_input("textured simplification runs on --engine cmgeom only");
      if (max_cost->count())
        throw CMGeom::Invalid_input("--max-cost simplifies geometry only: pass --no-texture (or --faces / --ratio)");
      if (o->prune && o->keep_charts)
        throw CMGeom::Invalid_input("--prune is not supported with --keep-charts; drop --keep-charts");
      if (o->flips && o->keep_charts)
        throw CMGeom::Invalid_input(
            "--flips is not supported with --keep-charts (flips would need UV rules); drop "
            "--keep-charts: the new atlas is made after the flips");
#ifndef CMGEOM_HAS_OSMESA
      if (o->texture_backend == "osmesa")
        throw CMGeom::Invalid_input("--texture-backend osmesa is not available in this build (no OSMesa); use cpu");
#endif
      if (tsize->count() && (o->texture_size < 16 || o->texture_size > 16384))
        throw CMGeom::Invalid_input("--texture-size must be in [16, 16384], got " + std::to_string(o->texture_size));
      const std::string ext = CMGeom::IO::extension(o->output);
      if (ext != ".obj" && ext != ".gltf" && ext != ".glb")
        throw CMGeom::Invalid_input(o->output + ": textured output must be .obj, .gltf or .glb (or pass --no-texture)");
      CMGeom::IO::load_textures(tm);
      TS::Textured_simplification_options to;
      to.target_faces = has_target ? target : 0;
      if (max_error->count()) to.max_error = o->max_error;
      to.quadric = qo;
      to.texture_size = o->texture_size;
      to.constraints.freeze_chart_boundaries = o->freeze_seams;
      to.keep_charts = o->keep_charts;
      to.flips = o->flips;
      to.prune_components = o->prune;
      to.surface_memory = !o->memoryless;
      to.memory.fit.rounds = o->fit_rounds;
      to.memory.fit.min_points_per_face = o->fit_min_points;
      to.memory.max_points = o->memory_points;
      to.paint_from_history = !o->bake_lookups;
      cmgeom_cli::Collapse_progress state{&bar, double(faces_in > target ? faces_in - target : 0)};
      const double t0 = cmgeom_cli::now_seconds();
#ifdef CMGEOM_HAS_OSMESA
      const TS::Textured_simplification_result r =
          o->texture_backend == "osmesa"
              ? TS::simplify_textured_mesh<TS::Osmesa_index_texture_resampler>(tm, to, state.visitor())
              : TS::simplify_textured_mesh(tm, to, state.visitor());
#else
      const TS::Textured_simplification_result r = TS::simplify_textured_mesh(tm, to, state.visitor());
#endif
      const double seconds = cmgeom_cli::now_seconds() - t0;
      state.done(r.faces_in, r.faces_out);
      const double write_start = cmgeom_cli::now_seconds();
      CMGeom::IO::write_textured_mesh(o->output, tm, o->gltf);
      const double seconds_write = cmgeom_cli::now_seconds() - write_start;
      if (r.stopped_by != TS::Stop_reason::target && has_target)  // (a bound alone ends where it stops)
        std::cerr
            << "cmgeom simplify: stopped at " << r.faces_out << " faces for a target of " << target << " ("
            << (r.stopped_by == TS::Stop_reason::chart_limit
                    ? "chart limit: no collapse left that keeps the input's charts; drop --keep-charts to go further"
                : r.stopped_by == TS::Stop_reason::max_error
                    ? (o->keep_charts ? "no collapse left that keeps both the input's charts and --max-error"
                                      : "no collapse left within --max-error")
                    : cmgeom_cli::no_collapse_reason(tm.mesh(), !o->prune))
            << ")\n";
      if (o->json) {
        nlohmann::ordered_json j;
        j["input"] = o->input;
        j["output"] = o->output;
        j["engine"] = o->engine;
        j["policy"] = o->policy;
        j["merge"] = merge_used;
        j["textured"] = true;
        j["charts"] = r.charts_kept ? "kept" : "rebuilt";
        j["flips"] = o->flips;
        j["prune"] = o->prune;
        j["surface_memory"] = !o->memoryless && !r.charts_kept;
        if (!r.charts_kept) {
          j["texels_baked"] = r.atlas.texels_baked;
          j["texels_painted"] = r.atlas.texels_painted;
        }
        if (r.charts_kept) j["texture_backend"] = o->texture_backend;
        j["faces_in"] = r.faces_in;
        if (has_target) j["target_faces"] = target;
        if (max_error->count()) {
          j["max_error"] = o->max_error;
          j["error_bound"] = r.error_bound;
        }
        j["faces_out"] = r.faces_out;
        j["stopped_by"] = TS::to_string(r.stopped_by);
        j["vertices_out"] = mesh.number_of_vertices();
        j["charts_in"] = r.charts_in;
        j["charts_out"] = r.charts_out;
        j["texture_width"] = r.texture_width;
        j["texture_height"] = r.texture_height;
        if (r.charts_kept) {
          j["refused_topology"] = r.statistics.topology;
          j["refused_uv_fold"] = r.statistics.uv_fold;
          j["refused_projection_overlap"] = r.statistics.projection_overlap;
        } else {
          j["atlas_coverage"] = r.atlas.coverage;
          j["texels_per_unit"] = r.atlas.texels_per_unit;
          j["seconds_charts"] = r.atlas.seconds_charts;
          j["seconds_bake"] = r.atlas.seconds_bake;
        }
        j["seconds"] = seconds;
        j["seconds_collapse"] = r.seconds_collapse;
        j["seconds_texture"] = r.seconds_texture;
        j["seconds_read"] = seconds_read;
        j["seconds_write"] = seconds_write;
        cmgeom_cli::print_json(j);
      } else {
        std::cout << o->input << ": " << r.faces_in << " -> " << r.faces_out << " faces, " << r.charts_in << " -> "
                  << r.charts_out << " charts in " << seconds << " s (textured, "
                  << (r.charts_kept ? "charts kept" : "new atlas") << ", " << o->policy << " policy)\n";
      }
      return 0;
    }
    if (file_uvs)
      std::cerr << "cmgeom simplify: note: texture coordinates are dropped (geometry-only simplification)\n";
    cmgeom_cli::Collapse_progress state{&bar, double(faces_in > target ? faces_in - target : 0)};
    TS::Mesh_simplification_options so;
    if (faces->count()) so.target_faces = o->faces;
    if (ratio->count()) so.target_ratio = o->ratio;
    if (max_cost->count()) so.max_cost = o->max_cost;
    if (max_error->count()) so.max_error = o->max_error;
    so.engine = o->engine == "cgal" ? TS::Simplification_engine::cgal : TS::Simplification_engine::cmgeom;
    so.quadric = qo;
    so.surface_memory = !o->memoryless && o->engine == "cmgeom";
    so.memory.fit.rounds = o->fit_rounds;
    so.memory.fit.min_points_per_face = o->fit_min_points;
    so.memory.max_points = o->memory_points;
    so.flips = o->flips;
    so.prune_components = o->prune;
    so.release_input_in_parts = true;  // the input is the file
    // Geometry only: the mesh is simplified without corner UV and face material maps (a textured
    // file simplified as geometry gives its maps up here), then wrapped in a new Textured_mesh
    // for writing.
    if (!geometry_only) {
      geometry = std::move(mesh);
      tm.clear();
    }
    auto uv = geometry.property_map<Mesh::Halfedge_index, CMGeom::Point_2>("h:uv");
    if (uv.second) geometry.remove_property_map(uv.first);
    auto material = geometry.property_map<Mesh::Face_index, int>("f:material");
    if (material.second) geometry.remove_property_map(material.first);
    const TS::Mesh_simplification_result r = TS::simplify_mesh(geometry, so, state.visitor());
    const double seconds = r.seconds;
    state.done(r.faces_in, r.faces_out);
    const std::size_t faces_out = r.faces_out;
    if ((r.stopped_by == TS::Stop_reason::no_collapse || r.stopped_by == TS::Stop_reason::max_error) && has_target)
      std::cerr << "cmgeom simplify: stopped at " << faces_out << " faces for a target of " << target << " ("
                << (r.stopped_by == TS::Stop_reason::max_error
                        ? std::string("no collapse left within --max-error")
                        : cmgeom_cli::no_collapse_reason(geometry, !o->prune && o->engine == "cmgeom"))
                << ")\n";

    const CMGeom::Textured_mesh result(std::move(geometry),
                                       CMGeom::Textured_mesh::without_uv_map);  // no UVs, no materials
    const double write_start = cmgeom_cli::now_seconds();
    CMGeom::IO::write_textured_mesh(o->output, result, o->gltf);
    const double seconds_write = cmgeom_cli::now_seconds() - write_start;

    if (o->json) {
      nlohmann::ordered_json j;
      j["input"] = o->input;
      j["output"] = o->output;
      j["engine"] = o->engine;
      j["policy"] = o->policy;
      j["merge"] = merge_used;
      j["flips"] = o->flips;
      j["prune"] = o->prune;
      j["surface_memory"] = !o->memoryless && o->engine == "cmgeom";
      j["fit_rounds"] = so.surface_memory && !max_error->count() ? o->fit_rounds : 0;
      j["fit_min_points"] = o->fit_min_points;
      j["fit_moves"] = r.fit_moves;
      j["memory_points"] = so.surface_memory ? o->memory_points : 0;
      j["faces_in"] = faces_in;
      if (has_target) j["target_faces"] = target;
      if (max_cost->count()) j["max_cost"] = o->max_cost;
      if (max_error->count()) {
        j["max_error"] = o->max_error;
        j["error_bound"] = r.error_bound;
      }
      j["faces_out"] = faces_out;
      j["stopped_by"] = TS::to_string(r.stopped_by);
      j["vertices_out"] = result.mesh().number_of_vertices();
      j["seconds"] = seconds;
      j["parts"] = r.parts;
      j["faces_after_parts"] = r.faces_after_parts;
      j["seconds_parts"] = r.seconds_parts;
      j["seconds_fit"] = r.seconds_fit;
      j["seconds_read"] = seconds_read;
      j["seconds_write"] = seconds_write;
      cmgeom_cli::print_json(j);
    } else {
      std::cout << o->input << ": " << faces_in << " -> " << faces_out << " faces in " << seconds << " s (" << o->engine
                << " engine, " << o->policy << " policy" << (o->flips ? ", flips" : "") << ")\n";
    }
    return 0;
  };
}
