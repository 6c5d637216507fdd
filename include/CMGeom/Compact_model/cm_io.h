// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The CM file (thesis §4.4.3: vertices, coefficient lists, normals, cone-type vertices, and faces
// as (vertex, coefficient list, normal) triples): write_cm(), read_cm(), parse_cm(), cm_bytes(),
// texture_path(). Binary, little-endian, ending with an FNV-1a checksum (fnv1a64(): offset basis
// 1469598103934665603, not the usual 14695981039346656037). Version 2 is written, versions 1 and
// 2 are read here, and version 3 (cm_compact_io.h) is read by parse_cm()/read_cm()
// too. Version 2 is a CMGeom change to the thesis' layout (same model, same numbers): a corner
// stores its vertex and, where the vertex has several sectors, a sector number, instead of three
// indices; a model with a vertex of more than 255 sectors is written as version 1. A model's level
// error table (Compact_model::level_errors), when it has one, follows the uvs (flag bit 2), and
// its reconstruction level (Compact_model::reconstruction_level), when set, is the last byte
// before the checksum (flag bit 3).
// Reading checks every count against the file size before allocating and every index and number
// after, throws CMGeom::IO_error (file, what) on the first failure and returns no partial model;
// write_cm() is atomic. Complexity: O(file size) (writing: O(F log F)).
//
// Manual: doc/Compact_model/README.md, "CM file format (versions 1 and 2, little-endian)".
#ifndef CMGEOM_COMPACT_MODEL_CM_IO_H
#define CMGEOM_COMPACT_MODEL_CM_IO_H

#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace CM {

namespace internal {

constexpr char cm_magic[8] = {'C', 'M', 'G', 'E', 'O', 'M', 'C', 'M'};
constexpr std::uint32_t cm_version = 2;  // the version written
constexpr std::size_t cm_header_size = 56;

inline std::uint64_t fnv1a64(const unsigned char* data, std::size_t n) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < n; ++i) {
    h ^= data[i];
    h *= 1099511628211ull;
  }
  return h;
}

// Little-endian writer/reader, independent of the host byte order.
struct Le_writer {
  std::string out;
  void u8(std::uint8_t v) { out.push_back(char(v)); }
  void u32(std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xffu));
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(char((v >> (8 * i)) & 0xffu));
  }
  void f32(double d) {
    const float f = float(d);
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    u32(v);
  }
  void f64(double d) {  // the compact file's header (cm_compact_io.h)
    std::uint64_t v;
    std::memcpy(&v, &d, 8);
    u64(v);
  }
};

struct Le_reader {
  const unsigned char* p;
  std::size_t n, pos = 0;
  const std::string& file;
  void need(std::size_t k, const char* what) const {
    if (k > n - pos)
      throw IO_error(file, std::string("truncated file: ") + what + " needs " + std::to_string(k) +
                               " bytes at offset " + std::to_string(pos) + ", " + std::to_string(n - pos) + " left");
  }
  std::uint8_t u8() { return p[pos++]; }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t(p[pos + i]) << (8 * i);
    pos += 4;
    return v;
  }
  std::uint64_t u64() {
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= std::uint64_t(p[pos + i]) << (8 * i);
    pos += 8;
    return v;
  }
  double f32() {
    const std::uint32_t v = u32();
    float f;
    std::memcpy(&f, &v, 4);
    return double(f);
  }
  double f64() {
    const std::uint64_t v = u64();
    double d;
    std::memcpy(&d, &v, 8);
    return d;
  }
};

}  // namespace internal

namespace internal {

/// Version 2's sector layout of a model (see the file comment): per vertex, its distinct
/// (coefficient list, normal) pairs in increasing order, and each corner's number in its vertex's
/// list. False when a vertex has more than 255 (the model is then written as version 1).
struct Cm_sectors {
  std::vector<std::uint8_t> count;                             // k_v
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;  // vertex by vertex
  std::vector<std::uint8_t> corner;                            // 3F sector numbers
  bool implicit = false;                                       // pairs[k] == (k, k), N = S = K
};

inline bool cm_sectors(const Compact_model& m, Cm_sectors& out) {
  struct Item {
    std::uint32_t v, s, n, corner;
  };
  std::vector<Item> items;
  items.reserve(3 * m.faces.size());
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Corner& c = m.faces[f][k];
      items.push_back({c.vertex, c.surface, c.normal, std::uint32_t(3 * f + std::size_t(k))});
    }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return a.v != b.v ? a.v < b.v : (a.s != b.s ? a.s < b.s : (a.n != b.n ? a.n < b.n : a.corner < b.corner));
  });
  out.count.assign(m.vertices.size(), 0);
  out.corner.assign(3 * m.faces.size(), 0);
  out.pairs.clear();
  for (std::size_t i = 0; i < items.size();) {
    const std::uint32_t v = items[i].v;
    unsigned local = 0;
    while (i < items.size() && items[i].v == v) {
      std::size_t j = i;
      while (j < items.size() && items[j].v == v && items[j].s == items[i].s && items[j].n == items[i].n) ++j;
      if (local == 255) return false;
      out.pairs.emplace_back(items[i].s, items[i].n);
      for (std::size_t t = i; t < j; ++t) out.corner[items[t].corner] = std::uint8_t(local);
      ++local;
      i = j;
    }
    out.count[v] = std::uint8_t(local);
  }
  out.implicit = m.normals.size() == out.pairs.size() && m.surfaces.size() == out.pairs.size();
  for (std::size_t k = 0; out.implicit && k < out.pairs.size(); ++k)
    out.implicit = out.pairs[k].first == k && out.pairs[k].second == k;
  return true;
}

}  // namespace internal

