// Chart-aware texture lookups (thesis §3.3): the chart map of a mesh's UV layout (Chart_map: per
// texel, the chart covering it, grown two texels into the gutters) lets sample_original() blend
// only texels of the chart a point belongs to, so that a lookup next to a chart's border never
// bleeds in the gutter's or a neighbouring chart's colours. Here each face's UV centroid is found
// in the map, and the face is looked up at its corners, pulled a little towards the centroid,
// through the map without its margin: inside charts the lookup is the plain bilinear one; where a
// tap falls outside the face's chart it keeps to the chart's own texels.
//
//   chart_lookup [mesh.obj]     (default: data/spot/spot.obj)
#include <CMGeom/Mesh_IO.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace TS = CMGeom::Textured_simplification;

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "data/spot/spot.obj";
  CMGeom::Textured_mesh tm;
  try {
    CMGeom::IO::read_textured_mesh(path, tm);  // validated mesh + decoded texture
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }
  if (!tm.has_uvs() || tm.materials().empty() || tm.materials()[0].diffuse_image.empty()) {
    std::cerr << path << ": no texture coordinates or no decoded texture\n";
    return EXIT_FAILURE;
  }
  const CMGeom::Image& texture = tm.materials()[0].diffuse_image;
  CMGeom::Surface_mesh& m = tm.mesh();

  // the UV layout: a triangle and a chart per face
  auto chart = m.add_property_map<CMGeom::Surface_mesh::Face_index, int>("f:example_chart", -1).first;
  const std::size_t charts = CMGeom::compute_chart_ids(m, tm.uv_map(), chart);
  std::vector<std::array<TS::UV2, 3>> triangles;
  std::vector<int> ids;
  for (auto f : m.faces()) {
    std::array<TS::UV2, 3> t;
    int k = 0;
    for (auto h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
      const CMGeom::Point_2 p = tm.uv(h);
      if (k < 3) t[std::size_t(k)] = {{p.x(), p.y()}};
      ++k;
    }
    triangles.push_back(t);
    ids.push_back(chart[f]);
  }
  // the chart map at the texture's resolution (the domain covers the UVs the layout uses)
  const TS::Texture_domain domain = TS::make_texture_domain(triangles, texture.width(), texture.height(), 8192);
  const TS::Chart_map map(domain, triangles, ids);
  // and without its margin: the texels whose centre a face of the chart covers, no more
  const TS::Chart_map tight(domain, triangles, ids, 0);

  std::size_t centroids_in_own_chart = 0, inside = 0, same_as_plain = 0, near_border = 0, kept_to_chart = 0;
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const std::uint32_t own = std::uint32_t(ids[i] + 1);
    const auto& t = triangles[i];
    const TS::UV2 c{{(t[0][0] + t[1][0] + t[2][0]) / 3, (t[0][1] + t[1][1] + t[2][1]) / 3}};
    const TS::UV2 a = map.domain().to_texel(c);
    centroids_in_own_chart += map.chart_of(float(a[0]), float(a[1])) == own;
    for (int k = 0; k < 3; ++k) {
      // a corner pulled 10 % towards the centroid: inside the face, often a texel from its border
      const TS::UV2 uv{{0.9 * t[std::size_t(k)][0] + 0.1 * c[0], 0.9 * t[std::size_t(k)][1] + 0.1 * c[1]}};
      const TS::UV2 x = tight.domain().to_texel(uv);
      float aware[4], plain[4];
      TS::sample_original(tight, texture, float(x[0]), float(x[1]), aware, own);
      TS::sample_original(tight, texture, float(x[0]), float(x[1]), plain, 0u);  // chart 0: plain bilinear
      // the four taps' texel centres all in the face's chart: the two lookups agree
      const double px = x[0] - 0.5, py = x[1] - 0.5;
      bool all_taps_own = true;
      for (int q = 0; q < 4; ++q)
        all_taps_own = all_taps_own && tight.chart_of(float(std::floor(px) + (q & 1) + 0.5),
                                                      float(std::floor(py) + (q >> 1) + 0.5)) == own;
      bool same = true;
      for (int ch = 0; ch < texture.channels(); ++ch) same = same && aware[ch] == plain[ch];
      if (all_taps_own) {
        ++inside;
        same_as_plain += same;
      } else {
        ++near_border;
        kept_to_chart += !same;
      }
    }
  }
  std::cout << path << ": " << triangles.size() << " faces, " << charts << " charts, chart map " << map.width() << " x "
            << map.height() << "\n"
            << "  face centroids on a texel of their own chart: " << centroids_in_own_chart << " of "
            << triangles.size() << "\n"
            << "  lookups with every tap in the face's chart: " << inside << ", the plain bilinear value in "
            << same_as_plain << "\n"
            << "  lookups with a tap outside the face's chart: " << near_border
            << ", differing from the bilinear value in " << kept_to_chart << "\n";
  // inside a chart the chart-aware lookup is the bilinear one. (How many centroids fall on their
  // own chart depends on the layout: charts that share texels, as the Duck's mirrored halves, give
  // a texel to one of them only; whether a lookup next to a border changes depends on the texture:
  // an atlas whose gutters repeat their charts' colours, as bob's, gives the same value either way.)
  const bool ok = inside > 0 && same_as_plain == inside;
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
