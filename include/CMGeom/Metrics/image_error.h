// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// image_error(): the image-space (appearance) error of thesis §2.3.2.1, eq. 2.1,
//
//   ||I1 - I2||_img = 1/m^2 sum_u sum_v ||I1(u,v) - I2(u,v)||^2,
//
// accumulated over several views (the thesis: "integrating ||I1 - I2||_img over all possible
// views"; we use a fixed view set, see Rendering/views.h). Two choices the thesis leaves open:
// the average runs over the pixels covered by EITHER mesh (alpha > 0 in either image), not over
// all m^2 pixels, so that the amount of empty background does not dilute the error; and the
// result is reported the way image comparisons usually are: RMSE per 8-bit channel,
// rmse = sqrt(sum ||d||^2 / (3 n)), and PSNR = 20 log10(255 / rmse) (+infinity when identical).
// `mean_squared_rgb` is eq. 2.1 itself restricted to covered pixels (RGB in [0,1]).
//
// Complexity: O(width x height) per view pair. No dependency on any renderer.
#ifndef CMGEOM_METRICS_IMAGE_ERROR_H
#define CMGEOM_METRICS_IMAGE_ERROR_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Image.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

namespace CMGeom {
namespace Metrics {

/// Result of an image comparison over one or several views.
struct Image_error {
  double rmse = 0.;                                       ///< per-channel RMSE in 8-bit units over covered pixels
  double psnr = std::numeric_limits<double>::infinity();  ///< dB, +inf when identical
  double mean_squared_rgb = 0.;                           ///< eq. 2.1 over covered pixels, RGB in [0,1]
  std::size_t pixels = 0;                                 ///< covered pixels (summed over views)
  std::size_t views = 0;
};

/// Accumulates eq. 2.1 over view pairs; RGBA 8-bit images of equal size, alpha = coverage.
class Image_error_accumulator {
public:
  void add(const Image& a, const Image& b) {
    if (a.width() != b.width() || a.height() != b.height() || a.channels() != 4 || b.channels() != 4 ||
        a.format() != Image::Format::UInt8 || b.format() != Image::Format::UInt8)
      throw Invalid_input("image_error: the two images must be RGBA 8-bit of the same size");
    const std::uint8_t* pa = a.bytes();
    const std::uint8_t* pb = b.bytes();
    const std::size_t n = std::size_t(a.width()) * std::size_t(a.height());
    for (std::size_t i = 0; i < n; ++i, pa += 4, pb += 4) {
      if (pa[3] == 0 && pb[3] == 0) continue;
      ++pixels_;
      for (int c = 0; c < 3; ++c) {
        const double d = double(pa[c]) - double(pb[c]);
        sum2_ += d * d;
      }
    }
    ++views_;
  }
  Image_error result() const {
    Image_error r;
    r.pixels = pixels_;
    r.views = views_;
    if (pixels_) {
      r.rmse = std::sqrt(sum2_ / (3. * double(pixels_)));
      r.mean_squared_rgb = sum2_ / (255. * 255.) / double(pixels_);
      r.psnr = r.rmse > 0. ? 20. * std::log10(255. / r.rmse) : std::numeric_limits<double>::infinity();
    }
    return r;
  }

private:
  double sum2_ = 0.;
  std::size_t pixels_ = 0, views_ = 0;
};

/// Image error of one pair of RGBA 8-bit renders (alpha = coverage).
inline Image_error image_error(const Image& a, const Image& b) {
  Image_error_accumulator acc;
  acc.add(a, b);
  return acc.result();
}

}  // namespace Metrics
}  // namespace CMGeom

#endif  // CMGEOM_METRICS_IMAGE_ERROR_H