/// The bytes of a CM file for `m` (see the file comment): version 2, or version 1 when a vertex
/// has more than 255 sectors. Throws Invalid_input if `m` is invalid.
inline std::string cm_bytes(const Compact_model& m) {
  m.validate();
  internal::Cm_sectors sec;
  const bool v2 = internal::cm_sectors(m, sec);
  internal::Le_writer w;
  w.out.reserve(64 + m.vertices.size() * 13 + m.normals.size() * 12 + m.surfaces.size() * 40 + m.faces.size() * 40 +
                (m.has_uvs() ? m.faces.size() * 24 + m.texture.size() : 0));
  w.out.append(internal::cm_magic, 8);
  w.u32(v2 ? internal::cm_version : 1u);
  w.u32((m.has_uvs() ? 1u : 0u) | (v2 && sec.implicit ? 2u : 0u) | (m.level_errors.empty() ? 0u : 4u) |
        (m.reconstruction_level >= 0 ? 8u : 0u));
  const std::vector<std::uint32_t> cones = m.cone_vertices();
  w.u64(m.vertices.size());
  w.u64(m.normals.size());
  w.u64(m.surfaces.size());
  w.u64(cones.size());
  w.u64(m.faces.size());
  for (const Vec3& v : m.vertices) {
    w.f32(v.x);
    w.f32(v.y);
    w.f32(v.z);
  }
  for (const Vec3& v : m.normals) {
    w.f32(v.x);
    w.f32(v.y);
    w.f32(v.z);
  }
  for (const Local_surface& s : m.surfaces) {
    w.u8(s.model);
    for (int k = 0; k < number_of_coefficients(s.model); ++k) w.f32(s.c[k]);
  }
  for (std::uint32_t c : cones) w.u32(c);
  if (v2) {
    for (std::uint8_t k : sec.count) w.u8(k);
    if (!sec.implicit)
      for (const auto& pr : sec.pairs) {
        w.u32(pr.first);
        w.u32(pr.second);
      }
    for (const auto& f : m.faces)
      for (const Corner& c : f) w.u32(c.vertex);
    for (std::size_t f = 0; f < m.faces.size(); ++f)
      for (int k = 0; k < 3; ++k)
        if (sec.count[m.faces[f][k].vertex] > 1) w.u8(sec.corner[3 * f + std::size_t(k)]);
  } else {
    for (const auto& f : m.faces)
      for (const Corner& c : f) {
        w.u32(c.vertex);
        w.u32(c.surface);
        w.u32(c.normal);
      }
  }
  if (m.has_uvs()) {
    w.u32(std::uint32_t(m.texture.size()));
    w.out.append(m.texture);
    for (const Face_uvs& f : m.uvs)
      for (const auto& uv : f) {
        w.f32(uv[0]);
        w.f32(uv[1]);
      }
  }
  if (!m.level_errors.empty()) {
    w.u8(std::uint8_t(m.level_errors.depth));
    w.f32(m.level_errors.unit);
    w.out.append(m.level_errors.rms.begin(), m.level_errors.rms.end());
    w.out.append(m.level_errors.max.begin(), m.level_errors.max.end());
  }
  if (m.reconstruction_level >= 0) w.u8(std::uint8_t(m.reconstruction_level));
  w.u64(internal::fnv1a64(reinterpret_cast<const unsigned char*>(w.out.data()), w.out.size()));
  return w.out;
}

#ifdef CMGEOM_COMPACT_MODEL_PRECOMPILED
namespace internal {
// Version 3 (cm_compact_io.h), compiled in the CMGeom::Compact_model library.
Compact_model parse_compact_cm(const std::string& bytes, const std::string& file);
}  // namespace internal
#endif

