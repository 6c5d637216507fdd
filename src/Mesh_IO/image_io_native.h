// PNG (libpng) and JPEG (libjpeg-turbo) read and PNG written (zlib) in process, without the OpenImageIO
// module: those two formats are nearly every texture a mesh names, and loading OpenImageIO as
// packaged by Debian 12 (about 260 shared libraries) costs about 0.2 s, which was most of the
// running time of a textured simplification of a small model. Other formats, and JPEG output, still
// go through the module (image_io_backend.h).
//
// The pixels are those the module gives: the file's values unchanged (no gamma conversion, straight
// alpha), a palette expanded to RGB or RGBA (tRNS to alpha), grey of 1, 2 or 4 bits widened to 8;
// 8-bit files give UInt8 images, 16-bit files Float32 ones (value / 65535); JPEG as 1 (grey) or 3
// channels (RGB). CMYK and YCCK JPEGs are left to the module. test_image_io.cpp checks that both
// agree.
#ifndef CMGEOM_SRC_MESH_IO_IMAGE_IO_NATIVE_H
#define CMGEOM_SRC_MESH_IO_IMAGE_IO_NATIVE_H

#include <CMGeom/Mesh_IO/Image.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace IO {
namespace internal {

enum class Native_format { none, png, jpeg };

/// The format of encoded bytes from their signature (`none`: not one read here).
Native_format native_format(const unsigned char* bytes, std::size_t size);

/// Decodes PNG or JPEG bytes; returns an empty string on success, else what is wrong. `handled`
/// is false (and `out` untouched) for bytes left to the module: other formats, CMYK JPEG.
std::string native_decode(const unsigned char* bytes, std::size_t size, Image& out, bool& handled);

/// Width and height from the header alone.
std::string native_size(const unsigned char* bytes, std::size_t size, std::pair<int, int>& out);

/// Encodes `image` as PNG (8 bits per channel; Float32 values clamped to [0,1] and rounded), zlib
/// level 3 and the 'up' filter on every row: a 2048 x 2048 atlas (DamagedHelmet) encoded by libpng
/// so took 0.12 s where level 6 with libpng's adaptive filters took 0.43 s, for 6.5 % more bytes
/// (2.88 against 2.71 MB). The encoder is now our own, on all cores: bands of rows of about 1 MB
/// deflated at once, each primed with the 32 kB before it and ended by a sync flush, joined into one
/// zlib stream with the bands' Adler-32 checksums combined (the method of pigz); the same bytes on
/// any number of threads. On 2 cores it writes WaterBottle's 2048 x 2048 atlas in 0.054 s and its
/// shared LOD atlas (2048 x 3072) in 0.10 s, where libpng took 0.097 s and 0.196 s, in 0.1-0.2 %
/// fewer bytes.
std::string png_encode(const Image& image, std::vector<unsigned char>& out);

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom

#endif  // CMGEOM_SRC_MESH_IO_IMAGE_IO_NATIVE_H
