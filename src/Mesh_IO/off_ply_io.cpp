// OFF and PLY geometry (own readers: errors carry line numbers where the format has lines; PLY
// in ASCII and both binary byte orders, faces and triangle strips, `element tristrips` as
// MeshLab's samples store them), and their writers.
#include "io_internal.h"

#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <new>
#include <sstream>
#include <tuple>
#include <utility>

namespace CMGeom {
namespace IO {
namespace internal {

namespace {

// The non-empty, comment-free lines of an OFF text as tokens, one line at a time (no line is
// stored: a 1M-face file held every line's tokens at once, 180 MB).
class Off_lines {
public:
  Off_lines(std::string_view data, const std::string& path) : p_(data.data()), end_(p_ + data.size()), path_(path) {}

  // The next line with a token: its tokens into `tok` (cleared first) and its number into `line`;
  // false at the end of the text.
  bool next(std::vector<std::string_view>& tok, std::size_t& line) {
    while (p_ < end_) {
      const char* nl = static_cast<const char*>(std::memchr(p_, '\n', std::size_t(end_ - p_)));
      if (!nl) nl = end_;
      ++line_;
      tok.clear();
      const char* q = p_;
      p_ = nl + (nl < end_ ? 1 : 0);
      while (q < nl) {
        while (q < nl && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
        if (q >= nl || *q == '#') break;
        if (*q == '\0') throw IO_error(path_, line_, "binary data (NUL byte) in a text OFF file");
        const char* b = q;
        while (q < nl && *q != ' ' && *q != '\t' && *q != '\r' && *q != '#') ++q;
        tok.emplace_back(b, std::size_t(q - b));
        if (q < nl && *q == '#') break;
      }
      if (!tok.empty()) {
        line = line_;
        return true;
      }
    }
    return false;
  }

private:
  const char* p_;
  const char* const end_;
  std::size_t line_ = 0;
  const std::string& path_;
};

}  // namespace

void read_off(const std::string& path, Polygon_soup& soup) {
  const File_bytes bytes(path);
  const std::string_view data = bytes.view();
  if (data.empty()) throw IO_error(path, "empty file");
  soup = Polygon_soup();
  soup.source = path;
  Off_lines lines(data, path);
  std::vector<std::string_view> tok;
  std::size_t line = 0;
  if (!lines.next(tok, line)) throw IO_error(path, "no content");
  const std::string_view head = tok[0];
  bool has_uv = false, counts_here = true;  // (whether `tok` holds the counts)
  if (head.size() >= 3 && head.substr(head.size() - 3) == "OFF") {
    if (tok.size() > 1 && tok[1] == "BINARY") throw IO_error(path, line, "binary OFF is not supported");
    if (head.find("4") != std::string_view::npos || head.find("n") != std::string_view::npos)
      throw IO_error(path, line, "only 3D OFF files are supported ('" + std::string(head) + "')");
    has_uv = head.find("ST") != std::string_view::npos;
    if (tok.size() >= 4)  // counts on the header line
      tok.erase(tok.begin());
    else
      counts_here = false;
  }
  if (!counts_here && !lines.next(tok, line)) throw IO_error(path, "truncated: missing vertex/face counts");
  long long nv = -1, nf = -1;
  if (tok.size() < 2 || !parse_number(tok[0], nv) || !parse_number(tok[1], nf) || nv < 0 || nf < 0)
    throw IO_error(path, line, "expected '<#vertices> <#faces> [<#edges>]'");
  // A declared count larger than the file could hold is corrupt (and must not allocate).
  if (std::size_t(nv) + std::size_t(nf) > data.size())
    throw IO_error(path, line,
                   "declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                       " faces, more than the file can hold");
  soup.positions.reserve(std::size_t(nv));
  if (has_uv) soup.uvs.reserve(std::size_t(nv));
  soup.face_start.reserve(std::size_t(nf) + 1);
  soup.face_line.reserve(std::size_t(nf));
  soup.corner_vertex.reserve(3 * std::size_t(nf));
  soup.corner_uv.reserve(3 * std::size_t(nf));
  soup.face_material.reserve(std::size_t(nf));
  for (long long i = 0; i < nv; ++i) {
    if (!lines.next(tok, line))
      throw IO_error(path, "truncated: " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    std::array<double, 3> x;
    if (tok.size() < 3) throw IO_error(path, line, "vertex needs three coordinates");
    for (int k = 0; k < 3; ++k) {
      if (!parse_number(tok[std::size_t(k)], x[std::size_t(k)]))
        throw IO_error(path, line, "bad vertex coordinate '" + std::string(tok[std::size_t(k)]) + "'");
      if (!std::isfinite(x[std::size_t(k)])) throw IO_error(path, line, "vertex coordinate is not finite");
    }
    soup.positions.push_back(x);
    if (has_uv) {
      std::array<double, 2> t;
      if (tok.size() < 5 || !parse_number(tok[3], t[0]) || !parse_number(tok[4], t[1]) || !std::isfinite(t[0]) ||
          !std::isfinite(t[1]))
        throw IO_error(path, line, "STOFF vertex needs two finite texture coordinates");
      soup.uvs.push_back(t);
    }
  }
  for (long long f = 0; f < nf; ++f) {
    if (!lines.next(tok, line))
      throw IO_error(path, "truncated: " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    long long n;
    if (!parse_number(tok[0], n) || n < 3 || std::size_t(n) + 1 > tok.size())
      throw IO_error(path, line, "face needs a corner count >= 3 followed by that many indices");
    const std::size_t first = soup.corner_vertex.size();
    for (long long k = 0; k < n; ++k) {
      long long idx;
      if (!parse_number(tok[std::size_t(k + 1)], idx))
        throw IO_error(path, line, "bad vertex index '" + std::string(tok[std::size_t(k + 1)]) + "'");
      if (idx < 0 || idx >= nv)
        throw IO_error(path, line,
                       "vertex index " + std::to_string(idx) + " out of range (" + std::to_string(nv) + " vertices)");
      soup.corner_vertex.push_back(std::uint32_t(idx));
    }
    for (std::size_t c = first; c < soup.corner_vertex.size(); ++c)
      soup.corner_uv.push_back(has_uv ? soup.corner_vertex[c] : Polygon_soup::no_index);
    soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
    soup.face_material.push_back(0);
    soup.face_line.push_back(line);
  }
  if (soup.number_of_faces() == 0) throw IO_error(path, "no faces in file");
}

namespace {

// PLY scalar types (both spellings of the specification).
enum class Ply_type : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };

bool ply_type(std::string_view t, Ply_type& out) {
  static const std::pair<const char*, Ply_type> names[] = {
      {"char", Ply_type::i8},   {"uchar", Ply_type::u8},   {"short", Ply_type::i16},   {"ushort", Ply_type::u16},
      {"int", Ply_type::i32},   {"uint", Ply_type::u32},   {"float", Ply_type::f32},   {"double", Ply_type::f64},
      {"int8", Ply_type::i8},   {"uint8", Ply_type::u8},   {"int16", Ply_type::i16},   {"uint16", Ply_type::u16},
      {"int32", Ply_type::i32}, {"uint32", Ply_type::u32}, {"float32", Ply_type::f32}, {"float64", Ply_type::f64}};
  for (const auto& [name, type] : names)
    if (t == name) {
      out = type;
      return true;
    }
  return false;
}

std::size_t ply_size(Ply_type t) {
  switch (t) {
    case Ply_type::i8:
    case Ply_type::u8:
      return 1;
    case Ply_type::i16:
    case Ply_type::u16:
      return 2;
    case Ply_type::i32:
    case Ply_type::u32:
    case Ply_type::f32:
      return 4;
    case Ply_type::f64:
      return 8;
  }
  return 0;
}

bool ply_integral(Ply_type t) { return t != Ply_type::f32 && t != Ply_type::f64; }

struct Ply_property {
  std::string name;
  bool list = false;
  Ply_type count = Ply_type::u8;  // (lists)
  Ply_type type = Ply_type::f32;  // the value's, or the list items'
};

struct Ply_element {
  std::string name;
  unsigned long long count = 0;
  std::vector<Ply_property> properties;
};

struct Ply_header {
  enum class Format { ascii, binary_little_endian, binary_big_endian } format = Format::ascii;
  std::vector<Ply_element> elements;
  std::size_t body = 0;       // offset of the body's first byte
  std::size_t body_line = 0;  // its line (ASCII)
};

// The header of a PLY file, checked with line numbers (a property before any element, a count
// larger than the file can hold, a missing vertex x, y, z or face list are refused here, before
// anything is allocated for the body).
Ply_header read_ply_header(std::string_view data, const std::string& path) {
  Ply_header hdr;
  std::size_t pos = 0, line_no = 0;
  bool have_format = false, ended = false;
  bool vertex_x = false, vertex_y = false, vertex_z = false, face_list = false;
  unsigned long long vertices = 0, faces = 0;
  while (pos < data.size() && !ended) {
    std::size_t nl = data.find('\n', pos);
    if (nl == std::string_view::npos) nl = data.size();
    std::string_view line = data.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    std::vector<std::string_view> tok;
    for (std::size_t i = 0; i < line.size();) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t b = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > b) tok.push_back(line.substr(b, i - b));
    }
    if (line_no == 1) {
      if (tok.size() != 1 || tok[0] != "ply") throw IO_error(path, 1, "not a PLY file (no 'ply' magic)");
      continue;
    }
    if (tok.empty()) continue;
    if (tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "format") {
      if (tok.size() != 3 || (tok[1] != "ascii" && tok[1] != "binary_little_endian" && tok[1] != "binary_big_endian"))
        throw IO_error(path, line_no, "bad PLY format line");
      have_format = true;
      hdr.format = tok[1] == "ascii"                  ? Ply_header::Format::ascii
                   : tok[1] == "binary_little_endian" ? Ply_header::Format::binary_little_endian
                                                      : Ply_header::Format::binary_big_endian;
    } else if (tok[0] == "element") {
      unsigned long long n;
      if (tok.size() != 3 || !parse_number(tok[2], n)) throw IO_error(path, line_no, "bad PLY element line");
      Ply_element& el = hdr.elements.emplace_back();
      el.name = std::string(tok[1]);
      el.count = n;
      if (el.name == "vertex") vertices = n;
      if (el.name == "face" || el.name == "tristrips") faces += n;
    } else if (tok[0] == "property") {
      if (hdr.elements.empty()) throw IO_error(path, line_no, "PLY property before any element");
      Ply_element& el = hdr.elements.back();
      Ply_property pr;
      if (tok.size() == 5 && tok[1] == "list") {
        if (!ply_type(tok[2], pr.count) || !ply_type(tok[3], pr.type))
          throw IO_error(path, line_no, "bad PLY list property type");
        if (!ply_integral(pr.count)) throw IO_error(path, line_no, "PLY list length type must be an integer type");
        pr.list = true;
        pr.name = std::string(tok[4]);
        if ((el.name == "face" || el.name == "tristrips") && (pr.name == "vertex_indices" || pr.name == "vertex_index"))
          face_list = true;
      } else if (tok.size() == 3 && ply_type(tok[1], pr.type)) {
        pr.name = std::string(tok[2]);
        if (el.name == "vertex") {
          vertex_x |= pr.name == "x";
          vertex_y |= pr.name == "y";
          vertex_z |= pr.name == "z";
        }
      } else {
        throw IO_error(path, line_no, "bad PLY property line");
      }
      el.properties.push_back(std::move(pr));
    } else if (tok[0] == "end_header") {
      ended = true;
    } else {
      throw IO_error(path, line_no, "unknown PLY header keyword '" + std::string(tok[0].substr(0, 40)) + "'");
    }
  }
  if (!ended) throw IO_error(path, "truncated PLY header (no end_header)");
  if (!have_format) throw IO_error(path, "PLY header without a format line");
  if (!vertex_x || !vertex_y || !vertex_z) throw IO_error(path, "PLY file without vertex x, y, z properties");
  if (!face_list) throw IO_error(path, "PLY file without a face or tristrips element with vertex_indices");
  hdr.body = (std::min)(pos, data.size());
  hdr.body_line = line_no + 1;
  // Every vertex takes at least 3 bytes (binary) or 6 characters (ASCII "0 0 0\n"), every face 4.
  const bool binary = hdr.format != Ply_header::Format::ascii;
  const unsigned long long body = data.size() - hdr.body;
  const unsigned long long need = vertices * (binary ? 3ull : 6ull) + faces * 4ull;
  if (vertices > body || faces > body || need > body)
    throw IO_error(path, "header declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
                             " faces, more than the file can hold (truncated or corrupt)");
  return hdr;
}

// The values of a PLY body, one at a time, in file order: whitespace-separated numbers (ASCII,
// with the line of each) or packed binary scalars of either byte order.
class Ply_body {
public:
  Ply_body(std::string_view data, const Ply_header& hdr, const std::string& path)
      : p_(data.data() + hdr.body),
        end_(data.data() + data.size()),
        line_(hdr.body_line),
        format_(hdr.format),
        path_(path) {}

  bool ascii() const { return format_ == Ply_header::Format::ascii; }
  // The line the next value starts on (ASCII; 0 for binary).
  std::size_t line() {
    if (!ascii()) return 0;
    skip_space();
    return line_;
  }
  // The next value, of type `t`, into `v`; false at the end of the data. An ASCII token that is
  // not a number of that type throws.
  bool next(Ply_type t, double& v) {
    if (ascii()) {
      skip_space();
      if (p_ == end_) return false;
      const char* b = p_;
      while (p_ < end_ && !is_space(*p_)) ++p_;
      std::string_view tok(b, std::size_t(p_ - b));
      if (ply_integral(t)) {
        long long i;
        if (!parse_number(tok, i)) bad(tok);
        v = double(i);
      } else if (!parse_number(tok, v)) {
        bad(tok);
      }
      return true;
    }
    const std::size_t n = ply_size(t);
    if (std::size_t(end_ - p_) < n) return false;
    unsigned char b[8];
    std::memcpy(b, p_, n);
    p_ += n;
    if (format_ == Ply_header::Format::binary_big_endian) std::reverse(b, b + n);
    switch (t) {
      case Ply_type::i8:
        v = double(std::int8_t(b[0]));
        break;
      case Ply_type::u8:
        v = double(b[0]);
        break;
      case Ply_type::i16:
        v = double(load<std::int16_t>(b));
        break;
      case Ply_type::u16:
        v = double(load<std::uint16_t>(b));
        break;
      case Ply_type::i32:
        v = double(load<std::int32_t>(b));
        break;
      case Ply_type::u32:
        v = double(load<std::uint32_t>(b));
        break;
      case Ply_type::f32:
        v = double(load<float>(b));
        break;
      case Ply_type::f64:
        v = load<double>(b);
        break;
    }
    return true;
  }
  // Skips `n` values of type `t`; false at the end of the data.
  bool skip(Ply_type t, unsigned long long n) {
    if (!ascii()) {
      const unsigned long long bytes = n * ply_size(t);
      if (n > std::size_t(end_ - p_) || bytes > std::size_t(end_ - p_)) return false;
      p_ += bytes;
      return true;
    }
    double v;
    for (unsigned long long i = 0; i < n; ++i)
      if (!next(t, v)) return false;
    return true;
  }

private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
  void skip_space() {
    while (p_ < end_ && is_space(*p_)) {
      if (*p_ == '\n') ++line_;
      ++p_;
    }
  }
  template <class T>
  static T load(const unsigned char* b) {
    T x;
    std::memcpy(&x, b, sizeof x);
    return x;
  }
  [[noreturn]] void bad(std::string_view tok) const {
    throw IO_error(path_, line_, "bad PLY value '" + std::string(tok.substr(0, 40)) + "'");
  }

  const char* p_;
  const char* const end_;
  std::size_t line_;
  Ply_header::Format format_;
  const std::string& path_;
};

// A non-negative vertex index read as a double, as a 32-bit index; one too large for 32 bits
// becomes 0xffffffff, which no vertex count reaches, so the range check of read_ply() names it.
std::uint32_t vertex_index(double v) { return v > 4294967295.0 ? 0xffffffffu : std::uint32_t(v); }

// Reads the body of a PLY file into `soup`: the vertices' x, y, z, the faces' vertex index lists
// and the triangles of triangle strips (`element tristrips`, as MeshLab's samples store them: a
// list of vertex indices where -1 starts a new strip; its k-th triangle is (s[k], s[k+1], s[k+2]),
// every other one reversed to keep the orientation; triangles with a repeated vertex, the joins of
// stitched strips, are dropped). Other elements and properties are read past. The indices are
// checked against the vertex count once every element is read (the vertices may come last).
void read_ply_body(std::string_view data, const Ply_header& hdr, const std::string& path, Polygon_soup& soup) {
  Ply_body body(data, hdr, path);
  unsigned long long vertices = 0, corners = 0;
  for (const Ply_element& el : hdr.elements) {
    if (el.name == "vertex" || el.name == "vertices") vertices += el.count;
    if (el.name == "face" || el.name == "faces" || el.name == "tristrips") corners += 3 * el.count;
  }
  // (every value takes at least a byte: no more room than the file can fill, whatever the
  // header declares for the elements its checks do not count, e.g. `element vertices`)
  soup.positions.reserve(std::size_t((std::min)(vertices, static_cast<unsigned long long>(data.size()))));
  soup.corner_vertex.reserve(std::size_t((std::min)(corners, static_cast<unsigned long long>(data.size()))));
  std::vector<std::uint32_t> strip;
  for (const Ply_element& el : hdr.elements) {
    const bool vertex = el.name == "vertex" || el.name == "vertices";
    const bool face = el.name == "face" || el.name == "faces";
    const bool strips = el.name == "tristrips";
    // the roles of the properties: 0 x, 1 y, 2 z, 3 the index list, -1 read past
    std::vector<int> role(el.properties.size(), -1);
    bool have_list = false;
    for (std::size_t k = 0; k < el.properties.size(); ++k) {
      const Ply_property& pr = el.properties[k];
      if (vertex && !pr.list) {
        const int axis = pr.name == "x" ? 0 : pr.name == "y" ? 1 : pr.name == "z" ? 2 : -1;
        if (axis >= 0 && std::find(role.begin(), role.end(), axis) == role.end()) role[k] = axis;
      }
      if ((face || strips) && pr.list && !have_list && (pr.name == "vertex_indices" || pr.name == "vertex_index")) {
        if (!ply_integral(pr.type) && el.count > 0)
          throw IO_error(path, "PLY element '" + el.name + "' without an integer vertex_indices list");
        role[k] = 3;
        have_list = true;
      }
    }
    if ((face || strips) && !have_list && el.count > 0)
      throw IO_error(path, "PLY element '" + el.name + "' without an integer vertex_indices list");
    auto truncated = [&](unsigned long long j) {
      return IO_error(path, "truncated PLY: element '" + el.name + "' item " + std::to_string(j) + " of " +
                                std::to_string(el.count));
    };
    for (unsigned long long j = 0; j < el.count; ++j) {
      const std::size_t item_line = body.line();
      std::array<double, 3> x{{0, 0, 0}};
      for (std::size_t k = 0; k < el.properties.size(); ++k) {
        const Ply_property& pr = el.properties[k];
        double v;
        if (!pr.list) {
          if (!body.next(pr.type, v)) throw truncated(j);
          if (role[k] >= 0) x[std::size_t(role[k])] = v;
          continue;
        }
        if (!body.next(pr.count, v)) throw truncated(j);
        if (v < 0)
          throw IO_error(path, item_line,
                         "PLY element '" + el.name + "' item " + std::to_string(j) + ": negative list length");
        const auto n = static_cast<unsigned long long>(v);
        if (role[k] != 3) {
          if (!body.skip(pr.type, n)) throw truncated(j);
          continue;
        }
        if (face) {
          for (unsigned long long i = 0; i < n; ++i) {
            if (!body.next(pr.type, v)) throw truncated(j);
            if (v < 0)
              throw IO_error(path, item_line,
                             "face " + std::to_string(soup.number_of_faces()) + ": negative vertex index " +
                                 std::to_string(static_cast<long long>(v)));
            soup.corner_vertex.push_back(vertex_index(v));
          }
          soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
          soup.face_line.push_back(item_line);
          continue;
        }
        strip.clear();
        std::size_t start = 0;  // first index of the current strip
        for (unsigned long long i = 0; i < n; ++i) {
          if (!body.next(pr.type, v)) throw truncated(j);
          if (v == -1) {
            start = std::size_t(i) + 1;
            strip.push_back(0);
            continue;
          }
          if (v < 0)
            throw IO_error(path, item_line,
                           "tristrips item " + std::to_string(j) + ": negative vertex index " +
                               std::to_string(static_cast<long long>(v)));
          strip.push_back(vertex_index(v));
          const std::size_t k2 = std::size_t(i);
          if (k2 < start + 2) continue;
          const std::uint32_t a = strip[k2 - 2], b = strip[k2 - 1], c = strip[k2];
          if (a == b || b == c || a == c) continue;
          const bool even = (k2 - start) % 2 == 0;
          soup.corner_vertex.push_back(even ? a : b);
          soup.corner_vertex.push_back(even ? b : a);
          soup.corner_vertex.push_back(c);
          soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
          soup.face_line.push_back(item_line);
        }
      }
      if (vertex) soup.positions.push_back(x);
    }
  }
}

}  // namespace

void read_ply(const std::string& path, Polygon_soup& soup) {
  soup = Polygon_soup();
  soup.source = path;
  const File_bytes bytes(path);
  const std::string_view data = bytes.view();
  if (data.empty()) throw IO_error(path, "empty file");
  const Ply_header hdr = read_ply_header(data, path);
  try {
    read_ply_body(data, hdr, path, soup);
  } catch (const std::bad_alloc&) {
    throw IO_error(path, "header declares more elements than can be allocated (corrupt file)");
  }
  if (soup.number_of_faces() == 0) throw IO_error(path, "no faces in file");
  for (std::size_t i = 0; i < soup.positions.size(); ++i) {
    const auto& p = soup.positions[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw IO_error(path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
  }
  const std::size_t nv = soup.positions.size(), nf = soup.number_of_faces();
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = soup.face_start[f], e = soup.face_start[f + 1];
    if (e - b < 3) throw IO_error(path, soup.face_line[f], "face " + std::to_string(f) + " has fewer than 3 corners");
    for (std::uint32_t c = b; c < e; ++c)
      if (soup.corner_vertex[c] >= nv)
        throw IO_error(path, soup.face_line[f],
                       "face " + std::to_string(f) + ": vertex index " + std::to_string(soup.corner_vertex[c]) +
                           " out of range (" + std::to_string(nv) + " vertices)");
  }
  soup.corner_uv.assign(soup.corner_vertex.size(), Polygon_soup::no_index);
  soup.face_material.assign(nf, 0);
}

// ------------------------------------------------------------------------------- writers

void write_bytes(const std::string& tmp, const std::string& path, std::string_view bytes) {
  std::ofstream os(tmp, std::ios::binary);
  if (!os) throw IO_error(path, std::string("cannot write: ") + std::strerror(errno));
  os.write(bytes.data(), std::streamsize(bytes.size()));
  os.flush();
  if (!os) throw IO_error(path, "write failed (disk full?)");
}

void write_off(const std::string& path, const Textured_mesh& tm, Atomic_output& out) {
  const Surface_mesh& m = tm.mesh();
  std::vector<std::uint32_t> vid(m.number_of_vertices() + m.number_of_removed_vertices(), 0);
  std::string s = "OFF\n" + std::to_string(m.number_of_vertices()) + " " + std::to_string(m.number_of_faces()) + " 0\n";
  std::uint32_t next = 0;
  for (auto v : m.vertices()) {
    vid[std::size_t(v)] = next++;
    const Point_3& p = m.point(v);
    append_double(s, p.x());
    s += ' ';
    append_double(s, p.y());
    s += ' ';
    append_double(s, p.z());
    s += '\n';
  }
  for (auto f : m.faces()) {
    s += std::to_string(m.degree(f));
    for (auto v : m.vertices_around_face(m.halfedge(f))) s += " " + std::to_string(vid[std::size_t(v)]);
    s += '\n';
  }
  write_bytes(out.add(path), path, s);
}

void write_ply(const std::string& path, const Textured_mesh& tm, Atomic_output& out) {
  const Surface_mesh& m = tm.mesh();
  std::vector<std::uint32_t> vid(m.number_of_vertices() + m.number_of_removed_vertices(), 0);
  std::string s = "ply\nformat binary_little_endian 1.0\ncomment written by CMGeom " CMGEOM_VERSION_STR
                  "\nelement vertex " +
                  std::to_string(m.number_of_vertices()) +
                  "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                  std::to_string(m.number_of_faces()) + "\nproperty list uchar int vertex_indices\nend_header\n";
  static_assert(sizeof(double) == 8 && sizeof(std::int32_t) == 4, "PLY writer assumes IEEE sizes");
  auto put = [&s](const void* p, std::size_t n) { s.append(static_cast<const char*>(p), n); };
  std::uint32_t next = 0;
  for (auto v : m.vertices()) {  // x86-64 and aarch64 are little-endian, as the header says
    vid[std::size_t(v)] = next++;
    const Point_3& p = m.point(v);
    const double xyz[3] = {p.x(), p.y(), p.z()};
    put(xyz, sizeof xyz);
  }
  for (auto f : m.faces()) {
    const std::uint8_t n = std::uint8_t(m.degree(f));
    put(&n, 1);
    for (auto v : m.vertices_around_face(m.halfedge(f))) {
      const std::int32_t i = std::int32_t(vid[std::size_t(v)]);
      put(&i, 4);
    }
  }
  write_bytes(out.add(path), path, s);
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
