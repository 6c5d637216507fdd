// Determinism of the command-line tool: each sub-command of a representative set is run twice
// with one thread and once with two; every output file must be byte-identical across the three
// runs (the guarantee of doc/Reliability.md). Then the pipeline as a whole, and the progress
// output on stderr in its three modes (terminal, pipe or file, --quiet; doc/CLI.md). Last, the
// level-of-detail chains of cmgeom lod and the GLB output of cmgeom simplify (the Khronos glTF
// validator of test/Mesh_IO/gltf_validator runs when Node.js and its npm package are present).
#include "cmgeom_test_meshes.h"
#include "cmgeom_test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <pty.h>
#include <regex>
#include <set>
#include <sstream>
#include <termios.h>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

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
                                        "\"coordinates\": \"") + c + "\"}]}");
  const std::string cages = base;
  check_deterministic({
      {"simplify weighted", "simplify {in} -o {dir}/w.obj --ratio 0.2 --policy weighted", {"w.obj"}},
      {"simplify plain", "simplify {in} -o {dir}/p.ply --ratio 0.2 --policy plain --no-texture", {"p.ply"}},
      {"error", "error {in} {dir}/w.obj --field {dir}/field.txt --json", {"field.txt"}},
      {"render", "render {dir}/w.obj -o {dir}/w.png --size 256x256 --wireframe", {"w.png"}},
      {"cm build", "cm build {in} -o {dir}/spot.cm --ratio 0.1", {"spot.cm"}},
      {"cm build joint", "cm build {in} -o {dir}/spot_joint.cm --ratio 0.1 --joint-fit", {"spot_joint.cm"}},
      {"cm build error control",
       "cm build {in} -o {dir}/spot_ec.cm --ratio 0.1 --joint-fit --error-bound 0.02 --error-rounds 3 --error-level 1",
       {"spot_ec.cm"}},
      {"cm reconstruct", "cm reconstruct {dir}/spot.cm -o {dir}/cm.ply --level 2", {"cm.ply"}},
      {"deform mean value", "deform {in} --cages '" + cages + "/mean_value.json' -o {dir}/mv.ply", {"mv.ply"}},
      {"deform green", "deform {in} --cages '" + cages + "/green.json' -o {dir}/g.ply", {"g.ply"}},
  }, base);
}

TEST(cmgeom_cli, CommandsOfTheCageAndTextureStagesAreDeterministic) {
  // Two box cages side by side around Spot (the *Cages system of cmgeom deform and influence),
  // a single box cage for cm deform, and a textured simplification of Spot with its texture.
  const std::string base = cmgeom_test::scratch_dir();
  const std::string faces = R"("faces": [[0,3,2,1],[4,5,6,7],[0,1,5,4],[1,2,6,5],[2,3,7,6],[3,0,4,7]])";
  cmgeom_test::write_text(base, "two.json", std::string(R"({"cages": [
    {"name": "left", "rest": {"vertices": [[-3,-3,-3],[0,-3,-3],[0,3,-3],[-3,3,-3],[-3,-3,3],[0,-3,3],[0,3,3],[-3,3,3]], )") +
    faces + R"(}, "deformed": [[-3,-3,-3],[0,-3,-3],[0,3,-3],[-3.5,3,-3],[-3,-3,3],[0,-3,3],[0,3,3],[-3.5,3,3.5]]},
    {"name": "right", "rest": {"vertices": [[0,-3,-3],[3,-3,-3],[3,3,-3],[0,3,-3],[0,-3,3],[3,-3,3],[3,3,3],[0,3,3]], )" +
    faces + R"(}, "deformed": [[0,-3,-3],[3,-3,-3],[3.5,3,-3],[0,3,-3],[0,-3,3],[3,-3,3],[3.5,3,3],[0,3,3]],
     "coordinates": "green"}]})");
  // cm deform reads one cage given by files.
  const char* quads = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  cmgeom_test::write_text(base, "box.obj", std::string("v -3 -3 -3\nv 3 -3 -3\nv 3 3 -3\nv -3 3 -3\n"
                                                       "v -3 -3 3\nv 3 -3 3\nv 3 3 3\nv -3 3 3\n") + quads);
  cmgeom_test::write_text(base, "box_sheared.obj", std::string("v -3 -3 -3\nv 3 -3 -3\nv 4 3 -3\nv -2 3 -3\n"
                                                               "v -3 -3 3\nv 3 -3 3\nv 4 3 3.5\nv -2 3 3.5\n") + quads);
  cmgeom_test::write_text(base, "one.json", R"({"cages": [{"rest": "box.obj", "deformed": "box_sheared.obj"}]})");
  check_deterministic({
      {"simplify textured", "simplify {in} -o {dir}/t.obj --ratio 0.2", {"t.obj", "t.mtl", "t_0_diffuse.png"}},
      {"deform two cages", "deform {in} --cages '" + base + "/two.json' -o {dir}/two.ply", {"two.ply"}},
      {"influence", "influence {in} --cages '" + base + "/two.json' -o {dir}/inf.png --size 128x128 --values {dir}/inf.txt",
       {"inf.png", "inf.txt"}},
      {"influence grid", "influence {in} --grid 2,2,1 --values {dir}/grid.txt", {"grid.txt"}},
      {"cm build", "cm build {in} -o {dir}/spot.cm --ratio 0.1", {"spot.cm"}},
      {"cm deform", "cm deform {dir}/spot.cm --cages '" + base + "/one.json' -o {dir}/cmd.ply --level 1", {"cmd.ply"}},
  }, base);
}

