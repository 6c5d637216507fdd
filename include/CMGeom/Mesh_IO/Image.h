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

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace CMGeom {

class Image {
public:
  enum class Format { UInt8, Float32 };

  Image() = default;
  Image(int width, int height, int channels, Format format = Format::UInt8)
      : width_(width), height_(height), channels_(channels), format_(format) {
    CGAL_precondition(width >= 0 && height >= 0 && channels >= 1 && channels <= 4);
    const std::size_t n = std::size_t(width) * std::size_t(height) * std::size_t(channels);
    if (format == Format::UInt8)
      internal::assign_on_huge_pages(bytes_, n, std::uint8_t(0));
    else
      internal::assign_on_huge_pages(floats_, n, 0.f);
  }

  // copies of large images (an atlas handed to every level of a chain) go on huge pages too
  Image(const Image& o)
      : width_(o.width_),
        height_(o.height_),
        channels_(o.channels_),
        format_(o.format_),
        bytes_(internal::copy_on_huge_pages(o.bytes_)),
        floats_(internal::copy_on_huge_pages(o.floats_)) {}
  Image(Image&&) noexcept = default;
  Image& operator=(const Image& o) {
    if (this != &o) {
      Image c(o);
      *this = std::move(c);
    }
    return *this;
  }
  Image& operator=(Image&&) noexcept = default;

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  Format format() const { return format_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  std::size_t index(int x, int y, int c = 0) const {
    return (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * std::size_t(channels_) + std::size_t(c);
  }

  /// 8-bit storage (precondition: format() == UInt8).
  std::uint8_t* bytes() { return bytes_.data(); }
  const std::uint8_t* bytes() const { return bytes_.data(); }
  /// Float storage (precondition: format() == Float32).
  float* floats() { return floats_.data(); }
  const float* floats() const { return floats_.data(); }

  /// Channel value in [0,1] whatever the storage (8-bit values are divided by 255).
  float value(int x, int y, int c) const {
    const std::size_t i = index(x, y, c);
    return format_ == Format::UInt8 ? float(bytes_[i]) * (1.f / 255.f) : floats_[i];
  }
  void set_value(int x, int y, int c, float v) {
    const std::size_t i = index(x, y, c);
    if (format_ == Format::UInt8) {
      v = v < 0.f ? 0.f : (v > 1.f ? 1.f : v);
      bytes_[i] = std::uint8_t(v * 255.f + 0.5f);
    } else {
      floats_[i] = v;
    }
  }

  friend bool operator==(const Image& a, const Image& b) {
    return a.width_ == b.width_ && a.height_ == b.height_ && a.channels_ == b.channels_ && a.format_ == b.format_ &&
           a.bytes_ == b.bytes_ && a.floats_ == b.floats_;
  }

private:
  int width_ = 0, height_ = 0, channels_ = 0;
  Format format_ = Format::UInt8;
  std::vector<std::uint8_t> bytes_;
  std::vector<float> floats_;
};

}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_IMAGE_H
