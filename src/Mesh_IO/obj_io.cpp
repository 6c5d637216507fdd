// OBJ + MTL reader and writer.
//
// Files of a megabyte or more are parsed on all cores in chunks of lines (read_obj_in_chunks);
// the soup is the one the line-by-line reader gives, which reads any file the chunks give up on
// (an error, an unknown statement) and so reports its errors and warnings.
//
// Own parser rather than tinyobjloader: every error must carry its line number (tinyobjloader
// reports out-of-range indices without one, or not at all), polygons must be split into fans as
// build_textured_mesh() does (textured_mesh.cpp), and coordinates must read back bit-exactly (std::from_chars /
// std::to_chars). The test suite cross-checks this parser against tinyobjloader on every textured model.
#include "io_internal.h"

#include <CMGeom/Error.h>
#include <CMGeom/internal/release_freed_memory.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <tbb/parallel_for.h>

#include <zlib.h>

namespace CMGeom {
namespace IO {
namespace internal {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw IO_error(path, "file not found");
  if (fs::is_directory(path, ec)) throw IO_error(path, "is a directory, not a mesh file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IO_error(path, std::string("cannot open: ") + std::strerror(errno));
  std::string data;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) throw IO_error(path, "cannot determine file size");
  data.resize(std::size_t(size));
  in.seekg(0, std::ios::beg);
  in.read(data.data(), size);
  if (!in) throw IO_error(path, "read failed");
  return data;
}

bool is_gzipped_path(const std::string& path) { return extension(path) == ".gz"; }

std::string gunzip_file(const std::string& path) {
  const std::string packed = slurp(path);  // (which reports a missing, unreadable or odd file)
  if (packed.size() < 2 || static_cast<unsigned char>(packed[0]) != 0x1f ||
      static_cast<unsigned char>(packed[1]) != 0x8b)
    throw IO_error(path, "not gzip data (the name ends in .gz)");
  std::string out;
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) throw IO_error(path, "cannot start zlib");
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(packed.data()));
  std::size_t left = packed.size();
  std::size_t produced = 0;
  out.resize((std::max)(std::size_t(1) << 16, 4 * packed.size()));
  int r = Z_OK;
  while (true) {
    if (z.avail_in == 0 && left > 0) {  // (zlib counts in 32-bit unsigned ints)
      const std::size_t take = (std::min)(left, std::size_t(1) << 30);
      z.avail_in = uInt(take);
      left -= take;
    }
    if (out.size() - produced < (std::size_t(1) << 16)) out.resize(2 * out.size());
    const std::size_t room = (std::min)(out.size() - produced, std::size_t(1) << 30);
    z.next_out = reinterpret_cast<Bytef*>(out.data() + produced);
    z.avail_out = uInt(room);
    r = inflate(&z, Z_NO_FLUSH);
    produced += room - z.avail_out;
    if (r == Z_STREAM_END) {
      // concatenated gzip members (as `cat a.gz b.gz` makes) are one file
      if (z.avail_in == 0 && left == 0) break;
      if (inflateReset(&z) != Z_OK) break;
      continue;
    }
    if (r != Z_OK && r != Z_BUF_ERROR) break;
    if (r == Z_BUF_ERROR && z.avail_in == 0 && left == 0) break;  // truncated
  }
  inflateEnd(&z);
  if (r != Z_STREAM_END)
    throw IO_error(path, std::string("corrupt or truncated gzip data") + (z.msg ? std::string(": ") + z.msg : ""));
  out.resize(produced);
  return out;
}

File_bytes::File_bytes(const std::string& path) {
  if (is_gzipped_path(path)) {
    copy_ = gunzip_file(path);
    return;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd >= 0) {
    struct stat st;
    if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
      void* p = ::mmap(nullptr, std::size_t(st.st_size), PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
      if (p != MAP_FAILED) {
        map_ = static_cast<const char*>(p);
        size_ = std::size_t(st.st_size);
      }
    }
    ::close(fd);
  }
  if (!map_) copy_ = slurp(path);  // which also reports a missing, unreadable or odd file
}