/// Parses the bytes of a CM file (version 1, 2 or 3); `file` names it in error messages. Version
/// 3 (the compact, quantized file of cm_compact_io.h) needs the CMGeom::Compact_model library.
inline Compact_model parse_cm(const std::string& bytes, const std::string& file = "<memory>") {
  using internal::Le_reader;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  if (bytes.size() < 8 || std::memcmp(bytes.data(), internal::cm_magic, 8) != 0)
    throw IO_error(file, "not a CM file (bad magic number)");
  if (bytes.size() >= 12 && data[8] == 3 && data[9] == 0 && data[10] == 0 && data[11] == 0) {
#ifdef CMGEOM_COMPACT_MODEL_PRECOMPILED
    return internal::parse_compact_cm(bytes, file);
#else
    throw IO_error(file, "a version 3 (compact) CM file: reading it needs the CMGeom::Compact_model library");
#endif
  }
  if (bytes.size() < internal::cm_header_size + 8)
    throw IO_error(file, "truncated file: " + std::to_string(bytes.size()) + " bytes, header needs " +
                             std::to_string(internal::cm_header_size + 8));
  Le_reader r{data, bytes.size() - 8, 8, file};  // the trailing checksum is not content
  const std::uint32_t version = r.u32();
  if (version != 1 && version != 2)
    throw IO_error(file, "unsupported CM version " + std::to_string(version) + " (this reader knows 1, 2 and 3)");
  const std::uint32_t flags = r.u32();
  const std::uint32_t known_flags = version == 1 ? 13u : 15u;
  if (flags & ~known_flags) throw IO_error(file, "unknown flags " + std::to_string(flags));
  const bool implicit = (flags & 2u) != 0;
  const std::uint64_t nv = r.u64(), nn = r.u64(), ns = r.u64(), nc = r.u64(), nf = r.u64();
  // Check every count against the bytes left before allocating (a corrupt count must not make us
  // allocate gigabytes); lists have at least 21 bytes each.
  const std::uint64_t left = r.n - r.pos;
  auto check = [&](std::uint64_t count, std::uint64_t unit, const char* what) {
    if (count > left / unit)
      throw IO_error(file, std::string("corrupt or truncated file: ") + std::to_string(count) + " " + what +
                               " do not fit in the remaining " + std::to_string(left) + " bytes");
  };
  check(nv, version == 1 ? 12 : 13, "vertices");
  check(nn, 12, "normals");
  check(ns, 21, "coefficient lists");
  check(nc, 4, "cone vertices");
  check(nf, version == 1 ? 36 : 12, "faces");
  const std::uint64_t stored = [&] {
    Le_reader t{data, bytes.size(), bytes.size() - 8, file};
    return t.u64();
  }();
  const std::uint64_t actual = internal::fnv1a64(data, bytes.size() - 8);

  Compact_model m;
  r.need(nv * 12, "vertices");
  m.vertices.resize(nv);
  for (Vec3& v : m.vertices) {
    const double x = r.f32(), y = r.f32(), z = r.f32();
    v = Vec3(x, y, z);
  }
  r.need(nn * 12, "normals");
  m.normals.resize(nn);
  for (Vec3& v : m.normals) {
    const double x = r.f32(), y = r.f32(), z = r.f32();
    v = Vec3(x, y, z);
  }
  m.surfaces.resize(ns);
  for (std::uint64_t i = 0; i < ns; ++i) {
    r.need(1, "coefficient list");
    Local_surface& s = m.surfaces[i];
    s.model = r.u8();
    const int k = number_of_coefficients(s.model);
    if (k == 0)
      throw IO_error(file, "coefficient list " + std::to_string(i) + ": unknown model id " + std::to_string(s.model));
    r.need(std::size_t(4 * k), "coefficient list");
    for (int j = 0; j < k; ++j) s.c[j] = r.f32();
  }
  r.need(nc * 4, "cone vertex list");
  std::vector<std::uint32_t> cones(nc);
  for (auto& c : cones) c = r.u32();
  m.faces.resize(nf);
  if (version == 1) {
    r.need(nf * 36, "faces");
    for (auto& f : m.faces)
      for (Corner& c : f) {
        c.vertex = r.u32();
        c.surface = r.u32();
        c.normal = r.u32();
      }
  } else {
    r.need(nv, "sector counts");
    std::vector<std::uint64_t> first(nv + 1, 0);  // first[v]: number of v's first sector
    for (std::uint64_t v = 0; v < nv; ++v) first[v + 1] = first[v] + r.u8();
    const std::uint64_t nk = first[nv];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    if (implicit) {
      if (nk != nn || nk != ns)
        throw IO_error(file, "implicit sector table: " + std::to_string(nk) + " sectors for " + std::to_string(nn) +
                                 " normals and " + std::to_string(ns) + " coefficient lists");
    } else {
      r.need(nk * 8, "sector table");  // nk <= 255 nv, nv bounded by the file size: no overflow
      pairs.resize(nk);
      for (auto& pr : pairs) {
        pr.first = r.u32();
        pr.second = r.u32();
      }
    }
    r.need(nf * 12, "faces");
    for (std::uint64_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = r.u32();
        if (v >= nv)
          throw IO_error(file, "face " + std::to_string(f) + " corner " + std::to_string(k) + ": vertex index " +
                                   std::to_string(v) + " out of range");
        if (first[v + 1] == first[v])
          throw IO_error(file, "face " + std::to_string(f) + " corner " + std::to_string(k) + ": vertex " +
                                   std::to_string(v) + " has no sector");
        m.faces[f][k].vertex = v;
      }
    for (std::uint64_t f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        Corner& c = m.faces[f][k];
        const std::uint64_t kv = first[c.vertex + 1] - first[c.vertex];
        std::uint64_t j = 0;
        if (kv > 1) {
          r.need(1, "corner sector numbers");
          j = r.u8();
          if (j >= kv)
            throw IO_error(file, "face " + std::to_string(f) + " corner " + std::to_string(k) + ": sector " +
                                     std::to_string(j) + " of a vertex with " + std::to_string(kv));
        }
        const std::uint64_t g = first[c.vertex] + j;
        c.surface = implicit ? std::uint32_t(g) : pairs[g].first;
        c.normal = implicit ? std::uint32_t(g) : pairs[g].second;
      }
  }
  if (flags & 1u) {
    r.need(4, "texture path length");
    const std::uint32_t len = r.u32();
    r.need(len, "texture path");
    m.texture.assign(reinterpret_cast<const char*>(data + r.pos), len);
    r.pos += len;
    r.need(nf * 24, "texture coordinates");
    m.uvs.resize(nf);
    for (Face_uvs& f : m.uvs)
      for (auto& uv : f) {
        uv[0] = float(r.f32());
        uv[1] = float(r.f32());
      }
  }
  if (flags & 4u) {
    r.need(5, "level error table");
    Level_errors& le = m.level_errors;
    le.depth = int(r.u8());
    le.unit = r.f32();
    if (le.depth > 12) throw IO_error(file, "level error table deeper than level 12");
    const std::uint64_t n = std::uint64_t(le.depth + 1) * nf;
    r.need(2 * n, "level error table");
    le.rms.assign(data + r.pos, data + r.pos + n);
    le.max.assign(data + r.pos + n, data + r.pos + 2 * n);
    r.pos += 2 * n;
  }
  if (flags & 8u) {
    r.need(1, "reconstruction level");
    m.reconstruction_level = int(r.u8());
    if (m.reconstruction_level > 12)
      throw IO_error(file, "reconstruction level " + std::to_string(m.reconstruction_level) + " above 12");
  }
  if (r.pos != r.n)
    throw IO_error(file, "corrupt file: " + std::to_string(r.n - r.pos) + " unexpected bytes before the checksum");
  if (stored != actual) throw IO_error(file, "checksum mismatch (the file is corrupt)");
  try {
    m.validate("CM content");
  } catch (const Invalid_input& e) {
    throw IO_error(file, e.what());
  }
  if (cones != m.cone_vertices()) throw IO_error(file, "cone-type vertex list does not match the conical surfaces");
  return m;
}