// The README's main job: every stage writes its files, the report names each picture it shows,
// every picture is a PNG, and the deformable CM stays close to the mesh deformed by the same cages.
TEST(cmgeom_cli, PipelineRunsEveryStageAndReportsIt) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string out = (fs::path(dir) / "out").string();
  const auto r = cmgeom_test::run_cli("pipeline -o '" + out + "' --size 64x64", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (int k = 1; k <= 6; ++k)
    EXPECT_NE(r.err.find("[" + std::to_string(k) + "/6]"), std::string::npos) << "no progress line for stage " << k;
  const std::string report = bytes_of((fs::path(out) / "report.md").string());
  for (const char* section : {"## Input model", "## Simplification", "## Compact Model", "## *Cages deformation",
                              "## Deformable Compact Model"})
    EXPECT_NE(report.find(section), std::string::npos) << "report.md has no section " << section;
  EXPECT_EQ(report.find("stopped at stage"), std::string::npos);
  // Every picture the report shows exists and starts with the PNG signature.
  std::size_t pictures = 0;
  for (std::size_t p = 0; (p = report.find("](", p)) != std::string::npos; p += 2) {
    const std::string name = report.substr(p + 2, report.find(')', p) - p - 2);
    const std::string png = bytes_of((fs::path(out) / name).string());
    EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << name;
    ++pictures;
  }
  EXPECT_GE(pictures, 15u);
  for (const char* f : {"simplified_weighted.obj", "simplified_plain.obj", "model.cm", "cm_regular.ply",
                        "cm_adaptive.ply", "rest_cages.json", "cages.json", "deformed.obj", "dcm_cages.obj",
                        "dcm_affine.obj", "report.html"})
    EXPECT_TRUE(fs::is_regular_file(fs::path(out) / f)) << f;
  // The deformable CM against the full mesh deformed by the same cages, measured by the error
  // command independently of the pipeline. What the method guarantees (thesis §6.3-6.4): the
  // deformed CM is the rest CM carried by maps that follow the cage deformation, so its distance to
  // the deformed mesh is the rest CM's distance to the input (the same level-2 reconstruction,
  // cm_regular.ply) scaled by the deformation's stretch, plus the error of blending per-vertex
  // affine maps. The pipeline's cages stretch their edges by at most 1.5 (0.52-1.50 measured), so
  // the bound is 1.5 x the rest distance, absolute units (measured: 3.69 % against 3.40 % at rest,
  // of the diagonals; a deformable CM that loses its local maps moves far beyond it).
  const auto rest = cmgeom_test::run_cli("error '" + std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj' '" + out +
                                             "/cm_regular.ply' --json",
                                         dir);
  ASSERT_EQ(rest.exit_code, 0) << rest.err;
  const auto e = cmgeom_test::run_cli("error '" + out + "/deformed.obj' '" + out + "/dcm_cages.obj' --json", dir);
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const auto j = nlohmann::json::parse(e.out), jr = nlohmann::json::parse(rest.out);
  const double deformed = j["absolute"]["hausdorff"].get<double>(), at_rest = jr["absolute"]["hausdorff"].get<double>();
  EXPECT_LT(deformed, 1.5 * at_rest) << "deformed " << deformed << ", at rest " << at_rest;
  EXPECT_GT(deformed, 0.0);
}