File_bytes::~File_bytes() {
  if (map_) ::munmap(const_cast<char*>(map_), size_);
}

void append_double(std::string& s, double x) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, x);
  s.append(buf, r.ptr);
}

namespace {

// A cursor over one line of text.
struct Line {
  const char* p;
  const char* end;
  void skip_ws() {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
  }
  bool at_end() {
    skip_ws();
    return p >= end;
  }
  std::string_view token() {
    skip_ws();
    const char* b = p;
    while (p < end && *p != ' ' && *p != '\t' && *p != '\r') ++p;
    return std::string_view(b, std::size_t(p - b));
  }
  std::string rest() {
    skip_ws();
    const char* e = end;
    while (e > p && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) --e;
    return std::string(p, e);
  }
};

std::string fix_slashes(std::string s) {
  for (char& c : s)
    if (c == '\\') c = '/';
  return s;
}

// The statements of grouping, smoothing and free-form geometry: not part of the polygon mesh.
bool is_ignored_statement(std::string_view key) {
  static const char* const keys[] = {
      "o",    "g",          "s",         "l",      "p",      "vp",    "cstype",   "deg",      "curv",  "surf",  "mg",
      "lod",  "shadow_obj", "trace_obj", "usemap", "maplib", "bevel", "c_interp", "d_interp", "ctech", "stech", "end",
      "parm", "trim",       "hole",      "scrv",   "sp",     "con",   "bmat",     "step",     "call",  "csh"};
  for (const char* k : keys)
    if (key == k) return true;
  return false;
}

// The numbers of a "v" line after its key (optional w or colour values are ignored); "" or what is
// wrong.
std::string parse_vertex(Line& l, std::array<double, 3>& x) {
  for (int i = 0; i < 3; ++i) {
    std::string_view t = l.token();
    if (!parse_number(t, x[std::size_t(i)])) return "vertex needs three numbers, got '" + std::string(t) + "'";
    if (!std::isfinite(x[std::size_t(i)])) return "vertex coordinate is not finite (" + std::string(t) + ")";
  }
  return std::string();
}

// The numbers of a "vt" line ("vt u" is legal: v defaults to 0).
std::string parse_texcoord(Line& l, std::array<double, 2>& t) {
  for (int i = 0; i < 2; ++i) {
    std::string_view s = l.token();
    if (i == 1 && s.empty()) {
      t[1] = 0.0;
      break;
    }
    if (!parse_number(s, t[std::size_t(i)])) return "texture coordinate needs numbers, got '" + std::string(s) + "'";
    if (!std::isfinite(t[std::size_t(i)])) return "texture coordinate is not finite (" + std::string(s) + ")";
  }
  return std::string();
}

// The numbers of a "vn" line (normals are recomputed from geometry: only their count matters).
std::string parse_normal(Line& l) {
  for (int i = 0; i < 3; ++i) {
    double d;
    std::string_view s = l.token();
    if (!parse_number(s, d)) return "normal needs three numbers, got '" + std::string(s) + "'";
  }
  return std::string();
}

// The corners of an "f" line, as 0-based indices (texture coordinate -1 for none), given how many
// positions, texture coordinates and normals the file defined before the line (1-based indices;
// negative ones count back from the latest element).
std::string parse_face(Line& l, std::size_t positions, std::size_t uvs, std::size_t normals, std::vector<long long>& cv,
                       std::vector<long long>& ct) {
  cv.clear();
  ct.clear();
  bool any_uv = false, any_no_uv = false;
  std::string error;
  auto resolve = [&](long long i, std::size_t count, const char* what) -> long long {
    const long long r = i > 0 ? i - 1 : (i < 0 ? (long long)count + i : -1);
    if (i == 0 || r < 0 || r >= (long long)count) {
      error = std::string(what) + " index " + std::to_string(i) + " out of range (" + std::to_string(count) +
              " defined so far)";
      return -1;
    }
    return r;
  };
  while (!l.at_end()) {
    std::string_view c = l.token();
    const std::size_t s1 = c.find('/');
    long long vi, ti = 0, ni = 0;
    if (!parse_number(c.substr(0, s1), vi)) return "bad face corner '" + std::string(c) + "'";
    if (s1 != std::string_view::npos) {
      std::string_view rest = c.substr(s1 + 1);
      const std::size_t s2 = rest.find('/');
      std::string_view tpart = rest.substr(0, s2);
      if (!tpart.empty() && !parse_number(tpart, ti))
        return "bad texture index in face corner '" + std::string(c) + "'";
      if (s2 != std::string_view::npos) {
        std::string_view npart = rest.substr(s2 + 1);
        if (!npart.empty() && !parse_number(npart, ni))
          return "bad normal index in face corner '" + std::string(c) + "'";
      }
    }
    cv.push_back(resolve(vi, positions, "vertex"));
    if (!error.empty()) return error;
    if (ti != 0) {
      ct.push_back(resolve(ti, uvs, "texture coordinate"));
      if (!error.empty()) return error;
      any_uv = true;
    } else {
      ct.push_back(-1);
      any_no_uv = true;
    }
    if (ni != 0) resolve(ni, normals, "normal");
    if (!error.empty()) return error;
  }
  if (cv.size() < 3) return "face with " + std::to_string(cv.size()) + " corner(s); at least 3 needed";
  if (any_uv && any_no_uv) return "face gives texture coordinates for some corners only";
  return std::string();
}

// Appends a parsed face (corners from parse_face) to the soup's corner arrays.
void add_face(Polygon_soup& soup, const std::vector<long long>& cv, const std::vector<long long>& ct, int material,
              std::size_t line_no) {
  for (std::size_t k = 0; k < cv.size(); ++k) {
    soup.corner_vertex.push_back(std::uint32_t(cv[k]));
    soup.corner_uv.push_back(ct[k] < 0 ? Polygon_soup::no_index : std::uint32_t(ct[k]));
  }
  soup.face_start.push_back(std::uint32_t(soup.corner_vertex.size()));
  soup.face_material.push_back(material);  // -1: before any usemtl
  soup.face_line.push_back(line_no);
}

// The OBJ's lines in chunks, parsed on all cores: a first pass counts each chunk's lines and
// its v, vt and vn statements, so that the second can resolve face indices (relative ones too)
// chunk by chunk. Only the statements of plain meshes are parsed so (v, vt, vn, f, comments,
// usemtl and mtllib, which are recorded and replayed in file order, and the ignored ones of
// is_ignored_statement); on anything else, an unknown statement or an error, it gives up and
// returns false, and the serial reader below, which reports it, reads the file. When it succeeds
// the soup is the serial reader's, element for element.
struct Obj_chunk {
  const char* begin;
  const char* end;
  std::size_t lines = 0, positions = 0, uvs = 0, normals = 0, faces = 0;  // counts, first pass
  Polygon_soup part;                                                      // faces' materials: event slot or -1
  struct Event {
    std::size_t line;  // in the chunk, 1-based
    bool usemtl;       // else mtllib
    std::string text;
  };
  std::vector<Event> events;
  bool ok = true;
};

void count_obj_chunk(Obj_chunk& c) {
  for_each_line(std::string_view(c.begin, std::size_t(c.end - c.begin)),
                [&](std::size_t, const char* p, const char* nl) {
                  ++c.lines;
                  while (p < nl && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
                  if (p + 1 < nl && p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) ++c.faces;
                  if (p < nl && *p == 'v') {
                    const char k = p + 1 < nl ? p[1] : ' ';
                    const bool end1 = k == ' ' || k == '\t' || k == '\r';
                    const bool end2 = p + 2 >= nl || p[2] == ' ' || p[2] == '\t' || p[2] == '\r';
                    if (end1)
                      ++c.positions;
                    else if (k == 't' && end2)
                      ++c.uvs;
                    else if (k == 'n' && end2)
                      ++c.normals;
                  }
                });
}

void parse_obj_chunk(Obj_chunk& c, std::size_t positions, std::size_t uvs, std::size_t normals) {
  Polygon_soup& soup = c.part;
  soup.positions.reserve(c.positions);
  soup.uvs.reserve(c.uvs);
  soup.face_start.reserve(c.faces + 1);  // triangles, most often
  soup.face_material.reserve(c.faces);
  soup.face_line.reserve(c.faces);
  soup.corner_vertex.reserve(3 * c.faces);
  soup.corner_uv.reserve(3 * c.faces);
  std::vector<long long> cv, ct;
  int slot = -1;
  // on the first line it cannot take, the chunk gives up (the remaining lines are skipped)
  for_each_line(
      std::string_view(c.begin, std::size_t(c.end - c.begin)), [&](std::size_t line_no, const char* b, const char* e) {
        if (!c.ok) return;
        Line l{b, e};
        if (std::memchr(l.p, '\0', std::size_t(l.end - l.p))) return void(c.ok = false);
        const std::string_view key = l.token();
        if (key.empty() || key[0] == '#') return;
        if (key == "v") {
          std::array<double, 3> x;
          if (!parse_vertex(l, x).empty()) return void(c.ok = false);
          soup.positions.push_back(x);
        } else if (key == "vt") {
          std::array<double, 2> t;
          if (!parse_texcoord(l, t).empty()) return void(c.ok = false);
          soup.uvs.push_back(t);
        } else if (key == "vn") {
          if (!parse_normal(l).empty()) return void(c.ok = false);
          ++normals;
        } else if (key == "f") {
          if (!parse_face(l, positions + soup.positions.size(), uvs + soup.uvs.size(), normals, cv, ct).empty())
            return void(c.ok = false);
          add_face(soup, cv, ct, slot, line_no);
        } else if (key == "usemtl" || key == "mtllib") {
          c.events.push_back({line_no, key == "usemtl", l.rest()});
          if (key == "usemtl") slot = int(c.events.size()) - 1;
        } else if (!is_ignored_statement(key)) {
          c.ok = false;
        }
      });
}

// Texture map statement: options (-bm 1.0, -o u v w, ...) then a file name that may hold spaces.
std::string texture_file_name(Line& l) {
  static const std::unordered_map<std::string, int> max_args = {
      {"-blendu", 1}, {"-blendv", 1}, {"-boost", 1}, {"-mm", 2},      {"-o", 3},    {"-s", 3}, {"-t", 3},
      {"-texres", 1}, {"-clamp", 1},  {"-bm", 1},    {"-imfchan", 1}, {"-type", 1}, {"-cc", 1}};
  for (;;) {
    l.skip_ws();
    const char* save = l.p;
    std::string_view tok = l.token();
    auto it = tok.size() > 1 && tok[0] == '-' ? max_args.find(std::string(tok)) : max_args.end();
    if (it == max_args.end()) {
      l.p = save;
      break;
    }
    for (int i = 0; i < it->second; ++i) {  // numeric arguments, or on/off words for a few
      const char* s2 = l.p;
      std::string_view a = l.token();
      double d;
      if (!(parse_number(a, d) || a == "on" || a == "off" || (i == 0 && it->first == "-imfchan") ||
            (i == 0 && it->first == "-type"))) {
        l.p = s2;
        break;
      }
    }
  }
  return fix_slashes(l.rest());
}

void read_mtl(const std::string& mtl_path, Polygon_soup& soup, std::unordered_map<std::string, int>& by_name) {
  const std::string data = slurp(mtl_path);
  const fs::path dir = fs::path(mtl_path).parent_path();
  int current = -1;
  for_each_line(data, [&](std::size_t line_no, const char* b, const char* e) {
    Line l{b, e};
    std::string_view key = l.token();
    if (key.empty() || key[0] == '#') return;
    if (key == "newmtl") {
      std::string name = l.rest();
      if (name.empty()) throw IO_error(mtl_path, line_no, "newmtl without a name");
      auto it = by_name.find(name);
      if (it != by_name.end()) {
        current = it->second;
      } else {
        current = int(soup.materials.size());
        soup.materials.emplace_back();
        soup.materials.back().name = name;
        by_name.emplace(name, current);
      }
      return;
    }
    if (current < 0) return;  // statements before the first newmtl have nothing to apply to
    Material& m = soup.materials[std::size_t(current)];
    if (key == "Kd") {
      for (int i = 0; i < 3; ++i) {
        double v;
        std::string_view t = l.token();
        if (!parse_number(t, v) || !std::isfinite(v))
          throw IO_error(mtl_path, line_no, "Kd needs three finite numbers");
        m.diffuse_color[std::size_t(i)] = v;
      }
    } else if (key == "map_Kd" || key == "map_Bump" || key == "map_bump" || key == "bump" || key == "norm" ||
               key == "map_Kn") {
      std::string name = texture_file_name(l);
      if (name.empty()) throw IO_error(mtl_path, line_no, std::string(key) + " without a file name");
      fs::path tex = fs::path(name).is_absolute() ? fs::path(name) : dir / name;
      std::error_code ec;
      if (!fs::is_regular_file(tex, ec))
        throw IO_error(mtl_path, line_no, "texture image '" + name + "' not found (looked for " + tex.string() + ")");
      const std::string abs = fs::absolute(tex).lexically_normal().string();
      if (key == "map_Kd")
        m.diffuse_texture = abs;
      else
        m.normal_texture = abs;
    }
  });
}

// Reads `data` on all cores (see Obj_chunk) into `soup` (holding only its source); `usemtl(name,
// line)` and `mtllib(text, line)` are the reader's handlers, called in file order, and
// `current_material` the material they set. Returns false, with `soup` in an unspecified state,
// when the serial reader must read the file.
template <class Usemtl, class Mtllib>
bool read_obj_in_chunks(std::string_view data, std::size_t chunk_bytes, Polygon_soup& soup, Usemtl usemtl,
                        Mtllib mtllib, int& current_material) {
  // chunks of about chunk_bytes, ending after a newline; their number depends on the size only
  const std::size_t n = (std::min)(std::size_t(4096), (std::max)(std::size_t(1), data.size() / chunk_bytes));
  std::vector<Obj_chunk> chunks(n);
  const char* const base = data.data();
  const char* const end = base + data.size();
  const char* at = base;
  for (std::size_t i = 0; i < n; ++i) {
    chunks[i].begin = at;
    const char* e = end;
    if (i + 1 < n) {
      const char* target = (std::max)(at, base + (i + 1) * (data.size() / n));
      const char* nl =
          target < end ? static_cast<const char*>(std::memchr(target, '\n', std::size_t(end - target))) : nullptr;
      e = nl ? nl + 1 : end;
    }
    chunks[i].end = e;
    at = e;
  }
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { count_obj_chunk(chunks[i]); });
  std::vector<std::size_t> positions(n + 1, 0), uvs(n + 1, 0), normals(n + 1, 0), lines(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    positions[i + 1] = positions[i] + chunks[i].positions;
    uvs[i + 1] = uvs[i] + chunks[i].uvs;
    normals[i + 1] = normals[i] + chunks[i].normals;
    lines[i + 1] = lines[i] + chunks[i].lines;
  }
  tbb::parallel_for(std::size_t(0), n,
                    [&](std::size_t i) { parse_obj_chunk(chunks[i], positions[i], uvs[i], normals[i]); });
  for (const Obj_chunk& c : chunks)
    if (!c.ok || c.part.positions.size() != c.positions || c.part.uvs.size() != c.uvs) return false;
  // materials in file order: each face's slot (its chunk's latest usemtl) becomes a material
  std::vector<int> at_start(n);
  std::vector<std::vector<int>> slot_material(n);
  for (std::size_t i = 0; i < n; ++i) {
    at_start[i] = current_material;
    for (const Obj_chunk::Event& e : chunks[i].events) {
      if (e.usemtl)
        usemtl(e.text, lines[i] + e.line);
      else
        mtllib(e.text, lines[i] + e.line);
      slot_material[i].push_back(current_material);
    }
  }
  std::vector<std::size_t> faces(n + 1, 0), corners(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    faces[i + 1] = faces[i] + chunks[i].part.number_of_faces();
    corners[i + 1] = corners[i] + chunks[i].part.corner_vertex.size();
  }
  if (corners[n] >= std::size_t(Polygon_soup::no_index)) return false;
  soup.positions.resize(positions[n]);
  soup.uvs.resize(uvs[n]);
  soup.face_start.resize(faces[n] + 1);
  soup.face_start[0] = 0;
  soup.corner_vertex.resize(corners[n]);
  soup.corner_uv.resize(corners[n]);
  soup.face_material.resize(faces[n]);
  soup.face_line.resize(faces[n]);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    Polygon_soup& part = chunks[i].part;
    std::copy(part.positions.begin(), part.positions.end(), soup.positions.begin() + std::ptrdiff_t(positions[i]));
    std::copy(part.uvs.begin(), part.uvs.end(), soup.uvs.begin() + std::ptrdiff_t(uvs[i]));
    std::copy(part.corner_vertex.begin(), part.corner_vertex.end(),
              soup.corner_vertex.begin() + std::ptrdiff_t(corners[i]));
    std::copy(part.corner_uv.begin(), part.corner_uv.end(), soup.corner_uv.begin() + std::ptrdiff_t(corners[i]));
    for (std::size_t f = 0; f < part.number_of_faces(); ++f) {
      const std::size_t g = faces[i] + f;
      soup.face_start[g + 1] = std::uint32_t(corners[i] + part.face_start[f + 1]);
      const int slot = part.face_material[f];
      soup.face_material[g] = slot < 0 ? at_start[i] : slot_material[i][std::size_t(slot)];
      soup.face_line[g] = lines[i] + part.face_line[f];
    }
    part = Polygon_soup();  // freed on the core that allocated it
  });
  // The chunks were allocated by the worker threads, in their own malloc arenas, which keep
  // what is freed: give it back, or a large file's chunks stay resident while its mesh is built.
  CMGeom::internal::release_freed_memory();
  return true;
}

}  // namespace

