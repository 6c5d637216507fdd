// Helpers of the Mesh_IO tests of the readers, the textured-mesh model, images and malformed
// input: the includes they share and the chart count of a textured mesh. Included by
// test_shared_models.cpp, test_obj_ply_readers.cpp, test_textured_mesh_model.cpp,
// test_gltf_read.cpp, test_image_io.cpp, test_malformed_input.cpp, test_atomic_file.cpp and
// test_info_cli.cpp.
#ifndef CMGEOM_TEST_MESH_IO_UTIL_H
#define CMGEOM_TEST_MESH_IO_UTIL_H

#include <CMGeom/Mesh_IO.h>
#include <CMGeom/Mesh_IO/textured_mesh_io.h>

#include "cmgeom_test_support.h"
#include "io_internal.h"  // src/Mesh_IO: the reader's own soup check

#include <nlohmann/json.hpp>

#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>

using namespace CMGeom;
using cmgeom_test::scratch_dir;
using cmgeom_test::shared_data;
using cmgeom_test::write_text;
namespace fs = std::filesystem;

namespace {

inline std::size_t mesh_charts(const Textured_mesh& tm) {
  auto ids = get(CGAL::dynamic_face_property_t<int>(), tm.mesh());  // scratch map on a const mesh
  return compute_chart_ids(tm.mesh(), tm.uv_map(), ids);
}

}  // namespace

#endif  // CMGEOM_TEST_MESH_IO_UTIL_H
