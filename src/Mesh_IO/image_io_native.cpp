// PNG and JPEG in process: see image_io_native.h.
//
// libpng and libjpeg report errors by longjmp. Each decoder below keeps what it allocates in a
// plain struct owned by its caller and has no object with a destructor in the frame that calls
// setjmp, so a jump back skips no destructor and leaves no value indeterminate.
#include "Mesh_IO/image_io_native.h"

#include <jpeglib.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>

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

struct Png_write_state {
  std::jmp_buf jump;
  char message[256];
  unsigned char* data;  // malloc'ed, grown by doubling
  std::size_t size, capacity;
  png_bytep* rows;
};

extern "C" void png_write_fail(png_structp png, png_const_charp message) {
  auto* s = static_cast<Png_write_state*>(png_get_error_ptr(png));
  std::snprintf(s->message, sizeof s->message, "%s", message);
  std::longjmp(s->jump, 1);
}

extern "C" void png_write_to_memory(png_structp png, png_bytep in, png_size_t n) {
  auto* s = static_cast<Png_write_state*>(png_get_io_ptr(png));
  if (s->size + n > s->capacity) {
    std::size_t c = (std::max)(s->capacity * 2, s->size + n);
    auto* grown = static_cast<unsigned char*>(std::realloc(s->data, c));
    if (!grown) png_error(png, "out of memory");
    s->data = grown;
    s->capacity = c;
  }
  std::memcpy(s->data + s->size, in, n);
  s->size += n;
}

extern "C" void png_flush_nothing(png_structp) {}

bool png_write(Png_write_state* s, const unsigned char* pixels, int W, int H, int C) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, s, png_write_fail, png_ignore_warning);
  if (!png) {
    std::snprintf(s->message, sizeof s->message, "out of memory");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    std::snprintf(s->message, sizeof s->message, "out of memory");
    return false;
  }
  if (setjmp(s->jump)) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, s, png_write_to_memory, png_flush_nothing);
  png_set_compression_level(png, 3);
  // the 'up' filter alone instead of libpng's choice per row among all five: on the atlases of
  // DamagedHelmet, bob and texturedknot, 1.6-3 times faster to encode and 2-4 % smaller
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  static const int colour_of[5] = {0, PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                   PNG_COLOR_TYPE_RGB_ALPHA};
  png_set_IHDR(png, info, png_uint_32(W), png_uint_32(H), 8, colour_of[C], PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  s->rows = static_cast<png_bytep*>(std::malloc(sizeof(png_bytep) * std::size_t(H)));
  if (!s->rows) png_error(png, "out of memory");
  const std::size_t row_bytes = std::size_t(W) * std::size_t(C);
  for (int y = 0; y < H; ++y) s->rows[y] = const_cast<png_bytep>(pixels + row_bytes * std::size_t(y));
  png_write_image(png, s->rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
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
    for (std::size_t i = 0; i < n; ++i) {
      const float v = std::isnan(f[i]) ? 0.f : (std::min)(1.f, (std::max)(0.f, f[i]));
      converted[i] = std::uint8_t(v * 255.f + 0.5f);
    }
    pixels = converted.data();
  }
  struct Buffers {
    Png_write_state s{};
    ~Buffers() {
      std::free(s.data);
      std::free(s.rows);
    }
  } b;
  if (!png_write(&b.s, pixels, W, H, C)) return std::string("cannot encode PNG: ") + b.s.message;
  out.assign(b.s.data, b.s.data + b.s.size);
  return {};
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
