// cmgeom render <mesh> -o out.png [--view az,el|preset] [--views v1;v2;...] [--size WxH] [--flat]
//               [--no-texture] [--wireframe] [--charts] [--field values.txt|.ply] [--range lo,hi]
//               [--ortho] [--caption text] [--atlas atlas.png] [--texture image.png]
// Headless picture of a mesh (Rendering package). Textured meshes are drawn with their texture
// unless --no-texture; --field colours the per-vertex values (one per line, or the "quality"
// property of a PLY written by `cmgeom error --field`) with a legend; --views draws a grid of
// several views with their names as captions; --atlas also writes the texture atlas with its UV
// layout.
#include "cli_common.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#include <CMGeom/Rendering/render_to_png.h>
#include <CMGeom/Rendering/views.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace {

double parse_number(const std::string& s, const std::string& file, std::size_t line) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != 0) throw CMGeom::IO_error(file, line, "not a number: '" + s + "'");
  return v;
}

// One value per line (blank lines and '#' comments ignored), or the "quality" vertex property of
// an ASCII PLY.
// A field value: a finite number (a NaN or infinity would colour the mesh with garbage).
double parse_field_value(const std::string& tok, const std::string& path, std::size_t line) {
  const double v = parse_number(tok, path, line);
  if (!std::isfinite(v)) throw CMGeom::IO_error(path, line, "field value '" + tok + "' is not a finite number");
  return v;
}

std::vector<double> read_field(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw CMGeom::IO_error(path, "cannot open the field file");
  std::vector<double> values;
  std::string line;
  std::size_t n = 0;
  if (CMGeom::IO::extension(path) == ".ply") {
    std::size_t vertices = 0, index = 0, count = 0;
    long quality = -1;
    bool in_vertex = false;
    while (std::getline(in, line)) {
      ++n;
      std::istringstream ls(line);
      std::string a, b, c;
      ls >> a >> b >> c;
      if (a == "format" && b != "ascii") throw CMGeom::IO_error(path, n, "only ASCII PLY field files are supported");
      if (a == "element") {
        in_vertex = b == "vertex";
        if (in_vertex) vertices = std::size_t(parse_number(c, path, n));
      } else if (a == "property" && in_vertex) {
        if (c == "quality") quality = long(count);
        ++count;
      } else if (a == "end_header") {
        break;
      }
    }
    if (quality < 0) throw CMGeom::IO_error(path, "no 'quality' vertex property");
    while (index < vertices && std::getline(in, line)) {
      ++n;
      std::istringstream ls(line);
      std::string tok;
      for (long k = 0; k <= quality; ++k)
        if (!(ls >> tok)) throw CMGeom::IO_error(path, n, "vertex line with too few values");
      values.push_back(parse_field_value(tok, path, n));
      ++index;
    }
    if (index < vertices) throw CMGeom::IO_error(path, n, "file ends before the last vertex");
    return values;
  }
  while (std::getline(in, line)) {
    ++n;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream ls(line);
    std::string tok;
    if (!(ls >> tok)) continue;
    values.push_back(parse_field_value(tok, path, n));
    if (ls >> tok) throw CMGeom::IO_error(path, n, "expected one value per line");
  }
  return values;
}

}  // namespace

