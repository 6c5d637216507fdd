// glTF 2.0 / GLB writer: the scene is assembled here, tinygltf serialises it (JSON and the GLB
// container). See write_gltf() in mesh_io.h for what is written.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "io_internal.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <type_traits>

namespace CMGeom {
namespace IO {
namespace internal {

namespace fs = std::filesystem;

std::string image_mime_type(const std::vector<unsigned char>& bytes) {
  static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), png, 8) == 0) return "image/png";
  if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) return "image/jpeg";
  return std::string();
}

namespace {

using Vertex_index = Surface_mesh::Vertex_index;
using Face_index = Surface_mesh::Face_index;
using Halfedge_index = Surface_mesh::Halfedge_index;

// A URI reference for a file name: RFC 3986 unreserved characters kept, the rest percent-encoded.
std::string uri_of_file_name(const std::string& name) {
  static const char hex[] = "0123456789ABCDEF";
  std::string s;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      s += char(c);
    } else {
      s += '%';
      s += hex[c >> 4];
      s += hex[c & 15];
    }
  }
  return s;
}

// Removes the colour-space chunks (iCCP, sRGB, gAMA, cHRM) of a PNG. glTF fixes the colour space
// of every texture (sRGB for base colour, linear for normal maps): its images should not carry
// colour-space information (ICC profiles, gamma) and viewers must ignore it (glTF 2.0
// specification, "Images"), so such a chunk only misleads; the Khronos validator warns about it
// (IMAGE_FEATURES_UNSUPPORTED; the shared textures of spot and bob carry one). The other chunks,
// pixel data included, are kept byte for byte; a PNG whose chunks cannot be walked is kept as it
// is, and one without such chunks is not copied (an atlas' PNG runs to megabytes).
void drop_colour_space_chunks(std::vector<unsigned char>& png) {
  auto be32 = [&](std::size_t i) {
    return std::uint32_t(png[i]) << 24 | std::uint32_t(png[i + 1]) << 16 | std::uint32_t(png[i + 2]) << 8 | png[i + 3];
  };
  auto is_colour_space = [&](std::size_t i) {
    const std::string type(png.begin() + std::ptrdiff_t(i + 4), png.begin() + std::ptrdiff_t(i + 8));
    return type == "iCCP" || type == "sRGB" || type == "gAMA" || type == "cHRM";
  };
  // the chunks' ends, checked first: nothing changes unless every chunk is whole
  std::vector<std::size_t> starts;
  bool any = false;
  std::size_t i = 8;
  while (i + 12 <= png.size()) {
    const std::size_t end = i + 12 + std::size_t(be32(i));
    if (end > png.size() || end < i) return;
    starts.push_back(i);
    any = any || is_colour_space(i);
    const bool last = std::equal(png.begin() + std::ptrdiff_t(i + 4), png.begin() + std::ptrdiff_t(i + 8), "IEND");
    i = end;
    if (last) break;
  }
  if (!any) return;
  std::vector<unsigned char> out(png.begin(), png.begin() + 8);
  out.reserve(png.size());
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::size_t end = k + 1 < starts.size() ? starts[k + 1] : i;
    if (!is_colour_space(starts[k]))
      out.insert(out.end(), png.begin() + std::ptrdiff_t(starts[k]), png.begin() + std::ptrdiff_t(end));
  }
  out.insert(out.end(), png.begin() + std::ptrdiff_t(i), png.end());  // bytes after IEND, if any
  png = std::move(out);
}

// The single binary buffer and its views (each view starts on a 4-byte boundary).
class Buffer_builder {
public:
  explicit Buffer_builder(tinygltf::Model& model) : model_(model) {}

  int add_view(const void* bytes, std::size_t size, int target, std::size_t stride) {
    while (data_.size() % 4) data_.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = data_.size();
    view.byteLength = size;
    view.byteStride = stride;
    view.target = target;
    const unsigned char* b = static_cast<const unsigned char*>(bytes);
    data_.insert(data_.end(), b, b + size);
    model_.bufferViews.push_back(view);
    return int(model_.bufferViews.size() - 1);
  }
  template <class T>
  int add_view(const std::vector<T>& values, int target, std::size_t stride) {
    static_assert(std::is_arithmetic<T>::value, "a view holds numbers");
    return add_view(values.data(), values.size() * sizeof(T), target, stride);
  }

