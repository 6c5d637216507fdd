// Tests of the image reading and writing: lossless PNG round trip, the in-process PNG and JPEG
// codecs against OpenImageIO, broken files refused, OpenImageIO loaded for other formats only.
#include "mesh_io_test_util.h"

#include <CMGeom/Mesh_IO/image_io.h>

#include <jpeglib.h>
#include <png.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <array>
#include <cstdio>
#include <iostream>

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

// Copies share their pixels until written: each side of a copy keeps its own values after writes
// through set_value(), bytes() and floats(), equality follows the pixels, and a moved-from image
// is empty.
TEST(Mesh_IO_image, CopiesShareTheirPixelsUntilOneIsWritten) {
  for (const Image::Format format : {Image::Format::UInt8, Image::Format::Float32}) {
    auto made = [&] {
      Image m(6, 4, 3, format);
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 6; ++x)
          for (int c = 0; c < 3; ++c) m.set_value(x, y, c, float((x + 2 * y + 5 * c) % 7) / 7.f);
      return m;
    };
    Image a = made();
    const Image reference = a;  // a second copy that is never written
    Image b = a;
    EXPECT_TRUE(b.shares_pixels_with(a));
    EXPECT_TRUE(b == a);
    b.set_value(1, 2, 0, 1.f);
    EXPECT_FALSE(b.shares_pixels_with(a));
    EXPECT_FALSE(b == a);
    EXPECT_EQ(a.value(1, 2, 0), reference.value(1, 2, 0));
    EXPECT_EQ(b.value(1, 2, 0), 1.f);
    // writes through the storage pointers unshare as well, from either side of the copy
    Image c = a;
    if (format == Image::Format::UInt8)
      a.bytes()[a.index(0, 0, 1)] = 255;
    else
      a.floats()[a.index(0, 0, 1)] = 1.f;
    EXPECT_EQ(a.value(0, 0, 1), 1.f);
    EXPECT_EQ(c.value(0, 0, 1), reference.value(0, 0, 1));
    EXPECT_TRUE(c == reference);
    // an unshared copy with the same pixels is still equal
    Image d = reference;
    d.unshare();
    EXPECT_FALSE(d.shares_pixels_with(reference));
    EXPECT_TRUE(d == reference);
    // a copy's pixels written on several threads at once, once unshared, leave the original be
    Image e = reference;
    e.unshare();
    tbb::parallel_for(0, 4, [&](int y) {
      for (int x = 0; x < 6; ++x) e.set_value(x, y, 2, 1.f);
    });
    EXPECT_TRUE(c == reference);
    EXPECT_EQ(e.value(5, 3, 2), 1.f);
    EXPECT_TRUE(reference == made());
    EXPECT_NE(reference.value(5, 3, 2), 1.f);
    Image moved = std::move(e);
    EXPECT_TRUE(e.empty());
    EXPECT_EQ(moved.width(), 6);
    EXPECT_EQ(moved.value(5, 3, 2), 1.f);
  }
}

// OpenImageIO (about 260 shared libraries) is loaded by the first image of a format other than PNG
// and JPEG, not at program start nor for those two: whether it was mapped is recorded while this
// program initialises, before main(); the PNG and JPEG part runs in a child process, which other
// tests of this program cannot have made load it.
namespace {
bool oiio_mapped() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find("libOpenImageIO") != std::string::npos) return true;
  return false;
}
const bool oiio_mapped_at_start = oiio_mapped();