// A stage that fails stops the run; the files of the finished stages stay and the report says
// where the run stopped.
TEST(cmgeom_cli, PipelineStopsAtTheFailingStageAndKeepsTheFinishedOnes) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string out = (fs::path(dir) / "out").string();
  const std::string bad = cmgeom_test::write_text(dir, "bad.json", "{\"cages\": [{\"rest\": {\"vertices\": [[0,0,0]]}}]}");
  // A small untextured sphere keeps the three stages that must finish quick.
  const std::string sphere = cmgeom_test::write_text(dir, "sphere.obj", cmgeom_test::icosphere_obj(3));
  const auto r = cmgeom_test::run_cli("pipeline --model '" + sphere + "' -o '" + out + "' --size 64x64 --cages '" + bad + "'", dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("*Cages deformation"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
  for (const char* name : {"input.png", "simplified_weighted.obj", "model.cm", "cm_regular.ply"})
    EXPECT_TRUE(fs::is_regular_file(fs::path(out) / name)) << name;
  EXPECT_FALSE(fs::exists(fs::path(out) / "deformed.obj"));
  const std::string report = bytes_of((fs::path(out) / "report.md").string());
  EXPECT_NE(report.find("stopped at stage '*Cages deformation"), std::string::npos);
  // A missing cage file is refused before anything is written.
  const std::string out2 = (fs::path(dir) / "out2").string();
  const auto m = cmgeom_test::run_cli("pipeline -o '" + out2 + "' --cages '" + dir + "/missing.json'", dir);
  EXPECT_EQ(m.exit_code, 1);
  EXPECT_NE(m.err.find("missing.json"), std::string::npos) << m.err;
  EXPECT_FALSE(fs::exists(out2));
  // So is a bad picture size.
  const auto z = cmgeom_test::run_cli("pipeline -o '" + out2 + "' --size 0x0", dir);
  EXPECT_EQ(z.exit_code, 1);
  EXPECT_NE(z.err.find("--size '0x0'"), std::string::npos) << z.err;
  EXPECT_FALSE(fs::exists(out2));
}

// ------------------------------------------------------------------ progress output
// doc/CLI.md, "Progress": on a terminal, a line redrawn with '\r' (label, percentage, rate) once
// a stage has run 0.5 s, then "<label> done in X s"; on a pipe or a file, one line per stage that
// took 0.5 s or more, "cmgeom: <label>: done in X s (<count> <unit>)"; with --quiet, nothing. The
// jobs run for seconds on a fast machine (a slow or busy one only makes them longer), so that
// their main stage always passes 0.5 s; no test depends on how long anything takes.
namespace {

// The 327,680-face icosphere in `dir`.
std::string large_sphere(const std::string& dir) {
  return cmgeom_test::write_text(dir, "sphere7.obj", cmgeom_test::icosphere_obj(7));
}

// A long job: its long stage's label, and whether that stage knows its count (then the
// terminal shows a rate in faces/s; otherwise the time left).
struct Long_job {
  std::string args, label;
  bool counted;
};

// Simplification with CGAL's engine (progress from cmgeom's own collapse visitor) and a Compact
// Model build with a round of error control (progress from the library's hook,
// Build_options::progress). Both print a JSON report.
std::vector<Long_job> long_jobs(const std::string& sphere, const std::string& dir) {
  return {{"simplify '" + sphere + "' -o '" + dir + "/s.obj' --ratio 0.1 --engine cgal --json", "simplify", false},
          {"cm build '" + sphere + "' -o '" + dir + "/s.cm' --ratio 0.01 --error-bound 1e-6 --error-rounds 1 --json",
           "cm build", true}};
}

// Exit code of run_cli_on_terminal() when the system gives no pseudo-terminal.
constexpr int no_terminal = -2;

// cmgeom with `args` (shell-quoted), its stderr on a pseudo-terminal whose output processing is
// off (so that '\n' is not turned into "\r\n"), its stdout in a file. `err` is all the terminal
// received.
cmgeom_test::Cli_result run_cli_on_terminal(const std::string& args, const std::string& dir) {
  const std::string out = (fs::path(dir) / "cli.stdout").string();
  const std::string cmd = std::string("'") + CMGEOM_CMGEOM_EXE + "' " + args + " > '" + out + "'";
  cmgeom_test::Cli_result r;
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) {
    r.exit_code = no_terminal;
    return r;
  }
  if (pid == 0) {
    termios t;
    if (tcgetattr(STDERR_FILENO, &t) == 0) {
      t.c_oflag &= ~tcflag_t(OPOST);
      tcsetattr(STDERR_FILENO, TCSANOW, &t);
    }
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  char buf[4096];
  for (;;) {  // until the child's side is closed (EIO on Linux)
    const ssize_t n = read(master, buf, sizeof buf);
    if (n > 0)
      r.err.append(buf, std::size_t(n));
    else if (n < 0 && errno == EINTR)
      continue;
    else
      break;
  }
  close(master);
  int status = 0;
  waitpid(pid, &status, 0);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = bytes_of(out);
  fs::remove(out);
  return r;
}

// `s` with '\r' shown as "\r", for failure messages.
std::string visible(std::string s) {
  for (std::size_t p = 0; (p = s.find('\r', p)) != std::string::npos; p += 2) s.replace(p, 1, "\\r");
  return s;
}

// A JSON report without its timings (the keys naming seconds), which differ from run to run.
std::string without_timings(const std::string& json_text) {
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(json_text);
  std::vector<std::string> timings;
  for (const auto& item : j.items())
    if (item.key().find("seconds") != std::string::npos) timings.push_back(item.key());
  for (const std::string& k : timings) j.erase(k);
  return j.dump();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

}  // namespace

TEST(cmgeom_cli, ProgressOnATerminalIsOneLineRedrawnPerStageThenDone) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string sphere = large_sphere(dir);
  for (const Long_job& job : long_jobs(sphere, dir)) {
    SCOPED_TRACE(job.args);
    const auto r = run_cli_on_terminal(job.args, dir);
    if (r.exit_code == no_terminal) GTEST_SKIP() << "no pseudo-terminal on this system (forkpty failed)";
    ASSERT_EQ(r.exit_code, 0) << visible(r.err);
    // Redrawn in place: '\r', the label, a percentage and, for a counted stage, a rate.
    const std::string bar = "\r" + job.label + " +[0-9]{1,3}%" + (job.counted ? "  [0-9.]+( [kMG])? faces/s" : "");
    EXPECT_TRUE(std::regex_search(r.err, std::regex(bar))) << visible(r.err);
    // Then the stage's last line, once, and never the format of logs.
    const std::regex done("\r" + job.label + " done in [0-9]+\\.[0-9]{2} s( \\([0-9]+ [a-z ]+\\))? *\n");
    EXPECT_EQ(std::distance(std::sregex_iterator(r.err.begin(), r.err.end(), done), std::sregex_iterator()), 1)
        << visible(r.err);
    EXPECT_EQ(r.err.find("cmgeom: "), std::string::npos) << visible(r.err);
    // The report on stdout is untouched by the terminal's progress.
    EXPECT_NO_THROW(nlohmann::json::parse(r.out)) << r.out;
  }
}

TEST(cmgeom_cli, ProgressOnAPipeIsOneLinePerLongStageAndQuietIsSilent) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string sphere = large_sphere(dir);
  const std::regex line("cmgeom: ([^:]+): done in ([0-9]+\\.[0-9]{2}) s( \\([0-9]+ [a-z ]+\\))?");
  for (const Long_job& job : long_jobs(sphere, dir)) {
    SCOPED_TRACE(job.args);
    const auto piped = cmgeom_test::run_cli(job.args, dir);  // stderr to a file
    ASSERT_EQ(piped.exit_code, 0) << piped.err;
    EXPECT_EQ(piped.err.find('\r'), std::string::npos) << visible(piped.err);
    // Every line is the end of a stage that took at least 0.5 s, each stage at most once, and
    // the long stage is there.
    std::vector<std::string> stages;
    for (const std::string& l : lines_of(piped.err)) {
      std::smatch m;
      ASSERT_TRUE(std::regex_match(l, m, line)) << "not a progress line: " << l;
      EXPECT_GE(std::stod(m[2].str()), 0.5) << l;
      EXPECT_EQ(std::count(stages.begin(), stages.end(), m[1].str()), 0) << "twice: " << l;
      stages.push_back(m[1].str());
    }
    EXPECT_EQ(std::count(stages.begin(), stages.end(), job.label), 1) << piped.err;
    // --quiet: nothing on stderr, the same report on stdout (its timings aside).
    const auto quiet = cmgeom_test::run_cli(job.args + " --quiet", dir);
    ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
    EXPECT_EQ(quiet.err, "");
    EXPECT_EQ(without_timings(quiet.out), without_timings(piped.out));
  }
  // A report without timings is identical byte for byte, with or without --quiet, on a pipe or
  // a terminal.
  const auto info = cmgeom_test::run_cli("info '" + sphere + "' --json", dir);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(cmgeom_test::run_cli("--quiet info '" + sphere + "' --json", dir).out, info.out);
  for (const char* quiet : {"", " --quiet"}) {
    const auto on_terminal = run_cli_on_terminal("info '" + sphere + "' --json" + quiet, dir);
    if (on_terminal.exit_code != no_terminal) EXPECT_EQ(on_terminal.out, info.out) << quiet;
  }
  // A failing command still prints its error with --quiet.
  const auto bad = cmgeom_test::run_cli("--quiet info '" + dir + "/missing.obj'", dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("missing.obj"), std::string::npos) << bad.err;
}

