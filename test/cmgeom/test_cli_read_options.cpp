// Reading options every mesh-reading command shares: zero-area faces and non-manifold input are
// refused with the option that reads them named in the message, that option is the command's own,
// and it reads them.
#include "cli_test_util.h"

namespace {

// icosphere(2) with one zero-area face: face 0 (a, b, c) becomes (a, m, c), (m, b, c) and the flat
// (b, m, a), m the midpoint of ab (a closed oriented manifold still: V + 1, E + 3, F + 2).
std::string sphere_with_a_flat_face_off() {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(2, p, f);
  const auto [a, b, c] = f[0];
  const std::size_t m = p.size();
  p.push_back({0.5 * (p[a][0] + p[b][0]), 0.5 * (p[a][1] + p[b][1]), 0.5 * (p[a][2] + p[b][2])});
  f[0] = {a, m, c};
  f.push_back({m, b, c});
  f.push_back({b, m, a});
  return off_text(p, f);
}

// Two icospheres touching at one vertex, which their faces share: a closed, consistently oriented
// surface with one non-manifold vertex (the second sphere is the first reflected through that vertex,
// its faces turned round to face outwards again).
std::string spheres_sharing_a_vertex_off() {
  std::vector<std::array<double, 3>> p;
  std::vector<std::array<std::size_t, 3>> f;
  cmgeom_test::icosphere(1, p, f);
  const std::size_t n = p.size();
  const std::array<double, 3> c = p[0];
  for (std::size_t i = 1; i < n; ++i) p.push_back({2 * c[0] - p[i][0], 2 * c[1] - p[i][1], 2 * c[2] - p[i][2]});
  const std::size_t nf = f.size();
  const auto mirrored = [&](std::size_t v) { return v == 0 ? std::size_t(0) : n + v - 1; };
  for (std::size_t i = 0; i < nf; ++i) f.push_back({mirrored(f[i][0]), mirrored(f[i][2]), mirrored(f[i][1])});
  return off_text(p, f);
}

// The options "(--name)" a message names.
std::vector<std::string> named_options(const std::string& message) {
  std::vector<std::string> names;
  for (std::size_t at = message.find("(--"); at != std::string::npos; at = message.find("(--", at + 1)) {
    const std::size_t end = message.find(')', at);
    if (end != std::string::npos) names.push_back(message.substr(at + 1, end - at - 1));
  }
  return names;
}

std::size_t off_face_count(const std::string& path) {
  std::ifstream in(path);
  std::string magic;
  std::size_t nv = 0, nf = 0;
  in >> magic >> nv >> nf;
  return nf;
}

}  // namespace

TEST(cmgeom_cli, ZeroAreaFacesAreRefusedNamingTheOptionThatKeepsThemAndTheOptionKeepsThem) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string in = cmgeom_test::write_text(dir, "flat.off", sphere_with_a_flat_face_off());
  const std::size_t faces_in = off_face_count(in);
  ASSERT_EQ(faces_in, 322u);
  const std::string simplify = "simplify '" + in + "' -o '" + dir + "/s.off' --faces 100";
  const std::string lod = "lod '" + in + "' -o '" + dir + "/l.glb' --faces 200,100 --no-error";
  for (const std::string& cmd : {simplify, lod}) {
    SCOPED_TRACE(cmd);
    const auto refused = cmgeom_test::run_cli(cmd, dir);
    EXPECT_EQ(refused.exit_code, 1);
    EXPECT_NE(refused.err.find("flat.off:"), std::string::npos) << refused.err;  // the file and line
    EXPECT_NE(refused.err.find("1 zero-area face"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("--allow-degenerate"), std::string::npos) << refused.err;
    EXPECT_EQ(cmgeom_test::count_files(dir), 1u);  // nothing written beside the input
  }
  const auto kept = cmgeom_test::run_cli(simplify + " --allow-degenerate", dir);
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_EQ(off_face_count(dir + "/s.off"), 100u);
  const auto chain = cmgeom_test::run_cli(lod + " --allow-degenerate", dir);
  ASSERT_EQ(chain.exit_code, 0) << chain.err;
  EXPECT_TRUE(fs::is_regular_file(dir + "/l.glb"));
}