  std::vector<unsigned char>& data() { return data_; }
  /// Room for `bytes` more without moving what is there (reserved, not touched: memory the views
  /// do not fill is never faulted in).
  void reserve_more(std::size_t bytes) { data_.reserve(data_.size() + bytes); }

private:
  tinygltf::Model& model_;
  std::vector<unsigned char> data_;
};

constexpr std::uint32_t no_vertex = std::numeric_limits<std::uint32_t>::max();

// The bits of a double: texture coordinates are told apart bit for bit.
std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, 8);
  return b;
}

// Unit area-weighted vertex normals (a vertex whose faces have no area gets +z).
std::vector<std::array<double, 3>> vertex_normals(const Surface_mesh& m) {
  std::vector<std::array<double, 3>> n(m.number_of_vertices() + m.number_of_removed_vertices(), {0, 0, 0});
  for (Face_index f : m.faces()) {
    const Halfedge_index h = m.halfedge(f);
    const Point_3& a = m.point(m.target(h));
    const Point_3& b = m.point(m.target(m.next(h)));
    const Point_3& c = m.point(m.source(h));
    const double ux = b.x() - a.x(), uy = b.y() - a.y(), uz = b.z() - a.z();
    const double vx = c.x() - a.x(), vy = c.y() - a.y(), vz = c.z() - a.z();
    const std::array<double, 3> cr = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
    for (Halfedge_index g : CGAL::halfedges_around_face(h, m))
      for (int k = 0; k < 3; ++k) n[std::size_t(m.target(g))][std::size_t(k)] += cr[std::size_t(k)];
  }
  for (auto& v : n) {
    const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0 && std::isfinite(l))
      v = {v[0] / l, v[1] / l, v[2] / l};
    else
      v = {0, 0, 1};
  }
  return n;
}

