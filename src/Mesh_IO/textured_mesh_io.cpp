// Textured meshes with images: decoding on read, PNG textures on write.
#include "io_internal.h"

#include <CMGeom/Mesh_IO/textured_mesh_io.h>

#include <tbb/parallel_for.h>

#include <exception>
#include <filesystem>
#include <functional>
#include <memory>

namespace CMGeom {
namespace IO {

namespace fs = std::filesystem;

void load_textures(Textured_mesh& mesh) {
  for (Material& m : mesh.materials()) {
    if (m.diffuse_image.empty()) {
      if (!m.diffuse_texture.empty())
        m.diffuse_image = read_image(m.diffuse_texture);
      else if (!m.diffuse_texture_blob.empty())
        m.diffuse_image =
            read_image_from_memory(m.diffuse_texture_blob, mesh.source() + " (material '" + m.name + "')");
    }
    if (m.normal_image.empty() && !m.normal_texture.empty()) m.normal_image = read_image(m.normal_texture);
  }
}

void read_textured_mesh(const std::string& path, Textured_mesh& out, const Read_options& options) {
  read_mesh(path, out, options);
  load_textures(out);
}

namespace {

// Encodes material textures for glTF: decoded images as PNG (each distinct image once), except an
// image that still holds the pixels of its material's PNG or JPEG file (or embedded bytes), which
// is stored as those bytes (a level of detail that is the input itself keeps its JPEG: no re-encoding,
// and DamagedHelmet's 2048 x 2048 albedo stays 0.94 MB instead of a larger PNG); files and embedded
// bytes that are PNG or JPEG as they are, other image files re-encoded as PNG.
class Gltf_image_encoder {
public:
  internal::Encoded_image operator()(const Material& m, bool diffuse) {
    const Image& img = diffuse ? m.diffuse_image : m.normal_image;
    if (!img.empty()) return encode(img, m, diffuse);
    internal::Encoded_image e = internal::encode_texture_file(m, diffuse);
    if (e.bytes.empty() || !e.mime_type.empty()) return e;
    const std::string& file = diffuse ? m.diffuse_texture : m.normal_texture;
    const Image decoded = file.empty() ? read_image_from_memory(e.bytes, m.name) : read_image(file);
    return encode(decoded, m, diffuse);
  }

  /// Encodes the distinct decoded images of every level's materials at once, in parallel (a
  /// chain of levels has one atlas per level, and PNG encoding is most of its writing time); the
  /// calls above then find them done. The first error is thrown as a serial run would.
  void encode_ahead(const std::vector<Gltf_level>& levels) {
    struct Todo {
      const Image* image;
      const Material* material;
      bool diffuse;
    };
    std::vector<Todo> todo;
    for (const Gltf_level& l : levels) {
      if (!l.mesh) continue;
      for (const Material& m : l.mesh->materials())
        for (bool diffuse : {true, false}) {
          const Image* img = diffuse ? &m.diffuse_image : &m.normal_image;
          if (img->empty()) continue;
          bool seen = false;
          for (const Todo& t : todo) seen = seen || *t.image == *img;
          if (!seen) todo.push_back({img, &m, diffuse});
        }
    }
    if (todo.size() < 2) return;  // nothing to gain
    std::vector<internal::Encoded_image> encoded(todo.size());
    std::vector<std::exception_ptr> failed(todo.size());
    tbb::parallel_for(std::size_t(0), todo.size(), [&](std::size_t i) {
      try {
        encoded[i] = fresh(*todo[i].image, *todo[i].material, todo[i].diffuse);
      } catch (...) {
        failed[i] = std::current_exception();
      }
    });
    for (const auto& e : failed)
      if (e) std::rethrow_exception(e);
    for (std::size_t i = 0; i < todo.size(); ++i)
      done_.emplace_back(std::make_unique<Image>(*todo[i].image), std::move(encoded[i]));
  }

private:
  /// The bytes of `m`'s PNG or JPEG texture file (or embedded image) when they decode to `img`,
  /// else `img` encoded as PNG.
  static internal::Encoded_image fresh(const Image& img, const Material& m, bool diffuse) {
    const std::string& file = diffuse ? m.diffuse_texture : m.normal_texture;
    std::error_code ec;
    if ((!file.empty() && std::filesystem::is_regular_file(file, ec)) || (diffuse && !m.diffuse_texture_blob.empty())) {
      internal::Encoded_image e = internal::encode_texture_file(m, diffuse);
      if (!e.bytes.empty() && (e.mime_type == "image/png" || e.mime_type == "image/jpeg")) {
        try {
          if (read_image_from_memory(e.bytes, m.name) == img) return e;
        } catch (const IO_error&) {
          // an unreadable file: the decoded image is encoded below
        }
      }
    }
    internal::Encoded_image e;
    e.bytes = encode_image(img, ".png", "texture of material '" + m.name + "'");
    e.mime_type = "image/png";
    return e;
  }

