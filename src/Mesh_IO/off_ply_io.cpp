// OFF (own reader: errors carry line numbers) and PLY (CGAL's PLY_reader for the header and the
// numbers; faces and triangle strips, `element tristrips` as MeshLab's samples store them) geometry,
// and their writers.
#include "io_internal.h"

#include <CMGeom/Error.h>

#include <CGAL/IO/PLY.h>

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

struct Token_line {
  std::size_t line;
  std::vector<std::string_view> tokens;
};

// Splits OFF text into non-empty, comment-free lines of tokens.
std::vector<Token_line> tokenize(const std::string& data, const std::string& path) {
  std::vector<Token_line> lines;
  for_each_line(data, [&](std::size_t line_no, const char* p, const char* nl) {
    Token_line tl{line_no, {}};
    const char* q = p;
    while (q < nl) {
      while (q < nl && (*q == ' ' || *q == '\t' || *q == '\r')) ++q;
      if (q >= nl || *q == '#') break;
      if (*q == '\0') throw IO_error(path, line_no, "binary data (NUL byte) in a text OFF file");
      const char* b = q;
      while (q < nl && *q != ' ' && *q != '\t' && *q != '\r' && *q != '#') ++q;
      tl.tokens.emplace_back(b, std::size_t(q - b));
      if (q < nl && *q == '#') break;
    }
    if (!tl.tokens.empty()) lines.push_back(std::move(tl));
  });
  return lines;
}

template <class T>
bool number(std::string_view t, T& out) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  auto r = std::from_chars(t.data(), t.data() + t.size(), out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

}  // namespace

