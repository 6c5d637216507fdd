// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The compact CM file, format version 3: see include/CMGeom/Compact_model/cm_compact_io.h for
// what is stored and how. Encoder and decoder share every function that turns stored integers
// into numbers (positions, normals, coefficient steps), so the model the encoder refits against
// is bit for bit the model the decoder returns.
#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/cm_io.h>

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace CMGeom {
namespace CM {

namespace {

using internal::Vec3;

constexpr std::uint32_t version3 = 3;
constexpr std::size_t header3_size = 8 + 4 + 4 + 4 * 3 + 8 * 4 + 1 + 8;  // 69 bytes
constexpr std::uint32_t max_count = 1u << 28;
constexpr std::uint32_t max_stream = 1u << 30;

// ------------------------------------------------------------------ varint streams

inline std::uint64_t zigzag(std::int64_t v) { return (std::uint64_t(v) << 1) ^ std::uint64_t(v >> 63); }
inline std::int64_t unzigzag(std::uint64_t u) { return std::int64_t(u >> 1) ^ -std::int64_t(u & 1u); }

struct Varint_writer {
  std::string s;
  void u(std::uint64_t v) {
    while (v >= 0x80u) {
      s.push_back(char((v & 0x7fu) | 0x80u));
      v >>= 7;
    }
    s.push_back(char(v));
  }
  void i(std::int64_t v) { u(zigzag(v)); }
};

struct Varint_reader {
  const std::string& s;
  const std::string& file;
  const char* what;
  std::size_t pos = 0;
  [[noreturn]] void fail(const std::string& m) const {
    throw IO_error(file, std::string("corrupt file: ") + what + " stream: " + m);
  }
  std::uint64_t u() {
    std::uint64_t v = 0;
    for (int shift = 0;; shift += 7) {
      if (pos >= s.size()) fail("ends early");
      if (shift > 63) fail("overlong number");
      const unsigned char b = static_cast<unsigned char>(s[pos++]);
      v |= std::uint64_t(b & 0x7fu) << shift;
      if (!(b & 0x80u)) return v;
    }
  }
  std::int64_t i() { return unzigzag(u()); }
  std::uint64_t below(std::uint64_t bound, const char* name) {
    const std::uint64_t v = u();
    if (v >= bound)
      fail(std::string(name) + " " + std::to_string(v) + " out of range (< " + std::to_string(bound) + ")");
    return v;
  }
  void finish() const {
    if (pos != s.size()) fail(std::to_string(s.size() - pos) + " unexpected bytes at its end");
  }
};

// ------------------------------------------------------------------ shared decoding rules

// Connectivity in decoding order: faces (new vertex ids, rotated so that a face hanging on an
// earlier one starts with the shared edge), and how each vertex is predicted.
struct Vertex_prediction {
  int kind = 0;  // 0: previous vertex (or the origin for vertex 0), 1: parallelogram a + b - d
  std::uint32_t a = 0, b = 0, d = 0;
};
struct Connectivity {
  std::vector<std::array<std::uint32_t, 3>> faces;
  std::vector<Vertex_prediction> prediction;  // one per vertex
};

using Grid_point = std::array<std::int64_t, 3>;

Grid_point predict(const std::vector<Grid_point>& q, std::uint32_t v, const Vertex_prediction& p) {
  if (p.kind == 1)
    return {q[p.a][0] + q[p.b][0] - q[p.d][0], q[p.a][1] + q[p.b][1] - q[p.d][1], q[p.a][2] + q[p.b][2] - q[p.d][2]};
  if (v == 0) return {0, 0, 0};
  return q[v - 1];
}

double to_float(double x) {
  volatile float f = float(x);  // see round_to_float in Compact_model.h
  return double(f);
}

Vec3 grid_position(const Grid_point& g, const double origin[3], double step) {
  return Vec3(to_float(origin[0] + double(g[0]) * step), to_float(origin[1] + double(g[1]) * step),
              to_float(origin[2] + double(g[2]) * step));
}

// Octahedral map of a unit vector to [-1, 1]^2 and back.
std::array<double, 2> octahedral(const Vec3& n) {
  const double s = std::abs(n.x) + std::abs(n.y) + std::abs(n.z);
  double u = n.x / s, v = n.y / s;
  if (n.z < 0.) {
    const double pu = (1. - std::abs(v)) * (u >= 0. ? 1. : -1.);
    const double pv = (1. - std::abs(u)) * (v >= 0. ? 1. : -1.);
    u = pu;
    v = pv;
  }
  return {u, v};
}

Vec3 from_octahedral(double u, double v) {
  double z = 1. - std::abs(u) - std::abs(v);
  double x = u, y = v;
  if (z < 0.) {
    x = (1. - std::abs(v)) * (u >= 0. ? 1. : -1.);
    y = (1. - std::abs(u)) * (v >= 0. ? 1. : -1.);
  }
  return internal::normalized(Vec3(x, y, z));
}

double octahedral_coordinate(std::int64_t q, int bits) {
  const double m = double((std::int64_t(1) << bits) - 1);
  return std::min(1., std::max(-1., double(q) / m * 2. - 1.));
}

Vec3 normal_from_grid(std::int64_t qu, std::int64_t qv, int bits) {
  const Vec3 n = from_octahedral(octahedral_coordinate(qu, bits), octahedral_coordinate(qv, bits));
  return Vec3(to_float(n.x), to_float(n.y), to_float(n.z));
}

// Nearest grid point in angle among the four around the octahedral coordinates of n.
std::array<std::int64_t, 2> normal_to_grid(const Vec3& n, int bits) {
  const double m = double((std::int64_t(1) << bits) - 1);
  const std::array<double, 2> uv = octahedral(internal::normalized(n));
  const double fu = (uv[0] + 1.) / 2. * m, fv = (uv[1] + 1.) / 2. * m;
  std::array<std::int64_t, 2> best{std::llround(fu), std::llround(fv)};
  double best_dot = -2.;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) {
      const std::int64_t a =
          std::min<std::int64_t>(std::int64_t(m), std::max<std::int64_t>(0, std::int64_t(std::floor(fu)) + i));
      const std::int64_t b =
          std::min<std::int64_t>(std::int64_t(m), std::max<std::int64_t>(0, std::int64_t(std::floor(fv)) + j));
      const double d = internal::dot(normal_from_grid(a, b, bits), internal::normalized(n));
      if (d > best_dot) {
        best_dot = d;
        best = {a, b};
      }
    }
  return best;
}

Vec3 predicted_normal(const std::vector<Vec3>& p, const Connectivity& c, const std::vector<std::size_t>& corners) {
  Vec3 s(0, 0, 0);
  for (std::size_t k : corners) {
    const auto& f = c.faces[k / 3];
    s += internal::cross(p[f[1]] - p[f[0]], p[f[2]] - p[f[0]]);
  }
  const double l = internal::length(s);
  return l > 0. && std::isfinite(l) ? s * (1. / l) : Vec3(0, 0, 1);
}

double sector_radius(const std::vector<Vec3>& p, const Connectivity& c, std::uint32_t v,
                     const std::vector<std::size_t>& corners) {
  double r = 0.;
  for (std::size_t k : corners)
    for (std::uint32_t w : c.faces[k / 3]) r = std::max(r, internal::length(p[w] - p[v]));
  return r;
}

// Monomial degree of coefficient j, the same for every model (Local_surface_traits.h; a cone's
// first five are those of its q).
int coefficient_degree(int j) {
  static const int degree[9] = {2, 2, 2, 1, 1, 3, 3, 3, 3};
  return degree[j];
}

// Step of coefficient j (see the header): quadric and cubic 2 t / (k r^d), cone 2 t^2 / (5 r^d).
double coefficient_step(std::uint8_t model, int j, double r, double t) {
  const int d = coefficient_degree(j);
  if (model == CONE_MODEL) return 2. * t * t / (5. * std::pow(r, d));
  return 2. * t / (double(number_of_coefficients(model)) * std::pow(r, d));
}

int stored_coefficients(std::uint8_t model) { return model == CONE_MODEL ? 5 : number_of_coefficients(model); }

// ------------------------------------------------------------------ streams in the file

std::size_t put_stream(internal::Le_writer& w, const std::string& raw, int level) {
  if (raw.size() >= max_stream) throw Invalid_input("compact CM: a stream exceeds 1 GiB");
  std::string packed(ZSTD_compressBound(raw.size()), '\0');
  const std::size_t n = ZSTD_compress(&packed[0], packed.size(), raw.data(), raw.size(), level);
  const bool use = !ZSTD_isError(n) && n < raw.size();
  const std::size_t before = w.out.size();
  w.u8(use ? 1 : 0);
  w.u32(std::uint32_t(raw.size()));
  w.u32(std::uint32_t(use ? n : raw.size()));
  w.out.append(use ? packed.data() : raw.data(), use ? n : raw.size());
  return w.out.size() - before;
}

std::string get_stream(internal::Le_reader& r, const char* what) {
  r.need(9, what);
  const unsigned method = r.u8();
  const std::uint64_t raw = r.u32(), stored = r.u32();
  if (method > 1) throw IO_error(r.file, std::string("corrupt file: unknown coding of the ") + what + " stream");
  if (raw >= max_stream) throw IO_error(r.file, std::string("corrupt file: ") + what + " stream too large");
  r.need(stored, what);
  const char* src = reinterpret_cast<const char*>(r.p + r.pos);
  r.pos += stored;
  if (method == 0) {
    if (raw != stored) throw IO_error(r.file, std::string("corrupt file: ") + what + " stream sizes disagree");
    return std::string(src, stored);
  }
  const unsigned long long content = ZSTD_getFrameContentSize(src, stored);
  if (content != raw)
    throw IO_error(r.file, std::string("corrupt file: ") + what + " stream is not a zstd frame of its size");
  std::string out(raw, '\0');
  const std::size_t n = ZSTD_decompress(raw ? &out[0] : nullptr, raw, src, stored);
  if (ZSTD_isError(n) || n != raw)
    throw IO_error(r.file, std::string("corrupt file: ") + what + " stream does not decompress");
  return out;
}

// ------------------------------------------------------------------ encoder

struct Encoded_connectivity {
  Connectivity c;
  std::vector<std::uint32_t> old_vertex;       // new id -> original id
  std::vector<std::array<int, 3>> old_corner;  // per new face: original face index * 3 + corner
  std::string stream;
};

Encoded_connectivity encode_connectivity(const Compact_model& m) {
  const std::size_t F = m.faces.size();
  // Undirected edges grouped: (min, max, face * 3 + local edge)
  struct Edge {
    std::uint32_t a, b;
    std::size_t fe;
  };
  std::vector<Edge> edges;
  edges.reserve(3 * F);
  for (std::size_t f = 0; f < F; ++f)
    for (int e = 0; e < 3; ++e) {
      std::uint32_t a = m.faces[f][e].vertex, b = m.faces[f][(e + 1) % 3].vertex;
      if (a > b) std::swap(a, b);
      edges.push_back({a, b, 3 * f + std::size_t(e)});
    }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : x.fe < y.fe);
  });
  std::vector<std::size_t> group_of(3 * F), group_begin;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    if (i == 0 || edges[i].a != edges[i - 1].a || edges[i].b != edges[i - 1].b) group_begin.push_back(i);
    group_of[edges[i].fe] = group_begin.size() - 1;
  }
  group_begin.push_back(edges.size());

  Encoded_connectivity out;
  out.c.faces.reserve(F);
  out.old_corner.reserve(F);
  std::vector<char> visited(F, 0);
  std::vector<std::size_t> queue_face;  // original face of each output face
  std::vector<int> queue_rotation;      // original corner at position 0
  std::vector<std::uint32_t> new_id(m.vertices.size(), std::numeric_limits<std::uint32_t>::max());
  std::uint32_t next = 0;
  Varint_writer symbols, parents, codes;
  std::size_t last_parent = 0;
  auto vertex_code = [&](std::uint32_t old, const Vertex_prediction& p) {
    if (new_id[old] == std::numeric_limits<std::uint32_t>::max()) {
      new_id[old] = next++;
      out.old_vertex.push_back(old);
      out.c.prediction.push_back(p);
      codes.u(0);
    } else {
      codes.u(next - new_id[old]);
    }
    return new_id[old];
  };
  auto emit = [&](std::size_t f, int rot, bool root, std::size_t parent, int e, int o) {
    visited[f] = 1;
    queue_face.push_back(f);
    queue_rotation.push_back(rot);
    std::array<std::uint32_t, 3> nf{};
    std::array<int, 3> oc{};
    for (int k = 0; k < 3; ++k) oc[k] = int(3 * f) + (rot + k) % 3;
    if (root) {
      symbols.u(0);
      for (int k = 0; k < 3; ++k) nf[k] = vertex_code(m.faces[f][(rot + k) % 3].vertex, Vertex_prediction());
    } else {
      symbols.u(std::uint64_t(1 + e + 3 * o));
      parents.u(parent - last_parent);
      last_parent = parent;
      const auto& pf = out.c.faces[parent];
      nf[0] = new_id[m.faces[f][rot].vertex];
      nf[1] = new_id[m.faces[f][(rot + 1) % 3].vertex];
      Vertex_prediction p;
      p.kind = 1;
      p.a = nf[0];
      p.b = nf[1];
      p.d = pf[(e + 2) % 3];
      nf[2] = vertex_code(m.faces[f][(rot + 2) % 3].vertex, p);
    }
    out.c.faces.push_back(nf);
    out.old_corner.push_back(oc);
  };
  std::size_t head = 0;
  for (std::size_t seed = 0; seed < F; ++seed) {
    if (visited[seed]) continue;
    emit(seed, 0, true, 0, 0, 0);
    while (head < queue_face.size()) {
      const std::size_t pi = head++;
      const std::size_t pf = queue_face[pi];
      const int prot = queue_rotation[pi];
      for (int e = 0; e < 3; ++e) {
        const int local = (prot + e) % 3;
        const std::uint32_t a = m.faces[pf][local].vertex, b = m.faces[pf][(local + 1) % 3].vertex;
        const std::size_t g = group_of[3 * pf + std::size_t(local)];
        for (std::size_t i = group_begin[g]; i < group_begin[g + 1]; ++i) {
          const std::size_t f = edges[i].fe / 3;
          if (visited[f]) continue;
          int rot = -1, o = 0;
          for (int k = 0; k < 3; ++k) {
            const std::uint32_t x = m.faces[f][k].vertex, y = m.faces[f][(k + 1) % 3].vertex;
            if (x == b && y == a) rot = k, o = 0;
            if (x == a && y == b) rot = k, o = 1;
          }
          emit(f, rot, false, pi, e, o);
        }
      }
    }
  }
  Varint_writer all;
  all.u(symbols.s.size());
  all.u(parents.s.size());
  all.s += symbols.s;
  all.s += parents.s;
  all.s += codes.s;
  out.stream = std::move(all.s);
  return out;
}

double sample_rms(const Local_surface& s, const std::vector<Vec3>& pts) {
  double e = 0.;
  for (const Vec3& p : pts) {
    const double d = evaluate_height(s, p.x, p.y) - p.z;
    e += d * d;
  }
  return pts.empty() ? 0. : std::sqrt(e / double(pts.size()));
}

}  // namespace

std::string compact_cm_bytes(const Compact_model& m, const Compact_encoding& enc, CM_file_parts* parts) {
  m.validate();
  if (m.faces.empty()) throw Invalid_input("compact CM: the model has no face");
  if (m.faces.size() >= max_count) throw Invalid_input("compact CM: too many faces");
  if (enc.normal_bits < 6 || enc.normal_bits > 20)
    throw Invalid_input("compact CM: normal bits must be in [6, 20], got " + std::to_string(enc.normal_bits));
  if (enc.zstd_level < 1 || enc.zstd_level > 22)
    throw Invalid_input("compact CM: zstd level must be in [1, 22], got " + std::to_string(enc.zstd_level));
  if (!(enc.tolerance >= 0.) || !std::isfinite(enc.tolerance))
    throw Invalid_input("compact CM: the tolerance must be a finite number >= 0");

  Encoded_connectivity ec = encode_connectivity(m);
  const Connectivity& c = ec.c;
  const std::size_t V = ec.old_vertex.size(), F = c.faces.size();

  // Grid of the positions.
  double lo[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                  std::numeric_limits<double>::infinity()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (std::uint32_t o : ec.old_vertex)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], m.vertices[o][k]);
      hi[k] = std::max(hi[k], m.vertices[o][k]);
    }
  const double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  double step = enc.tolerance > 0. ? enc.tolerance : 1e-4 * diag;
  if (!(step > 0.)) step = 1e-6;  // a single point: any grid does
  const double max_steps = double(std::int64_t(1) << 40);
  if (diag / step > max_steps)
    throw Invalid_input("compact CM: tolerance too small for the model's size (more than 2^40 grid steps)");
  std::vector<Grid_point> q(V);
  auto quantize = [&] {
    for (std::size_t v = 0; v < V; ++v)
      for (int k = 0; k < 3; ++k) q[v][k] = std::llround((m.vertices[ec.old_vertex[v]][k] - lo[k]) / step);
  };
  quantize();
  // A base face whose corners the grid rounds onto one line (two onto one grid point: a base
  // edge shorter than the step, as the chart-keeping simplification of a textured base leaves
  // along chart borders) would reconstruct into degenerate faces: the grid is halved until no
  // face that has an area before rounding loses it (exact integer test).
  auto flat_on_grid = [&](const std::array<std::uint32_t, 3>& f) {
    using I = __int128;
    const Grid_point &a = q[f[0]], &b = q[f[1]], &d = q[f[2]];
    const I u[3] = {I(b[0] - a[0]), I(b[1] - a[1]), I(b[2] - a[2])};
    const I w[3] = {I(d[0] - a[0]), I(d[1] - a[1]), I(d[2] - a[2])};
    return u[1] * w[2] - u[2] * w[1] == 0 && u[2] * w[0] - u[0] * w[2] == 0 && u[0] * w[1] - u[1] * w[0] == 0;
  };
  auto has_area = [&](const std::array<std::uint32_t, 3>& f) {
    const Vec3 a = m.vertices[ec.old_vertex[f[0]]], b = m.vertices[ec.old_vertex[f[1]]],
               d = m.vertices[ec.old_vertex[f[2]]];
    return internal::length(internal::cross(b - a, d - a)) > 0.;
  };
  for (int halvings = 0; halvings < 20 && diag / (step / 2.) <= max_steps; ++halvings) {
    bool flattened = false;
    for (const auto& f : c.faces)
      if (flat_on_grid(f) && has_area(f)) {
        flattened = true;
        break;
      }
    if (!flattened) break;
    step /= 2.;
    quantize();
  }
  const double t = step / 2.;
  std::vector<Vec3> p(V);
  for (std::size_t v = 0; v < V; ++v) p[v] = grid_position(q[v], lo, step);
  Varint_writer positions;
  for (std::size_t v = 0; v < V; ++v) {
    const Grid_point pr = predict(q, std::uint32_t(v), c.prediction[v]);
    for (int k = 0; k < 3; ++k) positions.i(q[v][k] - pr[k]);
  }

  // Sectors: per vertex, distinct (surface, normal) pairs in order of first appearance.
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> pairs(V);
  std::vector<std::uint32_t> local(3 * F);
  for (std::size_t f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) {
      const int oc = ec.old_corner[f][k];
      const Corner& corner = m.faces[std::size_t(oc / 3)][oc % 3];
      auto& list = pairs[c.faces[f][k]];
      const std::pair<std::uint32_t, std::uint32_t> key(corner.surface, corner.normal);
      const auto it = std::find(list.begin(), list.end(), key);
      local[3 * f + std::size_t(k)] = std::uint32_t(it - list.begin());
      if (it == list.end()) list.push_back(key);
    }
  Varint_writer sectors;
  std::vector<std::uint32_t> first(V + 1, 0);
  for (std::size_t v = 0; v < V; ++v) {
    if (pairs[v].size() > 255) throw Invalid_input("compact CM: a vertex has more than 255 sectors");
    sectors.u(pairs[v].size() - 1);
    first[v + 1] = first[v] + std::uint32_t(pairs[v].size());
  }
  const std::size_t K = first[V];
  std::vector<std::vector<std::size_t>> sector_corners(K);
  for (std::size_t f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = c.faces[f][k];
      if (pairs[v].size() > 1) sectors.u(local[3 * f + std::size_t(k)]);
      sector_corners[first[v] + local[3 * f + std::size_t(k)]].push_back(3 * f + std::size_t(k));
    }

  // Normals and coefficients, sector by sector.
  Varint_writer normals, coefficients;
  const int bits = enc.normal_bits;
  for (std::size_t v = 0; v < V; ++v)
    for (std::size_t j = 0; j < pairs[v].size(); ++j) {
      const std::size_t g = first[v] + j;
      const auto& corners = sector_corners[g];
      const Vec3 old_n = m.normals[pairs[v][j].second];
      const Local_surface& old_s = m.surfaces[pairs[v][j].first];
      const auto pq = normal_to_grid(predicted_normal(p, c, corners), bits);
      const auto nq = normal_to_grid(old_n, bits);
      normals.i(nq[0] - pq[0]);
      normals.i(nq[1] - pq[1]);
      const Vec3 new_n = normal_from_grid(nq[0], nq[1], bits);

      // Refit in the decoded frame to samples of the original surface over the sector's faces.
      const Local_frame old_frame(m.vertices[ec.old_vertex[v]], old_n), new_frame(p[v], new_n);
      std::vector<Vec3> pts;
      pts.push_back(new_frame.to_local(old_frame.origin));
      constexpr int n_sub = 4;
      for (std::size_t k : corners) {
        const auto& f = c.faces[k / 3];
        const Vec3 A = m.vertices[ec.old_vertex[f[0]]], B = m.vertices[ec.old_vertex[f[1]]],
                   C = m.vertices[ec.old_vertex[f[2]]];
        for (int a = 0; a <= n_sub; ++a)
          for (int b = 0; a + b <= n_sub; ++b) {
            const double wa = double(a) / n_sub, wb = double(b) / n_sub;
            const Vec3 P = wa * A + wb * B + (1. - wa - wb) * C;
            const Vec3 l = old_frame.to_local(P);
            const double h = evaluate_height(old_s, l.x, l.y);
            if (!std::isfinite(h)) continue;
            pts.push_back(new_frame.to_local(old_frame.to_world(l.x, l.y, h)));
          }
      }
      Local_surface s = old_s;
      Fit_result fit;
      if (old_s.model == QUADRIC_MODEL)
        fit = fit_quadric(pts);
      else if (old_s.model == CUBIC_MODEL)
        fit = fit_cubic(pts);
      else
        fit = fit_cone(pts);
      if (fit.ok && fit.surface.model == old_s.model && sample_rms(fit.surface, pts) < sample_rms(old_s, pts))
        s = fit.surface;
      double r = sector_radius(p, c, std::uint32_t(v), corners);
      if (!(r > 0.)) r = step;
      coefficients.u(s.model);
      for (int i = 0; i < stored_coefficients(s.model); ++i) {
        const double qc = s.c[i] / coefficient_step(s.model, i, r, t);
        if (!(std::abs(qc) < 4.5e15)) throw Invalid_input("compact CM: a coefficient is too large for the tolerance");
        coefficients.i(std::llround(qc));
      }
      if (s.model == CONE_MODEL) coefficients.u(s.c[5] < 0. ? 1u : 0u);
    }

  // Texture coordinates.
  Varint_writer uvs;
  if (m.has_uvs()) {
    float ulo[2] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity()};
    float uhi[2] = {-ulo[0], -ulo[1]};
    for (const Face_uvs& f : m.uvs)
      for (const auto& uv : f)
        for (int k = 0; k < 2; ++k) {
          if (!std::isfinite(uv[k])) throw Invalid_input("compact CM: a texture coordinate is not finite");
          ulo[k] = std::min(ulo[k], uv[k]);
          uhi[k] = std::max(uhi[k], uv[k]);
        }
    uvs.u(m.texture.size());
    for (char ch : m.texture) uvs.u(static_cast<unsigned char>(ch));
    for (int k = 0; k < 2; ++k) {
      std::uint32_t a, b;
      std::memcpy(&a, &ulo[k], 4);
      std::memcpy(&b, &uhi[k], 4);
      uvs.u(a);
      uvs.u(b);
    }
    std::vector<std::array<std::int64_t, 2>> last(V, {-1, -1});
    std::array<std::int64_t, 2> prev{0, 0};
    for (std::size_t f = 0; f < F; ++f)
      for (int k = 0; k < 3; ++k) {
        const int oc = ec.old_corner[f][k];
        const auto& uv = m.uvs[std::size_t(oc / 3)][oc % 3];
        std::array<std::int64_t, 2> g{};
        for (int i = 0; i < 2; ++i) {
          const double range = double(uhi[i]) - double(ulo[i]);
          g[i] = range > 0. ? std::llround((double(uv[i]) - double(ulo[i])) / range * 65535.) : 0;
        }
        const std::uint32_t v = c.faces[f][k];
        const auto pred = last[v][0] >= 0 ? last[v] : prev;
        uvs.i(g[0] - pred[0]);
        uvs.i(g[1] - pred[1]);
        last[v] = g;
        prev = g;
      }
  }

  // Level error table (Compact_model.h), faces in decoding order.
  std::string level_errors;
  if (!m.level_errors.empty()) {
    const Level_errors& le = m.level_errors;
    internal::Le_writer lw;
    lw.u8(std::uint8_t(le.depth));
    lw.f32(le.unit);
    // delta-coded (flag bit 2): a face's code at level l > 0 as its change from level l - 1,
    // modulo 256 (a face's codes move little from level to level: zstd then finds more repeats,
    // 15 % fewer bytes on the camel and the horse at depth 5)
    for (const std::vector<std::uint8_t>* codes : {&le.rms, &le.max})
      for (int l = 0; l <= le.depth; ++l)
        for (std::size_t f = 0; f < F; ++f) {
          const std::size_t k = std::size_t(l) * F + std::size_t(ec.old_corner[f][0] / 3);
          lw.u8(std::uint8_t((*codes)[k] - (l > 0 ? (*codes)[k - F] : 0)));
        }
    level_errors = std::move(lw.out);
  }

  internal::Le_writer w;
  w.out.assign(internal::cm_magic, 8);
  w.u32(version3);
  w.u32((m.has_uvs() ? 1u : 0u) | (m.level_errors.empty() ? 0u : 2u | 4u) | (m.reconstruction_level >= 0 ? 8u : 0u));
  w.u32(std::uint32_t(V));
  w.u32(std::uint32_t(F));
  w.u32(std::uint32_t(K));
  for (int k = 0; k < 3; ++k) w.f64(lo[k]);
  w.f64(step);
  w.u8(std::uint8_t(bits));
  w.f64(t);
  CM_file_parts pr;
  pr.header = w.out.size();
  pr.connectivity = put_stream(w, ec.stream, enc.zstd_level);
  pr.sectors = put_stream(w, sectors.s, enc.zstd_level);
  pr.positions = put_stream(w, positions.s, enc.zstd_level);
  pr.normals = put_stream(w, normals.s, enc.zstd_level);
  pr.coefficients = put_stream(w, coefficients.s, enc.zstd_level);
  pr.uvs = put_stream(w, uvs.s, enc.zstd_level);
  if (!level_errors.empty()) pr.level_errors = put_stream(w, level_errors, enc.zstd_level);
  if (m.reconstruction_level >= 0) {  // (counted with the header)
    w.u8(std::uint8_t(m.reconstruction_level));
    ++pr.header;
  }
  w.u64(internal::fnv1a64(reinterpret_cast<const unsigned char*>(w.out.data()), w.out.size()));
  pr.checksum = 8;
  if (parts) *parts = pr;
  return w.out;
}

