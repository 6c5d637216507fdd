// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// meshoptimizer 0.18 (Debian's libmeshoptimizer) as a peer of CMGeom's textured simplification,
// run by run_textured_peers.py. Plain C++17, no CGAL, its own small OBJ reader:
//
//   meshopt018_simplify IN.obj OUT.obj --faces N [--mtl PATH]
//
// The OBJ (v, vt, f with v/vt or v/vt/vn corners, or a geometry-only OBJ whose corners are all v
// or v//vn; polygons split into fans, 1-based or negative indices) becomes an indexed vertex buffer in which a vertex
// is a unique (position, uv) pair (and material, when the file uses several): the buffer is split at UV seams, so
// meshopt_simplify sees the seams as attribute discontinuities and keeps them (seam vertices only move along the seam).
// meshopt_simplify runs to a target of 3N indices with an unlimited error (1e30), no option.
// The output keeps the original positions and UVs of the kept vertices, drops the unused ones,
// repeats the input's usemtl statements and names its material library by absolute path (or the
// MTL given by --mtl), so it wears the original texture; it is written atomically (temporary file +
// rename). One JSON line on stdout:
//   {"variant":"meshopt018","faces_in":..,"target_faces":..,"faces_out":..,"seconds":.., ...}
// (seconds: the meshopt_simplify call alone). Errors: one line on stderr, exit code 1 for bad input,
// 2 for bad usage; no partial output file is left.
#include <meshoptimizer.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct Usage_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
struct Input_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

constexpr std::uint32_t no_uv = 0xffffffffu;

const char* const usage_line = "usage: meshopt018_simplify IN.obj OUT.obj --faces N [--mtl PATH]";