// Unit tangents of the glTF vertices of a primitive (`corner`: a corner of each; `indices`: its
// triangles) with their handedness, for normal maps: the direction of increasing u on each face,
// weighted by the face's area, averaged over the faces around each glTF vertex (a vertex split at a
// UV seam gets the faces of its side), then made orthogonal to the vertex normal. w is the sign
// that makes cross(normal, tangent) * w point along increasing v as CMGeom stores it (image up,
// the glTF viewers' convention for a tangent space without mirroring; w = -1 on mirrored charts).
// A vertex whose faces have no UV area gets any tangent orthogonal to its normal.
std::vector<std::array<double, 4>> vertex_tangents(const Textured_mesh& tm, const std::vector<Halfedge_index>& corner,
                                                   const std::vector<std::uint32_t>& indices,
                                                   const std::vector<std::array<double, 3>>& normals) {
  using V = std::array<double, 3>;
  auto sub = [](const V& a, const V& b) { return V{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  auto dot = [](const V& a, const V& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  auto cross = [](const V& a, const V& b) {
    return V{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  auto unit = [&](V a) {
    const double l = std::sqrt(dot(a, a));
    return l > 0 && std::isfinite(l) ? V{a[0] / l, a[1] / l, a[2] / l} : V{0, 0, 0};
  };
  const Surface_mesh& m = tm.mesh();
  auto position = [&](std::uint32_t i) {
    const Point_3& p = m.point(m.target(corner[i]));
    return V{p.x(), p.y(), p.z()};
  };
  std::vector<V> tu(corner.size(), V{0, 0, 0}), tv(corner.size(), V{0, 0, 0});
  for (std::size_t f = 0; f + 2 < indices.size(); f += 3) {
    const std::uint32_t c[3] = {indices[f], indices[f + 1], indices[f + 2]};
    const V e1 = sub(position(c[1]), position(c[0])), e2 = sub(position(c[2]), position(c[0]));
    const Point_2 t0 = tm.uv(corner[c[0]]), t1 = tm.uv(corner[c[1]]), t2 = tm.uv(corner[c[2]]);
    const double du1 = t1.x() - t0.x(), dv1 = t1.y() - t0.y(), du2 = t2.x() - t0.x(), dv2 = t2.y() - t0.y();
    const double det = du1 * dv2 - du2 * dv1;
    if (det == 0 || !std::isfinite(det)) continue;  // no UV area: no direction of u on this face
    // dP/du and dP/dv of the face, as unit vectors weighted by its area
    const double area = std::sqrt(dot(cross(e1, e2), cross(e1, e2)));
    const V su = unit(
        V{(e1[0] * dv2 - e2[0] * dv1) / det, (e1[1] * dv2 - e2[1] * dv1) / det, (e1[2] * dv2 - e2[2] * dv1) / det});
    const V sv = unit(
        V{(e2[0] * du1 - e1[0] * du2) / det, (e2[1] * du1 - e1[1] * du2) / det, (e2[2] * du1 - e1[2] * du2) / det});
    for (std::uint32_t i : c)
      for (std::size_t k = 0; k < 3; ++k) {
        tu[i][k] += area * su[k];
        tv[i][k] += area * sv[k];
      }
  }
  std::vector<std::array<double, 4>> out(corner.size());
  for (std::size_t i = 0; i < corner.size(); ++i) {
    const V& nv = normals[std::size_t(m.target(corner[i]))];
    V t = unit(sub(tu[i], V{nv[0] * dot(nv, tu[i]), nv[1] * dot(nv, tu[i]), nv[2] * dot(nv, tu[i])}));
    if (dot(t, t) == 0) {  // any direction orthogonal to the normal: its smallest axis crossed with it
      const std::size_t a = std::abs(nv[0]) <= std::abs(nv[1]) && std::abs(nv[0]) <= std::abs(nv[2]) ? 0
                            : std::abs(nv[1]) <= std::abs(nv[2])                                     ? 1
                                                                                                     : 2;
      V axis{0, 0, 0};
      axis[a] = 1;
      t = unit(cross(nv, axis));
    }
    const double w = dot(cross(nv, t), tv[i]) < 0 ? -1.0 : 1.0;
    out[i] = {t[0], t[1], t[2], w};
  }
  return out;
}

class Scene_writer {
public:
  Scene_writer(const std::string& path, const Gltf_options& options, const Image_encoder& encode)
      : path_(path), options_(options), encode_(encode), buffer_(model_) {
    model_.asset.version = "2.0";
    model_.asset.generator = "CMGeom " CMGEOM_VERSION_STR;
  }

  /// See Buffer_builder::reserve_more().
  void reserve_buffer(std::size_t bytes) { buffer_.reserve_more(bytes); }

  void add_level(const Gltf_level& level, std::size_t index) {
    if (!level.mesh) throw IO_error(path_, "level " + std::to_string(index) + " has no mesh");
    const Textured_mesh& tm = *level.mesh;
    const Surface_mesh& m = tm.mesh();
    if (m.number_of_faces() == 0) throw IO_error(path_, "refusing to write a mesh without faces");
    for (Face_index f : m.faces())
      if (m.degree(f) != 3) throw IO_error(path_, "glTF output needs a triangle mesh");

    // materials of this level, shared with earlier levels when identical
    // (a texture needs texture coordinates: without them materials keep their colour only)
    std::vector<int> material_of(tm.materials().size(), -1);
    for (std::size_t i = 0; i < tm.materials().size(); ++i) material_of[i] = material(tm.materials()[i], tm.has_uvs());

    const std::vector<std::array<double, 3>> normals =
        options_.normals ? vertex_normals(m) : std::vector<std::array<double, 3>>();

    // uniform quantisation grid of the level (KHR_mesh_quantization), undone by the node transform
    std::array<double, 3> lo = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                                std::numeric_limits<double>::max()};
    std::array<double, 3> hi = {-lo[0], -lo[1], -lo[2]};
    for (Vertex_index v : m.vertices()) {
      const Point_3& p = m.point(v);
      for (int k = 0; k < 3; ++k) {
        lo[std::size_t(k)] = std::min(lo[std::size_t(k)], p[k]);
        hi[std::size_t(k)] = std::max(hi[std::size_t(k)], p[k]);
      }
    }
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    const double step = extent > 0 ? extent / 65535.0 : 1.0;

    // faces by material, in face order
    const std::size_t nmat = std::max<std::size_t>(tm.materials().size(), 1);
    std::vector<std::vector<Face_index>> by_material(nmat);
    for (Face_index f : m.faces()) {
      int k = tm.materials().empty() ? 0 : tm.material(f);
      if (k < 0 || std::size_t(k) >= nmat) k = 0;
      by_material[std::size_t(k)].push_back(f);
    }

    tinygltf::Mesh gmesh;
    gmesh.name = level.name;
    for (std::size_t k = 0; k < nmat; ++k) {
      if (by_material[k].empty()) continue;
      tinygltf::Primitive prim;
      prim.mode = TINYGLTF_MODE_TRIANGLES;
      prim.material = tm.materials().empty() ? -1 : material_of[k];
      // a normal map needs a tangent space; without TANGENT viewers derive one of their own
      const bool tangents = !normals.empty() && tm.has_uvs() && prim.material >= 0 &&
                            model_.materials[std::size_t(prim.material)].normalTexture.index >= 0;
      add_primitive(tm, by_material[k], normals, tangents, lo, step, prim);
      gmesh.primitives.push_back(std::move(prim));
    }
    model_.meshes.push_back(std::move(gmesh));

    tinygltf::Node node;
    node.name = level.name;
    node.mesh = int(model_.meshes.size() - 1);
    if (options_.quantize) {
      node.translation = {lo[0], lo[1], lo[2]};
      node.scale = {step, step, step};
    }
    tinygltf::Value::Object extras;
    extras["level"] = tinygltf::Value(int(index));
    extras["faces"] = tinygltf::Value(int(m.number_of_faces()));
    if (level.error >= 0) extras["error"] = tinygltf::Value(level.error);
    if (level.ratio >= 0) extras["ratio"] = tinygltf::Value(level.ratio);
    node.extras = tinygltf::Value(std::move(extras));
    model_.nodes.push_back(std::move(node));
  }

  void finish(Atomic_output& out) {
    const std::size_t levels = model_.nodes.size();
    if (levels > 1) {
      tinygltf::Value::Array ids;
      for (std::size_t i = 1; i < levels; ++i) ids.emplace_back(int(i));
      tinygltf::Value::Object lod;
      lod["ids"] = tinygltf::Value(std::move(ids));
      model_.nodes[0].extensions["MSFT_lod"] = tinygltf::Value(std::move(lod));
      model_.extensionsUsed.push_back("MSFT_lod");
    }
    if (options_.quantize) {
      model_.extensionsUsed.push_back("KHR_mesh_quantization");
      model_.extensionsRequired.push_back("KHR_mesh_quantization");
    }
    tinygltf::Scene scene;
    scene.nodes = {0};  // the finest level; the coarser ones are reached through MSFT_lod
    model_.scenes.push_back(scene);
    model_.defaultScene = 0;

    const bool binary = extension(path_) == ".glb";
    const fs::path dir = fs::path(path_).parent_path();
    const std::string stem = fs::path(path_).stem().string();
    // images: embedded in the buffer (GLB) or files beside the .gltf
    if (binary) {
      std::size_t image_bytes = 0;
      for (const Encoded_image& e : images_) image_bytes += e.bytes.size() + 4;
      buffer_.reserve_more(image_bytes);
    }
    for (std::size_t i = 0; i < images_.size(); ++i) {
      tinygltf::Image& img = model_.images[i];
      if (binary) {
        img.bufferView = buffer_.add_view(images_[i].bytes, 0, 0);
        img.mimeType = images_[i].mime_type;
      } else {
        const std::string name =
            stem + "_" + std::to_string(i) + (images_[i].mime_type == "image/png" ? ".png" : ".jpg");
        write_file((dir / name).string(), std::string(images_[i].bytes.begin(), images_[i].bytes.end()), out);
        img.uri = uri_of_file_name(name);
      }
    }
    const std::vector<unsigned char>& data = buffer_.data();
    const std::size_t bytes = data.size();
    const std::string bin_name = stem + ".bin";
    if (!binary) write_file((dir / bin_name).string(), std::string(data.begin(), data.end()), out);
    // tinygltf writes the JSON; the buffer it would embed (as base64 in a .gltf written to a
    // stream, as a copy of it in a GLB) stands in as one byte, and the JSON's buffer entry is
    // replaced: a .bin file beside the .gltf, or the GLB's binary chunk, written below from the
    // buffer itself
    tinygltf::Buffer stand_in;
    stand_in.data.assign(1, 0);
    model_.buffers.push_back(std::move(stand_in));
    tinygltf::TinyGLTF writer;
    std::ostringstream s;
    if (!writer.WriteGltfSceneToStream(&model_, s, !binary, false)) throw IO_error(path_, "glTF serialisation failed");
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(s.str());
    nlohmann::ordered_json entry{{"byteLength", bytes}};
    if (!binary) entry["uri"] = uri_of_file_name(bin_name);
    j["buffers"] = nlohmann::ordered_json::array({entry});
    if (!binary) {
      write_file(path_, j.dump(2) + "\n", out);
      return;
    }
    // GLB 2.0: a 12-byte header, the JSON chunk (padded with spaces) and the binary chunk (padded
    // with zeros), each chunk's length a multiple of 4
    std::string json = j.dump();
    while (json.size() % 4) json.push_back(' ');
    const std::size_t padded = (bytes + 3) / 4 * 4;
    const std::size_t total = 12 + 8 + json.size() + 8 + padded;
    if (total > 0xffffffffu) throw IO_error(path_, "the GLB would be larger than 4 GB, more than the format holds");
    auto u32 = [](std::string& o, std::uint32_t v) {
      for (int k = 0; k < 4; ++k) o.push_back(char((v >> (8 * k)) & 0xffu));
    };
    std::string head;
    head.append("glTF", 4);
    u32(head, 2);
    u32(head, std::uint32_t(total));
    u32(head, std::uint32_t(json.size()));
    head.append("JSON", 4);
    std::string bin_head;
    u32(bin_head, std::uint32_t(padded));
    bin_head.append("BIN\0", 4);
    const std::string tmp = out.add(path_);
    std::ofstream os(tmp, std::ios::binary);
    if (!os) throw IO_error(path_, std::string("cannot write: ") + std::strerror(errno));
    os.write(head.data(), std::streamsize(head.size()));
    os.write(json.data(), std::streamsize(json.size()));
    os.write(bin_head.data(), std::streamsize(bin_head.size()));
    os.write(reinterpret_cast<const char*>(data.data()), std::streamsize(bytes));
    const char zeros[4] = {0, 0, 0, 0};
    os.write(zeros, std::streamsize(padded - bytes));
    os.flush();
    if (!os) throw IO_error(path_, "write failed (disk full?)");
  }

private:
  // The index of the glTF image of a texture (-1 when the material has none).
  int texture(const Material& mat, bool diffuse) {
    Encoded_image e = encode_(mat, diffuse);
    if (e.bytes.empty()) return -1;
    if (e.mime_type.empty()) e.mime_type = image_mime_type(e.bytes);
    if (e.mime_type != "image/png" && e.mime_type != "image/jpeg")
      throw IO_error(path_, "texture of material '" + mat.name + "' is neither PNG nor JPEG (glTF allows only those)");
    if (e.mime_type == "image/png") drop_colour_space_chunks(e.bytes);
    // (the levels of a chain that share one atlas hand the same bytes: one image; comparing sizes
    // first, then the bytes, costs less than hashing them)
    for (std::size_t i = 0; i < images_.size(); ++i)
      if (images_[i].bytes == e.bytes) return int(i);
    images_.push_back(std::move(e));
    model_.images.emplace_back();
    if (model_.samplers.empty()) {
      tinygltf::Sampler sampler;
      sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
      sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
      sampler.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;
      sampler.wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT;
      model_.samplers.push_back(sampler);
    }
    tinygltf::Texture t;
    t.sampler = 0;
    t.source = int(images_.size() - 1);
    model_.textures.push_back(t);
    return int(model_.textures.size() - 1);
  }

  // The index of a glTF material equal to `mat` (one is added when none is yet).
  int material(const Material& mat, bool textured) {
    const int diffuse = textured ? texture(mat, true) : -1;
    const int normal = textured ? texture(mat, false) : -1;
    tinygltf::Material g;
    g.name = mat.name;
    g.pbrMetallicRoughness.baseColorFactor = {mat.diffuse_color[0], mat.diffuse_color[1], mat.diffuse_color[2], 1.0};
    g.pbrMetallicRoughness.metallicFactor = 0.0;  // OBJ/MTL diffuse colours describe dielectrics
    g.pbrMetallicRoughness.roughnessFactor = 1.0;
    g.pbrMetallicRoughness.baseColorTexture.index = diffuse;
    g.normalTexture.index = normal;
    for (std::size_t i = 0; i < model_.materials.size(); ++i)
      if (model_.materials[i] == g) return int(i);
    model_.materials.push_back(std::move(g));
    return int(model_.materials.size() - 1);
  }

  int add_accessor(int view, int component, int type, std::size_t count, bool normalized, std::vector<double> min = {},
                   std::vector<double> max = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.normalized = normalized;
    a.minValues = std::move(min);
    a.maxValues = std::move(max);
    model_.accessors.push_back(std::move(a));
    return int(model_.accessors.size() - 1);
  }

  void add_primitive(const Textured_mesh& tm, const std::vector<Face_index>& faces,
                     const std::vector<std::array<double, 3>>& normals, bool tangents, const std::array<double, 3>& lo,
                     double step, tinygltf::Primitive& prim) {
    const Surface_mesh& m = tm.mesh();
    const bool uvs = tm.has_uvs();
    // the glTF vertices: a mesh vertex once per texture coordinate its corners have (seams split
    // it), numbered in the order of first use; the glTF vertices of one mesh vertex make a list
    std::vector<std::uint32_t> first(m.num_vertices(), no_vertex);  // by mesh vertex
    std::vector<std::uint32_t> other;                               // the list's next, by glTF vertex
    std::vector<Halfedge_index> corner;                             // a corner of every glTF vertex
    std::vector<std::uint32_t> indices;
    indices.reserve(faces.size() * 3);
    for (Face_index f : faces) {
      for (Halfedge_index h : CGAL::halfedges_around_face(m.halfedge(f), m)) {
        const std::size_t v = std::size_t(m.target(h));
        std::uint32_t id = first[v];
        if (uvs) {
          const Point_2 t = tm.uv(h);
          while (id != no_vertex) {
            const Point_2 s = tm.uv(corner[id]);
            if (bits(s.x()) == bits(t.x()) && bits(s.y()) == bits(t.y())) break;
            id = other[id];
          }
        }
        if (id == no_vertex) {
          id = std::uint32_t(corner.size());
          corner.push_back(h);
          other.push_back(first[v]);
          first[v] = id;
        }
        indices.push_back(id);
      }
    }
    const std::size_t n = corner.size();

    // POSITION
    {
      std::vector<double> mn(3, std::numeric_limits<double>::max()), mx(3, -std::numeric_limits<double>::max());
      if (options_.quantize) {
        std::vector<std::uint16_t> q;
        q.reserve(n * 4);
        for (Halfedge_index h : corner) {
          const Point_3& p = m.point(m.target(h));
          for (int k = 0; k < 3; ++k) {
            const double x = std::min(65535.0, std::max(0.0, std::round((p[k] - lo[std::size_t(k)]) / step)));
            q.push_back(std::uint16_t(x));
            mn[std::size_t(k)] = std::min(mn[std::size_t(k)], x);
            mx[std::size_t(k)] = std::max(mx[std::size_t(k)], x);
          }
          q.push_back(0);  // vertex attributes are 4-byte aligned
        }
        prim.attributes["POSITION"] =
            add_accessor(buffer_.add_view(q, TINYGLTF_TARGET_ARRAY_BUFFER, 8), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                         TINYGLTF_TYPE_VEC3, n, false, mn, mx);
      } else {
        std::vector<float> x;
        x.reserve(n * 3);
        for (Halfedge_index h : corner) {
          const Point_3& p = m.point(m.target(h));
          for (int k = 0; k < 3; ++k) {
            const float c = float(p[k]);
            x.push_back(c);
            mn[std::size_t(k)] = std::min(mn[std::size_t(k)], double(c));
            mx[std::size_t(k)] = std::max(mx[std::size_t(k)], double(c));
          }
        }
        prim.attributes["POSITION"] = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 12),
                                                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, false, mn, mx);
      }
    }
    // NORMAL
    if (!normals.empty()) {
      if (options_.quantize) {
        std::vector<std::int8_t> x;
        x.reserve(n * 4);
        for (Halfedge_index h : corner) {
          const auto& nv = normals[std::size_t(m.target(h))];
          for (int k = 0; k < 3; ++k) x.push_back(std::int8_t(std::lround(nv[std::size_t(k)] * 127.0)));
          x.push_back(0);
        }
        prim.attributes["NORMAL"] = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 4),
                                                 TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_TYPE_VEC3, n, true);
      } else {
        std::vector<float> x;
        x.reserve(n * 3);
        for (Halfedge_index h : corner) {
          const auto& nv = normals[std::size_t(m.target(h))];
          for (int k = 0; k < 3; ++k) x.push_back(float(nv[std::size_t(k)]));
        }
        prim.attributes["NORMAL"] = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 12),
                                                 TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, false);
      }
    }
    // TANGENT (xyz, handedness w)
    if (tangents) {
      const std::vector<std::array<double, 4>> t = vertex_tangents(tm, corner, indices, normals);
      if (options_.quantize) {
        std::vector<std::int8_t> x;
        x.reserve(n * 4);
        for (const auto& tv : t)
          for (int k = 0; k < 4; ++k) x.push_back(std::int8_t(std::lround(tv[std::size_t(k)] * 127.0)));
        prim.attributes["TANGENT"] = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 4),
                                                  TINYGLTF_COMPONENT_TYPE_BYTE, TINYGLTF_TYPE_VEC4, n, true);
      } else {
        std::vector<float> x;
        x.reserve(n * 4);
        for (const auto& tv : t)
          for (int k = 0; k < 4; ++k) x.push_back(float(tv[std::size_t(k)]));
        prim.attributes["TANGENT"] = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 16),
                                                  TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, n, false);
      }
    }
    // TEXCOORD_0 (glTF's v points down: v_gltf = 1 - v)
    if (uvs) {
      bool unit = options_.quantize;
      for (Halfedge_index h : corner) {
        const Point_2 t = tm.uv(h);
        unit = unit && t.x() >= 0 && t.x() <= 1 && t.y() >= 0 && t.y() <= 1;
      }
      if (unit) {
        std::vector<std::uint16_t> x;
        x.reserve(n * 2);
        for (Halfedge_index h : corner) {
          const Point_2 t = tm.uv(h);
          x.push_back(std::uint16_t(std::lround(t.x() * 65535.0)));
          x.push_back(std::uint16_t(std::lround((1.0 - t.y()) * 65535.0)));
        }
        prim.attributes["TEXCOORD_0"] =
            add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 4), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                         TINYGLTF_TYPE_VEC2, n, true);
      } else {
        std::vector<float> x;
        x.reserve(n * 2);
        for (Halfedge_index h : corner) {
          const Point_2 t = tm.uv(h);
          x.push_back(float(t.x()));
          x.push_back(float(1.0 - t.y()));
        }
        prim.attributes["TEXCOORD_0"] = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ARRAY_BUFFER, 8),
                                                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n, false);
      }
    }
    // indices: 16 bits while no index reaches 65535 (the primitive-restart value)
    if (n < 65535) {
      const std::vector<std::uint16_t> x(indices.begin(), indices.end());
      prim.indices = add_accessor(buffer_.add_view(x, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0),
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, indices.size(), false);
    } else {
      prim.indices = add_accessor(buffer_.add_view(indices, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, 0),
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size(), false);
    }
  }

  const std::string& path_;
  const Gltf_options& options_;
  const Image_encoder& encode_;
  tinygltf::Model model_;
  Buffer_builder buffer_;
  std::vector<Encoded_image> images_;
};

}  // namespace

