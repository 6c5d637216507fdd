// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Reading and writing *Cages system files (thesis §5.3), the JSON format of `cmgeom deform`,
// `cmgeom influence` and `cmgeom cm deform`: read_cage_system(), parse_cage_system(),
// write_cage_system(), read_polygons(), read_triangle_cage(). A file lists the join coordinates,
// a default h and the cages, each with its rest cage (a file or inline polygons, fan-triangulated
// in the order given), optional deformed pose, coordinates, h, per-border h (§5.5) and parent
// links (§5.3.4); paths are relative to the JSON file. Key choice: every key must be known (a typo
// is an error, not a silent default) and everything is validated; every error is one
// CMGeom::IO_error naming the file and the JSON pointer of the bad value. Input of any bytes gives
// a description or such an error. Complexity: O(input size + Σ m_i log m_i).
//
// Manual: doc/Cage_deformation/README.md, "`cmgeom deform`".
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_IO_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_IO_H

#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// Vertex positions and polygons (corners in file order) of any mesh file the project reads
/// (CMGeom::IO::read_polygon_soup: OBJ, OFF, PLY, glTF); throws IO_error on bad files.
template <class Index>
void read_polygons(const std::string& path, std::vector<Vec3>& points, std::vector<std::vector<Index>>& polygons) {
  const Polygon_soup soup = IO::read_polygon_soup(path);
  points.assign(soup.positions.begin(), soup.positions.end());
  polygons.clear();
  for (std::size_t f = 0; f < soup.number_of_faces(); ++f)
    polygons.emplace_back(soup.corner_vertex.begin() + soup.face_start[f],
                          soup.corner_vertex.begin() + soup.face_start[f + 1]);
}

/// A cage file as a Triangle_cage (polygons fan-triangulated in file order), not yet validated.
inline Triangle_cage read_triangle_cage(const std::string& path) {
  std::vector<Vec3> pts;
  std::vector<std::vector<std::uint32_t>> polys;
  read_polygons(path, pts, polys);
  return make_triangle_cage(pts, polys);
}

namespace internal {

class Cage_system_reader {
public:
  using json = nlohmann::json;

  Cage_system_reader(std::string source, std::string base_dir)
      : source_(std::move(source)), dir_(std::move(base_dir)) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& msg) const {
    throw IO_error(source_, (pointer.empty() ? std::string("/") : pointer) + ": " + msg);
  }

  Cage_system_description parse(const std::string& text) {
    json j;
    try {
      j = json::parse(text.begin(), text.end(), nullptr, true, false);
    } catch (const json::exception& e) {
      throw IO_error(source_, std::string("invalid JSON: ") + one_line(e.what()));
    }
    Cage_system_description d;
    d.source = source_;
    if (!j.is_object()) fail("", "expected a JSON object with an array \"cages\"");
    known_keys(j, "", {"cages", "join_coordinates", "join_harmonic", "h"});
    double default_h = 1.0;
    if (j.contains("h")) default_h = h_value(j["h"], "/h");
    if (j.contains("join_coordinates")) {
      d.join_coordinates = coordinate_type(j["join_coordinates"], "/join_coordinates");
      if (d.join_coordinates == Coordinate_type::green)
        fail("/join_coordinates", "join cages need C1 coordinates: mean_value or harmonic");
    }
    if (j.contains("join_harmonic")) d.join_harmonic = harmonic(j["join_harmonic"], "/join_harmonic");
    if (!j.contains("cages") || !j["cages"].is_array() || j["cages"].empty())
      fail("/cages", "expected a non-empty array of cages");
    const json& cages = j["cages"];
    for (std::size_t i = 0; i < cages.size(); ++i)
      d.cages.push_back(cage(cages[i], "/cages/" + std::to_string(i), default_h));
    links(cages, d);
    return d;
  }

private:
  static std::string one_line(std::string s) {
    for (char& c : s)
      if (c == '\n' || c == '\r') c = ' ';
    return s;
  }

  void known_keys(const json& o, const std::string& ptr, std::initializer_list<const char*> keys) const {
    for (auto it = o.begin(); it != o.end(); ++it) {
      bool ok = false;
      for (const char* k : keys) ok = ok || it.key() == k;
      if (!ok) fail(ptr + "/" + escape(it.key()), "unknown key");
    }
  }

