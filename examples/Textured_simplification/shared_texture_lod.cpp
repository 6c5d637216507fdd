// Levels of detail that share one texture (the thesis' future work, §7.1): one simplification run
// gives every level (simplify_to_levels()), the coarsest level's atlas is the only texture, and
// every finer level addresses it through the collapse history, so a renderer streams one texture
// and swaps geometry. Parts of the input the shared atlas would show badly get charts of their
// own in a strip under it; besides the geometric tests, the colours each finer face reads from
// the atlas are checked against a bake's (`overflow_colour_tolerance`).
//
// The example builds the chain three ways on the same input: an atlas per level (the reference),
// one shared atlas with the colour check off, and one shared atlas with it on (the default). For
// each level it measures the colour a face shows against the colour a bake of the input gives
// that point, sampled at four points of every face, and writes the shared chain as one GLB
// (MSFT_lod, one texture). This measure sees colour alone: an atlas of the level's own is
// near 0 by construction (it is painted and baked from the same input), so the price of sharing
// looks larger here than in rendered images, where both chains have the same geometry (the
// manual compares the chains by image error).
//
//   shared_texture_lod [mesh.obj] [ratios]   (default: data/spot/spot.obj, "1,0.25,0.05")
// Writes shared_texture_lod.glb in the current directory.
#include <CMGeom/Mesh_IO.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification/level_of_detail.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace TS = CMGeom::Textured_simplification;
using CMGeom::Point_3;
using CMGeom::Vector_3;

namespace {

// Bilinear read of an image at texture coordinates (u, v) (v = 1 is the top row; coordinates
// outside [0, 1] repeat, as glTF's and OBJ's default sampler does); RGB in [0, 1] (grey images
// spread to RGB).
std::array<float, 3> read_rgb(const CMGeom::Image& image, double u, double v) {
  const int W = image.width(), H = image.height(), C = image.channels();
  const double px = u * W - 0.5, py = (1.0 - v) * H - 0.5;
  const long long x0 = (long long)std::floor(px), y0 = (long long)std::floor(py);
  const double fx = px - double(x0), fy = py - double(y0);
  std::array<float, 3> out{{0.f, 0.f, 0.f}};
  for (int k = 0; k < 4; ++k) {
    const int x = int((((x0 + (k & 1)) % W) + W) % W), y = int((((y0 + (k >> 1)) % H) + H) % H);
    const double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
    for (int c = 0; c < 3; ++c) out[std::size_t(c)] += float(w * image.value(x, y, C >= 3 ? c : 0));
  }
  return out;
}

// Root mean square, over four points of every face (the centroid and the midpoints from it to the
// corners, weighted by the face's area), of the difference between the colour the level shows
// there and the colour a bake of the input gives that point (Atlas_source::colour_near(): the
// input's texture at its closest facing point). Colour values in [0, 1], RGB. The library's own
// colour check (internal::Shown_colour_error, internal/atlas_layers.h) takes the same samples per
// face; this measure differs where a whole level is measured: it weights faces by area, and it
// repeats texture coordinates outside [0, 1] (the input with its own texture has them) where the
// check, made for atlases, clamps them.
double shown_colour_rms(const CMGeom::Textured_mesh& level, const TS::Atlas_source& input) {
  const CMGeom::Surface_mesh& m = level.mesh();
  double sum = 0, weight = 0;
  for (auto f : m.faces()) {
    const int mat = get(level.material_map(), f);
    if (mat < 0 || std::size_t(mat) >= level.materials().size()) continue;
    const CMGeom::Image& atlas = level.materials()[std::size_t(mat)].diffuse_image;
    if (atlas.empty()) continue;
    std::array<Point_3, 3> p;
    std::array<CMGeom::Point_2, 3> t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
      p[std::size_t(k)] = m.point(m.target(h));
      t[std::size_t(k)] = get(level.uv_map(), h);
      ++k;
    }
    const Vector_3 n = CGAL::cross_product(p[1] - p[0], p[2] - p[0]);
    const double area = 0.5 * std::sqrt(n.squared_length());
    if (!(area > 0)) continue;
    const std::array<std::array<double, 3>, 4> at{
        {{1. / 3, 1. / 3, 1. / 3}, {2. / 3, 1. / 6, 1. / 6}, {1. / 6, 2. / 3, 1. / 6}, {1. / 6, 1. / 6, 2. / 3}}};
    for (const auto& b : at) {
      const Point_3 q(b[0] * p[0].x() + b[1] * p[1].x() + b[2] * p[2].x(),
                      b[0] * p[0].y() + b[1] * p[1].y() + b[2] * p[2].y(),
                      b[0] * p[0].z() + b[1] * p[1].z() + b[2] * p[2].z());
      const double u = b[0] * t[0].x() + b[1] * t[1].x() + b[2] * t[2].x();
      const double v = b[0] * t[0].y() + b[1] * t[1].y() + b[2] * t[2].y();
      const std::array<float, 3> shown = read_rgb(atlas, u, v);
      float baked[4] = {0.f, 0.f, 0.f, 1.f};
      input.colour_near(q, n, baked);
      if (input.colour_channels() < 3) baked[1] = baked[2] = baked[0];
      for (int c = 0; c < 3; ++c) {
        const double d = double(shown[std::size_t(c)]) - double(baked[c]);
        sum += area * d * d / 3;
      }
      weight += area;
    }
  }
  return weight > 0 ? std::sqrt(sum / weight) : 0.;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "data/spot/spot.obj";
  std::vector<double> ratios;
  {
    std::istringstream in(argc > 2 ? argv[2] : "1,0.25,0.05");
    for (std::string item; std::getline(in, item, ',');) ratios.push_back(std::atof(item.c_str()));
  }
  CMGeom::Textured_mesh input;
  try {
    CMGeom::IO::read_textured_mesh(path, input);  // validated mesh + decoded texture
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }
  const std::size_t faces_in = input.mesh().number_of_faces();
  TS::Level_of_detail_options options;
  for (double r : ratios) options.target_faces.push_back(std::max<std::size_t>(4, std::size_t(r * double(faces_in))));

