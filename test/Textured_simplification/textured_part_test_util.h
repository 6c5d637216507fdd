// Helpers of the tests of the texture part of Textured_simplification (thesis §3.3, §3.5, §3.6):
// the models of shared/data/textured and their UV layouts. Included by test_chart_constraints.cpp,
// test_index_texture.cpp, test_texture_generation.cpp, test_weighted_texture_deviation.cpp and
// test_textured_simplify_cli.cpp.
#ifndef CMGEOM_TEST_TEXTURED_PART_UTIL_H
#define CMGEOM_TEST_TEXTURED_PART_UTIL_H

#include "cmgeom_test_config.h"

#include <CMGeom/Metrics/texture_deviation.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>
#include <CMGeom/Textured_simplification.h>
#include <CMGeom/Textured_simplification/simplify_textured_mesh.h>
#ifdef CMGEOM_HAS_OSMESA
#include <CMGeom/Textured_simplification/Osmesa_index_texture_resampler.h>
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#include <CMGeom/Rendering/views.h>
#endif

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

namespace TS = CMGeom::Textured_simplification;
namespace fs = std::filesystem;
using TS::UV2;

struct Model {
  const char* dir;
  const char* file;
};
const Model kModels[] = {{"spot", "spot.obj"},
                         {"bob", "bob_tri.obj"},
                         {"fuze", "fuze.obj"},
                         {"DamagedHelmet", "DamagedHelmet.obj"},
                         {"WaterBottle", "WaterBottle.obj"},
                         {"Duck", "Duck.obj"},
                         {"bunny10k_textured", "bunny10k_textured.obj"},
                         {"texturedknot", "texturedknot.obj"}};

inline std::string model_path(const Model& m) {
  return std::string(CMGEOM_DATA_DIR) + "/textured/" + m.dir + "/" + m.file;
}

inline bool read_model(const Model& m, CMGeom::Textured_mesh& tm, bool textures) {
  const std::string path = model_path(m);
  if (!fs::exists(path)) return false;
  CMGeom::IO::Read_options ro;
  ro.repair = true;  // DamagedHelmet has a few non-manifold edges
  if (textures)
    CMGeom::IO::read_textured_mesh(path, tm, ro);
  else
    CMGeom::IO::read_mesh(path, tm, ro);
  return true;
}

// Per-face UV triangles and chart ids (independent of the package: charts.h from Mesh_IO).
inline std::size_t layout(const CMGeom::Textured_mesh& tm, std::vector<std::array<UV2, 3>>& tris,
                          std::vector<int>& ids) {
  return TS::internal::uv_layout(tm, tris, ids);
}

}  // namespace

#endif  // CMGEOM_TEST_TEXTURED_PART_UTIL_H