  // JSON pointer escaping (RFC 6901); control characters are shown as '?' to keep one line.
  static std::string escape(const std::string& k) {
    std::string r;
    for (char c : k.substr(0, 64)) {
      if (c == '~')
        r += "~0";
      else if (c == '/')
        r += "~1";
      else if (static_cast<unsigned char>(c) < 0x20)
        r += '?';
      else
        r += c;
    }
    if (k.size() > 64) r += "...";
    return r;
  }

  double number(const json& v, const std::string& ptr) const {
    if (!v.is_number()) fail(ptr, "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x)) fail(ptr, "must be a finite number");
    return x;
  }

  std::uint32_t index(const json& v, const std::string& ptr, std::size_t bound) const {
    if (!v.is_number_integer()) fail(ptr, "must be a non-negative integer");
    if (v.is_number_unsigned() ? v.get<std::uint64_t>() >= bound
                               : (v.get<std::int64_t>() < 0 || std::uint64_t(v.get<std::int64_t>()) >= bound))
      fail(ptr, "index out of range (must be below " + std::to_string(bound) + ")");
    return std::uint32_t(v.get<std::uint64_t>());
  }

  double h_value(const json& v, const std::string& ptr) const {
    const double h = v.is_number() ? v.get<double>() : -1.0;
    if (!(h > 0 && h <= 1)) fail(ptr, "must be a number in (0, 1]");
    return h;
  }

  Coordinate_type coordinate_type(const json& v, const std::string& ptr) const {
    const std::string s = v.is_string() ? v.get<std::string>() : std::string();
    if (s == "mean_value") return Coordinate_type::mean_value;
    if (s == "green") return Coordinate_type::green;
    if (s == "harmonic") return Coordinate_type::harmonic;
    fail(ptr, "unknown coordinates (expected \"mean_value\", \"green\" or \"harmonic\")");
  }

  Harmonic_options harmonic(const json& v, const std::string& ptr) const {
    Harmonic_options o;
    if (!v.is_object()) fail(ptr, "must be an object");
    known_keys(v, ptr, {"resolution", "interpolation", "outside"});
    if (v.contains("resolution")) {
      const json& r = v["resolution"];
      if (!r.is_number_integer() || r.get<std::int64_t>() < 8 || r.get<std::int64_t>() > 512)
        fail(ptr + "/resolution", "must be an integer in [8, 512]");
      o.resolution = int(r.get<std::int64_t>());
    }
    // (a key whose value is one of two names)
    auto choice = [&](const char* key, const char* first, const char* second) {
      const json& c = v[key];
      const std::string s = c.is_string() ? c.get<std::string>() : "";
      if (s != first && s != second)
        fail(ptr + "/" + key, std::string("must be \"") + first + "\" or \"" + second + "\"");
      return s == first;
    };
    if (v.contains("interpolation"))
      o.interpolation = choice("interpolation", "tricubic", "trilinear") ? Harmonic_interpolation::tricubic
                                                                         : Harmonic_interpolation::trilinear;
    if (v.contains("outside"))
      o.outside =
          choice("outside", "undefined", "mean_value") ? Harmonic_outside::undefined : Harmonic_outside::mean_value;
    return o;
  }

  std::string file_path(const json& v) const {
    std::filesystem::path p = v.get<std::string>();
    return (p.is_absolute() || dir_.empty() ? p : std::filesystem::path(dir_) / p).string();
  }

  std::vector<Vec3> points(const json& v, const std::string& ptr) const {
    if (!v.is_array()) fail(ptr, "must be an array of [x, y, z] positions");
    std::vector<Vec3> r;
    r.reserve(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string pi = ptr + "/" + std::to_string(i);
      if (!v[i].is_array() || v[i].size() != 3) fail(pi, "must be an array of 3 numbers");
      r.push_back({number(v[i][0], pi + "/0"), number(v[i][1], pi + "/1"), number(v[i][2], pi + "/2")});
    }
    return r;
  }

  Triangle_cage rest_cage(const json& v, const std::string& ptr, std::string& src) const {
    std::vector<Vec3> pts;
    std::vector<std::vector<std::uint32_t>> polys;
    if (v.is_string()) {
      src = file_path(v);
      try {
        read_polygons(src, pts, polys);
      } catch (const std::exception& e) {
        fail(ptr, one_line(e.what()));
      }
    } else if (v.is_object()) {
      src = "inline";
      known_keys(v, ptr, {"vertices", "faces"});
      if (!v.contains("vertices")) fail(ptr + "/vertices", "missing");
      if (!v.contains("faces")) fail(ptr + "/faces", "missing");
      pts = points(v["vertices"], ptr + "/vertices");
      const json& f = v["faces"];
      if (!f.is_array()) fail(ptr + "/faces", "must be an array of polygons");
      for (std::size_t i = 0; i < f.size(); ++i) {
        const std::string pi = ptr + "/faces/" + std::to_string(i);
        if (!f[i].is_array() || f[i].size() < 3) fail(pi, "must be an array of at least 3 vertex indices");
        std::vector<std::uint32_t> poly;
        for (std::size_t k = 0; k < f[i].size(); ++k)
          poly.push_back(index(f[i][k], pi + "/" + std::to_string(k), pts.size()));
        polys.push_back(std::move(poly));
      }
    } else {
      fail(ptr, "must be a file name or an object {\"vertices\", \"faces\"}");
    }
    try {
      return make_triangle_cage(pts, polys);
    } catch (const std::exception& e) {
      fail(ptr, one_line(e.what()));
    }
  }

  Cage_description cage(const json& c, const std::string& ptr, double default_h) const {
    if (!c.is_object()) fail(ptr, "must be an object");
    known_keys(c, ptr, {"name", "rest", "deformed", "coordinates", "harmonic", "h", "border_h", "parent"});
    Cage_description d;
    d.h = default_h;
    if (c.contains("name")) {
      if (!c["name"].is_string()) fail(ptr + "/name", "must be a string");
      d.name = c["name"].get<std::string>();
    }
    if (!c.contains("rest")) fail(ptr + "/rest", "missing (a file name or inline vertices and faces)");
    d.rest = rest_cage(c["rest"], ptr + "/rest", d.rest_source);
    try {
      d.reoriented = validate_cage(d.rest, d.rest_source);
    } catch (const std::exception& e) {
      fail(ptr + "/rest", one_line(e.what()));
    }
    d.deformed = d.rest.vertices;
    if (c.contains("deformed")) {
      const json& v = c["deformed"];
      const std::string p = ptr + "/deformed";
      if (v.is_string()) {
        const std::string file = file_path(v);
        std::vector<std::vector<std::uint32_t>> polys;
        try {
          read_polygons(file, d.deformed, polys);
        } catch (const std::exception& e) {
          fail(p, one_line(e.what()));
        }
        // Only positions are used; a file listing other faces (QMVC's Beast) is accepted.
        bool same = !polys.empty();
        try {
          Triangle_cage t = make_triangle_cage(d.deformed, polys);
          if (d.reoriented)
            for (auto& tr : t.triangles) std::swap(tr[1], tr[2]);
          same = same && t.triangles == d.rest.triangles;
        } catch (const std::exception&) {
          same = false;
        }
        if (!same)
          d.warnings.push_back(file + ": faces differ from the rest cage's; the rest cage's triangles are used");
      } else {
        d.deformed = points(v, p);
      }
      if (d.deformed.size() != d.rest.vertices.size())
        fail(p, "has " + std::to_string(d.deformed.size()) + " vertices and the rest cage has " +
                    std::to_string(d.rest.vertices.size()) + ": they must have the same vertices");
      for (std::size_t i = 0; i < d.deformed.size(); ++i)
        for (double x : d.deformed[i])
          if (!std::isfinite(x)) fail(p, "vertex " + std::to_string(i) + " is not finite");
    }
    if (c.contains("coordinates")) d.coordinates = coordinate_type(c["coordinates"], ptr + "/coordinates");
    if (c.contains("harmonic")) d.harmonic = harmonic(c["harmonic"], ptr + "/harmonic");
    if (c.contains("h")) d.h = h_value(c["h"], ptr + "/h");
    return d;
  }

  // Parent links: resolved after every cage is read, so that names can refer forwards.
  void links(const json& cages, Cage_system_description& d) const {
    std::map<std::string, std::size_t> by_name;
    for (std::size_t i = 0; i < d.cages.size(); ++i)
      if (!d.cages[i].name.empty() && !by_name.emplace(d.cages[i].name, i).second)
        fail("/cages/" + std::to_string(i) + "/name", "duplicate cage name");
    auto cage_ref = [&](const json& c, const std::string& p) {
      if (c.is_string()) {
        auto it = by_name.find(c.get<std::string>());
        if (it == by_name.end()) fail(p, "no cage has this name");
        return it->second;
      }
      return std::size_t(index(c, p, d.cages.size()));
    };
    for (std::size_t i = 0; i < d.cages.size(); ++i) {
      if (!cages[i].contains("border_h")) continue;
      const std::string ptr = "/cages/" + std::to_string(i) + "/border_h";
      const json& bs = cages[i]["border_h"];
      if (!bs.is_array()) fail(ptr, "must be an array of {\"cage\", \"h\"}");
      for (std::size_t k = 0; k < bs.size(); ++k) {
        const std::string bp = ptr + "/" + std::to_string(k);
        if (!bs[k].is_object()) fail(bp, "must be an object {\"cage\", \"h\"}");
        known_keys(bs[k], bp, {"cage", "h"});
        if (!bs[k].contains("cage")) fail(bp + "/cage", "missing");
        if (!bs[k].contains("h")) fail(bp + "/h", "missing");
        Cage_border_h b;
        b.cage = cage_ref(bs[k]["cage"], bp + "/cage");
        if (b.cage == i) fail(bp + "/cage", "a cage has no border with itself");
        for (const Cage_border_h& o : d.cages[i].border_h)
          if (o.cage == b.cage) fail(bp + "/cage", "this border is given twice");
        b.h = h_value(bs[k]["h"], bp + "/h");
        d.cages[i].border_h.push_back(b);
      }
    }
    for (std::size_t i = 0; i < d.cages.size(); ++i) {
      if (!cages[i].contains("parent")) continue;
      const std::string ptr = "/cages/" + std::to_string(i) + "/parent";
      const json& p = cages[i]["parent"];
      std::vector<std::pair<const json*, std::string>> items;
      if (p.is_array()) {
        for (std::size_t k = 0; k < p.size(); ++k) items.push_back({&p[k], ptr + "/" + std::to_string(k)});
      } else {
        items.push_back({&p, ptr});
      }
      std::vector<char> owned(d.cages[i].rest.vertices.size(), 0);
      for (const auto& [l, lp] : items) {
        if (!l->is_object()) fail(lp, "must be an object {\"cage\", \"vertices\"}");
        known_keys(*l, lp, {"cage", "vertices"});
        if (!l->contains("cage")) fail(lp + "/cage", "missing");
        const json& c = (*l)["cage"];
        Cage_parent_link link;
        link.cage = cage_ref(c, lp + "/cage");
        if (link.cage == i) fail(lp + "/cage", "a cage cannot be its own parent");
        const std::size_t n = d.cages[i].rest.vertices.size();
        if (l->contains("vertices")) {
          const json& vs = (*l)["vertices"];
          if (!vs.is_array()) fail(lp + "/vertices", "must be an array of vertex indices");
          for (std::size_t k = 0; k < vs.size(); ++k)
            link.vertices.push_back(index(vs[k], lp + "/vertices/" + std::to_string(k), n));
        } else {
          for (std::uint32_t k = 0; k < n; ++k) link.vertices.push_back(k);
        }
        for (std::size_t k = 0; k < link.vertices.size(); ++k)
          if (owned[link.vertices[k]]++)
            fail(lp + "/vertices",
                 "vertex " + std::to_string(link.vertices[k]) + " is owned twice (a vertex has at most one parent)");
        d.cages[i].parents.push_back(std::move(link));
      }
    }
    // Cycle check (iterative colouring: a deep chain cannot overflow the stack).
    std::vector<int> state(d.cages.size(), 0);  // 0 new, 1 on stack, 2 done
    for (std::size_t s = 0; s < d.cages.size(); ++s) {
      if (state[s]) continue;
      std::vector<std::pair<std::size_t, std::size_t>> stack{{s, 0}};
      state[s] = 1;
      while (!stack.empty()) {
        auto& [c, k] = stack.back();
        if (k == d.cages[c].parents.size()) {
          state[c] = 2;
          stack.pop_back();
          continue;
        }
        const std::size_t p = d.cages[c].parents[k++].cage;
        if (state[p] == 1) fail("/cages/" + std::to_string(c) + "/parent", "the parent links form a cycle");
        if (state[p] == 0) {
          state[p] = 1;
          stack.push_back({p, 0});
        }
      }
    }
  }

  std::string source_, dir_;
};

}  // namespace internal

/// Parses a cage-system JSON text; `source` names it in messages and `base_dir` resolves
/// relative cage file names. Throws IO_error (one line: source, JSON pointer, what).
inline Cage_system_description parse_cage_system(const std::string& text, const std::string& source,
                                                 const std::string& base_dir = std::string()) {
  return internal::Cage_system_reader(source, base_dir).parse(text);
}

/// Reads and validates a cage-system JSON file (format above).
inline Cage_system_description read_cage_system(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IO_error(path, "cannot open the cage-system file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw IO_error(path, "cannot read the cage-system file");
  return parse_cage_system(ss.str(), path, std::filesystem::path(path).parent_path().string());
}

/// The description as JSON with inline cages (rest vertices and triangles, deformed positions),
/// so that read_cage_system() reads it back to the same cages. Numbers are printed with 17
/// significant digits (exact round trip).
inline nlohmann::ordered_json cage_system_to_json(const Cage_system_description& d) {
  using oj = nlohmann::ordered_json;
  auto harmonic = [](const Harmonic_options& o) {
    oj h;
    h["resolution"] = o.resolution;
    h["interpolation"] = o.interpolation == Harmonic_interpolation::tricubic ? "tricubic" : "trilinear";
    if (o.outside == Harmonic_outside::mean_value) h["outside"] = "mean_value";
    return h;
  };
  oj j;
  j["join_coordinates"] = to_string(d.join_coordinates);
  if (d.join_coordinates == Coordinate_type::harmonic) j["join_harmonic"] = harmonic(d.join_harmonic);
  oj cages = oj::array();
  for (const Cage_description& c : d.cages) {
    oj o;
    if (!c.name.empty()) o["name"] = c.name;
    oj rest;
    rest["vertices"] = c.rest.vertices;
    rest["faces"] = c.rest.triangles;
    o["rest"] = rest;
    o["deformed"] = c.deformed;
    o["coordinates"] = to_string(c.coordinates);
    if (c.coordinates == Coordinate_type::harmonic) o["harmonic"] = harmonic(c.harmonic);
    o["h"] = c.h;
    if (!c.border_h.empty()) {
      oj bs = oj::array();
      for (const Cage_border_h& b : c.border_h) bs.push_back({{"cage", b.cage}, {"h", b.h}});
      o["border_h"] = bs;
    }
    if (!c.parents.empty()) {
      oj ps = oj::array();
      for (const Cage_parent_link& l : c.parents) ps.push_back({{"cage", l.cage}, {"vertices", l.vertices}});
      o["parent"] = ps;
    }
    cages.push_back(o);
  }
  j["cages"] = cages;
  return j;
}

namespace internal {
// Indented JSON with arrays of scalars on one line ("[0.5, 1, 2]"), so that a written system
// keeps one line per vertex and stays easy to edit by hand.
inline void print_compact(std::string& out, const nlohmann::ordered_json& j, int indent) {
  const auto scalar_array = [](const nlohmann::ordered_json& a) {
    for (const auto& x : a)
      if (x.is_structured()) return false;
    return true;
  };
  if (j.is_object()) {
    if (j.empty()) {
      out += "{}";
      return;
    }
    out += "{\n";
    std::size_t k = 0;
    for (auto it = j.begin(); it != j.end(); ++it, ++k) {
      out.append(std::size_t(indent + 1), ' ');
      out += nlohmann::ordered_json(it.key()).dump() + ": ";
      print_compact(out, it.value(), indent + 1);
      out += k + 1 < j.size() ? ",\n" : "\n";
    }
    out.append(std::size_t(indent), ' ');
    out += "}";
  } else if (j.is_array() && !scalar_array(j)) {
    out += "[\n";
    for (std::size_t k = 0; k < j.size(); ++k) {
      out.append(std::size_t(indent + 1), ' ');
      print_compact(out, j[k], indent + 1);
      out += k + 1 < j.size() ? ",\n" : "\n";
    }
    out.append(std::size_t(indent), ' ');
    out += "]";
  } else {
    std::string s = j.dump();
    bool numbers = j.is_array();
    for (const auto& x : j) numbers = numbers && x.is_number();
    if (numbers) {  // "[1,2,3]" -> "[1, 2, 3]"
      std::string t;
      for (char c : s) {
        t += c;
        if (c == ',') t += ' ';
      }
      s = t;
    }
    out += s;
  }
}
}  // namespace internal

/// Writes cage_system_to_json(d) to `path` atomically (no partial file on failure).
inline void write_cage_system(const std::string& path, const Cage_system_description& d) {
  std::string text;
  internal::print_compact(text, cage_system_to_json(d), 0);
  IO::write_file_atomically(path, text + "\n");
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_IO_H