void read_off(const std::string& path, Polygon_soup& soup) {
  const std::string data = mesh_file_text(path);
  if (data.empty()) throw IO_error(path, "empty file");
  soup = Polygon_soup();
  soup.source = path;
  std::vector<Token_line> lines = tokenize(data, path);
  if (lines.empty()) throw IO_error(path, "no content");
  std::size_t li = 0;
  const std::string_view head = lines[0].tokens[0];
  bool has_uv = false;
  if (head.size() >= 3 && head.substr(head.size() - 3) == "OFF") {
    if (lines[0].tokens.size() > 1 && lines[0].tokens[1] == "BINARY")
      throw IO_error(path, lines[0].line, "binary OFF is not supported");
    if (head.find("4") != std::string_view::npos || head.find("n") != std::string_view::npos)
      throw IO_error(path, lines[0].line, "only 3D OFF files are supported ('" + std::string(head) + "')");
    has_uv = head.find("ST") != std::string_view::npos;
    if (lines[0].tokens.size() >= 4) {  // counts on the header line
      lines[0].tokens.erase(lines[0].tokens.begin());
    } else {
      ++li;
    }
  }
  if (li >= lines.size()) throw IO_error(path, "truncated: missing vertex/face counts");
  long long nv = -1, nf = -1;
  if (lines[li].tokens.size() < 2 || !number(lines[li].tokens[0], nv) || !number(lines[li].tokens[1], nf) || nv < 0 ||
      nf < 0)
    throw IO_error(path, lines[li].line, "expected '<#vertices> <#faces> [<#edges>]'");
  // A declared count larger than the file could hold is corrupt (and must not allocate).
  if (std::size_t(nv) + std::size_t(nf) > data.size())
    throw IO_error(path, lines[li].line,
                   "declares " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                       " faces, more than the file can hold");
  ++li;
  soup.positions.reserve(std::size_t(nv));
  for (long long i = 0; i < nv; ++i, ++li) {
    if (li >= lines.size())
      throw IO_error(path, "truncated: " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    const Token_line& l = lines[li];
    std::array<double, 3> x;
    if (l.tokens.size() < 3) throw IO_error(path, l.line, "vertex needs three coordinates");
    for (int k = 0; k < 3; ++k) {
      if (!number(l.tokens[std::size_t(k)], x[std::size_t(k)]))
        throw IO_error(path, l.line, "bad vertex coordinate '" + std::string(l.tokens[std::size_t(k)]) + "'");
      if (!std::isfinite(x[std::size_t(k)])) throw IO_error(path, l.line, "vertex coordinate is not finite");
    }
    soup.positions.push_back(x);
    if (has_uv) {
      std::array<double, 2> t;
      if (l.tokens.size() < 5 || !number(l.tokens[3], t[0]) || !number(l.tokens[4], t[1]) || !std::isfinite(t[0]) ||
          !std::isfinite(t[1]))
        throw IO_error(path, l.line, "STOFF vertex needs two finite texture coordinates");
      soup.uvs.push_back(t);
    }
  }
  for (long long f = 0; f < nf; ++f, ++li) {
    if (li >= lines.size())
      throw IO_error(path, "truncated: " + std::to_string(f) + " of " + std::to_string(nf) + " faces");
    const Token_line& l = lines[li];
    long long n;
    if (!number(l.tokens[0], n) || n < 3 || std::size_t(n) + 1 > l.tokens.size())
      throw IO_error(path, l.line, "face needs a corner count >= 3 followed by that many indices");
    std::vector<std::uint32_t> c(static_cast<std::size_t>(n));
    for (long long k = 0; k < n; ++k) {
      long long idx;
      if (!number(l.tokens[std::size_t(k + 1)], idx))
        throw IO_error(path, l.line, "bad vertex index '" + std::string(l.tokens[std::size_t(k + 1)]) + "'");
      if (idx < 0 || idx >= nv)
        throw IO_error(path, l.line,
                       "vertex index " + std::to_string(idx) + " out of range (" + std::to_string(nv) + " vertices)");
      c[std::size_t(k)] = std::uint32_t(idx);
    }
    for (std::uint32_t k : c) {
      soup.corner_vertex.push_back(k);
      soup.corner_uv.push_back(has_uv ? k : Polygon_soup::no_index);
    }
    soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
    soup.face_material.push_back(0);
    soup.face_line.push_back(l.line);
  }
  if (soup.number_of_faces() == 0) throw IO_error(path, "no faces in file");
}

namespace {

// CGAL's PLY reader trusts the header (a "property" before any "element" crashes it, a huge
// count allocates before reading): the header is checked here first, with line numbers.
void check_ply_header(const std::string& data, const std::string& path) {
  static const char* const scalar_types[] = {"char",  "uchar",  "short",   "ushort", "int",   "uint",
                                             "float", "double", "int8",    "uint8",  "int16", "uint16",
                                             "int32", "uint32", "float32", "float64"};
  auto is_type = [](std::string_view t) {
    for (const char* s : scalar_types)
      if (t == s) return true;
    return false;
  };
  std::size_t pos = 0, line_no = 0;
  bool have_element = false, have_format = false, ended = false, binary = false;
  bool vertex_x = false, vertex_y = false, vertex_z = false, face_list = false;
  std::string element;
  unsigned long long vertices = 0, faces = 0;
  while (pos < data.size() && !ended) {
    std::size_t nl = data.find('\n', pos);
    if (nl == std::string::npos) nl = data.size();
    std::string line = data.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string_view> tok;
    for (std::size_t i = 0; i < line.size();) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t b = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (i > b) tok.emplace_back(line.data() + b, i - b);
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
      binary = tok[1] != "ascii";
    } else if (tok[0] == "element") {
      unsigned long long n;
      if (tok.size() != 3 || !number(tok[2], n)) throw IO_error(path, line_no, "bad PLY element line");
      element = std::string(tok[1]);
      if (element == "vertex") vertices = n;
      if (element == "face" || element == "tristrips") faces += n;
      have_element = true;
    } else if (tok[0] == "property") {
      if (!have_element) throw IO_error(path, line_no, "PLY property before any element");
      if (tok.size() == 5 && tok[1] == "list") {
        if (!is_type(tok[2]) || !is_type(tok[3])) throw IO_error(path, line_no, "bad PLY list property type");
        if ((element == "face" || element == "tristrips") && (tok[4] == "vertex_indices" || tok[4] == "vertex_index"))
          face_list = true;
      } else if (tok.size() == 3 && is_type(tok[1])) {
        if (element == "vertex") {
          vertex_x |= tok[2] == "x";
          vertex_y |= tok[2] == "y";
          vertex_z |= tok[2] == "z";
        }
      } else {
        throw IO_error(path, line_no, "bad PLY property line");
      }
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
  // Every vertex takes at least 3 bytes (binary) or 6 characters (ASCII "0 0 0\n"), every face 4.
  const unsigned long long body = data.size() - std::min<std::size_t>(pos, data.size());
  const unsigned long long need = vertices * (binary ? 3ull : 6ull) + faces * 4ull;
  if (vertices > body || faces > body || need > body)
    throw IO_error(path, "header declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
                             " faces, more than the file can hold (truncated or corrupt)");
}

namespace PLY = CGAL::IO::internal;

// The list `tag` of the current item of `el`, read as Int (the list's declared type).
template <class Int>
void take_list(PLY::PLY_element& el, const char* tag, std::vector<long long>& out) {
  std::vector<Int> v;
  el.assign(v, tag);
  out.assign(v.begin(), v.end());
}
using List_taker = void (*)(PLY::PLY_element&, const char*, std::vector<long long>&);

// How to read the vertex index list of element `el` (`vertex_indices` or `vertex_index`, any
// integer type), found once per element; a null taker if it has none.
std::pair<List_taker, const char*> index_list_of(PLY::PLY_element& el) {
  for (const char* tag : {"vertex_indices", "vertex_index"}) {
    if (el.has_property<std::vector<std::int32_t>>(tag)) return {&take_list<std::int32_t>, tag};
    if (el.has_property<std::vector<std::uint32_t>>(tag)) return {&take_list<std::uint32_t>, tag};
    if (el.has_property<std::vector<std::int16_t>>(tag)) return {&take_list<std::int16_t>, tag};
    if (el.has_property<std::vector<std::uint16_t>>(tag)) return {&take_list<std::uint16_t>, tag};
    if (el.has_property<std::vector<std::int8_t>>(tag)) return {&take_list<std::int8_t>, tag};
    if (el.has_property<std::vector<std::uint8_t>>(tag)) return {&take_list<std::uint8_t>, tag};
  }
  return {nullptr, nullptr};
}

// Reads the vertices, faces and triangle strips of a PLY stream (other elements are skipped).
// A strip is a list of vertex indices where -1 starts a new strip; its k-th triangle is
// (s[k], s[k+1], s[k+2]), every other one reversed to keep the orientation; triangles with a
// repeated vertex (the joins of stitched strips) are dropped.
void read_ply_elements(std::istream& in, const std::string& path, std::vector<Point_3>& points,
                       std::vector<std::vector<std::size_t>>& polygons) {
  PLY::PLY_reader reader(false);
  if (!reader.init(in)) throw IO_error(path, "malformed PLY header");
  std::vector<long long> idx;
  for (std::size_t e = 0; e < reader.number_of_elements(); ++e) {
    PLY::PLY_element& el = reader.element(e);
    const std::string name = el.name();
    const bool vertex = name == "vertex" || name == "vertices";
    const bool face = name == "face" || name == "faces";
    const bool strips = name == "tristrips";
    const auto [take, tag] = face || strips ? index_list_of(el) : std::pair<List_taker, const char*>{nullptr, nullptr};
    if ((face || strips) && !take && el.number_of_items() > 0)
      throw IO_error(path, "PLY element '" + name + "' without an integer vertex_indices list");
    for (std::size_t j = 0; j < el.number_of_items(); ++j) {
      for (std::size_t k = 0; k < el.number_of_properties(); ++k) {
        el.property(k)->get(in);
        if (in.fail())
          throw IO_error(path, "truncated PLY: element '" + name + "' item " + std::to_string(j) + " of " +
                                   std::to_string(el.number_of_items()));
      }
      if (vertex) {
        std::tuple<Point_3> v;
        PLY::process_properties(el, v, CGAL::IO::make_ply_point_reader(CGAL::make_nth_of_tuple_property_map<0>(v)));
        points.push_back(std::get<0>(v));
      } else if (face || strips) {
        take(el, tag, idx);
        if (face) {
          std::vector<std::size_t> poly;
          for (long long i : idx) {
            if (i < 0)
              throw IO_error(
                  path, "face " + std::to_string(polygons.size()) + ": negative vertex index " + std::to_string(i));
            poly.push_back(std::size_t(i));
          }
          polygons.push_back(std::move(poly));
          continue;
        }
        std::size_t start = 0;  // first index of the current strip
        for (std::size_t k = 0; k < idx.size(); ++k) {
          if (idx[k] == -1) {
            start = k + 1;
            continue;
          }
          if (idx[k] < 0)
            throw IO_error(path,
                           "tristrips item " + std::to_string(j) + ": negative vertex index " + std::to_string(idx[k]));
          if (k < start + 2) continue;
          const long long a = idx[k - 2], b = idx[k - 1], c = idx[k];
          if (a == b || b == c || a == c) continue;
          if ((k - start) % 2 == 0)
            polygons.push_back({std::size_t(a), std::size_t(b), std::size_t(c)});
          else
            polygons.push_back({std::size_t(b), std::size_t(a), std::size_t(c)});
        }
      }
    }
  }
}

}  // namespace

void read_ply(const std::string& path, Polygon_soup& soup) {
  soup = Polygon_soup();
  soup.source = path;
  std::string text = mesh_file_text(path);
  if (text.empty()) throw IO_error(path, "empty file");
  check_ply_header(text, path);
  // A .gz file is parsed from its decompressed bytes, in place (std::istringstream would copy
  // them); a plain one from the file again, its bytes freed first (a lower peak of memory).
  const bool packed = is_gzipped_path(path);
  if (!packed) std::string().swap(text);
  struct Bytes : std::streambuf {
    explicit Bytes(std::string& b) { setg(b.data(), b.data(), b.data() + b.size()); }
  } bytes(text);
  std::istream unpacked(&bytes);
  std::ifstream file;
  if (!packed) file.open(path, std::ios::binary);
  std::istream& in = packed ? unpacked : static_cast<std::istream&>(file);
  std::vector<Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  try {
    read_ply_elements(in, path, points, polygons);
  } catch (const std::bad_alloc&) {
    throw IO_error(path, "header declares more elements than can be allocated (corrupt file)");
  } catch (const IO_error&) {
    throw;
  } catch (const std::exception& e) {
    throw IO_error(path, std::string("malformed PLY: ") + e.what());
  }
  if (polygons.empty()) throw IO_error(path, "no faces in file");
  soup.positions.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point_3& p = points[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw IO_error(path, "vertex " + std::to_string(i) + " has a non-finite coordinate");
    soup.positions.push_back({p.x(), p.y(), p.z()});
  }
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const auto& c = polygons[f];
    if (c.size() < 3) throw IO_error(path, "face " + std::to_string(f) + " has fewer than 3 corners");
    for (std::size_t idx : c)
      if (idx >= points.size())
        throw IO_error(path, "face " + std::to_string(f) + ": vertex index " + std::to_string(idx) + " out of range (" +
                                 std::to_string(points.size()) + " vertices)");
    for (std::size_t k : c) {
      soup.corner_vertex.push_back(std::uint32_t(k));
      soup.corner_uv.push_back(Polygon_soup::no_index);
    }
    soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
    soup.face_material.push_back(0);
    soup.face_line.push_back(0);
  }
}

// ------------------------------------------------------------------------------- writers

namespace {
template <class F>
void write_through(const std::string& tmp, const std::string& path, F&& body) {
  std::ofstream os(tmp, std::ios::binary);
  if (!os) throw IO_error(path, std::string("cannot write: ") + std::strerror(errno));
  body(os);
  os.flush();
  if (!os) throw IO_error(path, "write failed (disk full?)");
}
}  // namespace

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
  write_through(out.add(path), path, [&](std::ostream& os) { os << s; });
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
  write_through(out.add(path), path, [&](std::ostream& os) { os.write(s.data(), std::streamsize(s.size())); });
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