// --quiet holds for the commands the pipeline runs in-process, whose own arguments do not
// repeat it: a successful run prints nothing on stderr.
TEST(cmgeom_cli, QuietPipelinePrintsNothingOnStderr) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string sphere = cmgeom_test::write_text(dir, "sphere.obj", cmgeom_test::icosphere_obj(3));
  const std::string out = (fs::path(dir) / "out").string();
  const auto r = cmgeom_test::run_cli("pipeline --model '" + sphere + "' -o '" + out + "' --size 64x64 --quiet", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(fs::is_regular_file(fs::path(out) / "report.md"));
}

// ------------------------------------------------------------------ levels of detail and glTF output
// cmgeom lod writes a level-of-detail chain as one glTF node per level (doc/CLI.md): the report
// on stdout, the nodes of the GLB (read back from its JSON chunk), the images each level draws,
// the refusals (nothing written), the OBJ copies of --obj-prefix; and cmgeom simplify writing a
// GLB that the Khronos validator accepts and that renders like the OBJ of the same run.
namespace {

std::string quoted(const std::string& s) { return "'" + s + "'"; }

// The JSON chunk of a GLB file (glTF 2.0 binary container: a 12-byte header, magic "glTF",
// version 2 and the file's length; then chunks of length, type and data, the JSON chunk first).
// A malformed container is a test failure (null returned).
nlohmann::json glb_json(const std::string& path) {
  const std::string b = bytes_of(path);
  auto u32 = [&](std::size_t at) {  // little-endian, as the container stores every integer
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) v |= std::uint32_t(static_cast<unsigned char>(b[at + k])) << (8 * k);
    return v;
  };
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0) {
    ADD_FAILURE() << path << ": not a GLB file (" << b.size() << " bytes)";
    return nullptr;
  }
  EXPECT_EQ(u32(4), 2u) << path << ": container version";
  EXPECT_EQ(u32(8), b.size()) << path << ": the header's length is not the file's";
  const std::size_t length = u32(12);
  if (u32(16) != 0x4E4F534Au || 20 + length > b.size()) {  // "JSON"
    ADD_FAILURE() << path << ": the first chunk is not a JSON chunk within the file";
    return nullptr;
  }
  return nlohmann::json::parse(b.substr(20, length));
}

// The images node `n` draws as base colour (through its mesh's primitives and their materials).
std::set<int> images_of_node(const nlohmann::json& j, std::size_t n) {
  std::set<int> images;
  for (const auto& p : j["meshes"][j["nodes"][n]["mesh"].get<std::size_t>()]["primitives"]) {
    if (!p.contains("material")) continue;
    const auto& m = j["materials"][p["material"].get<std::size_t>()];
    if (!m.contains("pbrMetallicRoughness") || !m["pbrMetallicRoughness"].contains("baseColorTexture")) continue;
    const std::size_t t = m["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<std::size_t>();
    images.insert(j["textures"][t]["source"].get<int>());
  }
  return images;
}

// The triangles of node `n`: its primitives' index counts / 3.
std::size_t triangles_of_node(const nlohmann::json& j, std::size_t n) {
  std::size_t indices = 0;
  for (const auto& p : j["meshes"][j["nodes"][n]["mesh"].get<std::size_t>()]["primitives"])
    indices += j["accessors"][p["indices"].get<std::size_t>()]["count"].get<std::size_t>();
  return indices / 3;
}

// Faces of an OBJ file: its "f" lines.
std::size_t obj_faces(const std::string& path) {
  std::size_t n = 0;
  for (const std::string& l : lines_of(bytes_of(path))) n += l.compare(0, 2, "f ") == 0;
  return n;
}

// Everything in `dir` (files and folders), for the checks that a refused command wrote nothing.
std::vector<std::string> entries_of(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// icosphere(level) as OFF text: a mesh without texture coordinates.
std::string icosphere_off(int level) {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(level, p, f);
  std::ostringstream s;
  s.precision(17);
  s << "OFF\n" << p.size() << " " << f.size() << " 0\n";
  for (const auto& q : p) s << q[0] << " " << q[1] << " " << q[2] << "\n";
  for (const auto& t : f) s << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return s.str();
}

// Why the Khronos glTF validator (test/Mesh_IO/gltf_validator) cannot run here ("" when it can).
std::string gltf_validator_missing() {
  const fs::path dir = CMGEOM_GLTF_VALIDATOR_DIR;
  if (std::system("command -v node > /dev/null 2>&1") != 0)
    return "node is not on PATH: install Node.js and npm, then run 'npm install' in " + dir.string();
  std::error_code ec;
  if (!fs::is_directory(dir / "node_modules" / "gltf-validator", ec))
    return "the glTF validator is not installed: run 'npm install' in " + dir.string() + " (scripts/test.sh does)";
  return std::string();
}

// The validator's report on `file`: its first line "errors=N warnings=N infos=N hints=N", then one
// line per issue. `errors` and `warnings` stay -1 (a test failure) when it could not validate.
struct Validation {
  int errors = -1, warnings = -1, infos = -1, hints = -1;
  std::string report;
};

Validation validate_gltf(const std::string& file) {
  const std::string report_file = file + ".validation.txt";
  const std::string cmd = "node " + quoted((fs::path(CMGEOM_GLTF_VALIDATOR_DIR) / "validate.js").string()) + " " +
                          quoted(file) + " > " + quoted(report_file) + " 2>&1";
  const int status = std::system(cmd.c_str());
  Validation v;
  v.report = bytes_of(report_file);
  fs::remove(report_file);
  if (status != 0 || std::sscanf(v.report.c_str(), "errors=%d warnings=%d infos=%d hints=%d", &v.errors, &v.warnings,
                                 &v.infos, &v.hints) != 4)
    ADD_FAILURE() << "the validator could not validate " << file << ":\n" << v.report;
  return v;
}

// The rendering commands' refusal in a build without a renderer (rendering_unavailable_message()).
bool renderer_missing(const cmgeom_test::Cli_result& r) {
  return r.exit_code != 0 && r.err.find("has no renderer") != std::string::npos;
}

}  // namespace

TEST(cmgeom_cli, LodWritesOneGlbNodePerLevelListedByMsftLod) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string duck = cmgeom_test::shared_data("textured/Duck/Duck.obj");
  const std::string validator_missing = gltf_validator_missing();
  if (!validator_missing.empty()) std::cout << "validator not run: " << validator_missing << "\n";
  for (const bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "--shared-texture" : "an atlas per level");
    const std::string glb = (fs::path(dir) / (shared ? "shared.glb" : "levels.glb")).string();
    const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(duck) + " -o " + quoted(glb) +
                                            " --ratios 1,0.25,0.05 --json" + (shared ? " --shared-texture" : ""),
                                        dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err, "");
    const nlohmann::json report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["textured"], true);
    EXPECT_EQ(report["shared_texture"], shared);
    const auto& levels = report["levels"];
    ASSERT_EQ(levels.size(), 3u);
    const std::size_t faces_in = report["faces_in"].get<std::size_t>();
    const double ratios[3] = {1, 0.25, 0.05};
    std::vector<std::size_t> faces;
    for (std::size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE("level " + std::to_string(i));
      const auto& l = levels[i];
      EXPECT_EQ(l["level"], i);
      EXPECT_EQ(l["is_input"], i == 0);
      EXPECT_EQ(l["target_faces"], std::size_t(std::llround(ratios[i] * double(faces_in))));
      faces.push_back(l["faces"].get<std::size_t>());
      // a snapshot is taken at the first collapse that reaches the target (one collapse removes
      // at most two faces)
      EXPECT_LE(faces[i], l["target_faces"].get<std::size_t>());
      EXPECT_GE(faces[i] + 2, l["target_faces"].get<std::size_t>());
      if (i > 0) EXPECT_LT(faces[i], faces[i - 1]);
      // level 0 keeps the input's texture unless one atlas serves all levels
      EXPECT_EQ(l["texture_width"].get<int>() > 0, shared || i > 0) << l;
    }
    EXPECT_EQ(faces[0], faces_in);

    // the GLB: three nodes, the first in the scene listing the other two by MSFT_lod
    const nlohmann::json j = glb_json(glb);
    ASSERT_TRUE(j.is_object());
    ASSERT_EQ(j["nodes"].size(), 3u);
    EXPECT_EQ(j["nodes"][0]["extensions"]["MSFT_lod"]["ids"], nlohmann::json::array({1, 2}));
    for (const std::size_t i : {std::size_t(1), std::size_t(2)}) EXPECT_FALSE(j["nodes"][i].contains("extensions")) << i;
    ASSERT_EQ(j["scenes"].size(), 1u);
    EXPECT_EQ(j["scene"], 0);
    EXPECT_EQ(j["scenes"][0]["nodes"], nlohmann::json::array({0}));
    EXPECT_NE(std::find(j["extensionsUsed"].begin(), j["extensionsUsed"].end(), "MSFT_lod"), j["extensionsUsed"].end());
    // each node: the level's faces (in its extras and in its mesh) and its error, growing with the level
    double previous_error = -1;
    for (std::size_t i = 0; i < 3; ++i) {
      SCOPED_TRACE("node " + std::to_string(i));
      const auto& extras = j["nodes"][i]["extras"];
      EXPECT_EQ(extras["level"], i);
      EXPECT_EQ(extras["faces"].get<std::size_t>(), faces[i]);
      EXPECT_EQ(triangles_of_node(j, i), faces[i]);
      ASSERT_TRUE(extras.contains("error"));
      const double error = extras["error"].get<double>();
      EXPECT_DOUBLE_EQ(error, levels[i]["hausdorff"].get<double>());
      EXPECT_GE(error, 0.0);
      if (i == 0) EXPECT_EQ(error, 0.0);  // the input itself
      else EXPECT_GT(error, previous_error);
      previous_error = error;
    }
    // the images: one shared atlas, or the input's texture and an atlas per simplified level
    ASSERT_TRUE(j.contains("images"));
    std::vector<std::set<int>> drawn;
    for (std::size_t i = 0; i < 3; ++i) drawn.push_back(images_of_node(j, i));
    if (shared) {
      EXPECT_EQ(j["images"].size(), 1u);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(drawn[i], std::set<int>({0})) << "node " << i;
    } else {
      EXPECT_EQ(j["images"].size(), 3u);
      for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(drawn[i].size(), 1u) << "node " << i;
      EXPECT_EQ((std::set<int>{*drawn[0].begin(), *drawn[1].begin(), *drawn[2].begin()}).size(), 3u)
          << "two levels draw the same image";
    }
    for (const auto& image : j["images"]) {
      EXPECT_TRUE(image.contains("bufferView")) << image;  // embedded, not a file beside the GLB
      EXPECT_EQ(image["mimeType"], "image/png") << image;
    }
    // a reader without MSFT_lod (cmgeom's own) sees the finest level
    const auto info = cmgeom_test::run_cli("info " + quoted(glb) + " --json", dir);
    ASSERT_EQ(info.exit_code, 0) << info.err;
    EXPECT_EQ(nlohmann::json::parse(info.out)["faces"].get<std::size_t>(), faces[0]);
    if (validator_missing.empty()) {
      const Validation v = validate_gltf(glb);
      EXPECT_EQ(v.errors, 0) << v.report;
      EXPECT_EQ(v.warnings, 0) << v.report;
    }
  }
}

// Refused chains: exit code 1 (2 for a usage error), one line on stderr naming the problem, and
// nothing in the output directory.
TEST(cmgeom_cli, LodRefusalsNameTheProblemAndWriteNothing) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string duck = cmgeom_test::shared_data("textured/Duck/Duck.obj");
  const std::string inputs = (fs::path(dir) / "inputs").string();
  fs::create_directories(inputs);
  const std::string sphere = cmgeom_test::write_text(inputs, "sphere.off", icosphere_off(2));
  struct Refusal {
    std::string input, args;  // args: "{out}" = the case's output directory
    int exit_code;
    std::string named;        // what the error line must say
  };
  const std::vector<Refusal> refusals = {
      {duck, "-o {out}/x.glb --ratios 1,1", 1, "the levels must decrease strictly (in faces: 4212 then 4212)"},
      {duck, "-o {out}/x.glb --ratios 0.5,0.7", 1, "the levels must decrease strictly (in faces: 2106 then 2948)"},
      {duck, "-o {out}/x.glb --ratios 0", 1, "--ratios: every ratio must be in (0, 1]"},
      {duck, "-o {out}/x.glb --ratios 1,0.5,-0.1", 1, "--ratios: every ratio must be in (0, 1]"},
      {duck, "-o {out}/x.glb --ratios 1,half", 1, "--ratios: 'half' is not a number"},
      {duck, "-o {out}/x.glb --faces 1000,0", 1, "--faces: every face count must be at least 1"},
      {duck, "-o {out}/x.obj --ratios 1,0.25", 1, "x.obj: a level-of-detail chain is written as .glb or .gltf"},
      {duck, "-o {out}/x --ratios 1,0.25", 1, "a level-of-detail chain is written as .glb or .gltf"},
      {duck, "-o {out}/x.glb", 1, "one of --ratios, --faces or --max-errors is required"},
      {duck, "-o {out}/x.glb --max-errors 0.01,0.01", 1, "--max-errors: the bounds must increase strictly"},
      {duck, "-o {out}/x.glb --ratios 1,0.25 --faces 1000", 2, "--ratios excludes --faces"},
      {sphere, "-o {out}/x.glb --ratios 1,0.25 --shared-texture", 1, "--shared-texture needs a textured input"},
      // every file is written or none: an --obj-prefix in a missing folder leaves no GLB behind
      {duck, "-o {out}/x.glb --ratios 1,0.25 --obj-prefix {out}/missing/P", 1, "does not exist"},
  };
  for (std::size_t k = 0; k < refusals.size(); ++k) {
    const Refusal& c = refusals[k];
    const std::string out = (fs::path(dir) / ("case" + std::to_string(k))).string();
    fs::create_directories(out);
    std::string args = c.args;
    for (std::size_t p; (p = args.find("{out}")) != std::string::npos;) args.replace(p, 5, out);
    SCOPED_TRACE("lod " + fs::path(c.input).filename().string() + " " + args);
    // --quiet: a progress line would be a second line on stderr
    const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(c.input) + " " + args, dir);
    EXPECT_EQ(r.exit_code, c.exit_code) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.compare(0, c.exit_code == 2 ? 21 : 19, c.exit_code == 2 ? "cmgeom: usage error: " : "cmgeom lod: error: "), 0)
        << r.err;
    EXPECT_NE(r.err.find(c.named), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_TRUE(entries_of(out).empty()) << "left behind: " << ::testing::PrintToString(entries_of(out));
  }
  // the same sphere without --shared-texture is a valid chain (the refusal is about the texture)
  const auto ok = cmgeom_test::run_cli("--quiet lod " + quoted(sphere) + " -o " + quoted(dir + "/sphere.glb") +
                                           " --ratios 1,0.25 --json", dir);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_EQ(nlohmann::json::parse(ok.out)["textured"], false);
  // a refused run keeps an existing output as it was
  const std::string kept = cmgeom_test::write_text(dir, "kept.glb", "not replaced");
  const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(duck) + " -o " + quoted(kept) +
                                          " --ratios 1,0.25 --obj-prefix " + quoted(dir + "/missing/P"), dir);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(bytes_of(kept), "not replaced");
}

