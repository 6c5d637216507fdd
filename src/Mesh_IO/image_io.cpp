// Image IO on OpenImageIO (found through pkg-config: its CMake config is broken on Debian 12).
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/image_io.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>

namespace CMGeom {
namespace IO {

namespace {

namespace OIIO = OIIO_NAMESPACE;

Image read_from(std::unique_ptr<OIIO::ImageInput> in, const std::string& name) {
  if (!in) {
    std::string e = OIIO::geterror();
    for (char& c : e) if (c == '\n') c = ' ';
    throw IO_error(name, "cannot read image" + (e.empty() ? std::string() : ": " + e));
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw IO_error(name, "image has no pixels");
  if (double(spec.width) * spec.height > 1.0e9)
    throw IO_error(name, "image is too large (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + ")");
  const int channels = std::min(spec.nchannels, 4);
  const bool eight_bit = spec.format == OIIO::TypeDesc::UINT8;
  Image img(spec.width, spec.height, channels, eight_bit ? Image::Format::UInt8 : Image::Format::Float32);
  void* data = eight_bit ? static_cast<void*>(img.bytes()) : static_cast<void*>(img.floats());
  const bool ok = in->read_image(0, 0, 0, channels, eight_bit ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT, data);
  if (!ok) {
    std::string e = in->geterror();
    for (char& c : e) if (c == '\n') c = ' ';
    throw IO_error(name, "cannot decode image: " + e);
  }
  in->close();
  return img;
}

OIIO::ImageSpec unassociated_config() {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // keep straight alpha: lossless RGBA round trips
  return config;
}

}  // namespace

Image read_image(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw IO_error(path, "image file not found");
  const OIIO::ImageSpec config = unassociated_config();
  return read_from(OIIO::ImageInput::open(path, &config), path);
}

Image read_image_from_memory(const std::vector<unsigned char>& bytes, const std::string& name) {
  if (bytes.empty()) throw IO_error(name, "embedded image is empty");
  OIIO::Filesystem::IOMemReader reader(const_cast<unsigned char*>(bytes.data()), bytes.size());
  const OIIO::ImageSpec config = unassociated_config();
  // The format is found from the content; the name only gives a hint.
  std::string hint = "embedded.png";
  if (bytes.size() > 2 && bytes[0] == 0xFF && bytes[1] == 0xD8) hint = "embedded.jpg";
  return read_from(OIIO::ImageInput::open(hint, &config, &reader), name);
}

std::pair<int, int> image_size(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw IO_error(path, "cannot read image header");
  return {in->spec().width, in->spec().height};
}

std::string write_image(const std::string& path, const Image& image, Atomic_output& out) {
  if (image.empty()) throw IO_error(path, "refusing to write an empty image");
  const std::string tmp = out.add(path);
  // The temporary name hides the extension OIIO picks the format from: pass it explicitly.
  std::string ext = std::filesystem::path(path).extension().string();
  if (ext.empty()) throw IO_error(path, "image file name needs an extension (.png, .jpg, ...)");
  auto o = OIIO::ImageOutput::create(ext.substr(1));
  if (!o) throw IO_error(path, "no image writer for '" + ext + "'");
  const bool keep_float = image.format() == Image::Format::Float32 && o->supports("floatformat");
  OIIO::ImageSpec spec(image.width(), image.height(), image.channels(),
                       keep_float ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  spec.attribute("png:compressionLevel", 6);
  if (!o->open(tmp, spec)) throw IO_error(path, "cannot write image: " + o->geterror());
  bool ok;
  if (image.format() == Image::Format::UInt8) {
    ok = o->write_image(OIIO::TypeDesc::UINT8, image.bytes());
  } else {
    ok = o->write_image(OIIO::TypeDesc::FLOAT, image.floats());  // OIIO converts (and clamps) for 8-bit
  }
  ok = o->close() && ok;
  if (!ok) throw IO_error(path, "cannot write image: " + o->geterror());
  return tmp;
}

void write_image(const std::string& path, const Image& image) {
  Atomic_output out;
  write_image(path, image, out);
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom
