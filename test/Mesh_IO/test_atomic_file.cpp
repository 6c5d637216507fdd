// Tests of the atomic writes of Mesh_IO: failed writes leave nothing and keep old files.
#include "mesh_io_test_util.h"

TEST(Mesh_IO_atomic, FailedWritesLeaveNothingAndKeepOldFiles) {
  const std::string dir = scratch_dir();
  const std::string path = write_text(dir, "t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Textured_mesh tm;
  IO::read_mesh(path, tm);
  EXPECT_THROW(IO::write_mesh((fs::path(dir) / "no_such_dir" / "x.obj").string(), tm), IO_error);
  EXPECT_THROW(IO::write_mesh((fs::path(dir) / "x.3mf").string(), tm), IO_error);
  // A texture that vanished makes the whole OBJ write fail: neither .obj nor .mtl appears,
  // and an existing output keeps its old content.
  const std::string existing = write_text(dir, "out.obj", "old content\n");
  tm.materials().push_back(Material());
  tm.materials()[0].name = "m";
  tm.materials()[0].diffuse_texture = (fs::path(dir) / "vanished.png").string();
  EXPECT_THROW(IO::write_mesh(existing, tm), IO_error);
  std::ifstream in(existing);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "old content");
  EXPECT_FALSE(fs::exists(fs::path(dir) / "out.mtl"));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << "temporary left: " << e.path();
}
