// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Image files (target CMGeom::Image_IO): PNG (libpng) and JPEG (libjpeg) read in process, PNG
// written in process; TIFF, EXR, JPEG output and whatever else the installed OpenImageIO handles
// through OpenImageIO, loaded on first use of such a format. Pixel values are the file's (no gamma
// conversion); alpha is kept unassociated (straight), so an RGBA PNG round trip is lossless. Writes
// are atomic (temporary file + rename).
#ifndef CMGEOM_MESH_IO_IMAGE_IO_H
#define CMGEOM_MESH_IO_IMAGE_IO_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Image.h>

#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace IO {

/// Reads an image; 8-bit files give an UInt8 image, deeper ones a Float32 image.
Image read_image(const std::string& path);

/// Decodes an image held in memory (e.g. a texture embedded in a glTF file). `name` is used in
/// error messages only.
Image read_image_from_memory(const std::vector<unsigned char>& bytes, const std::string& name);

/// Width and height from the file header, without decoding the pixels.
std::pair<int, int> image_size(const std::string& path);

/// Writes an image; the format follows the extension (.png, .jpg, .tif, .exr, ...).
/// UInt8 images are written as 8-bit, Float32 images as float where the format allows
/// (TIFF/EXR) and as 8-bit otherwise.
void write_image(const std::string& path, const Image& image);

/// Same, but the file is registered in `out` (see Atomic_output) instead of committed at once;
/// the returned path is the temporary file that was written.
class Atomic_output;
std::string write_image(const std::string& path, const Image& image, Atomic_output& out);

/// Encodes an image in memory in the format of `extension` (".png", ".jpg"): the bytes a file
/// written by write_image() would hold. `name` appears in error messages.
std::vector<unsigned char> encode_image(const Image& image, const std::string& extension, const std::string& name);

namespace internal {
/// Reading and PNG encoding through the OpenImageIO module even for PNG and JPEG (tests compare it
/// with the in-process codecs).
Image read_image_through_module(const std::string& path);
std::vector<unsigned char> encode_png_through_module(const Image& image);
}  // namespace internal

}  // namespace IO
}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_IMAGE_IO_H
