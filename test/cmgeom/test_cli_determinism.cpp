// Determinism of the command-line tool: each sub-command of a representative set is run twice
// with one thread and once with two; every output file must be byte-identical across the three
// runs (the guarantee of doc/Reliability.md).
#include "cli_test_util.h"

#include <sys/wait.h>

namespace {

struct Step {
  const char* name;
  std::string args;                  // "{in}" = bundled Spot, "{dir}" = run directory
  std::vector<std::string> outputs;  // files (relative to the run directory) to compare
};

std::string expand(std::string s, const std::string& dir) {
  const std::string spot = std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj";
  for (std::size_t p; (p = s.find("{in}")) != std::string::npos;) s.replace(p, 4, "'" + spot + "'");
  for (std::size_t p; (p = s.find("{dir}")) != std::string::npos;) s.replace(p, 5, "'" + dir + "'");
  return s;
}

// `base`: the test's scratch directory (inputs the steps need may already be there).
void check_deterministic(const std::vector<Step>& steps, const std::string& base) {
  std::vector<std::string> runs;
  const char* threads[] = {"--threads 1", "--threads 1", "--threads 2"};
  for (int r = 0; r < 3; ++r) {
    const std::string dir = (fs::path(base) / ("run" + std::to_string(r))).string();
    fs::create_directories(dir);
    runs.push_back(dir);
    for (const Step& s : steps) {
      const auto res = cmgeom_test::run_cli(std::string(threads[r]) + " " + expand(s.args, dir), base);
      ASSERT_EQ(res.exit_code, 0) << s.name << ": " << res.err;
    }
  }
  for (const Step& s : steps)
    for (const std::string& out : s.outputs) {
      SCOPED_TRACE(std::string(s.name) + ": " + out);
      const std::string first = bytes_of((fs::path(runs[0]) / out).string());
      ASSERT_FALSE(first.empty()) << "missing output";
      EXPECT_TRUE(first == bytes_of((fs::path(runs[1]) / out).string())) << "differs between two runs";
      EXPECT_TRUE(first == bytes_of((fs::path(runs[2]) / out).string())) << "differs between 1 and 2 threads";
    }
}

}  // namespace

TEST(cmgeom_cli, ConvertIsDeterministic) {
  check_deterministic({{"convert", "convert {in} -o {dir}/spot.obj", {"spot.obj", "spot.mtl"}},
                       {"convert ply", "convert {in} -o {dir}/spot.ply", {"spot.ply"}}},
                      cmgeom_test::scratch_dir());
}

TEST(cmgeom_cli, PipelineCommandsAreDeterministic) {
  // A box cage around Spot and a sheared copy of it, for cmgeom deform.
  const std::string base = cmgeom_test::scratch_dir();
  const char* box = "v -2 -2 -2\nv 2 -2 -2\nv 2 2 -2\nv -2 2 -2\nv -2 -2 2\nv 2 -2 2\nv 2 2 2\nv -2 2 2\n";
  const char* sheared = "v -2 -2 -2\nv 2 -2 -2\nv 3 2 -2\nv -1 2 -2\nv -2 -2 2\nv 2 -2 2\nv 3 2 2.5\nv -1 2 2.5\n";
  const char* faces = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  cmgeom_test::write_text(base, "rest.obj", std::string(box) + faces);
  cmgeom_test::write_text(base, "deformed.obj", std::string(sheared) + faces);
  for (const char* c : {"mean_value", "green"})
    cmgeom_test::write_text(base, std::string(c) + ".json",
                            std::string("{\"cages\": [{\"rest\": \"rest.obj\", \"deformed\": \"deformed.obj\", "
                                        "\"coordinates\": \"") +
                                c + "\"}]}");
  const std::string cages = base;
  check_deterministic(
      {
          {"simplify weighted", "simplify {in} -o {dir}/w.obj --ratio 0.2 --policy weighted", {"w.obj"}},
          {"simplify plain", "simplify {in} -o {dir}/p.ply --ratio 0.2 --policy plain --no-texture", {"p.ply"}},
          {"error", "error {in} {dir}/w.obj --field {dir}/field.txt --json", {"field.txt"}},
          {"render", "render {dir}/w.obj -o {dir}/w.png --size 256x256 --wireframe", {"w.png"}},
          {"cm build", "cm build {in} -o {dir}/spot.cm --ratio 0.1", {"spot.cm"}},
          {"cm build joint", "cm build {in} -o {dir}/spot_joint.cm --ratio 0.1 --joint-fit", {"spot_joint.cm"}},
          {"cm build fits chosen by measurement",
           "cm build {in} -o {dir}/spot_auto.cm --ratio 0.05 --no-texture --fit auto",
           {"spot_auto.cm"}},
          {"cm build error control",
           "cm build {in} -o {dir}/spot_ec.cm --ratio 0.1 --joint-fit --error-bound 0.02 --error-rounds 3 "
           "--error-level 1",
           {"spot_ec.cm"}},
          {"cm reconstruct", "cm reconstruct {dir}/spot.cm -o {dir}/cm.ply --level 2", {"cm.ply"}},
          {"deform mean value", "deform {in} --cages '" + cages + "/mean_value.json' -o {dir}/mv.ply", {"mv.ply"}},
          {"deform green", "deform {in} --cages '" + cages + "/green.json' -o {dir}/g.ply", {"g.ply"}},
      },
      base);
}

TEST(cmgeom_cli, CommandsOfTheCageAndTextureStagesAreDeterministic) {
  // Two box cages side by side around Spot (the *Cages system of cmgeom deform and influence),
  // a single box cage for cm deform, and a textured simplification of Spot with its texture.
  const std::string base = cmgeom_test::scratch_dir();
  const std::string faces = R"("faces": [[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]])";
  cmgeom_test::write_text(
      base, "two.json",
      std::string(R"({"cages": [
    {"name": "left", "rest": {"vertices": [[-3,-3,-3],[0,-3,-3],[0,3,-3],[-3,3,-3],[-3,-3,3],[0,-3,3],[0,3,3],[-3,3,3]], )") +
          faces +
          R"(}, "deformed": [[-3,-3,-3],[0,-3,-3],[0,3,-3],[-3.5,3,-3],[-3,-3,3],[0,-3,3],[0,3,3],[-3.5,3,3.5]]},
    {"name": "right", "rest": {"vertices": [[0,-3,-3],[3,-3,-3],[3,3,-3],[0,3,-3],[0,-3,3],[3,-3,3],[3,3,3],[0,3,3]], )" +
          faces + R"(}, "deformed": [[0,-3,-3],[3,-3,-3],[3.5,3,-3],[0,3,-3],[0,-3,3],[3,-3,3],[3.5,3,3],[0,3,3]],
     "coordinates": "green"}]})");
  // cm deform reads one cage given by files.
  const char* quads = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  cmgeom_test::write_text(base, "box.obj",
                          std::string("v -3 -3 -3\nv 3 -3 -3\nv 3 3 -3\nv -3 3 -3\n"
                                      "v -3 -3 3\nv 3 -3 3\nv 3 3 3\nv -3 3 3\n") +
                              quads);
  cmgeom_test::write_text(base, "box_sheared.obj",
                          std::string("v -3 -3 -3\nv 3 -3 -3\nv 4 3 -3\nv -2 3 -3\n"
                                      "v -3 -3 3\nv 3 -3 3\nv 4 3 3.5\nv -2 3 3.5\n") +
                              quads);
  cmgeom_test::write_text(base, "one.json", R"({"cages": [{"rest": "box.obj", "deformed": "box_sheared.obj"}]})");
  check_deterministic(
      {
          {"simplify textured", "simplify {in} -o {dir}/t.obj --ratio 0.2", {"t.obj", "t.mtl", "t_0_diffuse.png"}},
          {"deform two cages", "deform {in} --cages '" + base + "/two.json' -o {dir}/two.ply", {"two.ply"}},
          {"influence",
           "influence {in} --cages '" + base + "/two.json' -o {dir}/inf.png --size 128x128 --values {dir}/inf.txt",
           {"inf.png", "inf.txt"}},
          {"influence grid", "influence {in} --grid 2,2,1 --values {dir}/grid.txt", {"grid.txt"}},
          {"cm build", "cm build {in} -o {dir}/spot.cm --ratio 0.1", {"spot.cm"}},
          {"cm deform",
           "cm deform {dir}/spot.cm --cages '" + base + "/one.json' -o {dir}/cmd.ply --level 1",
           {"cmd.ply"}},
      },
      base);
}

// The tool executes itself again with glibc's huge-page tunable (tools/cmgeom/main.cpp): its
// outputs are those of the tool left as it is (CMGEOM_HUGE_PAGE_HEAP=0) and of the tool without
// any huge page (CMGEOM_HUGE_PAGES=0), and a GLIBC_TUNABLES the caller set already (another
// tunable) is kept and works.
TEST(cmgeom_cli, HugePageHeapChangesNoOutput) {
  const std::string base = cmgeom_test::scratch_dir();
  const std::string spot = std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj";
  const char* environments[] = {"", "CMGEOM_HUGE_PAGE_HEAP=0", "GLIBC_TUNABLES=glibc.malloc.check=0",
                                "CMGEOM_HUGE_PAGES=0"};
  std::vector<std::string> outputs;
  for (int k = 0; k < 4; ++k) {
    const std::string out = (fs::path(base) / ("w" + std::to_string(k) + ".ply")).string();
    const std::string cmd = std::string("env ") + environments[k] + " '" + CMGEOM_CMGEOM_EXE + "' --quiet simplify '" +
                            spot + "' -o '" + out + "' --ratio 0.2 --no-texture > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    outputs.push_back(bytes_of(out));
    ASSERT_FALSE(outputs.back().empty()) << cmd;
  }
  EXPECT_TRUE(outputs[0] == outputs[1]) << "the output depends on the heap's pages";
  EXPECT_TRUE(outputs[0] == outputs[2]) << "the output depends on the caller's GLIBC_TUNABLES";
  EXPECT_TRUE(outputs[0] == outputs[3]) << "the output depends on the process' huge pages";
}

// A value of CMGEOM_HUGE_PAGES other than 0 or 1 is refused before anything runs: exit code 2, the
// variable and the values it takes named, no output file.
TEST(cmgeom_cli, HugePageSettingRefusesOtherValues) {
  const std::string base = cmgeom_test::scratch_dir();
  const std::string spot = std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj";
  const std::string out = (fs::path(base) / "refused.ply").string();
  const std::string err = (fs::path(base) / "refused.txt").string();
  const std::string cmd = std::string("env CMGEOM_HUGE_PAGES=off '") + CMGEOM_CMGEOM_EXE + "' --quiet simplify '" +
                          spot + "' -o '" + out + "' --ratio 0.2 --no-texture > /dev/null 2> '" + err + "'";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << cmd;
  EXPECT_EQ(WEXITSTATUS(status), 2);
  EXPECT_NE(bytes_of(err).find("cmgeom: error: CMGEOM_HUGE_PAGES=off: expected 0"), std::string::npos) << bytes_of(err);
  EXPECT_FALSE(fs::exists(out));
}