TEST(cmgeom_cli, EveryRefusalOfAnInputNamesAnOptionOfItsOwnCommandThatReadsTheInput) {
  // Each command that reads a mesh and refuses it (zero-area faces; a non-manifold vertex) names
  // the option that reads it anyway: that option is the command's own, and with it the command
  // reads the file and finishes.
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string flat = cmgeom_test::write_text(dir, "flat.off", sphere_with_a_flat_face_off());
  const std::string bowtie = cmgeom_test::write_text(dir, "bowtie.off", spheres_sharing_a_vertex_off());
  struct Case {
    std::string command, help, expected;  // the run, the sub-command whose help lists the options, one of them
  };
  const std::vector<Case> cases = {
      {"simplify '" + flat + "' -o '" + dir + "/s.off' --faces 100", "simplify", "--allow-degenerate"},
      {"simplify '" + bowtie + "' -o '" + dir + "/s.off' --faces 60 --no-repair", "simplify", "--repair"},
      {"lod '" + flat + "' -o '" + dir + "/l.glb' --faces 200,100 --no-error", "lod", "--allow-degenerate"},
      {"cm build '" + flat + "' -o '" + dir + "/m.cm' --faces 100", "cm build", "--allow-degenerate"},
      {"lod '" + bowtie + "' -o '" + dir + "/l.glb' --faces 100,60 --no-error --no-repair", "lod", "--repair"},
      {"cm build '" + bowtie + "' -o '" + dir + "/m.cm' --faces 60 --no-repair", "cm build", "--repair"},
      {"deform '" + flat + "' --grid 1,1,1 -o '" + dir + "/d.off'", "deform", "--allow-degenerate"},
      {"deform '" + bowtie + "' --grid 1,1,1 -o '" + dir + "/d.off'", "deform", "--repair"},
      {"convert '" + flat + "' -o '" + dir + "/c.off'", "convert", "--allow-degenerate"},
      {"convert '" + bowtie + "' -o '" + dir + "/c.off'", "convert", "--repair"},
      {"pipeline --model '" + flat + "' -o '" + dir + "/p' --size 32x32", "pipeline", "--allow-degenerate"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.command);
    const auto refused = cmgeom_test::run_cli(c.command, dir);
    ASSERT_EQ(refused.exit_code, 1) << refused.err;
    // (the message names the command, a nested one by its full path: "cmgeom cm build: error: ")
    EXPECT_NE(refused.err.find("cmgeom " + c.help + ": error: "), std::string::npos) << refused.err;
    const std::vector<std::string> named = named_options(refused.err);
    EXPECT_NE(std::find(named.begin(), named.end(), c.expected), named.end()) << refused.err;
    const auto help = cmgeom_test::run_cli(c.help + " --help", dir);
    ASSERT_EQ(help.exit_code, 0);
    std::string with = c.command;
    for (const std::string& option : named) {
      EXPECT_NE(help.out.find(option + " "), std::string::npos) << "cmgeom " << c.help << " has no " << option;
      // (the option replaces its negation where the run asked for that)
      const std::string negation = " --no-" + option.substr(2);
      const std::size_t at = with.find(negation);
      if (at != std::string::npos) with.erase(at, negation.size());
      with += " " + option;
    }
    const auto read = cmgeom_test::run_cli(with, dir);
    if (c.help == "pipeline" && renderer_missing(read)) continue;  // (its pictures need one)
    EXPECT_EQ(read.exit_code, 0) << read.err;
    if (c.help == "pipeline") EXPECT_TRUE(fs::is_regular_file(dir + "/p/report.md"));
  }
  // the commands that approximate their input (simplify, lod, cm build) repair it by default,
  // saying what they changed; those that keep its elements (deform, convert) do so when asked
  for (const std::string& cmd : {"simplify '" + bowtie + "' -o '" + dir + "/s.off' --faces 60",
                                 "lod '" + bowtie + "' -o '" + dir + "/l.glb' --faces 100,60 --no-error",
                                 "cm build '" + bowtie + "' -o '" + dir + "/m.cm' --faces 60"}) {
    SCOPED_TRACE(cmd);
    const auto repaired = cmgeom_test::run_cli(cmd, dir);
    EXPECT_EQ(repaired.exit_code, 0) << repaired.err;
    EXPECT_NE(repaired.err.find("repaired: 1 non-manifold vertex duplicated"), std::string::npos) << repaired.err;
  }
  const auto deformed =
      cmgeom_test::run_cli("deform '" + bowtie + "' --grid 1,1,1 -o '" + dir + "/d.off' --repair", dir);
  ASSERT_EQ(deformed.exit_code, 0) << deformed.err;
  EXPECT_NE(deformed.err.find("repaired: 1 non-manifold vertex duplicated"), std::string::npos) << deformed.err;
}