  internal::Encoded_image encode(const Image& img, const Material& m, bool diffuse) {
    for (const auto& [image, encoded] : done_)
      if (*image == img) return encoded;
    internal::Encoded_image e = fresh(img, m, diffuse);
    done_.emplace_back(std::make_unique<Image>(img), e);
    return e;
  }

  std::vector<std::pair<std::unique_ptr<Image>, internal::Encoded_image>> done_;
};

}  // namespace

void write_textured_gltf(const std::string& path, const std::vector<Gltf_level>& levels, Atomic_output& out,
                         const Gltf_options& options) {
  Gltf_image_encoder encoder;
  encoder.encode_ahead(levels);
  internal::write_gltf(path, levels, options, out, std::ref(encoder));
}

void write_textured_gltf(const std::string& path, const std::vector<Gltf_level>& levels, const Gltf_options& options) {
  Atomic_output out;
  write_textured_gltf(path, levels, out, options);
  out.commit();
}

void write_textured_mesh(const std::string& path, const Textured_mesh& mesh, Atomic_output& out,
                         const Gltf_options& gltf_options) {
  const std::string ext = extension(path);
  if (ext == ".gltf" || ext == ".glb") {
    write_textured_gltf(path, {Gltf_level{&mesh, std::string("mesh"), -1, -1}}, out, gltf_options);
    return;
  }
  if (mesh.mesh().number_of_faces() == 0) throw IO_error(path, "refusing to write a mesh without faces");
  if (ext == ".off") {
    internal::write_off(path, mesh, out);
    return;
  }
  if (ext == ".ply") {
    internal::write_ply(path, mesh, out);
    return;
  }
  if (ext == ".stl") {
    internal::write_stl(path, mesh, out);
    return;
  }
  if (ext != ".obj")
    throw IO_error(path, "unsupported output type '" + ext + "' (expected .obj, .off, .ply, .stl, .gltf or .glb)");
  const std::string stem = fs::path(path).stem().string();
  const fs::path dir = fs::path(path).parent_path();
  internal::write_obj(
      path, mesh, out, [&](const Material& m, std::size_t i, const std::string& kind, Atomic_output& o) {
        const bool diffuse = kind == "diffuse";
        const Image& img = diffuse ? m.diffuse_image : m.normal_image;
        const std::string name = stem + "_" + std::to_string(i) + "_" + kind;
        if (!img.empty()) {
          write_image((dir / (name + ".png")).string(), img, o);
          return name + ".png";
        }
        if (diffuse && !m.diffuse_texture_blob.empty() && m.diffuse_texture.empty()) {
          Image decoded = read_image_from_memory(m.diffuse_texture_blob, m.name);
          write_image((dir / (name + ".png")).string(), decoded, o);
          return name + ".png";
        }
        return internal::copy_texture_file(path, diffuse ? m.diffuse_texture : m.normal_texture, name, o);
      });
}

void write_textured_mesh(const std::string& path, const Textured_mesh& mesh, const Gltf_options& gltf_options) {
  Atomic_output out;
  write_textured_mesh(path, mesh, out, gltf_options);
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom
