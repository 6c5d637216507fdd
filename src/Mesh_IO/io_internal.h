// Internal declarations shared by the Mesh_IO translation units (not installed).
#ifndef CMGEOM_SRC_MESH_IO_IO_INTERNAL_H
#define CMGEOM_SRC_MESH_IO_IO_INTERNAL_H

#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>

#include <charconv>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>

namespace CMGeom {
namespace IO {
namespace internal {

/// Whether the polygons of `soup` (its face_start and corner_vertex; vertex ids below `vertices`,
/// positions unused) form an oriented manifold polygon mesh: no polygon repeats a vertex, every
/// edge has at most two polygons, of opposite directions, and the polygons around every vertex
/// form one fan. The same answer as CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh
/// for such soups, by sorting the edges instead of a std::set (the reader's repair calls it twice
/// on every repaired file). O(C log C) for C corners.
bool is_oriented_manifold_soup(const Polygon_soup& soup, std::size_t vertices);

/// Files of `chunk_bytes` or more are parsed on all cores in chunks of about that size
/// (obj_io.cpp); 0 reads every file line by line. The soup, the errors and the warnings are the
/// same either way (a test compares them on mutated files with tiny chunks).
constexpr std::size_t obj_chunk_bytes = std::size_t(1) << 20;
/// True for a path ending in ".gz" (any case): the mesh readers decompress it (gzip, zlib) and
/// read the rest of the name's extension ("bunny.obj.gz" is an OBJ file); relative references
/// (an OBJ's material library) are resolved beside the .gz file, and errors name it.
bool is_gzipped_path(const std::string& path);
/// The whole decompressed content of a gzip file; IO_error (naming the file) when it is missing,
/// unreadable, or not valid gzip data to its end.
std::string gunzip_file(const std::string& path);

void read_obj(const std::string& path, Polygon_soup& soup, std::size_t chunk_bytes = obj_chunk_bytes);
void read_off(const std::string& path, Polygon_soup& soup);
void read_ply(const std::string& path, Polygon_soup& soup);
/// ASCII or binary STL (stl_io.cpp): equal corners merged into vertices, facet normals not read.
void read_stl(const std::string& path, Polygon_soup& soup);
void read_gltf(const std::string& path, Polygon_soup& soup);

// Called once per material texture that the MTL should reference; returns the file name (relative
// to the OBJ's directory) the texture was registered under in `out`, or "" to omit it.
// kind is "diffuse" or "normal".
using Texture_emitter =
    std::function<std::string(const Material& m, std::size_t index, const std::string& kind, Atomic_output& out)>;

void write_obj(const std::string& path, const Textured_mesh& tm, Atomic_output& out,
               const Texture_emitter& emit_texture);
// An encoded texture image for glTF output: PNG or JPEG bytes (empty: no texture).
struct Encoded_image {
  std::vector<unsigned char> bytes;
  std::string mime_type;  // "image/png" or "image/jpeg"; found from the bytes when empty
};
// Gives the encoded diffuse (diffuse = true) or normal texture of a material.
using Image_encoder = std::function<Encoded_image(const Material& m, bool diffuse)>;
void write_gltf(const std::string& path, const std::vector<Gltf_level>& levels, const Gltf_options& options,
                Atomic_output& out, const Image_encoder& encode);
// The texture file or embedded bytes of a material as they are (no decoding).
Encoded_image encode_texture_file(const Material& m, bool diffuse);
// "image/png" or "image/jpeg" from the first bytes, "" for anything else.
std::string image_mime_type(const std::vector<unsigned char>& bytes);
void write_off(const std::string& path, const Textured_mesh& tm, Atomic_output& out);
void write_ply(const std::string& path, const Textured_mesh& tm, Atomic_output& out);
/// Binary STL: 32-bit float corners, unit facet normals (zero for a degenerate face); triangles only.
void write_stl(const std::string& path, const Textured_mesh& tm, Atomic_output& out);

// Writes `bytes` to `tmp` (a file of an Atomic_output, which stands for `path`); IO_error naming
// `path` when it cannot be opened or written (off_ply_io.cpp).
void write_bytes(const std::string& tmp, const std::string& path, std::string_view bytes);

// A whole token as a number (std::from_chars, so a double reads back bit-exactly); a leading '+',
// which from_chars rejects and writers emit, is skipped. False for an empty token or trailing text.
template <class T>
bool parse_number(std::string_view t, T& out) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

// Shortest decimal text that reads back to the same double.
void append_double(std::string& s, double x);

// Calls f(line_number, begin, end) for every line of `data` (1-based numbers, '\n' excluded).
template <class F>
void for_each_line(std::string_view data, F&& f) {
  std::size_t line_no = 0;
  const char* p = data.data();
  const char* const end = p + data.size();
  while (p < end) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', std::size_t(end - p)));
    if (!nl) nl = end;
    f(++line_no, p, nl);
    p = nl + 1;
  }
}

// Reads a whole file; throws IO_error (missing, unreadable, directory).
std::string slurp(const std::string& path);

// A whole file's bytes, mapped read-only (no copy; the pages are read ahead at once) or, where
// the file cannot be mapped, read as slurp() does; the same errors as slurp().
class File_bytes {
public:
  explicit File_bytes(const std::string& path);
  ~File_bytes();
  File_bytes(const File_bytes&) = delete;
  File_bytes& operator=(const File_bytes&) = delete;
  std::string_view view() const { return map_ ? std::string_view(map_, size_) : std::string_view(copy_); }

private:
  const char* map_ = nullptr;
  std::size_t size_ = 0;
  std::string copy_;
};

// Texture emitter that copies the source file of the texture next to the output.
std::string copy_texture_file(const std::string& obj_path, const std::string& source, const std::string& suggested_name,
                              Atomic_output& out);

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom

#endif