void write_gltf(const std::string& path, const std::vector<Gltf_level>& levels, const Gltf_options& options,
                Atomic_output& out, const Image_encoder& encode) {
  const std::string ext = extension(path);
  if (ext != ".gltf" && ext != ".glb") throw IO_error(path, "glTF output must end in .gltf or .glb");
  if (levels.empty()) throw IO_error(path, "nothing to write (no level)");
  Scene_writer writer(path, options, encode);
  // the buffer reserved for the largest the levels' views can be (every corner its own vertex,
  // every attribute as floats, 4-byte indices): grown by doubling instead, the 1M-face input of a
  // chain was copied into ever larger fresh blocks, a tenth of the GLB's time
  std::size_t bound = 0;
  for (const Gltf_level& level : levels)
    if (level.mesh) bound += level.mesh->mesh().number_of_faces() * 3 * (4 + 12 + 12 + 16 + 8) + 64;
  writer.reserve_buffer(bound);
  for (std::size_t i = 0; i < levels.size(); ++i) writer.add_level(levels[i], i);
  writer.finish(out);
}

Encoded_image encode_texture_file(const Material& mat, bool diffuse) {
  Encoded_image e;
  const std::string& file = diffuse ? mat.diffuse_texture : mat.normal_texture;
  if (!file.empty()) {
    const std::string s = slurp(file);
    e.bytes.assign(s.begin(), s.end());
  } else if (diffuse && !mat.diffuse_texture_blob.empty()) {
    e.bytes = mat.diffuse_texture_blob;
  }
  e.mime_type = image_mime_type(e.bytes);
  return e;
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
