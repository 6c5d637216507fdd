// glTF 2.0 / GLB reader on tinygltf. Images are not decoded here (Mesh_IO has no image
// library): external images keep their path, embedded ones their encoded bytes. Primitives
// compressed with KHR_draco_mesh_compression are decoded by Google's Draco library (Debian's
// libdraco-dev); a file that requires another extension that changes how its data is read
// (EXT_meshopt_compression, ...) is refused by name.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "io_internal.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <draco/compression/decode.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string_view>

namespace CMGeom {
namespace IO {
namespace internal {

namespace fs = std::filesystem;

namespace {

// Keeps the encoded bytes of each image: decoding happens in Image_IO.
bool keep_encoded_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                        const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

// A URI reference's path with its %XX escapes decoded (glTF image URIs are URI references:
// "my%20duck.png" names the file "my duck.png"). A '%' not followed by two hex digits is kept.
std::string percent_decoded(const std::string& uri) {
  auto hex = [](char c) {
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
  };
  std::string s;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      s += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      s += uri[i];
    }
  }
  return s;
}

using Mat4 = std::array<double, 16>;  // column-major, as glTF stores it

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int rr = 0; rr < 4; ++rr) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[std::size_t(k * 4 + rr)] * b[std::size_t(c * 4 + k)];
      r[std::size_t(c * 4 + rr)] = s;
    }
  return r;
}

Mat4 node_matrix(const tinygltf::Node& n) {
  Mat4 m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  if (n.matrix.size() == 16) {
    for (std::size_t i = 0; i < 16; ++i) m[i] = n.matrix[i];
    return m;
  }
  Mat4 t = m, r = m, s = m;
  if (n.translation.size() == 3) {
    t[12] = n.translation[0];
    t[13] = n.translation[1];
    t[14] = n.translation[2];
  }
  if (n.rotation.size() == 4) {
    const double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    r = {1 - 2 * (y * y + z * z),
         2 * (x * y + z * w),
         2 * (x * z - y * w),
         0,
         2 * (x * y - z * w),
         1 - 2 * (x * x + z * z),
         2 * (y * z + x * w),
         0,
         2 * (x * z + y * w),
         2 * (y * z - x * w),
         1 - 2 * (x * x + y * y),
         0,
         0,
         0,
         0,
         1};
  }
  if (n.scale.size() == 3) {
    s[0] = n.scale[0];
    s[5] = n.scale[1];
    s[10] = n.scale[2];
  }
  return multiply(t, multiply(r, s));
}

// A primitive compressed with KHR_draco_mesh_compression keeps an "indices" accessor without a
// buffer view (the triangles are in the compressed data), which tinygltf 2.7 refuses ("invalid
// bufferView"). The glTF JSON with those primitives' "indices" dropped (the decoder gives their
// triangles), or nothing when no primitive needs it or the text is not a JSON object (tinygltf
// then reports what is wrong).
std::optional<std::string> json_without_draco_indices(std::string_view text) {
  if (text.find("KHR_draco_mesh_compression") == std::string_view::npos) return std::nullopt;
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return std::nullopt;
  bool changed = false;
  const auto meshes = j.find("meshes");
  if (meshes == j.end() || !meshes->is_array()) return std::nullopt;
  for (auto& mesh : *meshes) {
    if (!mesh.is_object()) continue;
    const auto primitives = mesh.find("primitives");
    if (primitives == mesh.end() || !primitives->is_array()) continue;
    for (auto& primitive : *primitives) {
      if (!primitive.is_object()) continue;
      const auto ext = primitive.find("extensions");
      if (ext == primitive.end() || !ext->is_object() || !ext->contains("KHR_draco_mesh_compression")) continue;
      changed = primitive.erase("indices") > 0 || changed;
    }
  }
  if (!changed) return std::nullopt;
  return j.dump();
}

std::uint32_t glb_word(const std::string_view bytes, std::size_t at) {
  std::uint32_t w;
  std::memcpy(&w, bytes.data() + at, 4);  // (GLB is little-endian, as x86-64 and aarch64)
  return w;
}

// The JSON chunk of the GLB container `bytes`, or nothing when the container is not one tinygltf
// would read (it then says why).
std::optional<std::string_view> glb_json_chunk(std::string_view bytes) {
  if (bytes.size() < 20 || bytes.substr(0, 4) != "glTF" || glb_word(bytes, 4) != 2) return std::nullopt;
  const std::size_t total = glb_word(bytes, 8), json_length = glb_word(bytes, 12);
  if (total > bytes.size() || glb_word(bytes, 16) != 0x4E4F534Au || json_length > total - 20) return std::nullopt;
  return bytes.substr(20, json_length);
}

// The GLB container `bytes` (glb_json_chunk() gave its JSON chunk) with that chunk replaced by
// `json`, padded with spaces to four bytes.
std::string glb_with_json(std::string_view bytes, const std::string& json) {
  const std::size_t total = glb_word(bytes, 8), json_length = glb_word(bytes, 12);
  std::string padded = json;
  padded.resize((padded.size() + 3) / 4 * 4, ' ');
  const std::string_view rest = bytes.substr(20 + json_length, total - 20 - json_length);  // (the BIN chunk)
  const std::uint32_t head[5] = {0x46546C67u, 2u, std::uint32_t(20 + padded.size() + rest.size()),
                                 std::uint32_t(padded.size()), 0x4E4F534Au};
  std::string out(reinterpret_cast<const char*>(head), sizeof head);
  out += padded;
  out.append(rest.data(), rest.size());
  return out;
}

// A primitive's triangles and attributes decoded from its KHR_draco_mesh_compression buffer view:
// positions (3 per point), texture coordinates (2 per point, empty without TEXCOORD_0) and the
// triangles' point indices (3 per face), as the accessors would give them uncompressed.
struct Draco_primitive {
  std::vector<double> positions, uvs;
  std::vector<std::size_t> indices;
};

Draco_primitive decode_draco_primitive(const tinygltf::Model& model, const tinygltf::Value& ext, bool with_uv,
                                       const std::string& path) {
  const char* what = "KHR_draco_mesh_compression";
  const tinygltf::Value& view = ext.Get("bufferView");
  const tinygltf::Value& attributes = ext.Get("attributes");
  if (!view.IsNumber() || !attributes.IsObject())
    throw IO_error(path, std::string(what) + ": needs a bufferView and attributes");
  const int bv_index = view.GetNumberAsInt();
  if (bv_index < 0 || std::size_t(bv_index) >= model.bufferViews.size())
    throw IO_error(path, std::string(what) + ": buffer view index out of range");
  const tinygltf::BufferView& bv = model.bufferViews[std::size_t(bv_index)];
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
    throw IO_error(path, std::string(what) + ": buffer index out of range");
  const auto& data = model.buffers[std::size_t(bv.buffer)].data;
  if (bv.byteOffset > data.size() || bv.byteLength > data.size() - bv.byteOffset)
    throw IO_error(path, std::string(what) + ": buffer view reaches past the end of its buffer");
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(data.data() + bv.byteOffset), bv.byteLength);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) throw IO_error(path, std::string(what) + ": " + decoded.status().error_msg_string());
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  // the attribute the extension maps `name` to, with `components` values a point
  auto attribute = [&](const char* name, int components) {
    const tinygltf::Value& id = attributes.Get(name);
    if (!id.IsNumber()) throw IO_error(path, std::string(what) + ": no " + name + " attribute");
    const draco::PointAttribute* a = mesh->GetAttributeByUniqueId(std::uint32_t(id.GetNumberAsInt()));
    if (!a || a->num_components() != components)
      throw IO_error(path, std::string(what) + ": " + name + " is not a " + std::to_string(components) +
                               "-component attribute of the compressed mesh");
    std::vector<double> out(std::size_t(mesh->num_points()) * std::size_t(components));
    float v[3];
    for (draco::PointIndex i(0); i < mesh->num_points(); ++i) {
      if (!a->ConvertValue<float>(a->mapped_index(i), std::int8_t(components), v))
        throw IO_error(path, std::string(what) + ": " + name + " values cannot be read");
      for (int c = 0; c < components; ++c) {
        if (!std::isfinite(v[c])) throw IO_error(path, std::string(what) + ": " + name + ": non-finite value");
        out[std::size_t(i.value()) * std::size_t(components) + std::size_t(c)] = v[c];
      }
    }
    return out;
  };
  Draco_primitive p;
  p.positions = attribute("POSITION", 3);
  if (with_uv) p.uvs = attribute("TEXCOORD_0", 2);
  p.indices.reserve(3 * std::size_t(mesh->num_faces()));
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::size_t d = mesh->face(f)[k].value();
      if (d >= mesh->num_points())
        throw IO_error(path, std::string(what) + ": index " + std::to_string(d) + " out of range (" +
                                 std::to_string(mesh->num_points()) + " vertices)");
      p.indices.push_back(d);
    }
  return p;
}

struct Accessor_reader {
  const tinygltf::Model& model;
  const std::string& path;

  // Reads `count x components` values of an accessor as doubles (normalised integers mapped to [0,1]).
  std::vector<double> read(int index, int components, const char* what) const {
    if (index < 0 || std::size_t(index) >= model.accessors.size())
      throw IO_error(path, std::string(what) + ": accessor index out of range");
    const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
    if (a.sparse.isSparse) throw IO_error(path, std::string(what) + ": sparse accessors are not supported");
    const int nc = tinygltf::GetNumComponentsInType(std::uint32_t(a.type));
    if (nc != components)
      throw IO_error(path, std::string(what) + ": expected " + std::to_string(components) + " components");
    if (a.bufferView < 0 || std::size_t(a.bufferView) >= model.bufferViews.size())
      throw IO_error(path, std::string(what) + ": missing buffer view");
    const tinygltf::BufferView& bv = model.bufferViews[std::size_t(a.bufferView)];
    if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
      throw IO_error(path, std::string(what) + ": buffer index out of range");
    const auto& data = model.buffers[std::size_t(bv.buffer)].data;
    const int csize = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType));
    if (csize <= 0) throw IO_error(path, std::string(what) + ": bad component type");
    const std::size_t elem = std::size_t(csize) * std::size_t(nc);
    const std::size_t stride = bv.byteStride ? bv.byteStride : elem;
    const std::size_t start = bv.byteOffset + a.byteOffset;
    if (a.count > 0 && (start + stride * (a.count - 1) + elem > data.size() ||
                        start + stride * (a.count - 1) + elem > bv.byteOffset + bv.byteLength))
      throw IO_error(path, std::string(what) + ": accessor reaches past the end of its buffer");
    std::vector<double> out(a.count * std::size_t(nc));
    for (std::size_t i = 0; i < a.count; ++i)
      for (int c = 0; c < nc; ++c) {
        const unsigned char* p = data.data() + start + i * stride + std::size_t(c * csize);
        double v;
        switch (a.componentType) {
          case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, p, 4);
            v = f;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
            std::memcpy(&v, p, 8);
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            v = *p / (a.normalized ? 255.0 : 1.0);
            break;
          case TINYGLTF_COMPONENT_TYPE_BYTE: {
            std::int8_t b;
            std::memcpy(&b, p, 1);
            v = a.normalized ? std::max(b / 127.0, -1.0) : b;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t s;
            std::memcpy(&s, p, 2);
            v = s / (a.normalized ? 65535.0 : 1.0);
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_SHORT: {
            std::int16_t s;
            std::memcpy(&s, p, 2);
            v = a.normalized ? std::max(s / 32767.0, -1.0) : s;
            break;
          }
          case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            std::uint32_t u;
            std::memcpy(&u, p, 4);
            v = u;
            break;
          }
          default:
            throw IO_error(path, std::string(what) + ": unsupported component type");
        }
        if (!std::isfinite(v)) throw IO_error(path, std::string(what) + ": non-finite value");
        out[i * std::size_t(nc) + std::size_t(c)] = v;
      }
    return out;
  }
};

}  // namespace

void read_gltf(const std::string& path, Polygon_soup& soup) {
  {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw IO_error(path, "file not found");
    if (fs::file_size(path, ec) == 0) throw IO_error(path, "empty file");
  }
  soup = Polygon_soup();
  soup.source = path;
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&keep_encoded_image, nullptr);
  std::string err, warn;
  const bool binary = extension(path) == ".glb";
  bool ok = false;
  try {
    // the file is read once; one with Draco-compressed primitives is given to tinygltf with their
    // "indices" dropped (json_without_draco_indices()), any other as it is
    const File_bytes bytes(path);
    const std::string_view all = bytes.view();
    std::optional<std::string> rewritten;
    if (!binary) {
      rewritten = json_without_draco_indices(all);
    } else if (const auto chunk = glb_json_chunk(all)) {
      if (const auto json = json_without_draco_indices(*chunk)) rewritten = glb_with_json(all, *json);
    }
    const std::string_view text = rewritten ? std::string_view(*rewritten) : all;
    const std::string base_dir = fs::path(path).parent_path().string();
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(text.data()),
                                              static_cast<unsigned int>(text.size()), base_dir)
                : loader.LoadASCIIFromString(&model, &err, &warn, text.data(), static_cast<unsigned int>(text.size()),
                                             base_dir);
  } catch (const std::exception& e) {
    throw IO_error(path, std::string("malformed glTF: ") + e.what());
  }
  if (!ok) {
    std::string msg = err.empty() ? "malformed glTF" : err;
    for (char& c : msg)
      if (c == '\n') c = ' ';
    throw IO_error(path, msg);
  }
  // extensions a reader must know to read the file right (glTF 2.0 §3.12): those that change how
  // geometry is stored, except Draco's, are refused by name; the others (texture transforms,
  // material models, ...) leave the geometry and the base colour as read here
  for (const std::string& e : model.extensionsRequired)
    if (e == "EXT_meshopt_compression" || e == "KHR_meshopt_compression" || e == "EXT_mesh_gpu_instancing")
      throw IO_error(path, "requires the glTF extension " + e +
                               ", which CMGeom does not read (decompress the file first, e.g. with gltfpack -noq or "
                               "gltf-transform)");
  const Accessor_reader reader{model, path};
  const fs::path dir = fs::path(path).parent_path();

  // Materials: base colour factor and texture, normal map.
  auto image_of_texture = [&](int tex) -> const tinygltf::Image* {
    if (tex < 0 || std::size_t(tex) >= model.textures.size()) return nullptr;
    const int src = model.textures[std::size_t(tex)].source;
    if (src < 0 || std::size_t(src) >= model.images.size()) return nullptr;
    return &model.images[std::size_t(src)];
  };
  auto texture_source = [&](const tinygltf::Image* img, std::string& file, std::vector<unsigned char>* blob) {
    if (!img) return;
    if (!img->uri.empty() && img->uri.compare(0, 5, "data:") != 0) {
      const fs::path p = dir / percent_decoded(img->uri);
      std::error_code ec;
      if (!fs::is_regular_file(p, ec)) throw IO_error(path, "texture image '" + img->uri + "' not found");
      file = fs::absolute(p).lexically_normal().string();
    } else if (blob) {
      *blob = img->image;
    }
  };
  for (const tinygltf::Material& gm : model.materials) {
    Material m;
    m.name = gm.name.empty() ? "material" + std::to_string(soup.materials.size()) : gm.name;
    const auto& f = gm.pbrMetallicRoughness.baseColorFactor;
    if (f.size() >= 3) m.diffuse_color = {f[0], f[1], f[2]};
    texture_source(image_of_texture(gm.pbrMetallicRoughness.baseColorTexture.index), m.diffuse_texture,
                   &m.diffuse_texture_blob);
    texture_source(image_of_texture(gm.normalTexture.index), m.normal_texture, nullptr);
    soup.materials.push_back(std::move(m));
  }

  // Welding by exact coordinate equality, so UV seams become shared edges.
  std::map<std::array<double, 3>, std::uint32_t> vertex_id;
  std::map<std::array<double, 2>, std::uint32_t> uv_id;
  bool any_uv = false, any_no_uv = false;

  auto add_primitive = [&](const tinygltf::Primitive& prim, const Mat4& M) {
    auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) throw IO_error(path, "primitive without POSITION");
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      soup.warnings.push_back(path + ": a point/line primitive was skipped");
      return;
    }
    auto uv_it = prim.attributes.find("TEXCOORD_0");
    const bool with_uv = uv_it != prim.attributes.end();
    (with_uv ? any_uv : any_no_uv) = true;
    const auto draco_it = prim.extensions.find("KHR_draco_mesh_compression");
    std::optional<Draco_primitive> compressed;
    if (draco_it != prim.extensions.end()) {
      if (prim.mode != TINYGLTF_MODE_TRIANGLES)
        throw IO_error(path, "KHR_draco_mesh_compression: only triangle lists can be compressed");
      compressed = decode_draco_primitive(model, draco_it->second, with_uv, path);
    }
    const std::vector<double> pos =
        compressed ? std::move(compressed->positions) : reader.read(pos_it->second, 3, "POSITION");
    const std::size_t nv = pos.size() / 3;
    std::vector<double> uv;
    if (with_uv) {
      uv = compressed ? std::move(compressed->uvs) : reader.read(uv_it->second, 2, "TEXCOORD_0");
      if (uv.size() / 2 != nv) throw IO_error(path, "TEXCOORD_0 and POSITION counts differ");
    }
    std::vector<std::uint32_t> local(nv), local_uv(nv, Polygon_soup::no_index);
    for (std::size_t i = 0; i < nv; ++i) {
      const double x = pos[3 * i], y = pos[3 * i + 1], z = pos[3 * i + 2];
      std::array<double, 3> p = {M[0] * x + M[4] * y + M[8] * z + M[12], M[1] * x + M[5] * y + M[9] * z + M[13],
                                 M[2] * x + M[6] * y + M[10] * z + M[14]};
      auto [it, ins] = vertex_id.emplace(p, std::uint32_t(soup.positions.size()));
      if (ins) soup.positions.push_back(p);
      local[i] = it->second;
      if (!uv.empty()) {
        std::array<double, 2> t = {uv[2 * i], 1.0 - uv[2 * i + 1]};  // glTF v points down
        auto [jt, jns] = uv_id.emplace(t, std::uint32_t(soup.uvs.size()));
        if (jns) soup.uvs.push_back(t);
        local_uv[i] = jt->second;
      }
    }
    std::vector<std::size_t> idx;
    if (compressed) {
      idx = std::move(compressed->indices);  // (checked by the decoder against its points, nv of them)
    } else if (prim.indices >= 0) {
      for (double d : reader.read(prim.indices, 1, "indices")) {
        if (d < 0 || d >= double(nv))
          throw IO_error(
              path, "index " + std::to_string((long long)d) + " out of range (" + std::to_string(nv) + " vertices)");
        idx.push_back(std::size_t(d));
      }
    } else {
      for (std::size_t i = 0; i < nv; ++i) idx.push_back(i);
    }
    std::vector<std::array<std::size_t, 3>> tris;
    if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
      if (idx.size() % 3) throw IO_error(path, "triangle index count is not a multiple of 3");
      for (std::size_t i = 0; i + 2 < idx.size(); i += 3) tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
    } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 0; i + 2 < idx.size(); ++i)
        tris.push_back(i % 2 ? std::array<std::size_t, 3>{idx[i + 1], idx[i], idx[i + 2]}
                             : std::array<std::size_t, 3>{idx[i], idx[i + 1], idx[i + 2]});
    } else {
      for (std::size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[0], idx[i], idx[i + 1]});
    }
    const int mat = prim.material >= 0 && std::size_t(prim.material) < soup.materials.size() ? prim.material : 0;
    for (const auto& t : tris) {
      for (std::size_t k : t) {
        soup.corner_vertex.push_back(local[k]);
        soup.corner_uv.push_back(local_uv[k]);
      }
      soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
      soup.face_material.push_back(mat);
      soup.face_line.push_back(0);
    }
  };

  std::vector<int> roots;
  const int scene = model.defaultScene >= 0 ? model.defaultScene : (model.scenes.empty() ? -1 : 0);
  if (scene >= 0 && std::size_t(scene) < model.scenes.size()) {
    roots = model.scenes[std::size_t(scene)].nodes;
  } else {
    for (std::size_t i = 0; i < model.nodes.size(); ++i) roots.push_back(int(i));
  }
  const Mat4 identity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::vector<std::pair<int, Mat4>> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, identity);
  std::size_t visited = 0;
  while (!stack.empty()) {
    auto [ni, parent] = stack.back();
    stack.pop_back();
    if (ni < 0 || std::size_t(ni) >= model.nodes.size()) throw IO_error(path, "node index out of range");
    if (++visited > 4 * model.nodes.size() + 16) throw IO_error(path, "node hierarchy has a cycle");
    const tinygltf::Node& node = model.nodes[std::size_t(ni)];
    const Mat4 M = multiply(parent, node_matrix(node));
    if (node.mesh >= 0) {
      if (std::size_t(node.mesh) >= model.meshes.size()) throw IO_error(path, "mesh index out of range");
      for (const auto& prim : model.meshes[std::size_t(node.mesh)].primitives) add_primitive(prim, M);
    }
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.emplace_back(*it, M);
  }
  if (soup.number_of_faces() == 0) throw IO_error(path, "no triangles in the default scene");
  if (any_uv && any_no_uv) throw IO_error(path, "some primitives have TEXCOORD_0 and others do not");
  if (!any_uv) soup.uvs.clear();
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
