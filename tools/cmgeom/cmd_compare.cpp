// cmgeom compare <reference> <approximation> [--size N] [--json] [-o grid.png] [--texture image.png]
// Image-space error (thesis §2.3.2.1, eq. 2.1; Rendering/image_space_error.h): both meshes are
// rendered from the 26 cube views at N x N pixels with identical lighting and camera, the
// approximation wearing the reference's texture; RMSE (8-bit units) and PSNR over the pixels
// covered by either mesh. -o writes a grid of the six axis views: reference, approximation and
// their difference (viridis, 0 to a quarter of the largest possible RGB distance).
#include "cli_common.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Rendering/colormap.h>
#include <CMGeom/Rendering/compose.h>
#include <CMGeom/Rendering/image_space_error.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#include <CMGeom/Rendering/render_to_png.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

namespace {

nlohmann::ordered_json psnr_json(double psnr) {
  return std::isfinite(psnr) ? nlohmann::ordered_json(psnr) : nlohmann::ordered_json(nullptr);
}

// Per-pixel RGB distance through the colour map; uncovered pixels stay white.
CMGeom::Image difference_picture(const CMGeom::Image& a, const CMGeom::Image& b) {
  CMGeom::Image d(a.width(), a.height(), 3);
  const double full = 255. * std::sqrt(3.) / 4.;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) {
      std::array<std::uint8_t, 3> c{{255, 255, 255}};
      if (a.bytes()[a.index(x, y, 3)] || b.bytes()[b.index(x, y, 3)]) {
        double s = 0.;
        for (int k = 0; k < 3; ++k) {
          const double e = double(a.bytes()[a.index(x, y, k)]) - double(b.bytes()[b.index(x, y, k)]);
          s += e * e;
        }
        c = CMGeom::Rendering::viridis(std::sqrt(s) / full);
      }
      for (int k = 0; k < 3; ++k) d.bytes()[d.index(x, y, k)] = c[k];
    }
  return d;
}

}  // namespace

CMGEOM_CLI_COMMAND(compare, "Image-space error (RMSE, PSNR) between two meshes over 26 views") {
  auto reference = std::make_shared<std::string>();
  auto approximation = std::make_shared<std::string>();
  auto output = std::make_shared<std::string>();
  auto size = std::make_shared<int>(512);
  auto json = std::make_shared<bool>(false);
  auto texture = std::make_shared<std::string>();
  auto reference_texture = std::make_shared<bool>(false);
  app.add_option("reference", *reference, "Reference (original) mesh")->required();
  app.add_option("approximation", *approximation, "Approximating mesh")->required();
  app.add_option("-o,--output", *output, "Write a PNG grid: reference / approximation / difference, 6 axis views");
  app.add_option("--size", *size, "Render size N (N x N pixels per view, default 512)")->check(CLI::Range(16, 4096));
  app.add_flag("--json", *json, "Print a JSON object instead of text");
  app.add_option("--texture", *texture, "Texture image of the reference when its file names none");
  app.add_flag("--reference-texture", *reference_texture,
               "Draw the approximation with the reference's texture even when it has its own");
  return [=]() -> int {
#ifndef CMGEOM_HAS_OSMESA
    throw CMGeom::Error(CMGeom::Rendering::rendering_unavailable_message());
#else
    namespace R = CMGeom::Rendering;
    // Drawn as the files hold them (polygon soups). The approximation wears its own texture when
    // its file names one (a textured simplification has a new atlas), else the reference's.
    CMGeom::Polygon_soup ref = cmgeom_cli::read_polygon_soup_with_progress(*reference);
    CMGeom::Polygon_soup app_mesh = cmgeom_cli::read_polygon_soup_with_progress(*approximation);
    if (texture->empty()) cmgeom_cli::load_soup_textures(ref);
    if (!*reference_texture) cmgeom_cli::load_soup_textures(app_mesh);
    R::Render_mesh a = R::make_render_mesh(ref);
    const R::Render_mesh b = R::make_render_mesh(app_mesh);
    CMGeom::Image image;
    if (!texture->empty()) {
      if (!ref.has_uvs()) throw CMGeom::Invalid_input(*reference + ": --texture needs texture coordinates");
      image = CMGeom::IO::read_image(*texture);
      for (auto& r : a.ranges) r.texture = &image;
    }
    R::Image_space_error_options opt;
    opt.size = *size;
    if (*reference_texture) opt.approximation_texture = R::Image_space_error_options::Approximation_texture::Reference;
    opt.keep_images = !output->empty();
    R::Renderer renderer;
    // The views are drawn inside image_space_error(), which has no hook: the stage reports its
    // end only.
    auto stage = std::make_unique<cmgeom_cli::Progress>("render views", double(2 * opt.views.size()), "pictures");
    const double t0 = cmgeom_cli::now_seconds();
    const R::Image_space_error e = R::image_space_error(renderer, a, b, opt);
    const double t1 = cmgeom_cli::now_seconds();
    stage.reset();
    if (!output->empty()) {
      std::vector<CMGeom::Image> cells;
      std::vector<std::string> captions;
      std::vector<std::size_t> axis;  // views with exactly one non-zero direction component
      for (std::size_t i = 0; i < opt.views.size(); ++i) {
        const double az = opt.views[i].azimuth, el = opt.views[i].elevation;
        const bool az_axis = std::abs(az / 90. - std::round(az / 90.)) < 1e-9;
        if (std::abs(std::abs(el) - 90.) < 1e-9 || (std::abs(el) < 1e-9 && az_axis)) axis.push_back(i);
      }
      const char* rows[3] = {"ref", "approx", "diff"};
      for (int r = 0; r < 3; ++r)
        for (std::size_t i : axis) {
          if (r == 0)
            cells.push_back(R::to_rgb(e.reference_images[i]));
          else if (r == 1)
            cells.push_back(R::to_rgb(e.approximation_images[i]));
          else
            cells.push_back(difference_picture(e.reference_images[i], e.approximation_images[i]));
          captions.push_back(std::string(rows[r]) + " " + opt.views[i].name);
        }
      CMGeom::IO::write_image(*output, R::make_grid(cells, captions, int(axis.size())));
    }
    nlohmann::ordered_json j;
    j["reference"] = *reference;
    j["approximation"] = *approximation;
    j["rmse"] = e.total.rmse;
    j["psnr"] = psnr_json(e.total.psnr);
    j["views"] = e.total.views;
    j["size"] = *size;
    j["pixels"] = e.total.pixels;
    j["mean_squared_rgb"] = e.total.mean_squared_rgb;
    nlohmann::ordered_json pv = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < e.per_view.size(); ++i)
      pv.push_back(
          {{"view", opt.views[i].name}, {"rmse", e.per_view[i].rmse}, {"psnr", psnr_json(e.per_view[i].psnr)}});
    j["per_view"] = pv;
    j["seconds"] = t1 - t0;
    if (*json) {
      cmgeom_cli::print_json(j);
      return 0;
    }
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "views          %zu at %dx%d (%s)\nrmse           %.4f (8-bit units)\npsnr           %.2f dB\n"
                  "covered pixels %zu\ntime           %.2f s\n",
                  e.total.views, *size, *size, renderer.description().c_str(), e.total.rmse, e.total.psnr,
                  e.total.pixels, t1 - t0);
    std::cout << "reference      " << *reference << "\napproximation  " << *approximation << "\n" << buf;
    if (!output->empty()) std::cout << "grid           " << *output << "\n";
    return 0;
#endif
  };
}
