// Tests of the refusals of the glTF writer, which must leave nothing behind, and of the texture
// types it re-encodes.
#include "gltf_write_test_util.h"

// ------------------------------------------------------------------ refusals

TEST(Mesh_IO_gltf_write, EmptyMeshIsRefusedAndNothingIsWritten) {
  const std::string dir = scratch_dir();
  const Textured_mesh empty;
  const Textured_mesh grid = textured_grid(2, textured_material("m", {1, 1, 1}, write_png(dir, "m.png", 1)));
  const std::string out = (fs::path(dir) / "out").string();
  fs::create_directories(out);
  for (const char* name : {"empty.glb", "empty.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(out, name);
    EXPECT_THROW(IO::write_mesh(path, empty), IO_error);
    EXPECT_THROW(IO::write_textured_mesh(path, empty), IO_error);
    EXPECT_THROW(IO::write_gltf(path, {}), IO_error);
    EXPECT_THROW(IO::write_gltf(path, {IO::Gltf_level{nullptr, "none", -1, -1}}), IO_error);
    // an empty level after a good one: the good one is not written either
    EXPECT_THROW(IO::write_gltf(path, {IO::Gltf_level{&grid, "a", -1, -1}, IO::Gltf_level{&empty, "b", -1, -1}}),
                 IO_error);
    EXPECT_EQ(count_files(out), 0u) << "a refused write left files behind";
  }
}

TEST(Mesh_IO_gltf_write, TextureNeitherPngNorJpegIsRefusedByWriteMesh) {
  const std::string dir = scratch_dir();
  const std::string in = (fs::path(dir) / "in").string(), out = (fs::path(dir) / "out").string();
  fs::create_directories(in);
  fs::create_directories(out);
  const std::string tga = (fs::path(in) / "paint.tga").string();
  IO::write_image(tga, pattern_image(8, 4, 1));
  ASSERT_FALSE(is_png(file_bytes(tga)));
  // the second material's texture is the TGA: the first one's image and the buffers are not kept
  const Textured_mesh cube = textured_cube(
      {textured_material("fine", {1, 1, 1}, write_png(in, "fine.png", 2)), textured_material("tga", {1, 1, 1}, tga)},
      1);
  for (const char* name : {"cube.gltf", "cube.glb"}) {
    SCOPED_TRACE(name);
    try {
      IO::write_mesh(out_path(out, name), cube);
      ADD_FAILURE() << "a TGA texture was written into a glTF file";
    } catch (const IO_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("neither PNG nor JPEG"), std::string::npos) << msg;
      EXPECT_NE(msg.find("'tga'"), std::string::npos) << "the message names the material: " << msg;
    }
    EXPECT_EQ(count_files(out), 0u) << "a refused write left files behind";
  }
}

TEST(Mesh_IO_gltf_write, WriteTexturedMeshEncodesOtherImageTypesAsPng) {
  const std::string dir = scratch_dir();
  const std::string in = (fs::path(dir) / "in").string();
  fs::create_directories(in);
  const std::string tga = (fs::path(in) / "paint.tga").string();
  IO::write_image(tga, pattern_image(8, 4, 1));
  const Image pixels = IO::read_image(tga);
  const Textured_mesh cube = textured_cube({textured_material("tga", {1, 1, 1}, tga)}, 0);
  for (const char* name : {"cube.gltf", "cube.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_textured_mesh(path, cube);
    Textured_mesh back;
    IO::read_mesh(path, back);
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    ASSERT_EQ(back.materials().size(), 1u);
    const Material& m = back.materials()[0];
    const std::string bytes = m.diffuse_texture.empty()
                                  ? std::string(m.diffuse_texture_blob.begin(), m.diffuse_texture_blob.end())
                                  : file_bytes(m.diffuse_texture);
    EXPECT_TRUE(is_png(bytes));
    if (!m.diffuse_texture.empty()) {
      EXPECT_EQ(fs::path(m.diffuse_texture).extension().string(), ".png");
    }
    EXPECT_TRUE(decode_image(bytes, dir) == pixels) << "the PNG does not hold the TGA's pixels";
  }
}
