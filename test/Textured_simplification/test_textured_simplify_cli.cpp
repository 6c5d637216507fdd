// Tests of `cmgeom simplify` on a textured input: OBJ + MTL + PNG output, JSON report, errors.
#include "textured_part_test_util.h"

namespace {

// `cmgeom simplify` on a textured input: OBJ + MTL + PNG, JSON keys, charts kept, target
// reached; identical bytes on a second run; clear errors for unusable texture options.
TEST(TexturedSimplification, CommandLineWritesObjMtlPng) {
  const std::string in = std::string(CMGEOM_DATA_DIR) + "/textured/bunny10k_textured/bunny10k_textured.obj";
  if (!fs::exists(in)) GTEST_SKIP() << "shared data not found: " << in;
  const std::string exe = CMGEOM_CMGEOM_EXE;
  const std::string dir = std::string(CMGEOM_TEST_TMP_DIR) + "/ts_textured_cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto run = [](const std::string& cmd, std::string* out = nullptr) {
    FILE* p = popen((cmd + " 2>/dev/null").c_str(), "r");
    std::string text;
    char buf[4096];
    std::size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
    const int status = pclose(p);
    if (out) *out = text;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  auto slurp = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  };
  std::string text;
  for (const char* name : {"a", "b"}) {
    ASSERT_EQ(
        run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/" + name + ".obj' --ratio 0.3 --keep-charts --json",
            &text),
        0);
  }
  const auto j = nlohmann::json::parse(text);
  for (const char* key : {"faces_in", "faces_out", "charts_in", "charts_out", "seconds", "stopped_by"})
    ASSERT_TRUE(j.contains(key)) << key;
  // the times of the three stages, as the geometry path and `lod` report them
  for (const char* key : {"seconds_read", "seconds", "seconds_write"}) {
    ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_GE(j[key].get<double>(), 0.0) << key;
  }
  EXPECT_EQ(j["charts_in"], j["charts_out"]);
  EXPECT_EQ(j["charts"], "kept");
  EXPECT_EQ(j["faces_in"].get<int>(), 9999);
  EXPECT_LE(j["faces_out"].get<int>(), 3000);
  EXPECT_TRUE(fs::exists(dir + "/a.mtl"));
  EXPECT_TRUE(fs::exists(dir + "/a_0_diffuse.png"));
  EXPECT_EQ(slurp(dir + "/a.obj").size() > 1000, true);
  // deterministic (the OBJ names its own MTL, so compare the textures and the MTL-free body)
  EXPECT_EQ(slurp(dir + "/a_0_diffuse.png"), slurp(dir + "/b_0_diffuse.png"));
  std::string a = slurp(dir + "/a.obj"), b = slurp(dir + "/b.obj");
  a = a.substr(a.find("\nv "));
  b = b.substr(b.find("\nv "));
  EXPECT_EQ(a, b);
  // the written mesh reads back with its UVs and texture
  CMGeom::Textured_mesh back;
  CMGeom::IO::read_textured_mesh(dir + "/a.obj", back);
  EXPECT_TRUE(back.has_uvs());
  ASSERT_FALSE(back.materials().empty());
  EXPECT_EQ(back.materials()[0].diffuse_image.width(), 512);
  // errors: one line, exit code 1, no output file
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/c.ply' --ratio 0.3"), 1);
#ifdef CMGEOM_HAS_OSMESA
  // the OpenGL backend writes the same files, byte for byte
  ASSERT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir +
                    "/gl.obj' --ratio 0.3 --keep-charts --texture-backend osmesa --json",
                &text),
            0);
  EXPECT_EQ(nlohmann::json::parse(text).value("texture_backend", ""), "osmesa");
  EXPECT_EQ(slurp(dir + "/a_0_diffuse.png"), slurp(dir + "/gl_0_diffuse.png"));
  std::string g = slurp(dir + "/gl.obj");
  EXPECT_EQ(a, g.substr(g.find("\nv ")));
#else
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir +
                "/c.obj' --ratio 0.3 --keep-charts --texture-backend osmesa"),
            1);
#endif
  EXPECT_EQ(run("'" + exe + "' simplify '" + in + "' -o '" + dir + "/c.obj' --ratio 0.3 --texture-size 4"), 1);
  EXPECT_FALSE(fs::exists(dir + "/c.obj"));
  EXPECT_FALSE(fs::exists(dir + "/c.ply"));
}

}  // namespace
