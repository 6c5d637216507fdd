// STL geometry: a reader of ASCII and binary STL (own reader, as for OFF and PLY: errors carry the
// line of an ASCII file or the triangle of a binary one) and a binary STL writer.
//
// STL stores every triangle with its own three corners; the reader merges corners whose
// coordinates are equal (bit for bit, after -0 becomes 0) into one vertex, numbered in order of
// first use, so that the result is a mesh and not a soup. Corners that are nearly but not exactly
// equal stay apart (the mesh then shows boundary edges or non-manifold spots where the file has
// cracks: build_textured_mesh() reports them). The facet normals are not read: a face's
// orientation is the order of its corners (counter-clockwise seen from outside, as the format
// says), which every writer follows while normals are often left zero.
#include "io_internal.h"

#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace CMGeom {
namespace IO {
namespace internal {

namespace {

constexpr std::size_t binary_header_bytes = 80, binary_triangle_bytes = 50;

// Merges equal corners into vertices (see the file comment): an open-addressing table of vertex
// ids, probed linearly, a corner compared with the positions already stored (4 bytes a slot, at
// most half full; std::unordered_map took twice the time of the rest of reading a 1M-face file).
class Corner_welder {
public:
  Corner_welder(Polygon_soup& soup, std::size_t expected_vertices) : soup_(soup) {
    std::size_t capacity = 64;
    while (capacity < 2 * expected_vertices) capacity *= 2;
    slots_.assign(capacity, empty);
  }
  std::uint32_t vertex(double x, double y, double z) {
    // (-0 and 0 are one place)
    const std::array<double, 3> p = {{x == 0 ? 0.0 : x, y == 0 ? 0.0 : y, z == 0 ? 0.0 : z}};
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(p) & mask;; i = (i + 1) & mask) {
      const std::uint32_t v = slots_[i];
      if (v == empty) {
        const std::uint32_t id = std::uint32_t(soup_.positions.size());
        slots_[i] = id;
        soup_.positions.push_back(p);
        if (2 * soup_.positions.size() > slots_.size()) grow();
        return id;
      }
      if (std::memcmp(soup_.positions[v].data(), p.data(), sizeof p) == 0) return v;
    }
  }

private:
  static constexpr std::uint32_t empty = 0xffffffffu;
  static std::size_t hash(const std::array<double, 3>& p) {
    std::uint64_t bits[3];
    std::memcpy(bits, p.data(), sizeof bits);
    std::uint64_t h = 0x9e3779b97f4a7c15ull;
    for (std::uint64_t b : bits) {
      h = (h ^ b) * 0xff51afd7ed558ccdull;
      h ^= h >> 32;
    }
    return std::size_t(h);
  }
  void grow() {
    std::vector<std::uint32_t> slots(2 * slots_.size(), empty);
    const std::size_t mask = slots.size() - 1;
    for (std::uint32_t v = 0; v < soup_.positions.size(); ++v) {
      std::size_t i = hash(soup_.positions[v]) & mask;
      while (slots[i] != empty) i = (i + 1) & mask;
      slots[i] = v;
    }
    slots_.swap(slots);
  }
  Polygon_soup& soup_;
  std::vector<std::uint32_t> slots_;
};

void end_face(Polygon_soup& soup, std::size_t line) {
  soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
  soup.face_line.push_back(line);
}

bool equal_no_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// The whitespace-separated words of an ASCII STL text, with their line numbers.
class Stl_words {
public:
  Stl_words(std::string_view data, const std::string& path) : p_(data.data()), end_(p_ + data.size()), path_(path) {}

