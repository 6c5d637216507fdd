// The image IO module: reading and writing images with OpenImageIO (found through pkg-config: its
// CMake config is broken on Debian 12). Loaded by image_io.cpp on first use; see
// image_io_backend.h.
#include "Mesh_IO/image_io_backend.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <memory>

namespace {

namespace OIIO = OIIO_NAMESPACE;
using CMGeom::Image;

std::string one_line(std::string e) {
  for (char& c : e)
    if (c == '\n') c = ' ';
  return e;
}

std::string read_from(std::unique_ptr<OIIO::ImageInput> in, Image& out) {
  if (!in) {
    const std::string e = one_line(OIIO::geterror());
    return "cannot read image" + (e.empty() ? std::string() : ": " + e);
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) return "image has no pixels";
  if (double(spec.width) * spec.height > 1.0e9)
    return "image is too large (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ")";
  const int channels = std::min(spec.nchannels, 4);
  const bool eight_bit = spec.format == OIIO::TypeDesc::UINT8;
  Image img(spec.width, spec.height, channels, eight_bit ? Image::Format::UInt8 : Image::Format::Float32);
  void* data = eight_bit ? static_cast<void*>(img.bytes()) : static_cast<void*>(img.floats());
  if (!in->read_image(0, 0, 0, channels, eight_bit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT, data))
    return "cannot decode image: " + one_line(in->geterror());
  in->close();
  out = std::move(img);
  return {};
}

OIIO::ImageSpec unassociated_config() {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // keep straight alpha: lossless RGBA round trips
  return config;
}

std::string read(const std::string& path, Image& out) {
  const OIIO::ImageSpec config = unassociated_config();
  return read_from(OIIO::ImageInput::open(path, &config), out);
}

std::string read_memory(const std::vector<unsigned char>& bytes, Image& out) {
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes.data()), bytes.size());
  OIIO::ImageSpec config = unassociated_config();
  // OpenImageIO 2.4 (Debian 12) does not pass the proxy argument of ImageInput::open on to the
  // format reader (it then looks for a file of the hint's name); the configuration attribute
  // "oiio:ioproxy" does reach it.
  void* proxy = &reader;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  // The format is found from the content; the name only gives a hint.
  std::string hint = "embedded.png";
  if (bytes.size() > 2 && bytes[0] == 0xFF && bytes[1] == 0xD8) hint = "embedded.jpg";
  return read_from(OIIO::ImageInput::open(hint, &config, &reader), out);
}

std::string size(const std::string& path, std::pair<int, int>& out) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) return "cannot read image header";
  out = {in->spec().width, in->spec().height};
  return {};
}

std::string write(const std::string& file, const std::string& extension, const Image& image) {
  auto o = OIIO::ImageOutput::create(extension.substr(1));
  if (!o) return "no image writer for '" + extension + "'";
  const bool keep_float = image.format() == Image::Format::Float32 && o->supports("floatformat");
  OIIO::ImageSpec spec(image.width(), image.height(), image.channels(),
                       keep_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  // zlib level 3: a 2048 x 2048 atlas (DamagedHelmet) encodes in 0.20 s instead of 0.41 s at level
  // 6, for 7.5 % more bytes (3.39 against 3.15 MB); encoding was most of the writing time
  spec.attribute("png:compressionLevel", 3);
  if (!o->open(file, spec)) return "cannot write image: " + one_line(o->geterror());
  bool ok;
  if (image.format() == Image::Format::UInt8)
    ok = o->write_image(OIIO::TypeDesc::UINT8, image.bytes());
  else
    ok = o->write_image(OIIO::TypeDesc::FLOAT, image.floats());  // OIIO converts (and clamps) for 8-bit
  ok = o->close() && ok;
  if (!ok) return "cannot write image: " + one_line(o->geterror());
  return {};
}

const CMGeom::IO::internal::Image_io_backend backend = {CMGeom::IO::internal::image_io_backend_version, &read,
                                                        &read_memory, &size, &write};

}  // namespace

extern "C" __attribute__((visibility("default"))) const CMGeom::IO::internal::Image_io_backend*
cmgeom_image_io_backend() {
  return &backend;
}
