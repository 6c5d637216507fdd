// Image IO: checks, error messages and atomic output here. PNG (read and written) and JPEG (read) are
// coded in process (image_io_native.cpp); every other format goes to the OpenImageIO module
// (image_io_oiio.cpp), loaded with dlopen on first use (see image_io_backend.h). The module is looked
// for, in order, at $CMGEOM_IMAGE_IO_MODULE, where this build put it, and where `cmake --install`
// puts it.
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/image_io.h>

#include "Mesh_IO/image_io_backend.h"
#include "Mesh_IO/image_io_native.h"
#include "Mesh_IO/io_internal.h"

#include <dlfcn.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <filesystem>
#include <mutex>

namespace CMGeom {
namespace IO {

namespace {

using internal::Image_io_backend;

const Image_io_backend* load_backend(std::string& tried) {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("CMGEOM_IMAGE_IO_MODULE"); env && *env) candidates.emplace_back(env);
  candidates.emplace_back(CMGEOM_IMAGE_IO_MODULE_BUILD_PATH);
  candidates.emplace_back(CMGEOM_IMAGE_IO_MODULE_INSTALL_PATH);
  for (const std::string& path : candidates) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      tried += " " + path + " (absent);";
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* e = dlerror();
      tried += " " + path + " (" + (e ? e : "cannot load") + ");";
      continue;
    }
    using Entry = const Image_io_backend* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "cmgeom_image_io_backend"));
    const Image_io_backend* b = entry ? entry() : nullptr;
    if (b && b->version == internal::image_io_backend_version) return b;  // stays loaded
    tried += " " + path + " (not a matching CMGeom image IO module);";
    dlclose(handle);
  }
  return nullptr;
}

/// The module, loaded once (thread-safe); throws IO_error naming `file` if it cannot be loaded.
const Image_io_backend& backend(const std::string& file) {
  static std::once_flag once;
  static const Image_io_backend* loaded = nullptr;
  static std::string tried;
  std::call_once(once, [] { loaded = load_backend(tried); });
  if (!loaded) throw IO_error(file, "image IO module not found; tried:" + tried);
  return *loaded;
}

void check(const std::string& file, const std::string& error) {
  if (!error.empty()) throw IO_error(file, error);
}

/// The whole file (internal::slurp); throws IO_error when it is absent, unreadable or empty.
std::string file_bytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw IO_error(path, "image file not found");
  std::string bytes = internal::slurp(path);
  if (bytes.empty()) throw IO_error(path, "image file is empty");
  return bytes;
}

const unsigned char* data_of(const std::string& bytes) { return reinterpret_cast<const unsigned char*>(bytes.data()); }

bool is_png_extension(std::string ext) {
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".png";
}

/// Encodes through the module, which writes files: into a private temporary file, whose bytes are
/// returned.
std::vector<unsigned char> module_encode(const Image& image, const std::string& extension, const std::string& name) {
  namespace fs = std::filesystem;
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  const fs::path tmp = fs::temp_directory_path(ec) /
                       ("cmgeom-encode-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + extension);
  if (ec) throw IO_error(name, "no temporary directory to encode the image in: " + ec.message());
  struct Remove {
    const fs::path& p;
    ~Remove() {
      std::error_code e;
      fs::remove(p, e);
    }
  } remove{tmp};
  check(name, backend(name).write(tmp.string(), extension, image));
  std::ifstream in(tmp, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw IO_error(name, "cannot read the encoded image back");
  if (bytes.empty()) throw IO_error(name, "image encoding gave no bytes");
  return bytes;
}

}  // namespace

Image read_image(const std::string& path) {
  const std::string bytes = file_bytes(path);
  Image img;
  bool handled = false;
  check(path, internal::native_decode(data_of(bytes), bytes.size(), img, handled));
  if (!handled) check(path, backend(path).read(path, img));
  return img;
}

Image read_image_from_memory(const std::vector<unsigned char>& bytes, const std::string& name) {
  if (bytes.empty()) throw IO_error(name, "embedded image is empty");
  Image img;
  bool handled = false;
  check(name, internal::native_decode(bytes.data(), bytes.size(), img, handled));
  if (!handled) check(name, backend(name).read_memory(bytes, img));
  return img;
}

std::pair<int, int> image_size(const std::string& path) {
  std::pair<int, int> wh{0, 0};
  const std::string bytes = file_bytes(path);
  if (internal::native_format(data_of(bytes), bytes.size()) != internal::Native_format::none)
    check(path, internal::native_size(data_of(bytes), bytes.size(), wh));
  else
    check(path, backend(path).size(path, wh));
  return wh;
}

std::string write_image(const std::string& path, const Image& image, Atomic_output& out) {
  if (image.empty()) throw IO_error(path, "refusing to write an empty image");
  // The temporary name hides the extension the format is chosen from: pass it explicitly.
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext.empty()) throw IO_error(path, "image file name needs an extension (.png, .jpg, ...)");
  if (is_png_extension(ext)) {
    std::vector<unsigned char> bytes;
    check(path, internal::png_encode(image, bytes));
    return write_file(path, std::string(bytes.begin(), bytes.end()), out);
  }
  const Image_io_backend& b = backend(path);
  const std::string tmp = out.add(path);
  check(path, b.write(tmp, ext, image));
  return tmp;
}

std::vector<unsigned char> encode_image(const Image& image, const std::string& extension, const std::string& name) {
  if (image.empty()) throw IO_error(name, "refusing to encode an empty image");
  if (is_png_extension(extension)) {
    std::vector<unsigned char> bytes;
    check(name, internal::png_encode(image, bytes));
    return bytes;
  }
  return module_encode(image, extension, name);
}

namespace internal {

Image read_image_through_module(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw IO_error(path, "image file not found");
  Image img;
  check(path, backend(path).read(path, img));
  return img;
}

std::vector<unsigned char> encode_png_through_module(const Image& image) {
  return module_encode(image, ".png", "(image IO module)");
}

}  // namespace internal

void write_image(const std::string& path, const Image& image) {
  Atomic_output out;
  write_image(path, image, out);
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom
