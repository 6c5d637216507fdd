// Determinism of the command-line tool: each sub-command of a representative set is run twice
// with one thread and once with two; every output file must be byte-identical across the three
// runs (the guarantee of doc/Reliability.md). Then the pipeline as a whole, and the progress
// output on stderr in its three modes (terminal, pipe or file, --quiet; doc/CLI.md).
#include "cmgeom_test_meshes.h"
#include "cmgeom_test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <iterator>
#include <pty.h>
#include <regex>
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
  // The deformable CM against the full mesh deformed by the same cages: the error command,
  // run independently of the pipeline, must find them within 5 % of the diagonal.
  const auto e = cmgeom_test::run_cli("error '" + out + "/deformed.obj' '" + out + "/dcm_cages.obj' --json", dir);
  ASSERT_EQ(e.exit_code, 0) << e.err;
  const auto j = nlohmann::json::parse(e.out);
  EXPECT_LT(j["hausdorff"].get<double>(), 0.05);
  EXPECT_GT(j["hausdorff"].get<double>(), 0.0);
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
