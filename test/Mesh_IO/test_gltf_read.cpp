// Tests of the glTF reader: embedded buffers, welding, flipped and textured meshes.
#include "mesh_io_test_util.h"

TEST(Mesh_IO_gltf, EmbeddedBufferWeldedFlippedAndTextured) {
  // A unit quad of two triangles, 4 unique positions given as 6 glTF vertices (as exporters
  // do at UV seams), base-colour texture as an external PNG.
  const std::string dir = scratch_dir();
  Image tex(2, 2, 3);
  tex.set_value(0, 0, 0, 1.f);
  IO::write_image((fs::path(dir) / "tex.png").string(), tex);
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};
  std::vector<float> uv = {0, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0};
  std::string bin(reinterpret_cast<const char*>(pos.data()), pos.size() * 4);
  bin.append(reinterpret_cast<const char*>(uv.data()), uv.size() * 4);
  std::ofstream(fs::path(dir) / "quad.bin", std::ios::binary) << bin;
  nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}, {"translation", {0, 0, 2}}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}}, {"material", 0}}}}}}},
      {"materials", {{{"name", "m"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
      {"textures", {{{"source", 0}}}},
      {"images", {{{"uri", "tex.png"}}}},
      {"buffers", {{{"uri", "quad.bin"}, {"byteLength", bin.size()}}}},
      {"bufferViews",
       {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 72}},
        {{"buffer", 0}, {"byteOffset", 72}, {"byteLength", 48}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", 6},
         {"type", "VEC3"},
         {"min", {0, 0, 0}},
         {"max", {1, 1, 0}}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", 6}, {"type", "VEC2"}}}}};
  const std::string path = write_text(dir, "quad.gltf", j.dump());
  Textured_mesh tm;
  IO::read_textured_mesh(path, tm);
  EXPECT_EQ(tm.mesh().number_of_vertices(), 4u);  // welded
  EXPECT_EQ(tm.mesh().number_of_faces(), 2u);
  ASSERT_TRUE(tm.has_uvs());
  for (auto v : tm.mesh().vertices()) EXPECT_EQ(tm.mesh().point(v).z(), 2.0);  // node translation
  for (auto h : tm.mesh().halfedges()) {
    if (tm.mesh().is_border(h)) continue;
    const Point_3 p = tm.mesh().point(tm.mesh().target(h));
    EXPECT_EQ(tm.uv(h), Point_2(p.x(), p.y()));  // v flipped: glTF v = 1 - y
  }
  ASSERT_EQ(tm.materials().size(), 1u);
  EXPECT_TRUE(tm.materials()[0].diffuse_image == tex);
  EXPECT_EQ(mesh_charts(tm), 1u);
}
