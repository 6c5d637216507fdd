// Tests of the image reading and writing: lossless PNG round trip, OpenImageIO loaded on first use.
#include "mesh_io_test_util.h"

TEST(Mesh_IO_image, RgbaPngRoundTripIsLossless) {
  const std::string dir = scratch_dir();
  Image img(7, 5, 4);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x)
      for (int c = 0; c < 4; ++c) img.bytes()[img.index(x, y, c)] = std::uint8_t((x * 37 + y * 11 + c * 71) % 256);
  const std::string path = (fs::path(dir) / "rgba.png").string();
  IO::write_image(path, img);
  EXPECT_TRUE(IO::read_image(path) == img);
  EXPECT_EQ(IO::image_size(path), std::make_pair(7, 5));
}

// OpenImageIO (about 260 shared libraries) is loaded by the first image read or written, not at
// program start: whether it was mapped is recorded while this program initialises, before main().
namespace {
bool oiio_mapped() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find("libOpenImageIO") != std::string::npos) return true;
  return false;
}
const bool oiio_mapped_at_start = oiio_mapped();
}  // namespace

TEST(Mesh_IO_image, OpenImageIOIsLoadedOnFirstUseOnly) {
  EXPECT_FALSE(oiio_mapped_at_start) << "OpenImageIO was loaded at program start";
  const std::string path = (fs::path(scratch_dir()) / "lazy.png").string();
  Image img(3, 2, 3);
  img.bytes()[img.index(2, 1, 0)] = 200;
  IO::write_image(path, img);
  EXPECT_TRUE(oiio_mapped()) << "writing an image did not go through OpenImageIO";
  EXPECT_TRUE(IO::read_image(path) == img);
}
