// The progress output of the cmgeom tool on stderr in its three modes (terminal, pipe or file,
// --quiet; doc/CLI.md).
#include "cli_test_util.h"

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
// Model build (the thesis' fits alone: the default --fit auto builds three models) with a round of
// error control (progress from the library's hook, Build_options::progress). Both print a JSON
// report.
std::vector<Long_job> long_jobs(const std::string& sphere, const std::string& dir) {
  return {{"simplify '" + sphere + "' -o '" + dir + "/s.obj' --ratio 0.1 --engine cgal --json", "simplify", false},
          {"cm build '" + sphere + "' -o '" + dir + "/s.cm' --ratio 0.01 --fit thesis --error-bound 1e-6 --error-rounds 1 "
           "--json",
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
void erase_timings(nlohmann::ordered_json& j) {
  if (j.is_array()) {
    for (auto& e : j) erase_timings(e);
    return;
  }
  if (!j.is_object()) return;
  std::vector<std::string> timings;
  for (auto& item : j.items()) {
    if (item.key().find("seconds") != std::string::npos)
      timings.push_back(item.key());
    else
      erase_timings(item.value());
  }
  for (const std::string& k : timings) j.erase(k);
}
std::string without_timings(const std::string& json_text) {
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(json_text);
  erase_timings(j);
  return j.dump();
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

namespace {

// The faces removed that the final progress line of stage `label` gives on a pipe (-1: no such line).
long faces_removed_in_progress(const std::string& err, const std::string& label) {
  const std::regex line("cmgeom: " + label + ": done in [0-9]+\\.[0-9]{2} s \\(([0-9]+) faces removed\\)");
  std::smatch m;
  return std::regex_search(err, m, line) ? std::stol(m[1].str()) : -1;
}

}  // namespace

// A simplification stopped by a bound rather than a face target (--max-cost alone): the final
// progress line counts the faces actually removed, as the report does.
TEST(cmgeom_cli, ProgressOfABoundedSimplificationCountsTheFacesRemoved) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string sphere = large_sphere(dir);
  const auto r = cmgeom_test::run_cli(
      "simplify '" + sphere + "' -o '" + dir + "/b.obj' --max-cost 1e-7 --engine cgal --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const long faces_in = j.at("faces_in").get<long>(), faces_out = j.at("faces_out").get<long>();
  // the bound stops the run well before the single face the bar counts towards
  ASSERT_GT(faces_out, 1);
  ASSERT_LT(faces_out, faces_in);
  EXPECT_EQ(faces_removed_in_progress(r.err, "simplify"), faces_in - faces_out) << r.err;
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

// Levels by error bound: the run's end is not known in advance (the bar counts towards one face);
// the final progress line counts the faces the chain actually removed, down to its last level.
TEST(cmgeom_cli, ProgressOfLevelsByErrorCountsTheFacesRemoved) {
  const std::string dir = cmgeom_test::scratch_dir();
  // 81,920 faces: the bounded runs and the levels' errors take a few seconds here, past the 0.5 s a
  // line needs
  const std::string sphere = cmgeom_test::write_text(dir, "sphere6.obj", cmgeom_test::icosphere_obj(6));
  const auto r =
      cmgeom_test::run_cli("lod '" + sphere + "' -o '" + dir + "/chain.glb' --max-errors 0,0.002,0.01 --json", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const long faces_in = j.at("faces_in").get<long>();
  const long last = j.at("levels").back().at("faces").get<long>();
  ASSERT_GT(last, 1);
  ASSERT_LT(last, faces_in);
  EXPECT_EQ(faces_removed_in_progress(r.err, "lod"), faces_in - last) << r.err;
}