  // The next word into `w` and its line into `line`; false at the end of the text.
  bool next(std::string_view& w, std::size_t& line) {
    while (p_ < end_ && is_space(*p_)) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
    if (p_ >= end_) return false;
    const char* b = p_;
    while (p_ < end_ && !is_space(*p_)) {
      if (*p_ == '\0') throw IO_error(path_, line_, "binary data (NUL byte) in an ASCII STL file");
      ++p_;
    }
    w = std::string_view(b, std::size_t(p_ - b));
    line = line_;
    return true;
  }
  // Skips the rest of the current line (a solid's name).
  void skip_line() {
    while (p_ < end_ && *p_ != '\n') ++p_;
  }

private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
  const char* p_;
  const char* const end_;
  std::size_t line_ = 1;
  const std::string& path_;
};

std::string quoted(std::string_view w) { return "'" + std::string(w.substr(0, 40)) + "'"; }

void read_ascii_stl(std::string_view data, const std::string& path, Polygon_soup& soup) {
  Stl_words words(data, path);
  Corner_welder weld(soup, data.size() / 1000);  // (a facet takes 200-300 bytes, a vertex has about six)
  std::string_view w;
  std::size_t line = 0;
  // expects the keyword `k` next (case-insensitive), after `what`
  auto expect = [&](std::string_view k, const char* what) {
    if (!words.next(w, line)) throw IO_error(path, std::string("truncated: expected '") + std::string(k) + "' " + what);
    if (!equal_no_case(w, k))
      throw IO_error(path, line, std::string("expected '") + std::string(k) + "' " + what + ", found " + quoted(w));
  };
  auto coordinate = [&](const char* what) {
    double x;
    if (!words.next(w, line)) throw IO_error(path, std::string("truncated: expected ") + what);
    if (!parse_number(w, x)) throw IO_error(path, line, std::string("bad ") + what + " " + quoted(w));
    return x;
  };
  bool in_solid = false, any_solid = false;
  while (words.next(w, line)) {
    if (!in_solid) {
      if (!equal_no_case(w, "solid"))
        throw IO_error(path, line, "expected 'solid' or the end of the file, found " + quoted(w));
      words.skip_line();
      in_solid = any_solid = true;
      continue;
    }
    if (equal_no_case(w, "endsolid")) {
      words.skip_line();
      in_solid = false;
      continue;
    }
    if (!equal_no_case(w, "facet")) throw IO_error(path, line, "expected 'facet' or 'endsolid', found " + quoted(w));
    const std::size_t facet_line = line;
    expect("normal", "after 'facet'");
    // the normal's three words, not read (see the file comment; old writers print a NaN as "-1.#IND00")
    for (int k = 0; k < 3; ++k)
      if (!words.next(w, line)) throw IO_error(path, "truncated: expected the facet normal's components");
    expect("outer", "after the facet normal");
    expect("loop", "after 'outer'");
    std::size_t corners = 0;
    for (;;) {
      if (!words.next(w, line)) throw IO_error(path, "truncated: facet without 'endloop'");
      if (equal_no_case(w, "endloop")) break;
      if (!equal_no_case(w, "vertex")) throw IO_error(path, line, "expected 'vertex' or 'endloop', found " + quoted(w));
      std::array<double, 3> p;
      for (int k = 0; k < 3; ++k) p[std::size_t(k)] = coordinate("vertex coordinate");
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
        throw IO_error(path, line, "vertex coordinate is not finite");
      soup.corner_vertex.push_back(weld.vertex(p[0], p[1], p[2]));
      ++corners;
    }
    if (corners < 3)
      throw IO_error(path, facet_line, "facet with " + std::to_string(corners) + " vertices (at least 3 needed)");
    expect("endfacet", "after 'endloop'");
    end_face(soup, facet_line);
  }
  if (!any_solid) throw IO_error(path, "no content");
  if (in_solid) soup.warnings.push_back(path + ": no 'endsolid' at the end");
}

float little_endian_float(const char* p) {
  float f;
  std::memcpy(&f, p, 4);  // x86-64 and aarch64 are little-endian, as the format
  return f;
}

void read_binary_stl(std::string_view data, const std::string& path, std::size_t triangles, Polygon_soup& soup) {
  Corner_welder weld(soup, triangles / 2);  // (a closed mesh's vertices; the table grows past it)
  soup.corner_vertex.reserve(3 * triangles);
  soup.face_start.reserve(triangles + 1);
  soup.face_line.reserve(triangles);
  const char* p = data.data() + binary_header_bytes + 4;
  for (std::size_t t = 0; t < triangles; ++t, p += binary_triangle_bytes) {
    for (int k = 0; k < 3; ++k) {
      const char* c = p + 12 + 12 * k;  // (the normal first)
      const double x = little_endian_float(c), y = little_endian_float(c + 4), z = little_endian_float(c + 8);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        throw IO_error(path, "triangle " + std::to_string(t) + ": vertex coordinate is not finite");
      soup.corner_vertex.push_back(weld.vertex(x, y, z));
    }
    end_face(soup, 0);
  }
}

// Whether the first bytes of `data` read as text (an ASCII STL that happens to have the size a
// binary header would give it).
bool looks_like_text(std::string_view data) {
  const std::size_t n = (std::min)(data.size(), std::size_t(1024));
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(data[i]);
    if (c < 9 || (c > 13 && c < 32) || c == 127) return false;
  }
  return true;
}

}  // namespace

