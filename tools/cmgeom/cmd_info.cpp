// cmgeom info <mesh> [--json] [--repair]: counts, topology and texture facts of a mesh file. Works
// on broken meshes too (non-manifold, inconsistent orientation): that is what it is for. With
// --repair it also gives the topology of the mesh as the commands that repair their input while
// reading (simplify, lod, cm build) see it, so that an input and its simplification compare.
#include "cli_common.h"

#include <CMGeom/Mesh_IO/image_io.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

CMGEOM_CLI_COMMAND(info, "Print vertices, faces, charts, topology and materials of a mesh file") {
  auto input = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto repair = std::make_shared<bool>(false);
  auto read = std::make_shared<CMGeom::IO::Read_options>();
  app.add_option("mesh", *input, "Mesh file (.obj, .off, .ply, .stl, .gltf, .glb)")->required();
  app.add_flag("--json", *json, "Print a JSON object instead of text");
  app.add_flag("--repair", *repair,
               "Also give the topology of the mesh as simplify, lod and cm build read it (non-manifold edges "
               "split, non-manifold vertices duplicated, orientation fixed; JSON \"repaired\")");
  cmgeom_cli::add_allow_degenerate_option(app, read->allow_degenerate_faces);
  cmgeom_cli::add_drop_repeated_option(app, read->drop_repeated_vertex_faces);
  return [input, json, repair, read]() -> int {
    const CMGeom::Polygon_soup soup = cmgeom_cli::read_polygon_soup_with_progress(*input);
    cmgeom_cli::print_warnings("info", soup.warnings);
    const CMGeom::Mesh_statistics st = CMGeom::analyze_soup(soup);
    // the mesh as the repairing readers build it, measured as the file is (its triangles, its
    // vertices with the duplicates the repair added)
    std::optional<CMGeom::Mesh_statistics> fixed;
    if (*repair) {
      CMGeom::IO::Read_options o = *read;
      o.repair = true;
      std::vector<std::string> warnings;
      o.warnings = &warnings;
      CMGeom::Surface_mesh m;
      CMGeom::IO::build_surface_mesh(soup, m, o);
      cmgeom_cli::print_warnings("info", warnings);
      CMGeom::Polygon_soup built;
      built.source = soup.source;
      built.positions.reserve(m.number_of_vertices());
      for (const auto v : m.vertices()) {
        const CMGeom::Point_3& p = m.point(v);
        built.positions.push_back({p.x(), p.y(), p.z()});
      }
      for (const auto f : m.faces()) {
        for (const auto h : CGAL::halfedges_around_face(m.halfedge(f), m))
          built.corner_vertex.push_back(std::uint32_t(m.target(h)));
        built.face_start.push_back(std::uint32_t(built.corner_vertex.size()));
      }
      built.corner_uv.assign(built.corner_vertex.size(), CMGeom::Polygon_soup::no_index);
      built.face_material.assign(m.number_of_faces(), 0);
      built.face_line.assign(m.number_of_faces(), 0);
      fixed = CMGeom::analyze_soup(built);
    }
    nlohmann::ordered_json j;
    j["file"] = *input;
    j["vertices"] = soup.positions.size();
    j["referenced_vertices"] = st.vertices;
    j["unreferenced_vertices"] = st.unreferenced_vertices;
    j["faces"] = st.faces;
    j["edges"] = st.edges;
    j["texture_coordinates"] = soup.uvs.size();
    j["charts"] = st.charts;
    j["closed"] = st.closed;
    j["manifold"] = st.manifold;
    j["oriented"] = st.oriented;
    j["genus"] = st.genus >= 0 ? nlohmann::ordered_json(st.genus) : nlohmann::ordered_json(nullptr);
    j["components"] = st.components;
    j["boundary_edges"] = st.boundary_edges;
    j["boundary_loops"] = st.boundary_loops;
    j["euler_characteristic"] = st.euler_characteristic;
    j["non_manifold_edges"] = st.non_manifold_edges;
    j["non_manifold_vertices"] = st.non_manifold_vertices;
    j["inconsistent_edges"] = st.inconsistent_edges;
    j["degenerate_faces"] = st.degenerate_faces;
    if (fixed) {
      nlohmann::ordered_json r;
      r["vertices"] = fixed->vertices;
      r["faces"] = fixed->faces;
      r["closed"] = fixed->closed;
      r["manifold"] = fixed->manifold;
      r["oriented"] = fixed->oriented;
      r["genus"] = fixed->genus >= 0 ? nlohmann::ordered_json(fixed->genus) : nlohmann::ordered_json(nullptr);
      r["components"] = fixed->components;
      r["boundary_loops"] = fixed->boundary_loops;
      r["euler_characteristic"] = fixed->euler_characteristic;
      j["repaired"] = r;
    }
    // Bounding box of the referenced vertices (what errors are expressed against: % of its diagonal).
    {
      std::array<double, 3> lo{{HUGE_VAL, HUGE_VAL, HUGE_VAL}}, hi{{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
      std::vector<char> used(soup.positions.size(), 0);
      for (const auto v : soup.corner_vertex) used[v] = 1;
      bool any = false;
      for (std::size_t i = 0; i < soup.positions.size(); ++i) {
        if (!used[i]) continue;
        any = true;
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::min(lo[k], double(soup.positions[i][k]));
          hi[k] = std::max(hi[k], double(soup.positions[i][k]));
        }
      }
      if (any) {
        j["bbox_min"] = lo;
        j["bbox_max"] = hi;
        j["diagonal"] = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
      } else {
        j["diagonal"] = nullptr;
      }
    }
    nlohmann::ordered_json mats = nlohmann::ordered_json::array();
    for (const CMGeom::Material& m : soup.materials) {
      nlohmann::ordered_json mj;
      mj["name"] = m.name;
      auto texture = [](const std::string& path) {
        nlohmann::ordered_json t;
        t["file"] = path;
        const auto [w, h] = CMGeom::IO::image_size(path);
        t["width"] = w;
        t["height"] = h;
        return t;
      };
      if (!m.diffuse_texture.empty())
        mj["diffuse_texture"] = texture(m.diffuse_texture);
      else if (!m.diffuse_texture_blob.empty())
        mj["diffuse_texture"] = "embedded";
      if (!m.normal_texture.empty()) mj["normal_texture"] = texture(m.normal_texture);
      mats.push_back(mj);
    }
    j["materials"] = mats;
    if (*json) {
      cmgeom_cli::print_json(j);
      return 0;
    }
    std::cout << *input << "\n"
              << "  vertices     " << soup.positions.size() << " (" << st.unreferenced_vertices << " unreferenced)\n"
              << "  faces        " << st.faces << "\n"
              << "  edges        " << st.edges << "\n"
              << "  components   " << st.components << "\n"
              << "  closed       " << (st.closed ? "yes" : "no") << " (" << st.boundary_edges << " boundary edges"
              << (st.manifold ? ", " + std::to_string(st.boundary_loops) + " loops" : std::string()) << ")\n"
              << "  manifold     " << (st.manifold ? "yes" : "no") << " (" << st.non_manifold_edges
              << " non-manifold edges, " << st.non_manifold_vertices << " non-manifold vertices)\n"
              << "  oriented     " << (st.oriented ? "yes" : "no") << "\n"
              << "  genus        " << (st.genus >= 0 ? std::to_string(st.genus) : std::string("n/a")) << "\n"
              << "  degenerate   " << st.degenerate_faces << " faces\n"
              << "  UV charts    " << st.charts << " (" << soup.uvs.size() << " texture coordinates)\n";
    if (fixed)
      std::cout << "  repaired     " << fixed->vertices << " vertices, genus "
                << (fixed->genus >= 0 ? std::to_string(fixed->genus) : std::string("n/a")) << ", " << fixed->components
                << " components, " << fixed->boundary_loops << " boundary loops, "
                << (fixed->manifold && fixed->oriented ? "manifold and oriented" : "still not manifold or oriented")
                << " (as simplify, lod and cm build read it)\n";
    for (const auto& mj : j["materials"]) {
      std::cout << "  material     " << mj["name"].get<std::string>();
      if (mj.contains("diffuse_texture") && mj["diffuse_texture"].is_object())
        std::cout << ", texture " << mj["diffuse_texture"]["width"] << "x" << mj["diffuse_texture"]["height"];
      std::cout << "\n";
    }
    return 0;
  };
}
