// PNG and JPEG in process: see image_io_native.h.
//
// libpng and libjpeg report errors by longjmp. Each decoder below keeps what it allocates in a
// plain struct owned by its caller and has no object with a destructor in the frame that calls
// setjmp, so a jump back skips no destructor and leaves no value indeterminate.
#include "Mesh_IO/image_io_native.h"

#include <jpeglib.h>
#include <png.h>
#include <zlib.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace CMGeom {
namespace IO {
namespace internal {

namespace {

constexpr double max_pixels = 1.0e9;

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// ---------------------------------------------------------------------------------------------
// PNG

struct Png_state {
  std::jmp_buf jump;
  char message[256];
  const unsigned char* data;
  std::size_t size, at;
  // decoded (malloc'ed; freed by the caller)
  unsigned char* pixels;
  png_bytep* rows;
  int width, height, channels, bit_depth;
};

extern "C" void png_fail(png_structp png, png_const_charp message) {
  auto* s = static_cast<Png_state*>(png_get_error_ptr(png));
  std::snprintf(s->message, sizeof s->message, "%s", message);
  std::longjmp(s->jump, 1);
}

extern "C" void png_ignore_warning(png_structp, png_const_charp) {}

extern "C" void png_read_from_memory(png_structp png, png_bytep out, png_size_t n) {
  auto* s = static_cast<Png_state*>(png_get_io_ptr(png));
  if (n > s->size - s->at) png_error(png, "file ends inside the image data (truncated?)");
  std::memcpy(out, s->data + s->at, n);
  s->at += n;
}

/// Decodes into s->pixels; returns false with s->message on error. `header_only`: width and height.
bool png_decode(Png_state* s, bool header_only) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, s, png_fail, png_ignore_warning);
  if (!png) {
    std::snprintf(s->message, sizeof s->message, "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(s->message, sizeof s->message, "out of memory");
    return false;
  }
  if (setjmp(s->jump)) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, s, png_read_from_memory);
  png_read_info(png, info);
  png_uint_32 w = 0, h = 0;
  int depth = 0, colour = 0;
  png_get_IHDR(png, info, &w, &h, &depth, &colour, nullptr, nullptr, nullptr);
  s->width = int(w);
  s->height = int(h);
  if (header_only) {
    png_destroy_read_struct(&png, &info, nullptr);
    return true;
  }
  if (double(w) * double(h) > max_pixels) png_error(png, "image is too large");
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
  if (depth == 16 && host_is_little_endian()) png_set_swap(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  s->channels = png_get_channels(png, info);
  s->bit_depth = png_get_bit_depth(png, info);
  if (s->channels < 1 || s->channels > 4 || (s->bit_depth != 8 && s->bit_depth != 16))
    png_error(png, "unsupported pixel layout");
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  s->pixels = static_cast<unsigned char*>(std::malloc(row_bytes * h));
  s->rows = static_cast<png_bytep*>(std::malloc(sizeof(png_bytep) * h));
  if (!s->pixels || !s->rows) png_error(png, "out of memory");
  for (png_uint_32 y = 0; y < h; ++y) s->rows[y] = s->pixels + row_bytes * y;
  png_read_image(png, s->rows);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

struct Png_buffers {
  Png_state s{};
  ~Png_buffers() {
    std::free(s.pixels);
    std::free(s.rows);
  }
};

std::string png_to_image(const unsigned char* bytes, std::size_t size, Image& out) {
  Png_buffers b;
  b.s.data = bytes;
  b.s.size = size;
  if (!png_decode(&b.s, false)) return std::string("cannot decode PNG: ") + b.s.message;
  const int W = b.s.width, H = b.s.height, C = b.s.channels;
  const std::size_t n = std::size_t(W) * std::size_t(H) * std::size_t(C);
  if (b.s.bit_depth == 8) {
    Image img(W, H, C, Image::Format::UInt8);
    std::memcpy(img.bytes(), b.s.pixels, n);
    out = std::move(img);
  } else {
    Image img(W, H, C, Image::Format::Float32);
    float* f = img.floats();
    for (std::size_t i = 0; i < n; ++i) {
      std::uint16_t v;
      std::memcpy(&v, b.s.pixels + 2 * i, 2);
      f[i] = float(v) * (1.0f / 65535.0f);
    }
    out = std::move(img);
  }
  return {};
}

// PNG writing, on all cores: the rows, each with the 'up' filter, are cut into bands of about
// png_band_bytes that are deflated at once, each band with the previous band's last 32 kB as its
// dictionary and ended by a sync flush (the last one by the stream's end), so that the bands
// concatenated are one zlib stream with the compression of a single one (the method of pigz); the
// bands' Adler-32 checksums are combined. The bands depend on the image's size alone: the same
// bytes on any number of threads.
constexpr std::size_t png_band_bytes = std::size_t(1) << 20;
constexpr int png_level = 3;
constexpr std::size_t deflate_window = 32768;
constexpr std::size_t zlib_piece = std::size_t(1) << 30;  // z_stream counts in 32-bit unsigned ints

void put_u32(std::vector<unsigned char>& o, std::uint32_t v) {
  const unsigned char b[4] = {static_cast<unsigned char>(v >> 24), static_cast<unsigned char>(v >> 16),
                              static_cast<unsigned char>(v >> 8), static_cast<unsigned char>(v)};
  o.insert(o.end(), b, b + 4);
}

void put_chunk(std::vector<unsigned char>& o, const char* type, const unsigned char* data, std::size_t n) {
  put_u32(o, std::uint32_t(n));
  const std::size_t at = o.size();
  o.insert(o.end(), type, type + 4);
  o.insert(o.end(), data, data + n);
  put_u32(o, std::uint32_t(crc32_z(0, o.data() + at, 4 + n)));
}

/// Rows [y0, y1) of the image, each filtered 'up' (type byte 2, then each byte minus the byte
/// above it, the row above the first being zeros), appended to `out`.
void filter_rows(const unsigned char* pixels, std::size_t row, std::size_t y0, std::size_t y1,
                 std::vector<unsigned char>& out) {
  for (std::size_t y = y0; y < y1; ++y) {
    out.push_back(2);
    const unsigned char* r = pixels + row * y;
    if (y == 0) {
      out.insert(out.end(), r, r + row);
    } else {
      const unsigned char* above = r - row;
      const std::size_t at = out.size();
      out.resize(at + row);
      for (std::size_t i = 0; i < row; ++i) out[at + i] = static_cast<unsigned char>(r[i] - above[i]);
    }
  }
}

/// Raw deflate of `in` into `out` (`flush`: Z_SYNC_FLUSH or Z_FINISH at its end); false on a
/// zlib failure.
bool deflate_band(z_stream& z, const unsigned char* in, std::size_t n, int flush, std::vector<unsigned char>& out) {
  std::size_t produced = 0;
  out.resize(deflateBound(&z, uLong(n)) + 1024);
  std::size_t left = n;
  while (true) {
    const std::size_t take = (std::min)(left, zlib_piece);
    z.next_in = const_cast<unsigned char*>(in);
    z.avail_in = uInt(take);
    in += take;
    left -= take;
    const int mode = left > 0 ? Z_NO_FLUSH : flush;
    while (true) {
      if (out.size() - produced < 64) out.resize(out.size() * 2);
      const std::size_t room = (std::min)(out.size() - produced, zlib_piece);
      z.next_out = out.data() + produced;
      z.avail_out = uInt(room);
      const int r = deflate(&z, mode);
      produced += room - z.avail_out;
      if (r == Z_STREAM_ERROR) return false;
      if (mode == Z_FINISH) {
        if (r == Z_STREAM_END) break;
      } else if (z.avail_in == 0 && z.avail_out > 0) {
        break;  // (a sync flush is complete when deflate() leaves room in the output)
      }
    }
    if (left == 0) break;
  }
  out.resize(produced);
  return true;
}

bool png_write(const unsigned char* pixels, int W, int H, int C, std::vector<unsigned char>& file,
               std::string& message) {
  const std::size_t row = std::size_t(W) * std::size_t(C), line = row + 1, height = std::size_t(H);
  const std::size_t rows_per_band = (std::max)(std::size_t(1), png_band_bytes / line);
  const std::size_t bands = (height + rows_per_band - 1) / rows_per_band;
  std::vector<std::vector<unsigned char>> packed(bands);
  std::vector<uLong> adler(bands, 1);
  std::vector<std::size_t> length(bands, 0);
  std::atomic<bool> failed{false};
  tbb::parallel_for(std::size_t(0), bands, [&](std::size_t b) {
    const std::size_t y0 = b * rows_per_band, y1 = (std::min)(height, y0 + rows_per_band);
    std::vector<unsigned char> data;
    // the dictionary: the filtered bytes just before the band (whole rows, then the last 32 kB)
    const std::size_t dict_rows = (std::min)(y0, (deflate_window + line - 1) / line);
    filter_rows(pixels, row, y0 - dict_rows, y1, data);
    const std::size_t skip = dict_rows * line, dict = (std::min)(skip, deflate_window);
    z_stream z{};
    if (deflateInit2(&z, png_level, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
      failed = true;
      return;
    }
    bool ok = dict == 0 || deflateSetDictionary(&z, data.data() + skip - dict, uInt(dict)) == Z_OK;
    const std::size_t n = data.size() - skip;
    ok = ok && deflate_band(z, data.data() + skip, n, b + 1 == bands ? Z_FINISH : Z_SYNC_FLUSH, packed[b]);
    deflateEnd(&z);
    if (!ok) failed = true;
    adler[b] = adler32_z(1, data.data() + skip, n);
    length[b] = n;
  });
  if (failed) {
    std::snprintf(&message[0], message.size(), "zlib failed to compress");
    return false;
  }
  uLong check = adler[0];
  for (std::size_t b = 1; b < bands; ++b) check = adler32_combine(check, adler[b], z_off_t(length[b]));
  std::vector<unsigned char> stream{0x78, 0x5e};  // zlib header: deflate, 32 kB window, fast level
  std::size_t total = 2 + 4;
  for (const auto& p : packed) total += p.size();
  stream.reserve(total);
  for (const auto& p : packed) stream.insert(stream.end(), p.begin(), p.end());
  put_u32(stream, std::uint32_t(check));

  static const unsigned char colour_of[5] = {0, 0, 4, 2, 6};  // grey, grey + alpha, RGB, RGBA
  std::vector<unsigned char> header;
  put_u32(header, std::uint32_t(W));
  put_u32(header, std::uint32_t(H));
  header.insert(header.end(), {8, colour_of[C], 0, 0, 0});  // 8 bits, deflate, adaptive filters, no interlace
  file.clear();
  file.reserve(stream.size() + 64 + 12 * (stream.size() / zlib_piece));
  const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  file.insert(file.end(), signature, signature + 8);
  put_chunk(file, "IHDR", header.data(), header.size());
  for (std::size_t at = 0; at < stream.size(); at += zlib_piece)  // (a chunk holds < 2^31 bytes)
    put_chunk(file, "IDAT", stream.data() + at, (std::min)(zlib_piece, stream.size() - at));
  put_chunk(file, "IEND", nullptr, 0);
  return true;
}

// ---------------------------------------------------------------------------------------------
// JPEG

struct Jpeg_state {
  jpeg_error_mgr manager;  // first: libjpeg hands back a pointer to it
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
  jpeg_decompress_struct info;
  unsigned char* pixels;  // malloc'ed; freed by the caller
  int width, height, channels;
  bool cmyk;
};

extern "C" void jpeg_fail(j_common_ptr info) {
  auto* s = reinterpret_cast<Jpeg_state*>(info->err);
  (*info->err->format_message)(info, s->message);
  std::longjmp(s->jump, 1);
}

extern "C" void jpeg_ignore_message(j_common_ptr, int) {}

/// Decodes into s->pixels; returns false with s->message on error. `header_only`: width, height
/// and whether the file is CMYK (or YCCK), which is left to the module.
bool jpeg_decode(Jpeg_state* s, const unsigned char* bytes, std::size_t size, bool header_only) {
  j_decompress_ptr info = &s->info;
  info->err = jpeg_std_error(&s->manager);
  s->manager.error_exit = jpeg_fail;
  s->manager.emit_message = jpeg_ignore_message;
  jpeg_create_decompress(info);
  if (setjmp(s->jump)) {
    jpeg_destroy_decompress(info);
    return false;
  }
  jpeg_mem_src(info, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(info, TRUE);
  s->width = int(info->image_width);
  s->height = int(info->image_height);
  s->cmyk = info->jpeg_color_space == JCS_CMYK || info->jpeg_color_space == JCS_YCCK;
  if (header_only || s->cmyk) {
    jpeg_destroy_decompress(info);
    return true;
  }
  if (double(info->image_width) * double(info->image_height) > max_pixels) {
    std::snprintf(s->message, sizeof s->message, "image is too large");
    jpeg_destroy_decompress(info);
    return false;
  }
  info->out_color_space = info->num_components == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_start_decompress(info);
  s->channels = info->output_components;
  const std::size_t row_bytes = std::size_t(info->output_width) * std::size_t(info->output_components);
  s->pixels = static_cast<unsigned char*>(std::malloc(row_bytes * info->output_height));
  if (!s->pixels) {
    std::snprintf(s->message, sizeof s->message, "out of memory");
    jpeg_destroy_decompress(info);
    return false;
  }
  while (info->output_scanline < info->output_height) {
    JSAMPROW row = s->pixels + row_bytes * info->output_scanline;
    jpeg_read_scanlines(info, &row, 1);
  }
  jpeg_finish_decompress(info);
  jpeg_destroy_decompress(info);
  return true;
}

struct Jpeg_buffers {
  Jpeg_state s{};
  ~Jpeg_buffers() { std::free(s.pixels); }
};

std::string jpeg_to_image(const unsigned char* bytes, std::size_t size, Image& out, bool& handled) {
  Jpeg_buffers b;
  if (!jpeg_decode(&b.s, bytes, size, false)) return std::string("cannot decode JPEG: ") + b.s.message;
  if (b.s.cmyk) {
    handled = false;
    return {};
  }
  const int W = b.s.width, H = b.s.height;
  if (b.s.channels != 1 && b.s.channels != 3) return "cannot decode JPEG: unsupported number of channels";
  Image img(W, H, b.s.channels, Image::Format::UInt8);
  std::memcpy(img.bytes(), b.s.pixels, std::size_t(W) * std::size_t(H) * std::size_t(b.s.channels));
  out = std::move(img);
  return {};
}

}  // namespace

Native_format native_format(const unsigned char* bytes, std::size_t size) {
  static const unsigned char png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (size >= 8 && std::memcmp(bytes, png_signature, 8) == 0) return Native_format::png;
  if (size >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) return Native_format::jpeg;
  return Native_format::none;
}

std::string native_decode(const unsigned char* bytes, std::size_t size, Image& out, bool& handled) {
  handled = true;
  switch (native_format(bytes, size)) {
    case Native_format::png:
      return png_to_image(bytes, size, out);
    case Native_format::jpeg:
      return jpeg_to_image(bytes, size, out, handled);
    default:
      handled = false;
      return {};
  }
}

std::string native_size(const unsigned char* bytes, std::size_t size, std::pair<int, int>& out) {
  switch (native_format(bytes, size)) {
    case Native_format::png: {
      Png_buffers b;
      b.s.data = bytes;
      b.s.size = size;
      if (!png_decode(&b.s, true)) return std::string("cannot read PNG header: ") + b.s.message;
      out = {b.s.width, b.s.height};
      return {};
    }
    case Native_format::jpeg: {
      Jpeg_buffers b;
      if (!jpeg_decode(&b.s, bytes, size, true)) return std::string("cannot read JPEG header: ") + b.s.message;
      out = {b.s.width, b.s.height};
      return {};
    }
    default:
      return "neither PNG nor JPEG";
  }
}

std::string png_encode(const Image& image, std::vector<unsigned char>& out) {
  const int W = image.width(), H = image.height(), C = image.channels();
  if (W <= 0 || H <= 0 || C < 1 || C > 4) return "cannot encode an empty image";
  std::vector<std::uint8_t> converted;
  const std::uint8_t* pixels = nullptr;
  if (image.format() == Image::Format::UInt8) {
    pixels = image.bytes();
  } else {
    const std::size_t n = std::size_t(W) * std::size_t(H) * std::size_t(C);
    converted.resize(n);
    const float* f = image.floats();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, std::size_t(1) << 16),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const float v = std::isnan(f[i]) ? 0.f : (std::min)(1.f, (std::max)(0.f, f[i]));
                          converted[i] = std::uint8_t(v * 255.f + 0.5f);
                        }
                      });
    pixels = converted.data();
  }
  std::string message(256, '\0');
  if (!png_write(pixels, W, H, C, out, message)) return "cannot encode PNG: " + std::string(message.c_str());
  return {};
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