void read_stl(const std::string& path, Polygon_soup& soup) {
  const File_bytes bytes(path);
  const std::string_view data = bytes.view();
  if (data.empty()) throw IO_error(path, "empty file");
  soup = Polygon_soup();
  soup.source = path;
  std::size_t first = 0;
  while (first < data.size() && std::isspace(static_cast<unsigned char>(data[first]))) ++first;
  const bool says_solid = data.size() - first >= 5 && equal_no_case(data.substr(first, 5), "solid");
  const bool text = says_solid && looks_like_text(data);
  bool binary = false;
  std::uint32_t triangles = 0;
  if (data.size() >= binary_header_bytes + 4) {
    std::memcpy(&triangles, data.data() + binary_header_bytes, 4);
    const std::size_t sized = binary_header_bytes + 4 + binary_triangle_bytes * std::size_t(triangles);
    // (binary files may begin with "solid" too: their size and their bytes tell them apart)
    // (some exporters pad a binary file past its last triangle: the bytes after it are left, with a warning)
    binary = data.size() >= sized && !text;
    if (binary && data.size() > sized)
      soup.warnings.push_back(path + ": " + std::to_string(data.size() - sized) + " bytes after the " +
                              std::to_string(triangles) + " triangles the binary header declares, not read");
    if (!binary && !text)
      throw IO_error(path,
                     "neither an ASCII STL file (text beginning with 'solid') nor a binary one (its header "
                     "declares " +
                         std::to_string(triangles) + " triangles, " + std::to_string(sized) + " bytes; the file has " +
                         std::to_string(data.size()) + ")");
  } else if (!says_solid) {
    throw IO_error(path, "neither an ASCII STL file (text beginning with 'solid') nor a binary one (" +
                             std::to_string(data.size()) + " bytes, shorter than the 84-byte header)");
  }
  try {
    if (binary)
      read_binary_stl(data, path, triangles, soup);
    else
      read_ascii_stl(data, path, soup);
  } catch (const std::bad_alloc&) {
    throw IO_error(path, "more triangles than can be allocated");
  }
  if (soup.number_of_faces() == 0) throw IO_error(path, "no faces in file");
  soup.corner_uv.assign(soup.corner_vertex.size(), Polygon_soup::no_index);
  soup.face_material.assign(soup.number_of_faces(), 0);
}

void write_stl(const std::string& path, const Textured_mesh& tm, Atomic_output& out) {
  const Surface_mesh& m = tm.mesh();
  if (m.number_of_faces() > 0xffffffffull)
    throw IO_error(path, "more than 2^32 - 1 faces: binary STL cannot count them");
  std::string s(binary_header_bytes, ' ');
  const std::string title = "binary STL written by CMGeom " CMGEOM_VERSION_STR;  // (not "solid ...": see read_stl)
  s.replace(0, (std::min)(title.size(), binary_header_bytes), title, 0, binary_header_bytes);
  const std::uint32_t n = std::uint32_t(m.number_of_faces());
  s.append(reinterpret_cast<const char*>(&n), 4);
  s.reserve(s.size() + binary_triangle_bytes * std::size_t(n));
  for (auto f : m.faces()) {
    if (m.degree(f) != 3)
      throw IO_error(path, "face " + std::to_string(std::size_t(f)) + " has " + std::to_string(m.degree(f)) +
                               " corners: STL stores triangles only");
    std::array<Point_3, 3> p;
    int k = 0;
    for (auto v : m.vertices_around_face(m.halfedge(f))) p[std::size_t(k++)] = m.point(v);
    Vector_3 normal = CGAL::cross_product(p[1] - p[0], p[2] - p[0]);
    const double length = std::sqrt(normal.squared_length());
    normal = length > 0 && std::isfinite(length) ? normal / length : Vector_3(0, 0, 0);
    float record[12] = {float(normal.x()), float(normal.y()), float(normal.z())};
    for (std::size_t c = 0; c < 3; ++c)
      for (int d = 0; d < 3; ++d) record[3 + 3 * c + std::size_t(d)] = float(p[c][d]);
    s.append(reinterpret_cast<const char*>(record), sizeof record);
    s.append(2, '\0');  // (attribute byte count)
  }
  write_bytes(out.add(path), path, s);
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