// A PNG written with libpng itself: `colour` a PNG_COLOR_TYPE_*, `depth` bits per sample; pixel
// values from a fixed pattern; a palette of 16 entries (with transparency when `trns`), an
// interlaced file when asked.
void write_test_png(const std::string& path, int W, int H, int colour, int depth, bool trns, bool interlace) {
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, W, H, depth, colour, interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (colour == PNG_COLOR_TYPE_PALETTE) {
    png_color palette[16];
    png_byte alpha[16];
    for (int i = 0; i < 16; ++i) {
      palette[i] = png_color{png_byte(i * 16), png_byte(255 - i * 13), png_byte((i * 71) % 256)};
      alpha[i] = png_byte(255 - i * 15);
    }
    png_set_PLTE(png, info, palette, 16);
    if (trns) png_set_tRNS(png, info, alpha, 16, nullptr);
  } else if (trns && (colour == PNG_COLOR_TYPE_GRAY || colour == PNG_COLOR_TYPE_RGB)) {
    png_color_16 key{};
    key.gray = 3;
    key.red = 3;
    key.green = 5;
    key.blue = 7;
    png_set_tRNS(png, info, nullptr, 0, &key);
  }
  png_write_info(png, info);
  if (depth == 16) png_set_swap(png);  // the rows below are in host (little-endian) order
  const int channels = png_get_channels(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  std::vector<png_byte> pixels(row_bytes * H);
  for (int y = 0; y < H; ++y)
    for (std::size_t i = 0; i < row_bytes; ++i) {
      const unsigned v = (i * 29 + y * 53 + channels) % 256;
      // palette indices below the palette's 16 entries (two per byte at 4 bits)
      pixels[y * row_bytes + i] = png_byte(colour != PNG_COLOR_TYPE_PALETTE ? v : depth == 8 ? v % 16 : v);
    }
  const int passes = png_set_interlace_handling(png);
  for (int pass = 0; pass < passes; ++pass)
    for (int y = 0; y < H; ++y) png_write_row(png, &pixels[y * row_bytes]);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

void write_test_jpeg(const std::string& path, int W, int H, int channels) {
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  jpeg_compress_struct c;
  jpeg_error_mgr err;
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  jpeg_stdio_dest(&c, f);
  c.image_width = W;
  c.image_height = H;
  c.input_components = channels;
  c.in_color_space = channels == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 90, TRUE);
  jpeg_start_compress(&c, TRUE);
  std::vector<unsigned char> row(std::size_t(W) * channels);
  while (c.next_scanline < c.image_height) {
    for (std::size_t i = 0; i < row.size(); ++i) row[i] = (unsigned char)((i * 7 + c.next_scanline * 3) % 256);
    JSAMPROW r = row.data();
    jpeg_write_scanlines(&c, &r, 1);
  }
  jpeg_finish_compress(&c);
  jpeg_destroy_compress(&c);
  std::fclose(f);
}

// Same size, channels and storage, and values within `tolerance` (0: equal).
::testing::AssertionResult same_pixels(const Image& a, const Image& b, float tolerance) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels() || a.format() != b.format())
    return ::testing::AssertionFailure() << a.width() << "x" << a.height() << "x" << a.channels() << " format "
                                         << int(a.format()) << " against " << b.width() << "x" << b.height() << "x"
                                         << b.channels() << " format " << int(b.format());
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < a.channels(); ++c)
        if (std::abs(a.value(x, y, c) - b.value(x, y, c)) > tolerance)
          return ::testing::AssertionFailure() << "pixel (" << x << ", " << y << ") channel " << c << ": "
                                               << a.value(x, y, c) << " against " << b.value(x, y, c);
  return ::testing::AssertionSuccess();
}
}  // namespace

