// Textured meshes with images: decoding on read, PNG textures on write.
#include "io_internal.h"

#include <CMGeom/Mesh_IO/textured_mesh_io.h>

#include <filesystem>

namespace CMGeom {
namespace IO {

namespace fs = std::filesystem;

void load_textures(Textured_mesh& mesh) {
  for (Material& m : mesh.materials()) {
    if (m.diffuse_image.empty()) {
      if (!m.diffuse_texture.empty()) m.diffuse_image = read_image(m.diffuse_texture);
      else if (!m.diffuse_texture_blob.empty())
        m.diffuse_image = read_image_from_memory(m.diffuse_texture_blob, mesh.source() + " (material '" + m.name + "')");
    }
    if (m.normal_image.empty() && !m.normal_texture.empty()) m.normal_image = read_image(m.normal_texture);
  }
}

void read_textured_mesh(const std::string& path, Textured_mesh& out, const Read_options& options) {
  read_mesh(path, out, options);
  load_textures(out);
}

void write_textured_mesh(const std::string& path, const Textured_mesh& mesh) {
  if (extension(path) != ".obj") {
    write_mesh(path, mesh);
    return;
  }
  if (mesh.mesh().number_of_faces() == 0) throw IO_error(path, "refusing to write a mesh without faces");
  Atomic_output out;
  const std::string stem = fs::path(path).stem().string();
  const fs::path dir = fs::path(path).parent_path();
  internal::write_obj(path, mesh, out,
                      [&](const Material& m, std::size_t i, const std::string& kind, Atomic_output& o) {
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
                        return internal::copy_texture_file(path, diffuse ? m.diffuse_texture : m.normal_texture,
                                                           name, o);
                      });
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom
