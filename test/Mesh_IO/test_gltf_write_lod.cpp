// Tests of the levels of detail written by the glTF writer: the MSFT_lod node structure, images
// shared between levels, decoded images still equal to their files stored as the files.
#include "gltf_write_test_util.h"

// ------------------------------------------------------------------ levels of detail

TEST(Mesh_IO_gltf_write, LevelsOfDetailAreMsftLodNodesOfOneScene) {
  const std::string dir = scratch_dir();
  const std::vector<Textured_mesh> meshes = lod_meshes(dir);
  const std::vector<IO::Gltf_level> levels = lod_levels(meshes);
  for (const char* name : {"lod.gltf", "lod.glb"}) IO::write_gltf(out_path(dir, name), levels);
  const nlohmann::json j = read_json(out_path(dir, "lod.gltf"));
  ASSERT_EQ(j["scenes"].size(), 1u);
  EXPECT_EQ(j["scene"], 0);
  EXPECT_EQ(j["scenes"][0]["nodes"], nlohmann::json::array({0}));
  ASSERT_EQ(j["nodes"].size(), 3u);
  EXPECT_EQ(j["nodes"][0]["extensions"]["MSFT_lod"]["ids"], nlohmann::json::array({1, 2}));
  EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MSFT_lod"), j["extensionsUsed"].end());
  EXPECT_FALSE(j.contains("extensionsRequired"));  // viewers without MSFT_lod show level 0
  for (std::size_t i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const auto& node = j["nodes"][i];
    EXPECT_EQ(node["name"], levels[i].name);
    EXPECT_FALSE(node.contains("children"));
    const auto& extras = node["extras"];
    EXPECT_EQ(extras["level"], i);
    EXPECT_EQ(extras["faces"], meshes[i].mesh().number_of_faces());
    if (levels[i].error >= 0) {
      EXPECT_DOUBLE_EQ(extras["error"].get<double>(), levels[i].error);
      EXPECT_DOUBLE_EQ(extras["ratio"].get<double>(), levels[i].ratio);
    } else {
      EXPECT_FALSE(extras.contains("error"));
      EXPECT_FALSE(extras.contains("ratio"));
    }
    // the node's mesh has the level's triangles
    const auto& prims = j["meshes"][node["mesh"].get<int>()]["primitives"];
    ASSERT_EQ(prims.size(), 1u);
    EXPECT_EQ(j["accessors"][prims[0]["indices"].get<int>()]["count"], 3 * meshes[i].mesh().number_of_faces());
  }
  // one texture file for all levels: one image, one material
  EXPECT_EQ(j["images"].size(), 1u);
  EXPECT_EQ(j["materials"].size(), 1u);
  EXPECT_EQ(count_files(dir), 4u);  // lod.gltf, lod.bin, lod_0.png, lod.glb
  // a reader without MSFT_lod sees the first level only, in either container
  for (const char* name : {"lod.gltf", "lod.glb"}) {
    Textured_mesh back;
    IO::read_mesh(out_path(dir, name), back);
    expect_same_faces(meshes[0], back, {1e-6 * bbox_diagonal(meshes[0])});
  }
}

TEST(Mesh_IO_gltf_write, LevelsWithEqualDecodedTexturesShareOneImage) {
  // textures that exist only as decoded images (a baked atlas): encoded once when the pixels
  // are equal, even in two separate Image objects; a different image is a second one
  const std::string dir = scratch_dir();
  Material m;
  m.name = "baked";
  m.diffuse_image = pattern_image(16, 16, 7);
  const Textured_mesh a = textured_grid(8, m), b = textured_grid(4, m);
  Material other = m;
  other.diffuse_image = pattern_image(16, 16, 8);
  const Textured_mesh c = textured_grid(2, other);
  const std::string path = out_path(dir, "baked.gltf");
  IO::write_textured_gltf(path, {IO::Gltf_level{&a, "a", -1, -1}, IO::Gltf_level{&b, "b", -1, -1}});
  nlohmann::json j = read_json(path);
  ASSERT_EQ(j["images"].size(), 1u);
  EXPECT_TRUE(IO::read_image(out_path(dir, j["images"][0]["uri"].get<std::string>())) == m.diffuse_image);
  IO::write_textured_gltf(path, {IO::Gltf_level{&a, "a", -1, -1}, IO::Gltf_level{&c, "c", -1, -1}});
  j = read_json(path);
  EXPECT_EQ(j["images"].size(), 2u);
  EXPECT_EQ(j["materials"].size(), 2u);
}

