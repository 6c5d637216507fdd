// OFF (own reader: errors carry line numbers) and PLY (CGAL's reader) geometry, and their writers.
#include "io_internal.h"

#include <CMGeom/Error.h>

#include <CGAL/IO/PLY.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <new>

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
  std::size_t line_no = 0;
  const char* p = data.data();
  const char* end = p + data.size();
  while (p < end) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', std::size_t(end - p)));
    if (!nl) nl = end;
    ++line_no;
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
    p = nl + 1;
  }
  return lines;
}

template <class T> bool number(std::string_view t, T& out) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  auto r = std::from_chars(t.data(), t.data() + t.size(), out);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

}  // namespace

void read_off(const std::string& path, Polygon_soup& soup) {
  const std::string data = slurp(path);
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
  if (lines[li].tokens.size() < 2 || !number(lines[li].tokens[0], nv) || !number(lines[li].tokens[1], nf) ||
      nv < 0 || nf < 0)
    throw IO_error(path, lines[li].line, "expected '<#vertices> <#faces> [<#edges>]'");
  // A declared count larger than the file could hold is corrupt (and must not allocate).
  if (std::size_t(nv) + std::size_t(nf) > data.size())
    throw IO_error(path, lines[li].line, "declares " + std::to_string(nv) + " vertices and " +
                                             std::to_string(nf) + " faces, more than the file can hold");
  ++li;
  soup.positions.reserve(std::size_t(nv));
  for (long long i = 0; i < nv; ++i, ++li) {
    if (li >= lines.size())
      throw IO_error(path, "truncated: " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    const Token_line& l = lines[li];
    std::array<double, 3> x;
    if (l.tokens.size() < 3)
      throw IO_error(path, l.line, "vertex needs three coordinates");
    for (int k = 0; k < 3; ++k) {
      if (!number(l.tokens[std::size_t(k)], x[std::size_t(k)]))
        throw IO_error(path, l.line, "bad vertex coordinate '" + std::string(l.tokens[std::size_t(k)]) + "'");
      if (!std::isfinite(x[std::size_t(k)]))
        throw IO_error(path, l.line, "vertex coordinate is not finite");
    }
    soup.positions.push_back(x);
    if (has_uv) {
      std::array<double, 2> t;
      if (l.tokens.size() < 5 || !number(l.tokens[3], t[0]) || !number(l.tokens[4], t[1]) ||
          !std::isfinite(t[0]) || !std::isfinite(t[1]))
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
        throw IO_error(path, l.line, "vertex index " + std::to_string(idx) + " out of range (" +
                                         std::to_string(nv) + " vertices)");
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

void read_ply(const std::string& path, Polygon_soup& soup) {
  soup = Polygon_soup();
  soup.source = path;
  {
    const std::string head = slurp(path).substr(0, 4);
    if (head.empty()) throw IO_error(path, "empty file");
    if (head.compare(0, 3, "ply") != 0) throw IO_error(path, 1, "not a PLY file (no 'ply' magic)");
  }
  std::ifstream in(path, std::ios::binary);
  std::vector<Point_3> points;
  std::vector<std::vector<std::size_t>> polygons;
  bool ok = false;
  try {
    ok = CGAL::IO::read_PLY(in, points, polygons, CGAL::parameters::use_binary_mode(true));
  } catch (const std::bad_alloc&) {
    throw IO_error(path, "header declares more elements than can be allocated (corrupt file)");
  } catch (const std::exception& e) {
    throw IO_error(path, std::string("malformed PLY: ") + e.what());
  }
  if (!ok) throw IO_error(path, "malformed or truncated PLY (CGAL's PLY reader failed)");
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
    if (c.size() < 3)
      throw IO_error(path, "face " + std::to_string(f) + " has fewer than 3 corners");
    for (std::size_t idx : c)
      if (idx >= points.size())
        throw IO_error(path, "face " + std::to_string(f) + ": vertex index " + std::to_string(idx) +
                                 " out of range (" + std::to_string(points.size()) + " vertices)");
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
template <class F> void write_through(const std::string& tmp, const std::string& path, F&& body) {
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
  std::string s = "OFF\n" + std::to_string(m.number_of_vertices()) + " " +
                  std::to_string(m.number_of_faces()) + " 0\n";
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
                  "\nelement vertex " + std::to_string(m.number_of_vertices()) +
                  "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                  std::to_string(m.number_of_faces()) +
                  "\nproperty list uchar int vertex_indices\nend_header\n";
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