  // The three chains: an atlas per level; one shared atlas, without and with the colour check.
  TS::Level_of_detail_result own, geometric, checked;
  try {
    own = TS::simplify_to_levels(input, options);
    options.shared_texture = true;
    options.overflow_colour_tolerance = 0;  // the geometric tests alone choose the overflow charts
    geometric = TS::simplify_to_levels(input, options);
    options.overflow_colour_tolerance = 0.2;  // the default: the colours are checked too
    checked = TS::simplify_to_levels(input, options);
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }

  // What a bake of the input gives each point: the reference colours.
  TS::Atlas_source reference(input, options.atlas);
  reference.prepare();

  std::cout << path << ": " << checked.levels.size() << " levels from one run, one "
            << checked.levels.back().atlas.texture_width << "x" << checked.levels.back().atlas.texture_height
            << " atlas shared by all (overflow strip " << std::fixed << std::setprecision(1)
            << 100 * checked.shared_texture_overflow << " % of its height)\n"
            << "  level   faces  Hausdorff  colour RMS: own atlas  shared (geometric tests)  shared (+ colour check)\n";
  bool ok = checked.levels.size() == ratios.size();
  const CMGeom::Image& shared = checked.levels.back().mesh.materials().at(0).diffuse_image;
  double sum_geometric = 0, sum_checked = 0;
  for (std::size_t i = 0; i < checked.levels.size(); ++i) {
    const TS::Level_of_detail& l = checked.levels[i];
    const double e_own = shown_colour_rms(own.levels[i].mesh, reference);
    const double e_geo = shown_colour_rms(geometric.levels[i].mesh, reference);
    const double e_chk = shown_colour_rms(l.mesh, reference);
    std::cout << std::setw(7) << i << std::setw(8) << l.mesh.mesh().number_of_faces() << std::setw(10)
              << std::setprecision(3) << 100 * l.hausdorff << " %" << std::setw(20) << std::setprecision(4) << e_own
              << std::setw(26) << e_geo << std::setw(25) << e_chk << "\n";
    // Every level has at most its target's faces (the input itself for a target at or above its
    // count), reads the one shared image, and keeps its texture coordinates inside it.
    ok = ok && l.mesh.mesh().number_of_faces() <= std::max(l.target_faces, faces_in * std::size_t(l.is_input));
    ok = ok && l.mesh.materials().size() == 1 && l.mesh.materials()[0].diffuse_image == shared;
    for (auto h : l.mesh.mesh().halfedges()) {
      if (l.mesh.mesh().is_border(h)) continue;
      const auto uv = get(l.mesh.uv_map(), h);
      ok = ok && uv.x() >= 0 && uv.x() <= 1 && uv.y() >= 0 && uv.y() <= 1;
    }
    // The measure itself: the input with its own texture reads back its own colours.
    if (l.is_input) ok = ok && e_own < 0.01;
    sum_geometric += e_geo;
    sum_checked += e_chk;
  }
  // The colour check earns its place: over the chain, the levels show colours nearer to a bake's
  // with it than with the geometric tests alone.
  ok = ok && sum_checked <= sum_geometric;
  std::cout << "  colour RMS summed over the levels: " << sum_geometric << " with the geometric tests alone, "
            << sum_checked << " with the colour check\n";

  // The shared chain as one GLB: a node per level (MSFT_lod), one image for all of them.
  std::vector<CMGeom::IO::Gltf_level> levels;
  for (std::size_t i = 0; i < checked.levels.size(); ++i)
    levels.push_back({&checked.levels[i].mesh, "LOD" + std::to_string(i), checked.levels[i].hausdorff, ratios[i]});
  try {
    CMGeom::IO::write_textured_gltf("shared_texture_lod.glb", levels);  // atomic: the whole file or none
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }
  std::cout << "  written: shared_texture_lod.glb\n";
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