TEST(Mesh_IO_image, CopyPixelIsTheValueRoundTrip) {
  // copy_pixel() is what set_value(value()) leaves, channel by channel: on 8-bit images for every
  // byte value (each survives the division by 255 and back), on float ones for any value; only the
  // channels asked for; and a copy of the image that shares its pixels is left as it was
  for (const Image::Format format : {Image::Format::UInt8, Image::Format::Float32}) {
    Image a(256, 2, 4, format);
    for (int x = 0; x < 256; ++x)
      for (int c = 0; c < 4; ++c) {
        if (format == Image::Format::UInt8)
          a.bytes()[a.index(x, 0, c)] = std::uint8_t((x + 61 * c) % 256);
        else
          a.floats()[a.index(x, 0, c)] = float(x + 61 * c) / 300.f - 0.25f;  // (some outside [0,1])
        a.set_value(x, 1, c, 0.5f);
      }
    const Image before = a;
    Image by_value = a, by_copy = a;
    for (int x = 0; x < 256; ++x) {
      const int channels = x % 5 == 0 ? -1 : 1 + x % 4;  // every one, or the first 1 to 4
      for (int c = 0; c < (channels < 0 ? 4 : channels); ++c)
        by_value.set_value(255 - x, 1, c, by_value.value(x, 0, c));
      by_copy.copy_pixel(255 - x, 1, x, 0, channels);
    }
    EXPECT_TRUE(by_copy == by_value) << (format == Image::Format::UInt8 ? "8-bit" : "float");
    EXPECT_FALSE(by_copy == before);
    EXPECT_TRUE(a == before);
    EXPECT_TRUE(a.shares_pixels_with(before));
  }
}

TEST(Mesh_IO_image, OpenImageIOIsLoadedForOtherFormatsOnly) {
  EXPECT_FALSE(oiio_mapped_at_start) << "OpenImageIO was loaded at program start";
  const std::string dir = scratch_dir();
  Image img(3, 2, 3);
  img.bytes()[img.index(2, 1, 0)] = 200;
  const std::string jpeg = (fs::path(dir) / "grey.jpg").string();
  write_test_jpeg(jpeg, 9, 4, 1);
  EXPECT_EXIT(
      {
        const std::string png = (fs::path(dir) / "lazy.png").string();
        IO::write_image(png, img);
        const bool round_trip = IO::read_image(png) == img;
        const bool jpeg_read = IO::read_image(jpeg).channels() == 1;
        std::_Exit(!round_trip ? 1 : !jpeg_read ? 2 : oiio_mapped() ? 3 : 0);
      },
      ::testing::ExitedWithCode(0), "")
      << "exit 1: PNG round trip, 2: JPEG read, 3: OpenImageIO was loaded for PNG or JPEG";
  const std::string tif = (fs::path(dir) / "lazy.tif").string();
  IO::write_image(tif, img);
  EXPECT_TRUE(oiio_mapped()) << "writing a TIFF did not go through OpenImageIO";
  EXPECT_TRUE(IO::read_image(tif) == img);
}