Compact_model quantized_model(const Compact_model& m, const Compact_encoding& encoding) {
  return internal::parse_compact_cm(compact_cm_bytes(m, encoding), "<memory>");
}

namespace internal {

Compact_model parse_compact_cm(const std::string& bytes, const std::string& file) {
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  if (bytes.size() < header3_size + 8) throw IO_error(file, "truncated file: shorter than a version 3 header");
  if (std::memcmp(bytes.data(), cm_magic, 8) != 0) throw IO_error(file, "not a CM file (bad magic number)");
  {
    Le_reader t{data, bytes.size(), bytes.size() - 8, file};
    if (t.u64() != fnv1a64(data, bytes.size() - 8)) throw IO_error(file, "checksum mismatch (the file is corrupt)");
  }
  Le_reader r{data, bytes.size() - 8, 8, file};
  if (r.u32() != version3) throw IO_error(file, "not a version 3 CM file");
  const std::uint64_t flags = r.u32();
  if (flags & ~15u) throw IO_error(file, "unknown flags " + std::to_string(flags));
  if ((flags & 6u) == 4u) throw IO_error(file, "corrupt file: flags say delta-coded level errors but there are none");
  const std::uint64_t V = r.u32(), F = r.u32(), K = r.u32();
  if (F == 0 || F >= max_count || V > 3 * F || V == 0 || K < V || K > 3 * F)
    throw IO_error(file, "corrupt file: inconsistent counts (" + std::to_string(V) + " vertices, " + std::to_string(F) +
                             " faces, " + std::to_string(K) + " sectors)");
  double lo[3];
  for (double& x : lo) x = r.f64();
  const double step = r.f64();
  const int bits = int(r.u8());
  const double t = r.f64();
  if (!std::isfinite(lo[0] + lo[1] + lo[2]) || !(step > 0.) || !std::isfinite(step) || bits < 6 || bits > 20 ||
      !(t > 0.) || !std::isfinite(t))
    throw IO_error(file, "corrupt file: invalid quantization parameters");
  const std::string cs = get_stream(r, "connectivity"), ss = get_stream(r, "sectors"), ps = get_stream(r, "positions"),
                    ns = get_stream(r, "normals"), fs = get_stream(r, "coefficients"), us = get_stream(r, "uvs");
  const std::string ls = (flags & 2u) ? get_stream(r, "level errors") : std::string();
  int reconstruction_level = -1;
  if (flags & 8u) {
    r.need(1, "reconstruction level");
    reconstruction_level = int(r.u8());
    if (reconstruction_level > 12)
      throw IO_error(file, "reconstruction level " + std::to_string(reconstruction_level) + " above 12");
  }
  if (r.pos != r.n)
    throw IO_error(file, "corrupt file: " + std::to_string(r.n - r.pos) + " unexpected bytes before the checksum");
  if (F > cs.size()) throw IO_error(file, "corrupt file: the connectivity stream is too short for its faces");

  // Connectivity.
  Connectivity c;
  c.faces.resize(F);
  c.prediction.reserve(V);
  {
    Varint_reader head{cs, file, "connectivity"};
    const std::uint64_t ns_sym = head.u(), ns_par = head.u();
    if (ns_sym > cs.size() - head.pos || ns_par > cs.size() - head.pos - ns_sym) head.fail("bad section sizes");
    const std::string sym_s = cs.substr(head.pos, ns_sym), par_s = cs.substr(head.pos + ns_sym, ns_par),
                      code_s = cs.substr(head.pos + ns_sym + ns_par);
    Varint_reader sym{sym_s, file, "connectivity"}, par{par_s, file, "connectivity"},
        code{code_s, file, "connectivity"};
    std::uint64_t next = 0, last_parent = 0;
    auto vertex = [&](const Vertex_prediction& p) -> std::uint32_t {
      const std::uint64_t k = code.u();
      if (k == 0) {
        if (next >= V) code.fail("more vertices than the header's " + std::to_string(V));
        c.prediction.push_back(p);
        return std::uint32_t(next++);
      }
      if (k > next) code.fail("vertex reference before the first vertex");
      return std::uint32_t(next - k);
    };
    for (std::uint64_t f = 0; f < F; ++f) {
      const std::uint64_t s = sym.below(7, "face symbol");
      auto& nf = c.faces[f];
      if (s == 0) {
        for (int k = 0; k < 3; ++k) nf[k] = vertex(Vertex_prediction());
      } else {
        const std::uint64_t parent = last_parent + par.u();
        if (parent >= f || parent < last_parent) par.fail("face " + std::to_string(f) + " hangs on a later face");
        last_parent = parent;
        const int e = int((s - 1) % 3), o = int((s - 1) / 3);
        const auto& pf = c.faces[parent];
        const std::uint32_t a = pf[e], b = pf[(e + 1) % 3];
        nf[0] = o == 0 ? b : a;
        nf[1] = o == 0 ? a : b;
        Vertex_prediction p;
        p.kind = 1;
        p.a = nf[0];
        p.b = nf[1];
        p.d = pf[(e + 2) % 3];
        nf[2] = vertex(p);
      }
      if (nf[0] == nf[1] || nf[1] == nf[2] || nf[0] == nf[2])
        throw IO_error(file, "corrupt file: face " + std::to_string(f) + " repeats a vertex");
    }
    sym.finish();
    par.finish();
    code.finish();
    if (next != V)
      throw IO_error(file,
                     "corrupt file: " + std::to_string(next) + " vertices used, header says " + std::to_string(V));
  }

  // Positions.
  std::vector<Grid_point> q(V);
  std::vector<Vec3> p(V);
  {
    Varint_reader in{ps, file, "positions"};
    const std::int64_t bound = std::int64_t(1) << 42;
    for (std::uint64_t v = 0; v < V; ++v) {
      const Grid_point pr = predict(q, std::uint32_t(v), c.prediction[v]);
      for (int k = 0; k < 3; ++k) {
        const std::int64_t d = in.i();
        if (d > bound || d < -bound || pr[k] > bound || pr[k] < -bound) in.fail("position out of range");
        q[v][k] = pr[k] + d;
      }
      p[v] = grid_position(q[v], lo, step);
    }
    in.finish();
  }

  // Sectors.
  std::vector<std::uint32_t> first(V + 1, 0), corner_sector(3 * F);
  {
    Varint_reader in{ss, file, "sectors"};
    for (std::uint64_t v = 0; v < V; ++v) first[v + 1] = first[v] + std::uint32_t(in.below(255, "sector count") + 1);
    if (first[V] != K) in.fail(std::to_string(first[V]) + " sectors, header says " + std::to_string(K));
    for (std::uint64_t f = 0; f < F; ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = c.faces[f][k];
        const std::uint32_t kv = first[v + 1] - first[v];
        corner_sector[3 * f + std::size_t(k)] = first[v] + (kv > 1 ? std::uint32_t(in.below(kv, "sector number")) : 0u);
      }
    in.finish();
  }
  std::vector<std::vector<std::size_t>> sector_corners(K);
  for (std::size_t k = 0; k < 3 * F; ++k) sector_corners[corner_sector[k]].push_back(k);

  Compact_model m;
  m.vertices = p;
  m.normals.resize(K);
  m.surfaces.resize(K);
  {
    Varint_reader nin{ns, file, "normals"}, cin{fs, file, "coefficients"};
    const std::int64_t top = (std::int64_t(1) << bits) - 1;
    for (std::uint64_t v = 0; v < V; ++v)
      for (std::uint32_t g = first[v]; g < first[v + 1]; ++g) {
        const auto& corners = sector_corners[g];
        if (corners.empty())
          throw IO_error(file, "corrupt file: a sector of vertex " + std::to_string(v) + " has no corner");
        const auto pq = normal_to_grid(predicted_normal(p, c, corners), bits);
        std::int64_t nq[2];
        for (int i = 0; i < 2; ++i) {
          const std::int64_t d = nin.i();
          if (d > top || d < -top) nin.fail("normal out of range");
          nq[i] = pq[i] + d;
          if (nq[i] < 0 || nq[i] > top) nin.fail("normal out of range");
        }
        m.normals[g] = normal_from_grid(nq[0], nq[1], bits);
        double r = sector_radius(p, c, std::uint32_t(v), corners);
        if (!(r > 0.)) r = step;
        Local_surface& s = m.surfaces[g];
        s.model = std::uint8_t(cin.below(3, "model id"));
        for (int i = 0; i < stored_coefficients(s.model); ++i) {
          const std::int64_t qc = cin.i();
          if (qc > (std::int64_t(1) << 53) || qc < -(std::int64_t(1) << 53)) cin.fail("coefficient out of range");
          s.c[i] = to_float(double(qc) * coefficient_step(s.model, i, r, t));
        }
        if (s.model == CONE_MODEL) s.c[5] = cin.below(2, "cone sign") ? -1. : 1.;
      }
    nin.finish();
    cin.finish();
  }
  m.faces.resize(F);
  for (std::size_t f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t g = corner_sector[3 * f + std::size_t(k)];
      m.faces[f][k] = Corner{c.faces[f][k], g, g};
    }

  if (flags & 1u) {
    Varint_reader in{us, file, "uvs"};
    const std::uint64_t len = in.u();
    if (len > us.size()) in.fail("texture path longer than the stream");
    m.texture.reserve(len);
    for (std::uint64_t i = 0; i < len; ++i) m.texture.push_back(char(in.below(256, "texture path byte")));
    float ulo[2], uhi[2];
    for (int k = 0; k < 2; ++k) {
      const std::uint32_t a = std::uint32_t(in.below(std::uint64_t(1) << 32, "uv bound"));
      const std::uint32_t b = std::uint32_t(in.below(std::uint64_t(1) << 32, "uv bound"));
      std::memcpy(&ulo[k], &a, 4);
      std::memcpy(&uhi[k], &b, 4);
      if (!std::isfinite(ulo[k]) || !std::isfinite(uhi[k]) || uhi[k] < ulo[k]) in.fail("invalid uv bounds");
    }
    m.uvs.resize(F);
    std::vector<std::array<std::int64_t, 2>> last(V, {-1, -1});
    std::array<std::int64_t, 2> prev{0, 0};
    for (std::size_t f = 0; f < F; ++f)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = c.faces[f][k];
        const auto pred = last[v][0] >= 0 ? last[v] : prev;
        std::array<std::int64_t, 2> g{};
        for (int i = 0; i < 2; ++i) {
          g[i] = pred[i] + in.i();
          if (g[i] < 0 || g[i] > 65535) in.fail("texture coordinate out of range");
          const double range = double(uhi[i]) - double(ulo[i]);
          m.uvs[f][k][i] = float(double(ulo[i]) + double(g[i]) / 65535. * range);
        }
        last[v] = g;
        prev = g;
      }
    in.finish();
  } else if (!us.empty()) {
    throw IO_error(file, "corrupt file: texture coordinates in an untextured model");
  }
  if (flags & 2u) {
    if (ls.size() < 5) throw IO_error(file, "corrupt file: the level error stream is too short");
    Level_errors& le = m.level_errors;
    le.depth = int(static_cast<unsigned char>(ls[0]));
    std::uint32_t ub = 0;
    for (int i = 0; i < 4; ++i) ub |= std::uint32_t(static_cast<unsigned char>(ls[std::size_t(1 + i)])) << (8 * i);
    float u;
    std::memcpy(&u, &ub, 4);
    le.unit = double(u);
    if (le.depth > 12) throw IO_error(file, "corrupt file: level error table deeper than level 12");
    const std::size_t n = std::size_t(le.depth + 1) * F;
    if (ls.size() != 5 + 2 * n) throw IO_error(file, "corrupt file: the level error stream does not match the faces");
    le.rms.assign(ls.begin() + 5, ls.begin() + std::ptrdiff_t(5 + n));
    le.max.assign(ls.begin() + std::ptrdiff_t(5 + n), ls.end());
    if (flags & 4u) {  // delta-coded (see the writer), modulo 256
      for (std::size_t k = F; k < n; ++k) {
        le.rms[k] = std::uint8_t(le.rms[k] + le.rms[k - F]);
        le.max[k] = std::uint8_t(le.max[k] + le.max[k - F]);
      }
    }
  }
  m.reconstruction_level = reconstruction_level;
  try {
    m.validate("CM content");
  } catch (const Invalid_input& e) {
    throw IO_error(file, e.what());
  }
  return m;
}

}  // namespace internal

}  // namespace CM
}  // namespace CMGeom
