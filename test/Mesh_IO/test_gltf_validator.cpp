// The Khronos glTF validator on every kind of file the glTF writer writes (skipped when Node.js
// or the validator's npm package is missing).
#include "gltf_write_test_util.h"

// ------------------------------------------------------------------ the Khronos validator

TEST(Mesh_IO_gltf_validator, EveryKindOfWrittenFileIsValid) {
  CMGEOM_REQUIRE_GLTF_VALIDATOR();
  const std::string dir = scratch_dir();
  std::vector<std::string> files;
  IO::Gltf_options quantize;
  quantize.quantize = true;
  const Textured_mesh cube = single_material_cube(dir), two = two_material_cube(dir);
  const std::vector<Textured_mesh> lod = lod_meshes(dir);
  const Textured_mesh tga_cube = [&] {
    const std::string tga = (fs::path(dir) / "in" / "paint.tga").string();
    IO::write_image(tga, pattern_image(8, 4, 1));
    return textured_cube({textured_material("tga", {1, 1, 1}, tga)}, 0);
  }();
  Material baked;
  baked.name = "baked";
  baked.diffuse_image = pattern_image(16, 16, 7);
  const Textured_mesh baked_grid = textured_grid(8, baked);
  for (const char* ext : {".glb", ".gltf"}) {
    auto path = [&](const std::string& stem) {
      files.push_back(out_path(dir, stem + ext));
      return files.back();
    };
    IO::write_mesh(path("cube"), cube);
    IO::write_mesh(path("two"), two);
    IO::write_textured_mesh(path("cube_q"), cube, quantize);
    IO::write_textured_mesh(path("grid_q"), lod[0], quantize);
    IO::write_gltf(path("lod"), lod_levels(lod));
    IO::write_gltf(path("lod_q"), lod_levels(lod), quantize);
    IO::write_textured_mesh(path("tga"), tga_cube);
    IO::write_textured_mesh(path("baked"), baked_grid);
  }
  for (const std::string& f : files) expect_valid_gltf(f);
}

TEST(Mesh_IO_gltf_validator, TexturedModelsConvertToValidGlb) {
  CMGEOM_REQUIRE_SHARED_DATA();
  CMGEOM_REQUIRE_GLTF_VALIDATOR();
  const std::string dir = scratch_dir();
  std::size_t models = 0;
  for (const auto& entry : fs::directory_iterator(shared_data("textured"))) {
    if (!entry.is_directory()) continue;
    for (const auto& file : fs::directory_iterator(entry.path())) {
      if (IO::extension(file.path().string()) != ".obj") continue;
      SCOPED_TRACE(file.path().string());
      IO::Read_options options;
      options.repair = true;  // DamagedHelmet is not manifold; the others read as they are
      Textured_mesh tm;
      IO::read_mesh(file.path().string(), tm, options);
      if (tm.materials().empty() && fs::exists(entry.path() / "spot_texture.png"))
        tm.materials().push_back(textured_material("spot", {1, 1, 1}, (entry.path() / "spot_texture.png").string()));
      const std::string glb = out_path(dir, file.path().stem().string() + ".glb");
      IO::write_mesh(glb, tm);
      expect_valid_gltf(glb);
      // quantized too: its 8-bit normals must still pass the validator's unit-length check
      const std::string quantized = out_path(dir, file.path().stem().string() + "_q.glb");
      IO::Gltf_options quantize;
      quantize.quantize = true;
      IO::write_textured_mesh(quantized, tm, quantize);
      expect_valid_gltf(quantized);
      ++models;
    }
  }
  EXPECT_GE(models, 8u);
}
