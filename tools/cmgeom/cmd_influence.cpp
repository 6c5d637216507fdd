// cmgeom influence <mesh> (--cages <system.json> | --grid nx,ny,nz [--h 0.6]) -o map.png
//                  [--values d.txt] [--view az,el|preset] [--size WxH] [--caption text] [--json]
// Influence map of a *Cages system (thesis §5.3.3, Fig. 5.2-5.3): for every mesh vertex p in leaf
// cage C_i the value d_i(p) = f_{h_i}(Π_j (1 − w_ij(p))), 1 where the cage's own transformation
// T_i is applied alone and 0 on the borders, where the join transformation takes over. The map is
// drawn on the rest pose with the Rendering package (colour map 0..1 with a legend); --values
// writes the values (one per line, input vertex order) and may replace -o.
#include "cli_common.h"

#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#include <CMGeom/Rendering/render_to_png.h>
#include <CMGeom/Rendering/views.h>

#include <cstdio>  // snprintf
#include <iostream>
#include <memory>
#include <sstream>

CMGEOM_CLI_COMMAND(influence, "Influence map d_i of a *Cages system on a mesh (PNG and/or values)") {
  namespace CD = CMGeom::Cage_deformation;
  struct Args {
    cmgeom_cli::Cage_source cages;
    std::string mesh, output, values, view = "iso", size = "1024x1024", caption;
    bool as_json = false;
  };
  auto a = std::make_shared<Args>();
  app.add_option("mesh", a->mesh, "Mesh (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  cmgeom_cli::add_cage_source_options(app, a->cages, cmgeom_cli::Cage_grid_options::mean_value);
  app.add_option("-o,--output", a->output, "Output PNG");
  app.add_option("--values", a->values, "Write d_i per vertex (one per line, input vertex order)");
  app.add_option("--view", a->view, "az,el in degrees or front|back|left|right|top|bottom|iso (default iso)");
  app.add_option("--size", a->size, "Picture size WxH (default 1024x1024)");
  app.add_option("--caption", a->caption, "Caption in the bottom-left corner");
  app.add_flag("--json", a->as_json, "Print counts as JSON");
  return [a]() -> int {
    a->cages.require();
    if (a->output.empty() && a->values.empty()) throw CMGeom::Invalid_input("give -o <map.png> and/or --values <file>");
    a->cages.check_h();
    const auto [w, hgt] = cmgeom_cli::parse_picture_size(a->size);
#ifndef CMGEOM_HAS_OSMESA
    if (!a->output.empty()) throw CMGeom::Error(CMGeom::Rendering::rendering_unavailable_message());
#endif
    // Drawn as the file holds it (polygon soup), like `cmgeom render`.
    const CMGeom::Polygon_soup soup = cmgeom_cli::read_polygon_soup_with_progress(a->mesh);
    for (const std::string& s : soup.warnings) std::cerr << "cmgeom influence: warning: " << s << "\n";
    if (soup.positions.empty()) throw CMGeom::Invalid_input(a->mesh + ": no vertices");
    const CD::Cage_system_description desc = a->cages.description(soup.positions);
    auto setup_stage = std::make_unique<cmgeom_cli::Progress>("cage setup", double(desc.cages.size()), "cages");
    const CD::Cage_system sys(desc);
    setup_stage.reset();
    // Only d_i is needed: float weights keep the binding small.
    cmgeom_cli::Progress bind_stage("bind", double(soup.positions.size()), "vertices");
    const CD::Cage_system_binding<float> b =
        sys.bind<float>(soup.positions, CD::Sine_smoothing(), CD::Sine_h_smoothing(), bind_stage.hook());
    bind_stage.done();
    std::vector<double> d(b.influence().begin(), b.influence().end());

    if (!a->values.empty()) {
      std::ostringstream s;
      for (double x : d) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.9g\n", x);
        s << buf;
      }
      CMGeom::IO::write_file_atomically(a->values, s.str());
    }
#ifdef CMGEOM_HAS_OSMESA
    if (!a->output.empty()) {
      namespace R = CMGeom::Rendering;
      R::Render_mesh rm = R::make_render_mesh(soup, &d);
      R::Render_options o;
      o.width = w;
      o.height = hgt;
      o.shading = R::Shading::Field;
      o.field_min = 0;
      o.field_max = 1;
      o.legend_label = "influence d";
      o.caption = a->caption;
      const R::View v = R::parse_view(a->view);
      o.view(v.azimuth, v.elevation);
      // One draw call: the stage reports its end only.
      cmgeom_cli::Progress stage("render", 1, "pictures");
      R::Renderer renderer;
      CMGeom::IO::write_image(a->output, R::render_picture(renderer, rm, o));
    }
#endif
    double mean = 0;
    for (double x : d) mean += x;
    mean /= double(d.size());
    nlohmann::ordered_json j;
    j["input"] = a->mesh;
    j["vertices"] = d.size();
    j["cages"] = desc.cages.size();
    j["leaf_cages"] = sys.leaf_cages().size();
    j["join_cages"] = sys.number_of_join_cages();
    j["joined_vertices"] = b.joined_points();
    j["outside_vertices"] = b.outside();
    j["mean_influence"] = mean;
    if (a->as_json)
      cmgeom_cli::print_json(j);
    else
      std::cout << "influence of " << sys.leaf_cages().size() << " leaf cages on " << d.size()
                << " vertices: " << b.joined_points() << " with join terms (d < 1), mean d " << mean << "\n";
    return 0;
  };
}