/// Reads a CM file. Throws IO_error (file, what) when it cannot be read or is malformed.
inline Compact_model read_cm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IO_error(path, "cannot open the file");
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IO_error(path, "read error");
  return parse_cm(bytes, path);
}

/// Writes a CM file atomically; returns its size in bytes.
inline std::size_t write_cm(const std::string& path, const Compact_model& m) {
  const std::string bytes = cm_bytes(m);
  IO::write_file_atomically(path, bytes);
  return bytes.size();
}

/// Same, but the file is registered in `out` and appears when `out` is committed, with the other
/// files registered there (e.g. a textured model's atlas).
inline std::size_t write_cm(const std::string& path, const Compact_model& m, IO::Atomic_output& out) {
  const std::string bytes = cm_bytes(m);
  IO::write_file(path, bytes, out);
  return bytes.size();
}

/// The texture image of `m` as a path usable from the current directory: a relative texture path
/// is relative to the directory of the CM file `cm_path` the model was read from (what `cmgeom cm
/// build` stores for the atlas it writes beside the CM); "" for an untextured model.
inline std::string texture_path(const Compact_model& m, const std::string& cm_path) {
  if (m.texture.empty() || std::filesystem::path(m.texture).is_absolute()) return m.texture;
  return (std::filesystem::path(cm_path).parent_path() / m.texture).string();
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_CM_IO_H