// The in-process PNG and JPEG decoders give the pixels OpenImageIO gives, over the PNG layouts
// (grey, grey + alpha, RGB, RGBA, palettes with and without transparency, 1 to 16 bits,
// interlaced) and every texture of the shared data set.
TEST(Mesh_IO_image, InProcessDecodersAgreeWithOpenImageIO) {
  const std::string dir = scratch_dir();
  struct Layout {
    int colour, depth;
    bool trns, interlace;
  };
  const Layout layouts[] = {
      {PNG_COLOR_TYPE_GRAY, 1, false, false},        {PNG_COLOR_TYPE_GRAY, 4, false, false},
      {PNG_COLOR_TYPE_GRAY, 8, false, false},        {PNG_COLOR_TYPE_GRAY, 8, true, false},
      {PNG_COLOR_TYPE_GRAY, 16, false, false},       {PNG_COLOR_TYPE_GRAY_ALPHA, 8, false, false},
      {PNG_COLOR_TYPE_GRAY_ALPHA, 16, false, false}, {PNG_COLOR_TYPE_RGB, 8, false, false},
      {PNG_COLOR_TYPE_RGB, 8, true, false},          {PNG_COLOR_TYPE_RGB, 8, false, true},
      {PNG_COLOR_TYPE_RGB, 16, false, false},        {PNG_COLOR_TYPE_RGB_ALPHA, 8, false, false},
      {PNG_COLOR_TYPE_RGB_ALPHA, 16, false, true},   {PNG_COLOR_TYPE_PALETTE, 4, false, false},
      {PNG_COLOR_TYPE_PALETTE, 8, false, false},     {PNG_COLOR_TYPE_PALETTE, 8, true, false},
  };
  int k = 0;
  for (const Layout& l : layouts) {
    const std::string path = (fs::path(dir) / ("layout" + std::to_string(k++) + ".png")).string();
    write_test_png(path, 13, 7, l.colour, l.depth, l.trns, l.interlace);
    SCOPED_TRACE("colour type " + std::to_string(l.colour) + ", " + std::to_string(l.depth) + " bits" +
                 (l.trns ? ", tRNS" : "") + (l.interlace ? ", interlaced" : ""));
    const Image native = IO::read_image(path), module = IO::internal::read_image_through_module(path);
    EXPECT_EQ(native.format(), l.depth == 16 ? Image::Format::Float32 : Image::Format::UInt8);
    EXPECT_TRUE(same_pixels(native, module, l.depth == 16 ? 1e-6f : 0.f));
  }
  for (int channels : {1, 3}) {
    const std::string path = (fs::path(dir) / ("c" + std::to_string(channels) + ".jpg")).string();
    write_test_jpeg(path, 21, 11, channels);
    EXPECT_TRUE(same_pixels(IO::read_image(path), IO::internal::read_image_through_module(path), 0.f));
    EXPECT_EQ(IO::image_size(path), std::make_pair(21, 11));
  }
  if (shared_data("SOURCES.md").empty()) {
    std::cout << "[ NOTE     ] shared data absent: the data set's textures were not compared\n";
    return;
  }
  int textures = 0;
  for (const auto& entry : fs::recursive_directory_iterator(shared_data("textured"))) {
    std::string ext = entry.path().extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".png" && ext != ".jpg" && ext != ".jpeg") continue;
    SCOPED_TRACE(entry.path().string());
    const Image native = IO::read_image(entry.path().string());
    EXPECT_TRUE(same_pixels(native, IO::internal::read_image_through_module(entry.path().string()), 0.f));
    EXPECT_EQ(IO::image_size(entry.path().string()), std::make_pair(native.width(), native.height()));
    ++textures;
  }
  EXPECT_GE(textures, 8);
}

// A PNG written in process decodes, through OpenImageIO, to the pixels written (8-bit exactly;
// Float32 clamped and rounded as OpenImageIO writes it), and OpenImageIO's PNG decodes in process
// to the same pixels.
TEST(Mesh_IO_image, InProcessPngEncoderAgreesWithOpenImageIO) {
  const std::string dir = scratch_dir();
  for (int channels = 1; channels <= 4; ++channels)
    for (Image::Format format : {Image::Format::UInt8, Image::Format::Float32}) {
      SCOPED_TRACE(std::to_string(channels) + " channels, " + (format == Image::Format::UInt8 ? "8-bit" : "float"));
      Image img(17, 9, channels, format);
      for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 17; ++x)
          for (int c = 0; c < channels; ++c)
            img.set_value(x, y, c, float((x * 31 + y * 17 + c * 5) % 300) / 280.f - 0.03f);
      const std::string ours = (fs::path(dir) / ("ours" + std::to_string(channels) + ".png")).string();
      const std::string theirs = (fs::path(dir) / ("theirs" + std::to_string(channels) + ".png")).string();
      IO::write_image(ours, img);
      const std::vector<unsigned char> module_bytes = IO::internal::encode_png_through_module(img);
      std::ofstream(theirs, std::ios::binary)
          .write(reinterpret_cast<const char*>(module_bytes.data()), std::streamsize(module_bytes.size()));
      const Image a = IO::internal::read_image_through_module(ours), b = IO::read_image(theirs);
      EXPECT_TRUE(same_pixels(a, b, 0.f));
      if (format == Image::Format::UInt8) EXPECT_TRUE(a == img);
      const std::vector<unsigned char> encoded = IO::encode_image(img, ".png", "test");
      EXPECT_TRUE(same_pixels(IO::read_image_from_memory(encoded, "test"), a, 0.f));
    }
}