struct Obj {
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<double, 2>> uvs;
  struct Tri {
    std::array<std::uint32_t, 3> p, t;
    int material;
  };
  std::vector<Tri> tris;
  std::vector<std::string> materials;  // in order of first use; "" = faces before any usemtl
  std::vector<std::string> mtllibs;    // as written
  bool geometry_only = false;          // no corner has a texture coordinate (t = no_uv)
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return std::string();
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::string where(const std::string& path, std::size_t line) { return path + ":" + std::to_string(line) + ": "; }

double parse_number(const std::string& tok, const std::string& path, std::size_t line, const char* what) {
  char* end = nullptr;
  const double x = tok.empty() ? 0.0 : std::strtod(tok.c_str(), &end);
  if (tok.empty() || end != tok.c_str() + tok.size() || !std::isfinite(x))
    throw Input_error(where(path, line) + what + " needs finite numbers, got '" + tok + "'");
  return x;
}

std::uint32_t parse_index(const std::string& tok, std::size_t count, const std::string& path, std::size_t line,
                          const char* what) {
  char* end = nullptr;
  const long long i = tok.empty() ? 0 : std::strtoll(tok.c_str(), &end, 10);
  if (tok.empty() || end != tok.c_str() + tok.size())
    throw Input_error(where(path, line) + "bad " + what + " index '" + tok + "'");
  const long long r = i > 0 ? i - 1 : (long long)count + i;
  if (i == 0 || r < 0 || r >= (long long)count)
    throw Input_error(where(path, line) + what + " index " + std::to_string(i) + " out of range (" +
                      std::to_string(count) + " defined so far)");
  return std::uint32_t(r);
}

Obj read_obj(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Input_error(path + ": cannot read");
  Obj obj;
  std::map<std::string, int> material_index;
  int current = -1;
  auto use_material = [&](const std::string& name) {
    auto it = material_index.find(name);
    if (it != material_index.end()) return it->second;
    const int id = int(obj.materials.size());
    obj.materials.push_back(name);
    material_index.emplace(name, id);
    return id;
  };
  std::string raw;
  std::size_t line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string line = trim(raw);
    if (line.empty() || line[0] == '#') continue;
    const auto sp = line.find_first_of(" \t");
    const std::string key = line.substr(0, sp);
    const std::string rest = sp == std::string::npos ? std::string() : trim(line.substr(sp + 1));
    std::istringstream is(rest);
    if (key == "v") {
      std::array<std::string, 3> t;
      is >> t[0] >> t[1] >> t[2];
      obj.positions.push_back({parse_number(t[0], path, line_no, "vertex"), parse_number(t[1], path, line_no, "vertex"),
                               parse_number(t[2], path, line_no, "vertex")});
    } else if (key == "vt") {
      std::string u, v;
      is >> u >> v;
      obj.uvs.push_back({parse_number(u, path, line_no, "texture coordinate"),
                         v.empty() ? 0.0 : parse_number(v, path, line_no, "texture coordinate")});
    } else if (key == "f") {
      std::vector<std::pair<std::uint32_t, std::uint32_t>> c;
      for (std::string s; is >> s;) {
        const auto s1 = s.find('/');
        if (s1 == std::string::npos || s1 + 1 >= s.size() || s[s1 + 1] == '/') {
          // a corner without texture coordinate: a geometry-only file has only such corners
          if (!obj.uvs.empty() || (!obj.tris.empty() && !obj.geometry_only))
            throw Input_error(where(path, line_no) + "face corner '" + s +
                              "' has no texture coordinate (v/vt or v/vt/vn needed)");
          obj.geometry_only = true;
          c.emplace_back(parse_index(s.substr(0, s1), obj.positions.size(), path, line_no, "vertex"), no_uv);
          continue;
        }
        if (obj.geometry_only)
          throw Input_error(where(path, line_no) + "face corner '" + s +
                            "' has a texture coordinate, earlier ones none");
        const auto s2 = s.find('/', s1 + 1);
        const std::string vt = s.substr(s1 + 1, s2 == std::string::npos ? std::string::npos : s2 - s1 - 1);
        c.emplace_back(parse_index(s.substr(0, s1), obj.positions.size(), path, line_no, "vertex"),
                       parse_index(vt, obj.uvs.size(), path, line_no, "texture coordinate"));
      }
      if (c.size() < 3)
        throw Input_error(where(path, line_no) + "face with " + std::to_string(c.size()) +
                          " corner(s); at least 3 needed");
      if (current < 0) current = use_material("");
      for (std::size_t k = 1; k + 1 < c.size(); ++k)
        obj.tris.push_back(
            {{c[0].first, c[k].first, c[k + 1].first}, {c[0].second, c[k].second, c[k + 1].second}, current});
    } else if (key == "usemtl") {
      if (rest.empty()) throw Input_error(where(path, line_no) + "usemtl without a material name");
      current = use_material(rest);
    } else if (key == "mtllib") {
      if (rest.empty()) throw Input_error(where(path, line_no) + "mtllib without a file name");
      obj.mtllibs.push_back(rest);
    }
  }
  if (obj.tris.empty()) throw Input_error(path + ": no faces");
  return obj;
}

// mtllib names resolved as CMGeom's reader does: the whole rest of the line if it names a file,
// else each whitespace-separated name.
std::vector<std::string> resolve_mtllibs(const std::string& obj_path, const std::vector<std::string>& libs) {
  const fs::path dir = fs::absolute(obj_path).parent_path();
  std::vector<std::string> out;
  for (std::string whole : libs) {
    std::replace(whole.begin(), whole.end(), '\\', '/');
    std::error_code ec;
    std::vector<std::string> names;
    if (fs::is_regular_file(dir / whole, ec)) {
      names.push_back(whole);
    } else {
      std::istringstream is(whole);
      for (std::string n; is >> n;) names.push_back(n);
    }
    for (const std::string& n : names) {
      const fs::path p = (dir / n).lexically_normal();  // dir / absolute = absolute
      if (!fs::is_regular_file(p, ec))
        std::cerr << "meshopt018_simplify: warning: " << obj_path << ": material library '" << n
                  << "' not found (looked for " << p.string() << ")\n";
      out.push_back(p.string());
    }
  }
  return out;
}