TEST(cmgeom_cli, LodObjPrefixWritesEveryLevelAsObj) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string duck = cmgeom_test::shared_data("textured/Duck/Duck.obj");
  const std::string prefix = (fs::path(dir) / "duck").string();
  const auto r = cmgeom_test::run_cli("--quiet lod " + quoted(duck) + " -o " + quoted(dir + "/duck.glb") +
                                          " --ratios 1,0.25,0.05 --obj-prefix " + quoted(prefix) + " --json",
                                      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const auto& levels = report["levels"];
  ASSERT_EQ(levels.size(), 3u);
  for (std::size_t k = 0; k < levels.size(); ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    const std::string obj = prefix + "_" + std::to_string(k) + ".obj";
    ASSERT_TRUE(fs::is_regular_file(obj)) << obj;
    EXPECT_EQ(obj_faces(obj), levels[k]["faces"].get<std::size_t>());
    // its material names a texture written beside it
    const std::string mtl = bytes_of(prefix + "_" + std::to_string(k) + ".mtl");
    const std::size_t map = mtl.find("map_Kd ");
    ASSERT_NE(map, std::string::npos) << mtl;
    const std::string texture = mtl.substr(map + 7, mtl.find('\n', map) - map - 7);
    EXPECT_EQ(bytes_of((fs::path(dir) / texture).string()).substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << texture;
  }
  EXPECT_FALSE(fs::exists(prefix + "_3.obj"));
}

// The issue's target: the GLB of every shared textured model simplified to 10 % passes the
// Khronos validator with no error and no warning, and rendered it matches the OBJ written by the
// same (deterministic) run: image RMSE <= 0.5 over cmgeom compare's 26 views at 256 x 256. Each
// side wears its own texture: compare is given no --texture and no --reference-texture, so the
// OBJ draws its atlas PNG and the GLB its embedded atlas (checked below on Duck, where drawing the
// GLB with the reference's texture instead gives a far larger RMSE).
TEST(cmgeom_cli, SimplifiedGlbOfEveryTexturedModelIsValidAndRendersLikeTheObj) {
  CMGEOM_REQUIRE_SHARED_DATA();
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string validator_missing = gltf_validator_missing();
  if (!validator_missing.empty()) std::cout << "validator not run: " << validator_missing << "\n";
  std::vector<fs::path> models;
  for (const auto& folder : fs::directory_iterator(cmgeom_test::shared_data("textured"))) {
    if (!folder.is_directory()) continue;
    for (const auto& file : fs::directory_iterator(folder.path()))
      if (file.path().extension() == ".obj") models.push_back(file.path());
  }
  std::sort(models.begin(), models.end());
  EXPECT_GE(models.size(), 8u);
  auto rmse_of = [&](const std::string& args) {
    const auto c = cmgeom_test::run_cli("--quiet compare " + args + " --json --size 256", dir);
    if (renderer_missing(c)) return -2.0;
    EXPECT_EQ(c.exit_code, 0) << args << "\n" << c.err;
    if (c.exit_code != 0) return -1.0;
    const nlohmann::json j = nlohmann::json::parse(c.out);
    EXPECT_GT(j["pixels"].get<std::size_t>(), 0u) << args;
    return j["rmse"].get<double>();
  };
  for (const fs::path& model : models) {
    const std::string name = model.stem().string();
    SCOPED_TRACE(name);
    // spot's OBJ names no texture: its image is beside it
    const fs::path spot_texture = model.parent_path() / "spot_texture.png";
    const std::string texture = fs::exists(spot_texture) ? " --texture " + quoted(spot_texture.string()) : "";
    const std::string obj = (fs::path(dir) / (name + ".obj")).string(), glb = (fs::path(dir) / (name + ".glb")).string();
    std::size_t faces[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      const auto s = cmgeom_test::run_cli("--quiet simplify " + quoted(model.string()) + " --ratio 0.1 -o " +
                                              quoted(k ? glb : obj) + texture + " --json",
                                          dir);
      ASSERT_EQ(s.exit_code, 0) << s.err;
      const nlohmann::json j = nlohmann::json::parse(s.out);
      EXPECT_EQ(j["textured"], true);
      faces[k] = j["faces_out"].get<std::size_t>();
    }
    EXPECT_EQ(faces[0], faces[1]) << "the two runs differ";
    EXPECT_EQ(obj_faces(obj), faces[0]);
    // the GLB carries its own atlas: one embedded PNG, drawn by every primitive
    const nlohmann::json j = glb_json(glb);
    ASSERT_TRUE(j.is_object());
    ASSERT_EQ(j["images"].size(), 1u);
    EXPECT_TRUE(j["images"][0].contains("bufferView"));
    EXPECT_EQ(j["images"][0]["mimeType"], "image/png");
    EXPECT_EQ(images_of_node(j, 0), std::set<int>({0}));
    EXPECT_EQ(triangles_of_node(j, 0), faces[0]);

    std::string validation = "not run";
    if (validator_missing.empty()) {
      const Validation v = validate_gltf(glb);
      EXPECT_EQ(v.errors, 0) << v.report;
      EXPECT_EQ(v.warnings, 0) << v.report;
      validation = v.report.substr(0, v.report.find('\n'));
    }
    const double rmse = rmse_of(quoted(obj) + " " + quoted(glb));
    if (rmse == -2.0) GTEST_SKIP() << "this build of cmgeom has no renderer: the GLB files were validated only";
    EXPECT_GE(rmse, 0.0);
    EXPECT_LE(rmse, 0.5) << "the GLB renders unlike the OBJ";
    std::cout << name << ": " << faces[0] << " faces; validator: " << validation << "; RMSE OBJ vs GLB "
              << rmse << "\n";
    if (name == "Duck") {
      // against the original: the GLB in its own atlas scores as the OBJ does; in the original's
      // texture (--reference-texture) it is far off, so the comparisons above saw the GLB's atlas
      const double own = rmse_of(quoted(model.string()) + " " + quoted(glb));
      const double obj_own = rmse_of(quoted(model.string()) + " " + quoted(obj));
      const double foreign = rmse_of(quoted(model.string()) + " " + quoted(glb) + " --reference-texture");
      EXPECT_NEAR(own, obj_own, 0.5);
      EXPECT_GT(foreign, own + 10) << "own atlas " << own << ", reference's texture " << foreign;
      std::cout << name << " against the original: GLB " << own << ", OBJ " << obj_own
                << ", GLB in the original's texture " << foreign << "\n";
    }
  }
}

// cm reconstruct and cm deform report the library's reconstruction time alone
// (reconstruct_seconds) beside the whole command's (seconds: reading, deforming, writing
// included), and the size of what they wrote.
TEST(cmgeom_cli, CmReconstructAndDeformReportReconstructionTimeWithinTheCommandTime) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string spot = "'" + std::string(CMGEOM_SOURCE_DIR) + "/data/spot/spot.obj'";
  const std::string cm = "'" + dir + "/spot.cm'";
  const auto b = cmgeom_test::run_cli("cm build " + spot + " -o " + cm + " --ratio 0.1", dir);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"reconstruct regular", "cm reconstruct " + cm + " -o '" + dir + "/r.ply' --level 2 --json"},
      {"reconstruct along N", "cm reconstruct " + cm + " -o '" + dir + "/n.ply' --level 2 --projection normal --json"},
      {"reconstruct adaptive", "cm reconstruct " + cm + " -o '" + dir + "/a.ply' --edge-length 0.05 --max-level 3 --json"},
      {"deform", "cm deform " + cm + " --affine 1,0.2,0,0,0,1,0,0,0,0,1.5,0 -o '" + dir + "/d.ply' --level 2 --json"}};
  for (const auto& [name, args] : commands) {
    SCOPED_TRACE(name);
    const auto r = cmgeom_test::run_cli(args, dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_TRUE(j.contains("reconstruct_seconds") && j.contains("seconds") && j.contains("vertices")) << r.out;
    const double rec = j["reconstruct_seconds"].get<double>(), all = j["seconds"].get<double>();
    EXPECT_GE(rec, 0.);
    EXPECT_LE(rec, all);
    const std::size_t V = j["base_vertices"].get<std::size_t>(), F = j["base_faces"].get<std::size_t>();
    const std::size_t vertices = j["vertices"].get<std::size_t>(), faces = j["faces"].get<std::size_t>();
    EXPECT_GT(vertices, V);
    if (name != "reconstruct adaptive") {
      // Level 2 of a closed base: 16 triangles per base face, 3 points per base edge (E = 3F/2),
      // 3 interior points per base face.
      EXPECT_EQ(faces, 16 * F);
      EXPECT_EQ(vertices, V + 3 * (3 * F / 2) + 3 * F);
    }
  }
}