CMGEOM_CLI_COMMAND(render, "Render a mesh to a PNG picture (shaded, textured, wireframe, charts, fields)") {
  struct Args {
    std::string mesh, output, view = "iso", views, size = "1024x1024", field, range, caption, atlas, texture,
                              label = "value";
    bool flat = false, no_texture = false, wireframe = false, charts = false, ortho = false;
  };
  auto a = std::make_shared<Args>();
  app.add_option("mesh", a->mesh, "Mesh file (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  app.add_option("-o,--output", a->output, "Output PNG")->required();
  app.add_option("--view", a->view, "az,el in degrees or front|back|left|right|top|bottom|iso (default iso)");
  app.add_option("--views", a->views, "Several views separated by ';' (grid with captions), e.g. 'front;left;top'");
  app.add_option("--size", a->size, "Picture (or grid cell) size WxH (default 1024x1024)");
  app.add_flag("--flat", a->flat, "Flat shading (one normal per face)");
  app.add_flag("--no-texture", a->no_texture, "Ignore the texture of a textured mesh");
  app.add_flag("--wireframe", a->wireframe, "Draw the edges");
  app.add_flag("--charts", a->charts, "Draw the chart boundaries (UV seams) in red");
  app.add_option("--field", a->field,
                 "Per-vertex values (.txt one per line, or .ply 'quality') shown with a colour map");
  app.add_option("--range", a->range, "Colour-map range lo,hi (default: range of the values)");
  app.add_option("--label", a->label, "Title of the colour-map legend (default 'value')");
  app.add_flag("--ortho", a->ortho, "Orthographic projection");
  app.add_option("--caption", a->caption, "Caption in the bottom-left corner");
  app.add_option("--atlas", a->atlas, "Also write the texture atlas with its UV layout to this PNG");
  app.add_option("--texture", a->texture,
                 "Texture image for a mesh with UVs but no material (replaces the material's)");
  return [a]() -> int {
#ifndef CMGEOM_HAS_OSMESA
    throw CMGeom::Error(CMGeom::Rendering::rendering_unavailable_message());
#else
    namespace R = CMGeom::Rendering;
    const auto [w, h] = cmgeom_cli::parse_picture_size(a->size);
    // Drawn as the file holds it (polygon soup): non-manifold input needs no repair.
    CMGeom::Polygon_soup tm = cmgeom_cli::read_polygon_soup_with_progress(a->mesh);
    cmgeom_cli::print_warnings("render", tm.warnings);
    if (a->texture.empty() && !a->no_texture) cmgeom_cli::load_soup_textures(tm);
    std::vector<double> field;
    if (!a->field.empty()) {
      field = read_field(a->field);
      if (field.size() != tm.positions.size())
        throw CMGeom::Invalid_input(a->field + ": " + std::to_string(field.size()) + " values for " +
                                    std::to_string(tm.positions.size()) + " vertices of " + a->mesh);
    }
    R::Render_mesh rm = R::make_render_mesh(tm, field.empty() ? nullptr : &field);
    CMGeom::Image texture;
    if (!a->texture.empty()) {
      if (!tm.has_uvs()) throw CMGeom::Invalid_input(a->mesh + ": --texture needs texture coordinates");
      texture = CMGeom::IO::read_image(a->texture);
      for (auto& r : rm.ranges) r.texture = &texture;
    }
    R::Render_options o;
    o.width = w;
    o.height = h;
    o.shading = !field.empty()                     ? R::Shading::Field
                : (rm.texture() && !a->no_texture) ? R::Shading::Textured
                : a->flat                          ? R::Shading::Flat
                                                   : R::Shading::Smooth;
    o.wireframe = a->wireframe;
    o.charts = a->charts;
    if (a->charts && !tm.has_uvs()) throw CMGeom::Invalid_input(a->mesh + ": --charts needs texture coordinates");
    if (a->ortho) o.projection = R::Projection::Orthographic;
    if (!a->range.empty()) {
      const auto comma = a->range.find(',');
      if (comma == std::string::npos) throw CMGeom::Invalid_input("bad --range '" + a->range + "': expected lo,hi");
      o.field_min = parse_number(a->range.substr(0, comma), "--range", 0);
      o.field_max = parse_number(a->range.substr(comma + 1), "--range", 0);
    }
    if (!field.empty()) o.legend_label = a->label;
    // A picture is one draw call, which has no hook: the stage advances by views.
    cmgeom_cli::Progress stage("render");
    R::Renderer renderer;
    if (a->views.empty()) {
      const R::View v = R::parse_view(a->view);
      o.view(v.azimuth, v.elevation);
      o.caption = a->caption;
      stage.set_total(1, "pictures");
      CMGeom::IO::write_image(a->output, R::render_picture(renderer, rm, o));
    } else {
      std::vector<std::string> names;
      std::stringstream ss(a->views);
      std::string item;
      while (std::getline(ss, item, ';'))
        if (!item.empty()) names.push_back(item);
      stage.set_total(double(names.size()), "pictures");
      std::vector<CMGeom::Image> cells;
      for (const std::string& n : names) {
        const R::View v = R::parse_view(n);
        o.view(v.azimuth, v.elevation);
        cells.push_back(R::render_picture(renderer, rm, o));
        stage.update(double(cells.size()) / double(names.size()));
      }
      if (!a->caption.empty())
        for (auto& n : names) n = a->caption + " " + n;
      CMGeom::IO::write_image(a->output, R::make_grid(cells, names, int(std::ceil(std::sqrt(double(cells.size()))))));
    }
    stage.done();
    if (!a->atlas.empty()) {
      if (!tm.has_uvs()) throw CMGeom::Invalid_input(a->mesh + ": --atlas needs texture coordinates");
      cmgeom_cli::Progress atlas_stage("render atlas", 1, "pictures");
      CMGeom::IO::write_image(a->atlas, R::to_rgb(renderer.render_uv_atlas(rm, std::min(w, h))));
    }
    return 0;
#endif
  };
}