TEST(Mesh_IO_gltf_write, ImagesEncodedTogetherGoToTheirOwnMaterials) {
  // a chain's distinct atlases are encoded in parallel before the file is assembled: each
  // material must still get its own image's pixels, and an image equal to an earlier one none
  const std::string dir = scratch_dir();
  std::vector<Material> mats(4);
  std::vector<Textured_mesh> meshes;
  for (int i = 0; i < 4; ++i) {
    mats[std::size_t(i)].name = "level" + std::to_string(i);
    mats[std::size_t(i)].diffuse_image = pattern_image(24 + 8 * i, 16, 11 + i);
  }
  mats[3].diffuse_image = mats[1].diffuse_image;  // the same pixels as level 1's
  for (int i = 0; i < 4; ++i) meshes.push_back(textured_grid(8 - i, mats[std::size_t(i)]));
  std::vector<IO::Gltf_level> levels;
  for (int i = 0; i < 4; ++i)
    levels.push_back(IO::Gltf_level{&meshes[std::size_t(i)], "l" + std::to_string(i), -1, -1});
  const std::string path = out_path(dir, "chain.gltf");
  IO::write_textured_gltf(path, levels);
  const nlohmann::json j = read_json(path);
  ASSERT_EQ(j["images"].size(), 3u);
  ASSERT_EQ(j["materials"].size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    SCOPED_TRACE(k);
    const int t = j["materials"][k]["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<int>();
    const int img = j["textures"][std::size_t(t)]["source"].get<int>();
    const std::string uri = j["images"][std::size_t(img)]["uri"].get<std::string>();
    EXPECT_TRUE(IO::read_image(out_path(dir, uri)) == mats[k].diffuse_image);
  }
}

TEST(Mesh_IO_gltf_write, DecodedImagesStillEqualToTheirFilesKeepTheFilesBytes) {
  // a level that is the input itself holds its texture decoded, with the file it came from: the
  // file's bytes are stored (a JPEG stays a JPEG, not re-encoded); an image changed since it was
  // read is encoded as PNG with its new pixels
  const std::string dir = scratch_dir();
  const std::string jpeg = out_path(dir, "albedo.jpg"), png = out_path(dir, "albedo.png");
  IO::write_image(jpeg, pattern_image(32, 16, 5));
  IO::write_image(png, pattern_image(16, 32, 6));
  std::vector<Material> mats(3);
  mats[0].name = "from_jpeg";
  mats[0].diffuse_texture = jpeg;
  mats[1].name = "from_png";
  mats[1].diffuse_texture = png;
  mats[2].name = "changed";
  mats[2].diffuse_texture = png;
  for (Material& m : mats) m.diffuse_image = IO::read_image(m.diffuse_texture);
  mats[2].diffuse_image.set_value(3, 4, 0, 1.f - mats[2].diffuse_image.value(3, 4, 0));
  std::vector<Textured_mesh> meshes;
  for (int i = 0; i < 3; ++i) meshes.push_back(textured_grid(6 - i, mats[std::size_t(i)]));
  std::vector<IO::Gltf_level> levels;
  for (int i = 0; i < 3; ++i)
    levels.push_back(IO::Gltf_level{&meshes[std::size_t(i)], "l" + std::to_string(i), -1, -1});
  const std::string path = out_path(dir, "chain.gltf");
  IO::write_textured_gltf(path, levels);
  const nlohmann::json j = read_json(path);
  ASSERT_EQ(j["images"].size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE(mats[k].name);
    const int t = j["materials"][k]["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<int>();
    const int img = j["textures"][std::size_t(t)]["source"].get<int>();
    const std::string stored = out_path(dir, j["images"][std::size_t(img)]["uri"].get<std::string>());
    if (k < 2)
      EXPECT_EQ(file_bytes(stored), file_bytes(mats[k].diffuse_texture)) << "the file's bytes were not kept";
    else
      EXPECT_NE(file_bytes(stored), file_bytes(mats[k].diffuse_texture));
    EXPECT_EQ(fs::path(stored).extension().string(), k == 0 ? ".jpg" : ".png");
    EXPECT_TRUE(IO::read_image(stored) == mats[k].diffuse_image);
  }
}