std::string first_material_name(const std::string& mtl) {
  std::ifstream in(mtl);
  for (std::string line; std::getline(in, line);) {
    std::istringstream is(line);
    std::string key;
    is >> key;
    if (key == "newmtl") {
      std::string rest;
      std::getline(is, rest);
      rest = trim(rest);
      if (!rest.empty()) return rest;
    }
  }
  throw Input_error(mtl + ": no newmtl statement");
}

std::string number(double x) {  // shortest text that reads back as x
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

void write_atomically(const std::string& path, const std::string& content) {
  const fs::path target(path);
  const fs::path tmp =
      fs::absolute(target).parent_path() / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary);
    out << content;
    out.close();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw Input_error(path + ": cannot write");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Input_error(path + ": cannot write (" + ec.message() + ")");
  }
}

int run(int argc, char** argv) {
  std::vector<std::string> pos;
  long long faces = -1;
  std::string mtl;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--faces" || a == "--mtl") {
      if (i + 1 >= argc) throw Usage_error(a + " needs a value");
      const std::string v = argv[++i];
      if (a == "--mtl") {
        mtl = v;
        continue;
      }
      char* end = nullptr;
      faces = std::strtoll(v.c_str(), &end, 10);
      if (v.empty() || end != v.c_str() + v.size() || faces < 1 ||
          v.find_first_not_of("0123456789") != std::string::npos)
        throw Usage_error("--faces needs a positive integer, got '" + v + "'");
    } else if (a.size() > 1 && a[0] == '-') {
      throw Usage_error("unknown option " + a);
    } else {
      pos.push_back(a);
    }
  }
  if (pos.size() != 2) throw Usage_error("expected IN.obj and OUT.obj");
  if (faces < 0) throw Usage_error("--faces is required");
  std::string mtl_override;
  if (!mtl.empty()) {
    std::error_code ec;
    mtl_override = fs::absolute(mtl).lexically_normal().string();
    if (!fs::is_regular_file(mtl_override, ec)) throw Usage_error("--mtl: no file " + mtl_override);
  }

  const Obj obj = read_obj(pos[0]);

  // vertex buffer split at UV seams: positions and UVs identified by value (an OBJ may repeat a
  // value under two indices), one vertex per distinct (position, uv[, material])
  std::map<std::array<double, 3>, std::uint32_t> pos_id;
  std::map<std::array<double, 2>, std::uint32_t> uv_id;
  std::vector<std::uint32_t> canon_pos(obj.positions.size()), canon_uv(obj.uvs.size());
  for (std::size_t i = 0; i < obj.positions.size(); ++i)
    canon_pos[i] = pos_id.emplace(obj.positions[i], std::uint32_t(pos_id.size())).first->second;
  for (std::size_t i = 0; i < obj.uvs.size(); ++i)
    canon_uv[i] = uv_id.emplace(obj.uvs[i], std::uint32_t(uv_id.size())).first->second;
  const bool multi_material = obj.materials.size() > 1;
  std::map<std::array<std::uint32_t, 3>, std::uint32_t> vertex_id;
  std::vector<std::uint32_t> v_pos, v_uv;
  std::vector<int> v_mat;
  std::vector<float> xyz;
  std::vector<unsigned int> indices;
  indices.reserve(obj.tris.size() * 3);
  for (const Obj::Tri& t : obj.tris)
    for (int c = 0; c < 3; ++c) {
      const std::array<std::uint32_t, 3> key{canon_pos[t.p[c]], t.t[c] == no_uv ? 0u : canon_uv[t.t[c]],
                                             multi_material ? std::uint32_t(t.material) : 0u};
      auto it = vertex_id.find(key);
      if (it == vertex_id.end()) {
        it = vertex_id.emplace(key, std::uint32_t(v_pos.size())).first;
        v_pos.push_back(t.p[c]);
        v_uv.push_back(t.t[c]);
        v_mat.push_back(t.material);
        const auto& p = obj.positions[t.p[c]];
        xyz.insert(xyz.end(), {float(p[0]), float(p[1]), float(p[2])});
      }
      indices.push_back(it->second);
    }

  const std::size_t faces_in = obj.tris.size();
  const std::size_t target_index_count = 3 * std::min<std::size_t>(std::size_t(faces), faces_in);
  std::vector<unsigned int> result(indices.size());
  float result_error = 0.f;
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = meshopt_simplify(result.data(), indices.data(), indices.size(), xyz.data(), v_pos.size(),
                                         3 * sizeof(float), target_index_count, 1e30f, 0, &result_error);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.resize(n);

  std::vector<std::string> mtl_paths =
      mtl_override.empty() ? resolve_mtllibs(pos[0], obj.mtllibs) : std::vector<std::string>{mtl_override};
  std::vector<std::string> names = obj.materials;
  if (names.size() == 1 && names[0].empty() && !mtl_override.empty()) names[0] = first_material_name(mtl_override);

  std::string vs, vts, fs_;
  std::unordered_map<std::uint32_t, std::uint32_t> out_pos, out_uv;  // obj index -> output index (1-based)
  const std::string* current = nullptr;
  for (std::size_t i = 0; i < n; i += 3) {
    const std::string& name = names[std::size_t(v_mat[result[i]])];
    if ((current == nullptr || *current != name) && !name.empty()) fs_ += "usemtl " + name + "\n";
    current = &name;
    fs_ += "f";
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = result[i + std::size_t(k)];
      auto p = out_pos.emplace(v_pos[v], std::uint32_t(out_pos.size() + 1));
      if (p.second) {
        const auto& x = obj.positions[v_pos[v]];
        vs += "v " + number(x[0]) + " " + number(x[1]) + " " + number(x[2]) + "\n";
      }
      if (obj.geometry_only) {
        fs_ += " " + std::to_string(p.first->second);
        continue;
      }
      auto t = out_uv.emplace(v_uv[v], std::uint32_t(out_uv.size() + 1));
      if (t.second) {
        const auto& u = obj.uvs[v_uv[v]];
        vts += "vt " + number(u[0]) + " " + number(u[1]) + "\n";
      }
      fs_ += " " + std::to_string(p.first->second) + "/" + std::to_string(t.first->second);
    }
    fs_ += "\n";
  }
  std::string text = "# meshoptimizer " + std::to_string(MESHOPTIMIZER_VERSION / 1000) + "." +
                     std::to_string(MESHOPTIMIZER_VERSION % 1000 / 10) +
                     " meshopt_simplify, vertex buffer split at UV seams\n";
  text += "# input " + fs::absolute(pos[0]).lexically_normal().string() + ": " + std::to_string(faces_in) +
          " faces, target " + std::to_string(faces) + ", output " + std::to_string(n / 3) + "\n";
  for (const std::string& m : mtl_paths) text += "mtllib " + m + "\n";
  text += vs + vts + fs_;
  write_atomically(pos[1], text);

  std::cout << "{\"variant\":\"meshopt018\",\"faces_in\":" << faces_in << ",\"target_faces\":" << faces
            << ",\"faces_out\":" << n / 3 << ",\"seconds\":" << number(seconds) << ",\"vertices_in\":" << v_pos.size()
            << ",\"result_error\":" << number(double(result_error)) << ",\"meshoptimizer\":\""
            << MESHOPTIMIZER_VERSION / 1000 << "." << MESHOPTIMIZER_VERSION % 1000 / 10 << "\"}" << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const Usage_error& e) {
    std::cerr << "meshopt018_simplify: error: " << e.what() << "\n" << usage_line << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "meshopt018_simplify: error: " << e.what() << "\n";
    return 1;
  }
}
