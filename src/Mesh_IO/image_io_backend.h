// The interface between CMGeom's image IO (image_io.cpp, linked into programs) and the module that
// does the work with OpenImageIO (image_io_oiio.cpp, loaded with dlopen on the first image read or
// written). OpenImageIO as packaged by Debian 12 pulls in about 260 shared libraries whose loading
// costs about 0.35 s at every program start; behind the module, only runs that touch images pay it.
//
// Both sides are built together by the same compiler, so C++ types cross the boundary; the module
// throws nothing: every function returns an empty string on success, else what went wrong (the
// caller adds the file name).
#ifndef CMGEOM_SRC_MESH_IO_IMAGE_IO_BACKEND_H
#define CMGEOM_SRC_MESH_IO_IMAGE_IO_BACKEND_H

#include <CMGeom/Mesh_IO/Image.h>

#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace IO {
namespace internal {

struct Image_io_backend {
  /// Equal to image_io_backend_version in a module that matches this header.
  int version;
  std::string (*read)(const std::string& path, Image& out);
  std::string (*read_memory)(const std::vector<unsigned char>& bytes, Image& out);
  std::string (*size)(const std::string& path, std::pair<int, int>& out);
  /// Writes `image` to `file` in the format of `extension` (".png", ...).
  std::string (*write)(const std::string& file, const std::string& extension, const Image& image);
};

constexpr int image_io_backend_version = 1;

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom

/// The module's one exported symbol.
extern "C" const CMGeom::IO::internal::Image_io_backend* cmgeom_image_io_backend();

#endif  // CMGEOM_SRC_MESH_IO_IMAGE_IO_BACKEND_H
