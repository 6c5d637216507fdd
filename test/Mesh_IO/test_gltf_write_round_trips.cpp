// Tests of the glTF 2.0 / GLB writer (write_mesh, write_textured_mesh, write_gltf,
// write_textured_gltf): round trips through the reader on meshes built here and on the shared
// textured models, several materials, KHR_mesh_quantization, tangents, PNG chunks.
#include "gltf_write_test_util.h"

// ------------------------------------------------------------------ round trips

TEST(Mesh_IO_gltf_write, CubeWithSeamsRoundTripsThroughGlbAndGltf) {
  const std::string dir = scratch_dir();
  const Textured_mesh cube = single_material_cube(dir);
  for (const char* name : {"cube.glb", "cube.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_mesh(path, cube);
    Textured_mesh back;
    IO::read_mesh(path, back);
    EXPECT_EQ(back.mesh().number_of_vertices(), 8u);  // split at the seams on write, welded on read
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    expect_same_texture_bytes(cube, back, path);
    // every cube corner is on three tiles of the atlas: 3 x 8 glTF vertices
    if (IO::extension(path) == ".gltf") {
      const nlohmann::json j = read_json(path);
      const int position = j["meshes"][0]["primitives"][0]["attributes"]["POSITION"];
      EXPECT_EQ(j["accessors"][position]["count"], 24);
      EXPECT_EQ(j["asset"]["version"], "2.0");
      // the .bin and the two images beside the .gltf, named after it
      EXPECT_TRUE(fs::exists(out_path(dir, "cube.bin")));
      EXPECT_EQ(j["images"].size(), 2u);
    }
  }
  // .gltf output: the .gltf, its .bin and two images; .glb: one file
  EXPECT_EQ(count_files(dir), 5u);
}

// A file name with spaces: the writer percent-encodes the image and buffer URIs, the reader
// decodes them; and the textures of a .glb (embedded bytes) decode in memory to the source's pixels.
TEST(Mesh_IO_gltf_write, NamesWithSpacesAndEmbeddedTexturesReadBack) {
  const std::string dir = scratch_dir();
  Textured_mesh cube = single_material_cube(dir);
  IO::load_textures(cube);
  for (const char* name : {"my cube.gltf", "my cube.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_textured_mesh(path, cube);
    Textured_mesh back;
    IO::read_textured_mesh(path, back);
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    ASSERT_EQ(back.materials().size(), cube.materials().size());
    for (std::size_t i = 0; i < cube.materials().size(); ++i)
      EXPECT_TRUE(back.materials()[i].diffuse_image == cube.materials()[i].diffuse_image)
          << "material " << i << ": the texture read back differs from the one written";
  }
}

TEST(Mesh_IO_gltf_write, TwoMaterialsGiveTwoPrimitivesAndKeepFaceMaterials) {
  const std::string dir = scratch_dir();
  const Textured_mesh cube = two_material_cube(dir);
  for (const char* name : {"two.gltf", "two.glb"}) {
    SCOPED_TRACE(name);
    const std::string path = out_path(dir, name);
    IO::write_mesh(path, cube);
    Textured_mesh back;
    IO::read_mesh(path, back);
    ASSERT_EQ(back.materials().size(), 2u);
    expect_same_faces(cube, back, {1e-6 * bbox_diagonal(cube)});
    expect_same_texture_bytes(cube, back, path);
    // faces of each material: 6 of 12
    std::size_t stone = 0;
    for (Face_index f : back.mesh().faces()) stone += back.materials()[std::size_t(back.material(f))].name == "stone";
    EXPECT_EQ(stone, 6u);
  }
  const nlohmann::json j = read_json(out_path(dir, "two.gltf"));
  ASSERT_EQ(j["meshes"].size(), 1u);
  const auto& prims = j["meshes"][0]["primitives"];
  ASSERT_EQ(prims.size(), 2u);
  EXPECT_NE(prims[0]["material"], prims[1]["material"]);
  ASSERT_EQ(j["materials"].size(), 2u);
  EXPECT_EQ(j["images"].size(), 2u);
  std::vector<std::string> mime;
  for (const auto& img : j["images"]) mime.push_back(fs::path(img["uri"].get<std::string>()).extension().string());
  std::sort(mime.begin(), mime.end());
  EXPECT_EQ(mime, (std::vector<std::string>{".jpg", ".png"}));  // each image keeps its format
  for (const auto& prim : prims) {
    const auto& mat = j["materials"][prim["material"].get<int>()];
    EXPECT_EQ(j["accessors"][prim["indices"].get<int>()]["count"], 18);  // 6 triangles each
    EXPECT_EQ(mat["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    EXPECT_TRUE(mat["pbrMetallicRoughness"].contains("baseColorTexture"));
  }
}

TEST(Mesh_IO_gltf_write, TexturedModelsRoundTripThroughGlbAndGltf) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  // spot has no MTL: its texture is assigned here; DamagedHelmet needs repair (non-manifold),
  // and its duplicated vertices are welded again on read, so it is read back with repair too
  for (const char* model : {"textured/Duck/Duck.obj", "textured/spot/spot.obj",
                            "textured/DamagedHelmet/DamagedHelmet.obj", "textured/fuze/fuze.obj"}) {
    SCOPED_TRACE(model);
    IO::Read_options options;
    options.repair = std::string(model).find("DamagedHelmet") != std::string::npos;
    Textured_mesh tm;
    IO::read_mesh(shared_data(model), tm, options);
    if (tm.materials().empty())
      tm.materials().push_back(textured_material("spot", {1, 1, 1}, shared_data("textured/spot/spot_texture.png")));
    ASSERT_TRUE(tm.has_uvs());
    const std::string stem = fs::path(model).stem().string();
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(ext);
      const std::string path = out_path(dir, stem + ext);
      IO::write_mesh(path, tm);
      Textured_mesh back;
      IO::read_mesh(path, back, options);
      EXPECT_EQ(back.mesh().number_of_faces(), tm.mesh().number_of_faces());
      expect_same_faces(tm, back, {1e-6 * bbox_diagonal(tm)});
      expect_same_texture_bytes(tm, back, path);
    }
  }
}

TEST(Mesh_IO_gltf_write, QuantizedPositionsAndUvsStayWithinTheGridStep) {
  const std::string dir = scratch_dir();
  IO::Gltf_options quantize;
  quantize.quantize = true;
  const Textured_mesh cube = single_material_cube(dir);
  const Textured_mesh grid = textured_grid(12, cube.materials()[0]);
  for (const auto& [mesh, stem] : {std::make_pair(&cube, "cube"), std::make_pair(&grid, "grid")}) {
    const auto b = CGAL::bbox_3(mesh->mesh().points().begin(), mesh->mesh().points().end());
    const double extent = std::max({b.xmax() - b.xmin(), b.ymax() - b.ymin(), b.zmax() - b.zmin()});
    for (const char* ext : {".glb", ".gltf"}) {
      const std::string path = out_path(dir, std::string(stem) + "_q" + ext);
      SCOPED_TRACE(path);
      IO::write_textured_mesh(path, *mesh, quantize);
      Textured_mesh back;
      IO::read_mesh(path, back);
      // rounding to the nearest of 65536 grid values: half a step at most (mesh_io.h), read back
      // through the node's scale and translation in double precision
      Tolerance tol{extent / 131070 * (1 + 1e-9)};
      tol.uv = 0.5 / 65535 + 1e-12;
      expect_same_faces(*mesh, back, tol);
    }
    const nlohmann::json j = read_json(out_path(dir, std::string(stem) + "_q.gltf"));
    auto contains = [](const nlohmann::json& list, const char* s) {
      return std::find(list.begin(), list.end(), s) != list.end();
    };
    EXPECT_TRUE(contains(j["extensionsUsed"], "KHR_mesh_quantization"));
    EXPECT_TRUE(contains(j["extensionsRequired"], "KHR_mesh_quantization"));
    const auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
    EXPECT_EQ(j["accessors"][attributes["POSITION"].get<int>()]["componentType"], 5123);  // unsigned short
    EXPECT_EQ(j["accessors"][attributes["NORMAL"].get<int>()]["componentType"], 5120);    // byte
    const auto& uv = j["accessors"][attributes["TEXCOORD_0"].get<int>()];
    EXPECT_EQ(uv["componentType"], 5123);
    EXPECT_EQ(uv["normalized"], true);
  }
}

TEST(Mesh_IO_gltf_write, NormalMapsGetUnitTangentsAlongUWithHandedness) {
  // A flat grid (normal +z) with u along +x and v along +y: tangent +x, and cross(normal,
  // tangent) = +y is the direction of increasing v (w = 1). Mirrored (u along -x): tangent -x,
  // w = -1. Without a normal map no tangent is written.
  const std::string dir = scratch_dir();
  Material m = textured_material("bumpy", {1, 1, 1}, write_png(dir, "base.png", 1));
  m.normal_texture = write_png(dir, "normal.png", 2);
  Textured_mesh plain = textured_grid(4, m, 0), mirrored = plain;
  for (auto h : mirrored.mesh().halfedges())
    if (!mirrored.mesh().is_border(h)) mirrored.set_uv(h, Point_2(1 - mirrored.uv(h).x(), mirrored.uv(h).y()));
  Textured_mesh no_normal_map = plain;
  no_normal_map.materials()[0].normal_texture.clear();
  for (const auto& [mesh, stem, x_sign] :
       {std::make_tuple(&plain, "plain", 1.0), std::make_tuple(&mirrored, "mirrored", -1.0),
        std::make_tuple(&no_normal_map, "no_normal_map", 0.0)}) {
    SCOPED_TRACE(stem);
    const std::string path = out_path(dir, std::string(stem) + ".gltf");
    IO::write_mesh(path, *mesh);
    const nlohmann::json j = read_json(path);
    const auto& attributes = j["meshes"][0]["primitives"][0]["attributes"];
    if (x_sign == 0) {
      EXPECT_FALSE(attributes.contains("TANGENT"));
      continue;
    }
    ASSERT_TRUE(attributes.contains("TANGENT"));
    EXPECT_EQ(j["accessors"][attributes["TANGENT"].get<int>()]["type"], "VEC4");
    const std::vector<float> t = float_accessor(j, path, attributes["TANGENT"]);
    ASSERT_EQ(t.size(), 4 * 25u);
    for (std::size_t i = 0; i < t.size(); i += 4) {
      EXPECT_EQ(t[i], x_sign) << "vertex " << i / 4;
      EXPECT_EQ(t[i + 1], 0.f);
      EXPECT_EQ(t[i + 2], 0.f);
      EXPECT_EQ(t[i + 3], x_sign) << "vertex " << i / 4;
    }
  }
}

TEST(Mesh_IO_gltf_write, PngColourSpaceChunksAreDroppedAndPixelsKept) {
  // spot's texture has iCCP and cHRM chunks (glTF viewers must ignore them; the validator warns)
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = scratch_dir();
  const std::string source = shared_data("textured/spot/spot_texture.png");
  const std::vector<std::string> source_chunks = png_chunks(file_bytes(source));
  ASSERT_NE(std::find(source_chunks.begin(), source_chunks.end(), "iCCP"), source_chunks.end());
  const Textured_mesh cube = textured_cube({textured_material("spot", {1, 1, 1}, source)}, 0);
  const std::string path = out_path(dir, "cube.glb");
  IO::write_mesh(path, cube);
  Textured_mesh back;
  IO::read_mesh(path, back);
  ASSERT_EQ(back.materials().size(), 1u);
  const std::string blob(back.materials()[0].diffuse_texture_blob.begin(),
                         back.materials()[0].diffuse_texture_blob.end());
  std::vector<std::string> kept;
  for (const std::string& c : source_chunks)
    if (c != "iCCP" && c != "sRGB" && c != "gAMA" && c != "cHRM") kept.push_back(c);
  EXPECT_EQ(png_chunks(blob), kept);
  EXPECT_TRUE(decode_image(blob, dir) == IO::read_image(source));
}
