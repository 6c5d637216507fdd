// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// image_space_error(): the appearance error of thesis §2.3.2.1 (eq. 2.1) between a reference
// mesh and an approximation, measured on renders from a fixed view set (by default the 26 cube
// directions of views.h) at a fixed resolution, with identical lighting and camera for both
// (the camera is framed on the REFERENCE's bounding box). Texture of the approximation
// (`Image_space_error_options::approximation_texture`): by default (`Own_or_reference`) its own
// texture when it has one — a textured simplification writes a new atlas, and drawing its new
// UVs into the old atlas would be meaningless — otherwise the reference's first texture through
// the approximation's UVs (simplifiers that keep UVs but write no material); `Reference` forces
// the latter, so that only geometry and parameterisation differences show. Pixels covered by
// either mesh count (see Metrics/image_error.h for RMSE and PSNR).
//
// Complexity: 2 x views renders of O(F + W H samples) each.
#ifndef CMGEOM_RENDERING_IMAGE_SPACE_ERROR_H
#define CMGEOM_RENDERING_IMAGE_SPACE_ERROR_H

#include <CMGeom/Metrics/image_error.h>
#include <CMGeom/Rendering/Render_mesh.h>
#include <CMGeom/Rendering/Render_options.h>
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/views.h>

#include <vector>

namespace CMGeom {
namespace Rendering {

struct Image_space_error_options {
  int size = 512;  ///< square renders of size x size pixels
  std::vector<View> views = cube_views_26();
  /// Shading of both meshes; Textured falls back to Smooth when the reference has no texture.
  Shading shading = Shading::Textured;
  bool keep_images = false;  ///< return the renders as well
  /// Which texture the approximation wears (see the file comment).
  enum class Approximation_texture { Own_or_reference, Reference };
  Approximation_texture approximation_texture = Approximation_texture::Own_or_reference;
};

struct Image_space_error {
  Metrics::Image_error total;  ///< over all views
  std::vector<Metrics::Image_error> per_view;
  std::vector<Image> reference_images, approximation_images;  ///< when keep_images
};

/// See the file comment. `renderer` is reused for all views (one upload per mesh).
inline Image_space_error image_space_error(Renderer& renderer, const Render_mesh& reference,
                                           const Render_mesh& approximation,
                                           const Image_space_error_options& options = Image_space_error_options()) {
  const Image* texture = reference.texture();
  Render_mesh approx = approximation;
  const bool own =
      options.approximation_texture == Image_space_error_options::Approximation_texture::Own_or_reference &&
      approximation.has_uvs() && approximation.texture() != nullptr;
  if (!own)
    for (auto& r : approx.ranges) r.texture = approximation.has_uvs() ? texture : nullptr;
  std::vector<Render_options> views;
  for (const View& v : options.views) {
    Render_options o;
    o.width = o.height = options.size;
    o.shading =
        (options.shading == Shading::Textured && !(texture && reference.has_uvs())) ? Shading::Smooth : options.shading;
    o.view(v.azimuth, v.elevation).fit_to(reference.bbox);
    views.push_back(o);
  }
  Image_space_error r;
  std::vector<Image> a = renderer.render_views(reference, views);
  std::vector<Image> b = renderer.render_views(approx, views);
  Metrics::Image_error_accumulator total;
  for (std::size_t i = 0; i < a.size(); ++i) {
    total.add(a[i], b[i]);
    r.per_view.push_back(Metrics::image_error(a[i], b[i]));
  }
  r.total = total.result();
  if (options.keep_images) {
    r.reference_images = std::move(a);
    r.approximation_images = std::move(b);
  }
  return r;
}

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_IMAGE_SPACE_ERROR_H
