// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// A texture image held in memory: width x height pixels of 1-4 interleaved channels, stored
// either as 8-bit unsigned values (what PNG/JPEG files hold) or as 32-bit floats (what the
// texture resampling of chapter 3 produces). Row 0 is the TOP row of the picture, as in image
// files; texture coordinate v = 1 is the top row (OBJ/OpenGL convention, v points up).
// Reading and writing files is in image_io.h (target CMGeom::Image_IO, links OpenImageIO).
#ifndef CMGEOM_MESH_IO_IMAGE_H
#define CMGEOM_MESH_IO_IMAGE_H

#include <CMGeom/internal/huge_pages.h>

#include <CGAL/assertions.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace CMGeom {

/// Copies share their pixels until one of them is written (copy on write): the first write access
/// to a copy (bytes(), floats() or set_value() on a non-const Image) whose pixels another Image
/// still shares copies them first, so copying an image (a texture handed to every level of a
/// chain, a material copied with its mesh) costs nothing until it is changed. Several threads may
/// write distinct pixels of one Image at once when its pixels are its own: call bytes() or
/// floats() (or unshare()) once before handing it to them.
class Image {
public:
  enum class Format { UInt8, Float32 };

  Image() = default;
  Image(int width, int height, int channels, Format format = Format::UInt8)
      : width_(width), height_(height), channels_(channels), format_(format) {
    CGAL_precondition(width >= 0 && height >= 0 && channels >= 1 && channels <= 4);
    const std::size_t n = std::size_t(width) * std::size_t(height) * std::size_t(channels);
    pixels_ = std::make_shared<Pixels>();
    if (format == Format::UInt8)
      internal::assign_on_huge_pages(pixels_->bytes, n, std::uint8_t(0));
    else
      internal::assign_on_huge_pages(pixels_->floats, n, 0.f);
    point_at_pixels();
  }

  Image(const Image& o) = default;
  Image(Image&& o) noexcept
      : width_(o.width_),
        height_(o.height_),
        channels_(o.channels_),
        format_(o.format_),
        pixels_(std::move(o.pixels_)),
        bytes_(o.bytes_),
        floats_(o.floats_) {
    o.clear();
  }
  Image& operator=(const Image& o) = default;
  Image& operator=(Image&& o) noexcept {
    if (this != &o) {
      width_ = o.width_;
      height_ = o.height_;
      channels_ = o.channels_;
      format_ = o.format_;
      pixels_ = std::move(o.pixels_);
      bytes_ = o.bytes_;
      floats_ = o.floats_;
      o.clear();
    }
    return *this;
  }

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  Format format() const { return format_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  std::size_t index(int x, int y, int c = 0) const {
    return (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * std::size_t(channels_) + std::size_t(c);
  }

  /// 8-bit storage (precondition: format() == UInt8); the non-const one unshares the pixels.
  std::uint8_t* bytes() {
    unshare();
    return bytes_;
  }
  const std::uint8_t* bytes() const { return bytes_; }
  /// Float storage (precondition: format() == Float32); the non-const one unshares the pixels.
  float* floats() {
    unshare();
    return floats_;
  }
  const float* floats() const { return floats_; }

  /// Channel value in [0,1] whatever the storage (8-bit values are divided by 255).
  float value(int x, int y, int c) const {
    const std::size_t i = index(x, y, c);
    return format_ == Format::UInt8 ? float(bytes_[i]) * (1.f / 255.f) : floats_[i];
  }
  void set_value(int x, int y, int c, float v) {
    unshare();
    const std::size_t i = index(x, y, c);
    if (format_ == Format::UInt8) {
      v = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
      bytes_[i] = std::uint8_t(v * 255.f + 0.5f);
    } else {
      floats_[i] = v;
    }
  }

  /// Copies the first `channels` channels (every one when negative) of pixel (fx, fy) to pixel
  /// (tx, ty): what set_value(tx, ty, c, value(fx, fy, c)) leaves, without the conversions (an
  /// 8-bit value survives the round trip through [0,1] unchanged).
  void copy_pixel(int tx, int ty, int fx, int fy, int channels = -1) {
    unshare();
    const int n = channels < 0 || channels > channels_ ? channels_ : channels;
    const std::size_t to = index(tx, ty), from = index(fx, fy);
    if (format_ == Format::UInt8) {
      std::uint8_t* b = bytes_;  // (a local: the stores through it cannot change it)
      for (int c = 0; c < n; ++c) b[to + std::size_t(c)] = b[from + std::size_t(c)];
    } else {
      float* f = floats_;
      for (int c = 0; c < n; ++c) f[to + std::size_t(c)] = f[from + std::size_t(c)];
    }
  }

  /// Gives the image pixels of its own (a copy when another Image shares them).
  void unshare() {
    if (pixels_ && pixels_.use_count() > 1) copy_pixels();
  }
  /// Whether the two images share their pixels (one is an unchanged copy of the other).
  bool shares_pixels_with(const Image& o) const { return pixels_ != nullptr && pixels_ == o.pixels_; }

  friend bool operator==(const Image& a, const Image& b) {
    if (a.width_ != b.width_ || a.height_ != b.height_ || a.channels_ != b.channels_ || a.format_ != b.format_)
      return false;
    if (a.pixels_ == b.pixels_) return true;
    const std::size_t n = std::size_t(a.width_) * std::size_t(a.height_) * std::size_t(a.channels_);
    return a.format_ == Format::UInt8 ? std::equal(a.bytes_, a.bytes_ + n, b.bytes_)
                                      : std::equal(a.floats_, a.floats_ + n, b.floats_);
  }

private:
  struct Pixels {
    std::vector<std::uint8_t> bytes;
    std::vector<float> floats;
  };

  // (apart from unshare(), which per-pixel writers call: the check stays inline, the copy does not)
  void copy_pixels() {
    auto own = std::make_shared<Pixels>();
    own->bytes = internal::copy_on_huge_pages(pixels_->bytes);
    own->floats = internal::copy_on_huge_pages(pixels_->floats);
    pixels_ = std::move(own);
    point_at_pixels();
  }
  void point_at_pixels() {
    bytes_ = pixels_ && !pixels_->bytes.empty() ? pixels_->bytes.data() : nullptr;
    floats_ = pixels_ && !pixels_->floats.empty() ? pixels_->floats.data() : nullptr;
  }
  void clear() {
    width_ = height_ = channels_ = 0;
    format_ = Format::UInt8;
    pixels_.reset();
    bytes_ = nullptr;
    floats_ = nullptr;
  }

  int width_ = 0, height_ = 0, channels_ = 0;
  Format format_ = Format::UInt8;
  std::shared_ptr<Pixels> pixels_;
  // (the storage of *pixels_, kept at hand: the pixel accessors read through them)
  std::uint8_t* bytes_ = nullptr;
  float* floats_ = nullptr;
};

}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_IMAGE_H
