// The renderer's library is opened when the first picture is asked for (src/GL_context): where it
// cannot be opened, or is not libOSMesa, the commands that draw fail with one line that says why,
// and write nothing; the variable CMGEOM_OSMESA_LIBRARY chooses the library.
#include "cli_test_util.h"

#include <cstdlib>

namespace {

// Sets an environment variable for the commands run while it lives (std::system passes the
// environment on), and restores the previous state.
struct Scoped_env {
  std::string name;
  bool had = false;
  std::string previous;
  Scoped_env(const std::string& n, const std::string& value) : name(n) {
    if (const char* v = std::getenv(n.c_str())) {
      had = true;
      previous = v;
    }
    setenv(n.c_str(), value.c_str(), 1);
  }
  ~Scoped_env() {
    if (had)
      setenv(name.c_str(), previous.c_str(), 1);
    else
      unsetenv(name.c_str());
  }
};

}  // namespace

TEST(cmgeom_cli, DrawingWithoutItsLibraryFailsWithOneLineAndWritesNothing) {
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string mesh = cmgeom_test::write_text(dir, "sphere.obj", cmgeom_test::icosphere_obj(2));
  const std::string render = "render '" + mesh + "' -o '" + dir + "/out.png' --size 64x64";
  const std::string compare = "compare '" + mesh + "' '" + mesh + "' --size 32 -o '" + dir + "/cmp.png'";
  {  // the library as found: the picture is drawn (the run this test compares against)
    const auto drawn = cmgeom_test::run_cli(render, dir);
    if (renderer_missing(drawn)) GTEST_SKIP() << "this build has no renderer: " << drawn.err;
    ASSERT_EQ(drawn.exit_code, 0) << drawn.err;
    ASSERT_TRUE(fs::is_regular_file(dir + "/out.png"));
    fs::remove(dir + "/out.png");
  }
  struct Case {
    std::string library, says;
  };
  // a file that does not exist; a library that is not libOSMesa (zlib, which the tool links)
  const std::vector<Case> cases = {{dir + "/no/libOSMesa.so", "cannot load libOSMesa (" + dir + "/no/libOSMesa.so"},
                                   {"libz.so.1", "libOSMesa has no OSMesaCreateContextAttribs"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.library);
    const Scoped_env env("CMGEOM_OSMESA_LIBRARY", c.library);
    for (const std::string& command : {render, compare}) {
      SCOPED_TRACE(command);
      const auto failed = cmgeom_test::run_cli(command, dir);
      EXPECT_EQ(failed.exit_code, 1) << failed.err;
      EXPECT_NE(failed.err.find(c.says), std::string::npos) << failed.err;
      EXPECT_EQ(std::count(failed.err.begin(), failed.err.end(), '\n'), 1) << "not one line:\n" << failed.err;
      EXPECT_EQ(cmgeom_test::count_files(dir), 1u) << "a failed drawing left a file";  // the input only
    }
  }
}