void read_obj(const std::string& path, Polygon_soup& soup, std::size_t chunk_bytes) {
  const File_bytes bytes(path);
  const std::string_view data = bytes.view();
  if (data.empty()) throw IO_error(path, "empty file");
  soup = Polygon_soup();
  soup.source = path;
  const fs::path dir = fs::path(path).parent_path();

  std::unordered_map<std::string, int> material_by_name;
  int current_material = -1;
  std::size_t n_normals = 0;
  std::size_t unknown_statements = 0;
  std::vector<long long> cv, ct;  // corners of the current face (vertex, texcoord) as written

  auto material_for = [&](const std::string& name) {
    auto it = material_by_name.find(name);
    if (it != material_by_name.end()) return it->second;
    const int id = int(soup.materials.size());
    soup.materials.emplace_back();
    soup.materials.back().name = name;
    material_by_name.emplace(name, id);
    return id;
  };
  auto usemtl = [&](const std::string& name, std::size_t line_no) {
    if (name.empty()) throw IO_error(path, line_no, "usemtl without a material name");
    current_material = material_for(name);
  };
  auto mtllib = [&](const std::string& text, std::size_t line_no) {
    // The name may contain spaces; several libraries may be listed. Try the whole rest first.
    std::string whole = fix_slashes(text);
    std::vector<std::string> names;
    std::error_code ec;
    if (fs::is_regular_file(dir / whole, ec)) {
      names.push_back(whole);
    } else {
      std::istringstream is(whole);
      for (std::string n; is >> n;) names.push_back(n);
    }
    for (const std::string& n : names) {
      const fs::path mp = fs::path(n).is_absolute() ? fs::path(n) : dir / n;
      if (!fs::is_regular_file(mp, ec)) {
        soup.warnings.push_back(path + ":" + std::to_string(line_no) + ": material library '" + n +
                                "' not found; materials keep their names only");
        continue;
      }
      read_mtl(mp.string(), soup, material_by_name);
    }
  };

  const bool in_chunks = chunk_bytes > 0 && data.size() >= chunk_bytes &&
                         read_obj_in_chunks(data, chunk_bytes, soup, usemtl, mtllib, current_material);
  if (!in_chunks) {  // a small file, or one the chunks gave up on: line by line, errors reported
    soup = Polygon_soup();
    soup.source = path;
    material_by_name.clear();
    current_material = -1;
    for_each_line(data, [&](std::size_t line_no, const char* b, const char* e) {
      Line l{b, e};
      // Binary garbage is rejected early with a clear message instead of a cascade of errors.
      for (const char* q = l.p; q < l.end; ++q)
        if (*q == '\0') throw IO_error(path, line_no, "binary data (NUL byte) in a text OBJ file");
      std::string_view key = l.token();
      if (key.empty() || key[0] == '#') return;
      if (key == "v") {
        std::array<double, 3> x;
        const std::string error = parse_vertex(l, x);
        if (!error.empty()) throw IO_error(path, line_no, error);
        soup.positions.push_back(x);
      } else if (key == "vt") {
        std::array<double, 2> t;
        const std::string error = parse_texcoord(l, t);
        if (!error.empty()) throw IO_error(path, line_no, error);
        soup.uvs.push_back(t);
      } else if (key == "vn") {
        const std::string error = parse_normal(l);
        if (!error.empty()) throw IO_error(path, line_no, error);
        ++n_normals;
      } else if (key == "f") {
        const std::string error = parse_face(l, soup.positions.size(), soup.uvs.size(), n_normals, cv, ct);
        if (!error.empty()) throw IO_error(path, line_no, error);
        // Polygons are kept whole here; build_textured_mesh() splits them into fans.
        add_face(soup, cv, ct, current_material, line_no);
      } else if (key == "usemtl") {
        usemtl(l.rest(), line_no);
      } else if (key == "mtllib") {
        mtllib(l.rest(), line_no);
      } else if (is_ignored_statement(key)) {
        // grouping, smoothing, free-form geometry: not part of the polygon mesh
      } else {
        // Exporters add their own statements (even a stray "V F 0" count line): skip them, say so.
        if (unknown_statements++ < 3)
          soup.warnings.push_back(path + ":" + std::to_string(line_no) + ": unknown OBJ statement '" +
                                  std::string(key.substr(0, 40)) + "' skipped");
      }
    });
  }
  if (unknown_statements > 3)
    soup.warnings.push_back(path + ": " + std::to_string(unknown_statements - 3) + " more unknown statements skipped");
  if (soup.number_of_faces() == 0) throw IO_error(path, "no faces in file");
  // Faces before any usemtl: material 0 when the file uses no material at all, otherwise a
  // "default" material is added for them.
  bool unassigned = false;
  for (int& fm : soup.face_material) unassigned |= fm < 0;
  if (unassigned) {
    const int def = soup.materials.empty() ? 0 : material_for("default");
    for (int& fm : soup.face_material)
      if (fm < 0) fm = def;
  }
}