// A PNG large enough to be deflated in several bands (about 1 MB each, on all cores; one band per
// row when a row is longer) decodes, in process and through OpenImageIO, to the pixels written,
// and its bytes do not depend on the number of threads.
TEST(Mesh_IO_image, PngWrittenInBandsDecodesToThePixelsOnAnyNumberOfThreads) {
  const std::string dir = scratch_dir();
  const std::array<std::array<int, 3>, 3> shapes{{{1500, 700, 3}, {420000, 3, 3}, {999, 1201, 4}}};
  for (const auto& [W, H, C] : shapes) {
    SCOPED_TRACE(std::to_string(W) + " x " + std::to_string(H) + " x " + std::to_string(C));
    Image img(W, H, C);
    std::uint32_t state = 12345;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        for (int c = 0; c < C; ++c) {
          // smooth gradients (long matches across the bands' borders) with noise in a corner
          state = state * 1664525u + 1013904223u;
          const int noise = x < W / 4 && y < H / 4 ? int(state >> 27) : 0;
          img.bytes()[img.index(x, y, c)] = std::uint8_t((x / 3 + y * 2 + c * 40 + noise) % 256);
        }
    std::vector<unsigned char> bytes[2];
    for (int k = 0; k < 2; ++k) {
      tbb::task_arena arena(k == 0 ? 1 : tbb::task_arena::automatic);
      arena.execute([&] { bytes[k] = IO::encode_image(img, ".png", "test"); });
    }
    EXPECT_EQ(bytes[0], bytes[1]);
    EXPECT_TRUE(IO::read_image_from_memory(bytes[1], "test") == img);
    const std::string path = (fs::path(dir) / "bands.png").string();
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes[1].data()), std::streamsize(bytes[1].size()));
    EXPECT_TRUE(IO::internal::read_image_through_module(path) == img);
    // compressed as one stream would be: smaller than the raw pixels by far
    EXPECT_LT(bytes[1].size(), std::size_t(W) * std::size_t(H) * std::size_t(C) / 4);
  }
}

// Broken PNG and JPEG files fail with the file's name and what is wrong, not a crash.
TEST(Mesh_IO_image, TruncatedOrCorruptFilesAreRefusedWithTheirName) {
  const std::string dir = scratch_dir();
  const std::string png = (fs::path(dir) / "whole.png").string();
  write_test_png(png, 64, 64, PNG_COLOR_TYPE_RGB, 8, false, false);
  const std::string jpg = (fs::path(dir) / "whole.jpg").string();
  write_test_jpeg(jpg, 64, 64, 3);
  for (const std::string& whole : {png, jpg}) {
    std::ifstream in(whole, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string ext = fs::path(whole).extension().string();
    const std::string cut = write_text(dir, "cut" + ext, bytes.substr(0, bytes.size() / 3));
    std::string garbled_bytes = bytes;
    for (std::size_t i = 40; i < garbled_bytes.size(); i += 7) garbled_bytes[i] = char(garbled_bytes[i] ^ 0x5a);
    const std::string garbled = write_text(dir, "garbled" + ext, garbled_bytes);
    for (const std::string& bad : {cut, garbled}) {
      SCOPED_TRACE(bad);
      try {
        (void)IO::read_image(bad);
        // libjpeg decodes some corrupt data with warnings only (as every JPEG reader does): then
        // the pixels at least have the header's size
        EXPECT_EQ(ext, ".jpg") << "a broken PNG was read";
      } catch (const IO_error& e) {
        EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
      }
    }
  }
  try {
    (void)IO::read_image_from_memory({0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0}, "embedded texture");
    ADD_FAILURE() << "a 10-byte PNG was read";
  } catch (const IO_error& e) {
    EXPECT_NE(std::string(e.what()).find("embedded texture"), std::string::npos) << e.what();
  }
}