// --------------------------------------------------------------------------------- writer

std::string copy_texture_file(const std::string& obj_path, const std::string& source, const std::string& suggested_name,
                              Atomic_output& out) {
  std::error_code ec;
  if (source.empty()) return std::string();
  if (!fs::is_regular_file(source, ec)) throw IO_error(source, "texture image not found");
  const fs::path dir = fs::path(obj_path).parent_path();
  const std::string name = suggested_name + fs::path(source).extension().string();
  const fs::path dest = dir / name;
  if (fs::exists(dest, ec) && fs::equivalent(dest, source, ec)) return name;  // already there
  const std::string tmp = out.add(dest.string());
  if (!fs::copy_file(source, tmp, fs::copy_options::overwrite_existing, ec))
    throw IO_error(dest.string(), "cannot copy texture: " + ec.message());
  return name;
}

void write_obj(const std::string& path, const Textured_mesh& tm, Atomic_output& out,
               const Texture_emitter& emit_texture) {
  using vertex_descriptor = Surface_mesh::Vertex_index;
  const Surface_mesh& m = tm.mesh();
  const fs::path obj(path);
  const std::string stem = obj.stem().string();
  std::string s;
  s.reserve(64 * (m.number_of_vertices() + m.number_of_faces()));
  s += "# written by CMGeom " CMGEOM_VERSION_STR "\n";

  const bool with_materials = !tm.materials().empty();
  std::string mtl;
  if (with_materials) {
    const std::string mtl_name = stem + ".mtl";
    s += "mtllib " + mtl_name + "\n";
    for (std::size_t i = 0; i < tm.materials().size(); ++i) {
      const Material& mat = tm.materials()[i];
      mtl += "newmtl " + mat.name + "\nKd ";
      for (int c = 0; c < 3; ++c) {
        append_double(mtl, mat.diffuse_color[std::size_t(c)]);
        mtl += c < 2 ? " " : "\n";
      }
      const std::string d = emit_texture(mat, i, "diffuse", out);
      if (!d.empty()) mtl += "map_Kd " + d + "\n";
      const std::string n = emit_texture(mat, i, "normal", out);
      if (!n.empty()) mtl += "map_Bump " + n + "\n";
    }
    const std::string mtl_tmp = out.add((obj.parent_path() / mtl_name).string());
    std::ofstream os(mtl_tmp, std::ios::binary);
    os << mtl;
    if (!os) throw IO_error(mtl_tmp, "write failed");
  }

  // Vertices in index order (a mesh read from a file keeps the file's order).
  std::vector<std::uint32_t> vid(m.number_of_vertices() + m.number_of_removed_vertices(), 0);
  std::uint32_t next = 1;
  for (vertex_descriptor v : m.vertices()) {
    vid[std::size_t(v)] = next++;
    const Point_3& p = m.point(v);
    s += "v ";
    append_double(s, p.x());
    s += ' ';
    append_double(s, p.y());
    s += ' ';
    append_double(s, p.z());
    s += '\n';
  }
  // Texture coordinates: one record per distinct (u, v) value, in face order.
  std::vector<std::uint32_t> hid;
  if (tm.has_uvs()) {
    struct Key_hash {
      std::size_t operator()(const std::pair<double, double>& k) const {
        return std::hash<double>()(k.first) * 1000003u ^ std::hash<double>()(k.second);
      }
    };
    std::unordered_map<std::pair<double, double>, std::uint32_t, Key_hash> uv_id;
    hid.assign(m.number_of_halfedges() + m.number_of_removed_halfedges(), 0);
    std::uint32_t next_uv = 1;
    for (auto f : m.faces())
      for (auto h : m.halfedges_around_face(m.halfedge(f))) {
        const Point_2 t = tm.uv(h);
        auto [it, inserted] = uv_id.emplace(std::make_pair(t.x(), t.y()), next_uv);
        if (inserted) {
          ++next_uv;
          s += "vt ";
          append_double(s, t.x());
          s += ' ';
          append_double(s, t.y());
          s += '\n';
        }
        hid[std::size_t(h)] = it->second;
      }
  }
  int current = -1;
  for (auto f : m.faces()) {
    if (with_materials && tm.material(f) != current) {
      current = tm.material(f);
      if (current >= 0 && std::size_t(current) < tm.materials().size())
        s += "usemtl " + tm.materials()[std::size_t(current)].name + "\n";
    }
    s += 'f';
    for (auto h : m.halfedges_around_face(m.halfedge(f))) {
      s += ' ';
      s += std::to_string(vid[std::size_t(m.target(h))]);
      if (tm.has_uvs()) {
        s += '/';
        s += std::to_string(hid[std::size_t(h)]);
      }
    }
    s += '\n';
  }
  write_bytes(out.add(path), path, s);
}

}  // namespace internal
}  // namespace IO
}  // namespace CMGeom
