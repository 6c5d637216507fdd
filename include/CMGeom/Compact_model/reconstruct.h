// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Reconstruction of a surface from a Compact Model (thesis §4.5): reconstruct_regular(),
// Regular_reconstructor (the same, made again and again: per deformation frame),
// reconstruct_adaptive(), Reconstruction_options and the adaptive criteria Edge_length_criterion,
// Region_of_interest_criterion, Silhouette_criterion, Always_split. Every base triangle is
// subdivided (regular: 4^L triangles; adaptive: 2-, 3- or 4-splits of the edges a criterion
// selects, §4.5.2) and every new point p goes to Phi(p) = sum_i W_i(p) S-bar_i(p),
// W_i = alpha_i^3 / sum_k alpha_k^3 (§4.5.1); a point on a sharp base edge goes to the point of
// S^n ∩ S^m ∩ pi closest to it. Key choice: the points of a base edge are computed, and its
// segments split, by the edge alone, so neighbouring triangles never crack and every output point
// exists once. TBB-parallel with output bit-identical to the serial run; uvs are interpolated per
// base face (§4.5.4); Reconstruction_options::vertex_maps is the deformation hook of §6.4.
//
// Manual: doc/Compact_model/README.md, "Choices where the thesis is open (and why)".
#ifndef CMGEOM_COMPACT_MODEL_RECONSTRUCT_H
#define CMGEOM_COMPACT_MODEL_RECONSTRUCT_H

#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Compact_model/local_surface_projection.h>
#include <CMGeom/Error.h>
#include <CMGeom/Progress.h>
#include <CMGeom/config.h>
#include <CMGeom/internal/huge_pages.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

// The row kernel of regular reconstruction along N evaluates four grid points at once in AVX
// registers (GCC/Clang vector types on x86-64, when the processor has AVX, checked at run time;
// the scalar kernel otherwise). Each lane performs exactly the scalar operations, in the same
// order (no FMA: the project compiles with -ffp-contract=off and the kernel enables AVX only), so
// the results are bit-identical to the scalar kernel's, whichever runs.
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && defined(__SSE2__) && !defined(CMGEOM_NO_SIMD)
#define CMGEOM_CM_SIMD_ROWS 1
#include <immintrin.h>
#endif

namespace CMGeom {
namespace CM {

/// How S-bar_i(p) is computed (§4.5.1).
enum class Projection { along_normal, closest_point };

/// Affine map T(x) = M (x - rest) + deformed of one base vertex (thesis §6.3), see the
/// deformation hook in the file comment. `identity` marks maps that are exactly x -> x (they are
/// skipped, so that unmoved regions stay bit-identical to the plain reconstruction).
struct Vertex_affine_map {
  double M[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};  ///< row-major
  Vec3 rest, deformed;
  bool identity = true;
};

struct Reconstruction_options {
  Projection projection = Projection::closest_point;  ///< the thesis' results use closest point
  bool parallel = true;                               ///< TBB over base edges and faces
  /// Optional per-base-vertex affine maps (one per base vertex; nullptr = plain reconstruction).
  const std::vector<Vertex_affine_map>* vertex_maps = nullptr;
  /// Optional progress hook (CMGeom/Progress.h): the fraction of the reconstruction done, from
  /// the calling thread, at a bounded rate; it must be cheap. Empty: no reports.
  Progress_callback progress;
};

/// A reconstructed point with its blended unit normal (what adaptive criteria look at).
struct Sample {
  Vec3 point, normal;
};

/// The arrays of a Reconstruction: std::vectors whose resize() leaves new elements unwritten
/// (CMGeom::internal::Unwritten_allocator; reconstruct_*() writes every element, and a fresh
/// output is not written twice). Code that resizes one itself must write the new elements.
template <class T>
using Output_array = std::vector<T, CMGeom::internal::Unwritten_allocator<T>>;

/// Output of reconstruct_*(): an indexed triangle mesh with per-corner texture coordinates
/// (when the model is textured) and the base face of every triangle.
struct Reconstruction {
  Output_array<Vec3> points;
  Output_array<Vec3> normals;  ///< blended normal of every point
  Output_array<std::array<std::uint32_t, 3>> triangles;
  Output_array<std::uint32_t> base_face;          ///< per triangle
  Output_array<std::array<float, 2>> corner_uvs;  ///< 3 per triangle, or empty
};

// ------------------------------------------------------------------ criteria
/// Where an adaptive criterion is asked about an edge: the base face(s) it lies in (two for a
/// segment of an interior base edge, `face[1] == face[0]` inside a face or on the border) and the
/// number of halvings that made it. A criterion callable as `c(a, b, site)` receives it; one
/// callable as `c(a, b)` sees the samples alone.
struct Split_site {
  std::uint32_t face[2];
  int level;
};

/// Splits every edge (adaptive with this criterion = regular subdivision).
struct Always_split {
  bool operator()(const Sample&, const Sample&) const { return true; }
};
/// §4.5.2 "Length": |Phi(p1) Phi(p2)| greater than a threshold.
struct Edge_length_criterion {
  double max_length;
  bool operator()(const Sample& a, const Sample& b) const {
    return internal::squared_length(a.point - b.point) > max_length * max_length;
  }
};
/// §4.5.2 "Region of interest": at least one end point within a ball.
struct Region_of_interest_criterion {
  Vec3 center;
  double radius;
  bool operator()(const Sample& a, const Sample& b) const {
    const double r2 = radius * radius;
    return internal::squared_length(a.point - center) <= r2 || internal::squared_length(b.point - center) <= r2;
  }
};
/// §4.5.2 "Silhouette" for a viewpoint: an end point is on the silhouette when its normal is
/// within `tolerance` (cosine) of orthogonal to the view direction; an edge whose two ends face
/// opposite ways also straddles the silhouette (our addition: the contour can pass between two
/// samples neither of which is within the tolerance).
struct Silhouette_criterion {
  Vec3 eye;
  double tolerance = 0.2;
  double facing(const Sample& s) const {
    const Vec3 d = internal::normalized(eye - s.point);
    return internal::dot(d, s.normal);
  }
  bool operator()(const Sample& a, const Sample& b) const {
    const double fa = facing(a), fb = facing(b);
    return std::abs(fa) < tolerance || std::abs(fb) < tolerance || (fa > 0) != (fb > 0);
  }
};

namespace internal {

template <class C, class = void>
struct Takes_split_site : std::false_type {};
template <class C>
struct Takes_split_site<
    C, std::void_t<decltype(std::declval<const C&>()(std::declval<const Sample&>(), std::declval<const Sample&>(),
                                                     std::declval<const Split_site&>()))>> : std::true_type {};

/// Asks criterion `c` about the edge (a, b) at `site` (see Split_site).
template <class C>
bool ask_criterion(const C& c, const Sample& a, const Sample& b, const Split_site& site) {
  if constexpr (Takes_split_site<C>::value)
    return c(a, b, site);
  else
    return c(a, b);
}

// Edges of the base mesh, faces' sides, and per-corner frames (computed once).
struct Base_topology {
  struct Edge {
    std::uint32_t a, b;              // a < b
    std::uint32_t face[2], side[2];  // side k of a face joins its corners k and k+1; face[1] = npos if border
  };
  static constexpr std::uint32_t npos = 0xffffffffu;
  std::vector<Edge> edges;
  std::vector<std::array<std::uint32_t, 3>> face_edges;
  std::vector<Local_frame> frames;  // 3 per face
  // Per face corner c, the local coordinates of the face's three vertices in that corner's frame:
  // the frame map is affine, so a point a0 v0 + a1 v1 + a2 v2 has local coordinates
  // a0 L[0] + a1 L[1] + a2 L[2] (6 multiply-adds instead of a world point and 3 dot products).
  std::vector<std::array<Vec3, 3>> corner_local;  // 3 per face

  explicit Base_topology(const Compact_model& m) {
    const std::size_t F = m.faces.size();
    face_edges.resize(F);
    frames.resize(3 * F);
    corner_local.resize(3 * F);
    std::vector<std::array<std::uint32_t, 4>> sides;  // (a, b, face, side)
    sides.reserve(3 * F);
    for (std::uint32_t f = 0; f < F; ++f)
      for (std::uint32_t k = 0; k < 3; ++k) {
        std::uint32_t a = m.faces[f][k].vertex, b = m.faces[f][(k + 1) % 3].vertex;
        if (a > b) std::swap(a, b);
        sides.push_back({a, b, f, k});
        frames[3 * f + k] = m.frame(m.faces[f][k]);
        for (int i = 0; i < 3; ++i)
          corner_local[3 * f + k][i] = frames[3 * f + k].to_local(m.vertices[m.faces[f][i].vertex]);
      }
    // (a, b, face, side) in lexicographic order, in linear time (this runs before every
    // reconstruction): a counting sort on a keeps the (face, side) order of generation, then each
    // vertex's few sides are put in order of b by a stable insertion sort.
    {
      const std::size_t V = m.vertices.size();
      std::vector<std::uint32_t> start(V + 1, 0u);
      for (const auto& sd : sides) ++start[sd[0] + 1];
      for (std::size_t v = 0; v < V; ++v) start[v + 1] += start[v];
      std::vector<std::array<std::uint32_t, 4>> sorted(sides.size());
      {
        std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
        for (const auto& sd : sides) sorted[fill[sd[0]]++] = sd;
      }
      for (std::size_t v = 0; v < V; ++v)
        for (std::uint32_t i = start[v] + 1; i < start[v + 1]; ++i) {
          const std::array<std::uint32_t, 4> x = sorted[i];
          std::uint32_t j = i;
          for (; j > start[v] && sorted[j - 1][1] > x[1]; --j) sorted[j] = sorted[j - 1];
          sorted[j] = x;
        }
      sides.swap(sorted);
    }
    for (std::size_t i = 0; i < sides.size();) {
      Edge e{sides[i][0], sides[i][1], {sides[i][2], npos}, {sides[i][3], 0}};
      std::size_t j = i + 1;
      // A non-manifold edge (more than two faces) is reconstructed from its first two faces;
      // all of them share its points.
      if (j < sides.size() && sides[j][0] == e.a && sides[j][1] == e.b) {
        e.face[1] = sides[j][2];
        e.side[1] = sides[j][3];
      }
      const auto id = std::uint32_t(edges.size());
      for (; j < sides.size() && sides[j][0] == e.a && sides[j][1] == e.b; ++j) {}
      for (std::size_t k = i; k < j; ++k) face_edges[sides[k][2]][sides[k][3]] = id;
      edges.push_back(e);
      i = j;
    }
  }
};

// A vertex map written about the point c: T(x) = M (x - c) + offset, offset = M (c - rest) +
// deformed, in this order of operations wherever a kernel below needs it (so that every kernel's
// bits agree). With c = rest, offset = deformed exactly.
inline Vec3 map_offset(const Vertex_affine_map& T, const Vec3& c) {
  const Vec3 d = c - T.rest;
  return Vec3((T.M[0][0] * d.x + T.M[0][1] * d.y + T.M[0][2] * d.z) + T.deformed.x,
              (T.M[1][0] * d.x + T.M[1][1] * d.y + T.M[1][2] * d.z) + T.deformed.y,
              (T.M[2][0] * d.x + T.M[2][1] * d.y + T.M[2][2] * d.z) + T.deformed.z);
}

// The maps of K base vertices v[0..K-1] that the samples of one base edge or face all blend:
// each map, whether any of them moves, and (when one does) their offsets about the first map's
// rest point, map_offset(*T[c], T[0]->rest), as the four-lane kernels read them.
template <int K>
struct Corner_maps {
  const Vertex_affine_map* T[K];
  Vec3 O[K];
  bool moved = false;
  Corner_maps(const std::vector<Vertex_affine_map>& maps, const std::uint32_t* v) {
    for (int c = 0; c < K; ++c) {
      T[c] = &maps[v[c]];
      moved = moved || !T[c]->identity;
    }
    if (moved)
      for (int c = 0; c < K; ++c) O[c] = map_offset(*T[c], T[0]->rest);
  }
};

// Applies sum_k w[k] T_{v[k]} to a sample (point, and normal through the cofactor matrix of the
// blended M, which maps the normal of a tangent plane to the normal of its image, orientation
// included). Corners with zero weight are ignored; if every weighted corner is an identity map,
// the sample is left untouched (bit-exact identity). The blend is one affine map about the rest
// point c of the first corner's map, B (x - c) + t with B = sum_k w[k] M_k and t = sum_k w[k]
// offset_k (map_offset()): a point costs one product by B instead of one per corner, and a base
// vertex (one map, weight 1, x = c) lands exactly on its deformed point.
inline void apply_vertex_maps(const std::vector<Vertex_affine_map>& maps, int n, const std::uint32_t* v,
                              const double* w, Sample& s) {
  bool moved = false;
  for (int k = 0; k < n; ++k) moved = moved || (w[k] != 0. && !maps[v[k]].identity);
  if (!moved) return;
  double B[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  Vec3 t(0, 0, 0);
  const Vec3 c = maps[v[0]].rest;
  for (int k = 0; k < n; ++k) {
    if (w[k] == 0.) continue;
    const Vertex_affine_map& T = maps[v[k]];
    const Vec3 o = map_offset(T, c);
    t = Vec3(t.x + w[k] * o.x, t.y + w[k] * o.y, t.z + w[k] * o.z);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) B[i][j] += w[k] * T.M[i][j];
  }
  const Vec3 p = s.point - c;
  const Vec3 q((B[0][0] * p.x + B[0][1] * p.y + B[0][2] * p.z) + t.x,
               (B[1][0] * p.x + B[1][1] * p.y + B[1][2] * p.z) + t.y,
               (B[2][0] * p.x + B[2][1] * p.y + B[2][2] * p.z) + t.z);
  // Cofactor matrix C of B: C n = (B a) x (B b) for n = a x b.
  const Vec3 r0(B[0][0], B[0][1], B[0][2]), r1(B[1][0], B[1][1], B[1][2]), r2(B[2][0], B[2][1], B[2][2]);
  const Vec3 c0 = cross(r1, r2), c1 = cross(r2, r0), c2 = cross(r0, r1);
  const Vec3 cn(dot(c0, s.normal), dot(c1, s.normal), dot(c2, s.normal));
  s.point = q;
  if (squared_length(cn) > 0.) s.normal = normalized(cn);
}

#ifdef CMGEOM_CM_SIMD_ROWS
// Four-lane vectors for the AVX row kernel (see the note at the includes); every function that
// takes or returns one is compiled for AVX and inlined into the kernel.
namespace simd {
typedef double d4 __attribute__((vector_size(32)));
typedef long long m4 __attribute__((vector_size(32)));
#define CMGEOM_CM_AVX __attribute__((target("avx"))) CMGEOM_ALWAYS_INLINE
CMGEOM_CM_AVX d4 splat(double s) { return d4{s, s, s, s}; }
CMGEOM_CM_AVX d4 sqrt(d4 a) { return (d4)_mm256_sqrt_pd((__m256d)a); }
// m ? a : b per lane (m: all ones or zero).
CMGEOM_CM_AVX d4 select(m4 m, d4 a, d4 b) { return (d4)(((m4)a & m) | ((m4)b & ~m)); }
// Four doubles from p and to p, unaligned.
CMGEOM_CM_AVX d4 load(const double* p) {
  d4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
CMGEOM_CM_AVX void store(double* p, d4 v) { std::memcpy(p, &v, sizeof v); }
inline bool has_avx() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}
}  // namespace simd
#endif

// Normalised blend weights of the vertex maps (§6.4): alpha_i^3 / sum_j alpha_j^3 at barycentric
// (a0, a1, a2) of a base face, (1 - t)^3 and t^3 normalised at parameter t of a base edge. The
// one home of this arithmetic: every caller that must give the same bits (the Evaluator's mapped
// reconstruction, DCM::Deformable_reconstruction) computes the weights here.
inline void face_map_weights(double a0, double a1, double a2, double* wn) {
  const double w[3] = {a0 * a0 * a0, a1 * a1 * a1, a2 * a2 * a2};
  const double sum = w[0] + w[1] + w[2];
  wn[0] = w[0] / sum;
  wn[1] = w[1] / sum;
  wn[2] = w[2] / sum;
}
inline void edge_map_weights(double t, double* wn) {
  const double wa = (1. - t) * (1. - t) * (1. - t), wb = t * t * t, sum = wa + wb;
  wn[0] = wa / sum;
  wn[1] = wb / sum;
}

// Those weights at every point of regular reconstruction at step 1/n, the same for every base
// edge and face: `edge` holds 2 per point k = 1 .. n-1 of an edge (from a to b), `face` 3 per
// interior point of a face in output order (rows j = 1 .. n-2, i = 1 .. n-1-j). Built once per
// reconstruction (or per Deformable_reconstruction) instead of once per edge and face.
// With `face_kernel_lanes`, `face_lanes` holds the face weights again in the lanes of
// Face_lane_table (12 per group of four points: the four weights of corner 0, of corner 1, of
// corner 2; lanes past the last point repeat it), which the AVX face kernel along N reads when it
// maps the points it has just computed.
struct Map_weight_tables {
  std::size_t n;
  std::vector<double> edge, face, face_lanes;
  bool face_weights_positive = true;  // no interior weight underflows to 0 (the lanes need that)
  bool edge_weights_positive = true;
  explicit Map_weight_tables(std::size_t steps, bool face_kernel_lanes = false) : n(steps), edge(2 * (steps - 1)) {
    for (std::size_t k = 1; k < n; ++k) edge_map_weights(double(k) / double(n), &edge[2 * (k - 1)]);
    const std::size_t count = n > 1 ? (n - 1) * (n - 2) / 2 : 0;
    face.resize(3 * count);
    std::size_t k = 0;
    for (std::size_t j = 1; j + 1 < n; ++j)
      for (std::size_t i = 1; i + j < n; ++i, ++k)
        face_map_weights(double(n - i - j) / double(n), double(i) / double(n), double(j) / double(n), &face[3 * k]);
    if (face_kernel_lanes) face_lanes.resize(12 * ((count + 3) / 4));
    for (std::size_t g = 0; 4 * g < count && face_kernel_lanes; ++g)
      for (std::size_t l = 0; l < 4; ++l)
        for (std::size_t c = 0; c < 3; ++c)
          face_lanes[12 * g + 4 * c + l] = face[3 * (std::min)(4 * g + l, count - 1) + c];
    face_weights_positive = std::find(face.begin(), face.end(), 0.) == face.end();
    edge_weights_positive = std::find(edge.begin(), edge.end(), 0.) == edge.end();
  }
  std::size_t bytes() const { return (edge.size() + face.size() + face_lanes.size()) * sizeof(double); }
};

// The interior points of a face at step 1/n as along_normal_face() computes them, in groups of
// four lanes (output order, rows j = 1 .. n-2, i = 1 .. n-1-j, a group may span two rows; lanes
// past the last point repeat it): per group, 4 values each of a0, a1, a2, the corner weights
// w_c = a_c^3 and 1 / (w_0 + w_1 + w_2), with along_normal_row_scalar()'s operations (so the same
// bits). The same for every face: built once per reconstruction; 56 bytes per interior point of
// one face.
struct Face_lane_table {
  static constexpr std::size_t per_group = 28;
  std::size_t n = 0, count = 0, groups = 0;
  std::vector<double> lanes;
  explicit Face_lane_table(std::size_t steps) : n(steps) {
    if (n < 3) return;
    count = (n - 1) * (n - 2) / 2;
    groups = (count + 3) / 4;
    lanes.resize(per_group * groups);
    const double step = 1. / double(n);
    std::size_t i = 1, j = 1;  // grid point of the next lane
    for (std::size_t g = 0; g < groups; ++g) {
      double* L = &lanes[per_group * g];
      for (std::size_t l = 0; l < 4; ++l) {
        const double a0 = double(n - i - j) * step, a1 = double(i) * step, a2 = double(j) * step;
        const double w0 = a0 * a0 * a0, w1 = a1 * a1 * a1, w2 = a2 * a2 * a2;
        const double v[7] = {a0, a1, a2, w0, w1, w2, 1. / (w0 + w1 + w2)};
        for (std::size_t q = 0; q < 7; ++q) L[4 * q + l] = v[q];
        if (4 * g + l + 1 < count && ++i + j == n) {  // else the last point again
          i = 1;
          ++j;
        }
      }
    }
  }
};

#ifdef CMGEOM_CM_SIMD_ROWS
namespace simd {
// The maps of apply_vertex_maps_lanes(): every lane the same K maps (broadcast)...
template <int K>
struct Shared_maps {
  const Vertex_affine_map* const* T;  // T[c]
  const Vec3* O;                      // O[c] = map_offset(*T[c], T[0]->rest)
  CMGEOM_CM_AVX d4 M(int c, int i, int j) const { return splat(T[c]->M[i][j]); }
  CMGEOM_CM_AVX d4 offset(int c, int axis) const { return splat(O[c][axis]); }
  CMGEOM_CM_AVX d4 center(int axis) const { return splat(T[0]->rest[axis]); }
};
// ... or K maps per lane.
template <int K>
struct Lane_maps {
  const Vertex_affine_map* T[4][K];  // T[lane][c]
  Vec3 O[4][K];                      // map_offset(*T[lane][c], T[lane][0]->rest)
  CMGEOM_CM_AVX d4 M(int c, int i, int j) const {
    return d4{T[0][c]->M[i][j], T[1][c]->M[i][j], T[2][c]->M[i][j], T[3][c]->M[i][j]};
  }
  CMGEOM_CM_AVX d4 offset(int c, int axis) const {
    return d4{O[0][c][axis], O[1][c][axis], O[2][c][axis], O[3][c][axis]};
  }
  CMGEOM_CM_AVX d4 center(int axis) const {
    return d4{T[0][0]->rest[axis], T[1][0]->rest[axis], T[2][0]->rest[axis], T[3][0]->rest[axis]};
  }
};
}  // namespace simd

// apply_vertex_maps() in four lanes: lane l maps the sample whose point and normal are lane l of
// s[0..2] and s[3..5] (replaced by the result) with the maps c = 0..K-1 of `maps` and the weights
// w[c], every weight non-zero and some map of each lane not the identity (the callers check).
// Each lane performs apply_vertex_maps()'s operations in its order, so the bits are the same.
template <int K, class Maps>
CMGEOM_CM_AVX void apply_vertex_maps_lanes(const Maps& maps, const simd::d4 (&w)[K], simd::d4 (&s)[6]) {
  using D = simd::d4;
  using simd::splat;
  const D zero = splat(0.);
  D tx = zero, ty = zero, tz = zero;
  D B[3][3] = {{zero, zero, zero}, {zero, zero, zero}, {zero, zero, zero}};
  for (int c = 0; c < K; ++c) {
    tx = tx + w[c] * maps.offset(c, 0);
    ty = ty + w[c] * maps.offset(c, 1);
    tz = tz + w[c] * maps.offset(c, 2);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) B[i][j] += w[c] * maps.M(c, i, j);
  }
  const D px = s[0] - maps.center(0), py = s[1] - maps.center(1), pz = s[2] - maps.center(2);
  const D qx = (B[0][0] * px + B[0][1] * py + B[0][2] * pz) + tx;
  const D qy = (B[1][0] * px + B[1][1] * py + B[1][2] * pz) + ty;
  const D qz = (B[2][0] * px + B[2][1] * py + B[2][2] * pz) + tz;
  // Rows of the cofactor matrix: r1 x r2, r2 x r0, r0 x r1 (apply_vertex_maps()'s cross()).
  const D c0x = B[1][1] * B[2][2] - B[1][2] * B[2][1], c0y = B[1][2] * B[2][0] - B[1][0] * B[2][2],
          c0z = B[1][0] * B[2][1] - B[1][1] * B[2][0];
  const D c1x = B[2][1] * B[0][2] - B[2][2] * B[0][1], c1y = B[2][2] * B[0][0] - B[2][0] * B[0][2],
          c1z = B[2][0] * B[0][1] - B[2][1] * B[0][0];
  const D c2x = B[0][1] * B[1][2] - B[0][2] * B[1][1], c2y = B[0][2] * B[1][0] - B[0][0] * B[1][2],
          c2z = B[0][0] * B[1][1] - B[0][1] * B[1][0];
  const D cx = c0x * s[3] + c0y * s[4] + c0z * s[5], cy = c1x * s[3] + c1y * s[4] + c1z * s[5],
          cz = c2x * s[3] + c2y * s[4] + c2z * s[5];
  const D s2 = cx * cx + cy * cy + cz * cz;
  const simd::m4 pos = s2 > zero;  // false for NaN, as the scalar test
  const D inv = splat(1.) / simd::sqrt(simd::select(pos, s2, splat(1.)));
  s[0] = qx;
  s[1] = qy;
  s[2] = qz;
  s[3] = simd::select(pos, cx * inv, s[3]);
  s[4] = simd::select(pos, cy * inv, s[4]);
  s[5] = simd::select(pos, cz * inv, s[5]);
}

// Four samples of Vec3 arrays into lanes (p[l], n[l] -> lane l of s[0..2], s[3..5]) and back.
CMGEOM_CM_AVX void load_lanes(const Vec3* const (&p)[4], const Vec3* const (&n)[4], simd::d4 (&s)[6]) {
  s[0] = simd::d4{p[0]->x, p[1]->x, p[2]->x, p[3]->x};
  s[1] = simd::d4{p[0]->y, p[1]->y, p[2]->y, p[3]->y};
  s[2] = simd::d4{p[0]->z, p[1]->z, p[2]->z, p[3]->z};
  s[3] = simd::d4{n[0]->x, n[1]->x, n[2]->x, n[3]->x};
  s[4] = simd::d4{n[0]->y, n[1]->y, n[2]->y, n[3]->y};
  s[5] = simd::d4{n[0]->z, n[1]->z, n[2]->z, n[3]->z};
}
CMGEOM_CM_AVX void store_lanes(const simd::d4 (&s)[6], Vec3* const (&p)[4], Vec3* const (&n)[4]) {
  for (int l = 0; l < 4; ++l) {
    *p[l] = Vec3(s[0][l], s[1][l], s[2][l]);
    *n[l] = Vec3(s[3][l], s[4][l], s[5][l]);
  }
}

// apply_vertex_maps() on the four consecutive samples in_p[0..3], in_n[0..3], written to
// out_p, out_n (which may be in_p, in_n): all four blend the maps T[0..K-1], sample l with the
// weights w[K l .. K l + K - 1] (non-zero; some map not the identity).
template <int K>
__attribute__((target("avx"))) void apply_vertex_maps_avx(const Vertex_affine_map* const* T, const Vec3* O,
                                                          const double* w, const Vec3* in_p, const Vec3* in_n,
                                                          Vec3* out_p, Vec3* out_n) {
  simd::d4 wl[K];
  for (int c = 0; c < K; ++c) wl[c] = simd::d4{w[c], w[K + c], w[2 * K + c], w[3 * K + c]};
  simd::d4 s[6];
  load_lanes({in_p, in_p + 1, in_p + 2, in_p + 3}, {in_n, in_n + 1, in_n + 2, in_n + 3}, s);
  apply_vertex_maps_lanes<K>(simd::Shared_maps<K>{T, O}, wl, s);
  store_lanes(s, {out_p, out_p + 1, out_p + 2, out_p + 3}, {out_n, out_n + 1, out_n + 2, out_n + 3});
}
#endif

// apply_vertex_maps() on `count` samples that all blend the maps of the same K base vertices
// v[0..K-1], sample k with the weights w[K k .. K k + K - 1]: reads in_p, in_n and writes out_p,
// out_n (the same arrays or disjoint ones). The samples of a base edge or face in regular
// reconstruction share their vertices, so the identity test is made once and, with AVX, four
// samples are mapped at a time; the bits are apply_vertex_maps()'s either way.
template <int K>
void apply_shared_vertex_maps(const std::vector<Vertex_affine_map>& maps, const std::uint32_t* v, const double* w,
                              std::size_t count, const Vec3* in_p, const Vec3* in_n, Vec3* out_p, Vec3* out_n) {
  const Corner_maps<K> corners(maps, v);
  std::size_t k = 0;
#ifdef CMGEOM_CM_SIMD_ROWS
  if (corners.moved && simd::has_avx()) {
    for (; k + 4 <= count; k += 4) {
      // A zero weight drops its map from apply_vertex_maps()'s identity test: such groups go
      // through the scalar path below (never in regular reconstruction, whose weights are > 0).
      if (std::find(w + K * k, w + K * (k + 4), 0.) != w + K * (k + 4)) break;
      apply_vertex_maps_avx<K>(corners.T, corners.O, w + K * k, in_p + k, in_n + k, out_p + k, out_n + k);
    }
  }
#endif
  for (; k < count; ++k) {
    Sample s{in_p[k], in_n[k]};
    if (corners.moved) apply_vertex_maps(maps, K, v, w + K * k, s);
    out_p[k] = s.point;
    out_n[k] = s.normal;
  }
}

// apply_vertex_maps() on samples k_begin .. k_end-1 of run e (see apply_vertex_maps_across()).
template <int K, class Corner>
void apply_vertex_maps_one_run(const std::vector<Vertex_affine_map>& maps, const Corner& corner, std::size_t e,
                               std::size_t k_begin, std::size_t k_end, std::size_t per, const double* w,
                               const Vec3* in_p, const Vec3* in_n, Vec3* out_p, Vec3* out_n) {
  std::uint32_t v[K];
  for (int c = 0; c < K; ++c) v[c] = corner(e, c);
  for (std::size_t k = k_begin; k < k_end; ++k) {
    Sample s{in_p[per * e + k], in_n[per * e + k]};
    apply_vertex_maps(maps, K, v, w + K * k, s);
    out_p[per * e + k] = s.point;
    out_n[per * e + k] = s.normal;
  }
}

#ifdef CMGEOM_CM_SIMD_ROWS
// The AVX part of apply_vertex_maps_across(): runs e = 0, 4, 8, ... while four remain; returns
// the first run it left.
template <int K, class Corner>
__attribute__((target("avx"))) std::size_t apply_vertex_maps_across_avx(const std::vector<Vertex_affine_map>& maps,
                                                                        const Corner& corner, std::size_t count,
                                                                        std::size_t per, const double* w,
                                                                        const Vec3* in_p, const Vec3* in_n, Vec3* out_p,
                                                                        Vec3* out_n) {
  std::size_t e = 0;
  for (; e + 4 <= count; e += 4) {
    simd::Lane_maps<K> T;
    bool moved[4] = {false, false, false, false};
    for (int l = 0; l < 4; ++l)
      for (int c = 0; c < K; ++c) {
        T.T[l][c] = &maps[corner(e + l, c)];
        moved[l] = moved[l] || !T.T[l][c]->identity;
      }
    if (!(moved[0] || moved[1] || moved[2] || moved[3])) {
      if (out_p != in_p || out_n != in_n)
        for (std::size_t i = per * e; i < per * (e + 4); ++i) {
          out_p[i] = in_p[i];
          out_n[i] = in_n[i];
        }
      continue;
    }
    for (int l = 0; l < 4; ++l)  // (the offsets, once one of the four runs is known to move)
      for (int c = 0; c < K; ++c) T.O[l][c] = map_offset(*T.T[l][c], T.T[l][0]->rest);
    const simd::m4 keep{moved[0] ? 0LL : -1LL, moved[1] ? 0LL : -1LL, moved[2] ? 0LL : -1LL, moved[3] ? 0LL : -1LL};
    for (std::size_t k = 0; k < per; ++k) {
      const double* wk = w + K * k;
      if (std::find(wk, wk + K, 0.) != wk + K) {  // a zero weight: apply_vertex_maps() decides alone
        for (std::size_t l = 0; l < 4; ++l)
          apply_vertex_maps_one_run<K>(maps, corner, e + l, k, k + 1, per, w, in_p, in_n, out_p, out_n);
        continue;
      }
      simd::d4 wl[K];
      for (int c = 0; c < K; ++c) wl[c] = simd::splat(wk[c]);
      const std::size_t i0 = per * e + k, i1 = i0 + per, i2 = i1 + per, i3 = i2 + per;
      simd::d4 s[6], in[6];
      load_lanes({in_p + i0, in_p + i1, in_p + i2, in_p + i3}, {in_n + i0, in_n + i1, in_n + i2, in_n + i3}, s);
      for (int i = 0; i < 6; ++i) in[i] = s[i];
      apply_vertex_maps_lanes<K>(T, wl, s);
      for (int i = 0; i < 6; ++i) s[i] = simd::select(keep, in[i], s[i]);
      store_lanes(s, {out_p + i0, out_p + i1, out_p + i2, out_p + i3},
                  {out_n + i0, out_n + i1, out_n + i2, out_n + i3});
    }
  }
  return e;
}
#endif

// apply_vertex_maps() on sample k of run e, for e < count and k < per, of `count` runs of `per`
// consecutive samples (the points of base elements of one level: vertices, edges or faces), run e
// at in_p + per e, in_n + per e: it blends the maps of base vertices corner(e, 0 .. K-1) with the
// weights w[K k .. K k + K - 1], the same in every run. Written to out_p, out_n (the same arrays
// or disjoint ones). This serves runs shorter than four samples (levels 0 to 2), which
// apply_shared_vertex_maps() cannot put in lanes: with AVX, four runs are mapped at a time, lane
// l taking run e + l (a lane whose maps are all identities keeps its sample); the bits are
// apply_vertex_maps()'s either way.
template <int K, class Corner>
void apply_vertex_maps_across(const std::vector<Vertex_affine_map>& maps, const Corner& corner, std::size_t count,
                              std::size_t per, const double* w, const Vec3* in_p, const Vec3* in_n, Vec3* out_p,
                              Vec3* out_n) {
  std::size_t e = 0;
#ifdef CMGEOM_CM_SIMD_ROWS
  if (simd::has_avx()) e = apply_vertex_maps_across_avx<K>(maps, corner, count, per, w, in_p, in_n, out_p, out_n);
#endif
  for (; e < count; ++e) apply_vertex_maps_one_run<K>(maps, corner, e, 0, per, per, w, in_p, in_n, out_p, out_n);
}

template <class Traits>
class Evaluator {
public:
  // `map_weights` (the tables of the level, needed with maps by along_normal_face() and
  // edge_points()) must outlive the evaluator.
  Evaluator(const Compact_model& m, const Base_topology& topo, const Traits& traits, Projection proj,
            const std::vector<Vertex_affine_map>* maps = nullptr, const Map_weight_tables* map_weights = nullptr)
      : m_(m), topo_(topo), traits_(traits), proj_(proj), maps_(maps), map_weights_(map_weights) {
    if (maps_ && maps_->size() != m.vertices.size())
      throw Invalid_input("reconstruction: " + std::to_string(maps_->size()) + " vertex maps for " +
                          std::to_string(m.vertices.size()) + " base vertices");
  }

  // Position of base vertex i in the output (deformed when maps are given).
  Vec3 base_point(std::size_t i) const {
    return maps_ && !(*maps_)[i].identity ? (*maps_)[i].deformed : m_.vertices[i];
  }

  // S-bar of p on corner `c` of face f, with the surface normal there.
  Sample project(std::uint32_t f, int c, const Vec3& p) const {
    const Local_frame& fr = topo_.frames[3 * f + c];
    if (proj_ == Projection::along_normal) {
      const Vec3 l = fr.to_local(p);
      return along_normal_local(f, c, l.x, l.y);
    }
    const Local_surface& s = m_.surfaces[m_.faces[f][c].surface];
    double uv[2];
    const Vec3 q = closest_point(fr, s, p, traits_, uv);
    return {q, surface_normal(fr, s, uv[0], uv[1], traits_)};
  }

  // S-bar along N of the point with local coordinates (x, y, ·) in corner c of face f: one height
  // evaluation gives the point and the normal (what project() computes from a world point).
  Sample along_normal_local(std::uint32_t f, int c, double x, double y) const {
    const Local_frame& fr = topo_.frames[3 * f + c];
    double d[5];
    const double h = traits_.height(m_.surfaces[m_.faces[f][c].surface], x, y, d);
    Sample r{fr.to_world(x, y, h), fr.N};
    if (std::isfinite(d[0]) && std::isfinite(d[1])) r.normal = normalized(fr.N - d[0] * fr.U - d[1] * fr.V);
    return r;
  }

  // One corner's term of the blend along N at barycentric (a0, a1, a2): adds (w / sum) times the
  // corner surface's point to p (inv = 1 / sum) and w times its unit normal to q. The point comes
  // from the corner frame's images L of the base triangle; the normal is weighted as w / |g| in
  // one step (one square root, one division). interior() and along_normal_row_scalar() both use it, so
  // regular, adaptive and (identity-)mapped reconstructions along N agree bit for bit.
  CMGEOM_ALWAYS_INLINE void add_along_normal(const Local_frame& fr, const Local_surface& s,
                                             const std::array<Vec3, 3>& L, double a0, double a1, double a2, double w,
                                             double inv, Vec3& p, Vec3& q) const {
    const double x = a0 * L[0].x + a1 * L[1].x + a2 * L[2].x;
    const double y = a0 * L[0].y + a1 * L[1].y + a2 * L[2].y;
    double d[5];
    const double h = traits_.height(s, x, y, d);
    p += (w * inv) * fr.to_world(x, y, h);
    const Vec3 g = fr.N - d[0] * fr.U - d[1] * fr.V;
    const double g2 = squared_length(g);
    if (std::isfinite(g2) && g2 > 0.)
      q += (w / std::sqrt(g2)) * g;
    else
      q += w * fr.N;
  }

  // Phi along N at every interior grid point (i, j) of face f on the regular grid of step 1/n,
  // rows j = 1 .. n-2, i = 1 .. n-1-j, written in that order to pts[] and nrm[] (consecutive, as
  // the output stores a face's interior): interior() with the corner frames, surfaces and local
  // corner coordinates read once per face (the kernel of regular reconstruction); the results
  // are bit-identical to interior()'s. With vertex maps, every point is then mapped as
  // interior() maps it (same normalised weights), so mapped faces also give interior()'s bits.
  // The step is that of `lanes` (1/lanes.n; its lanes are what the AVX path reads), and `scratch`
  // is the caller's buffer, reused from face to face.
  void along_normal_face(std::uint32_t f, const Face_lane_table& lanes, std::vector<double>& scratch, Vec3* pts,
                         Vec3* nrm) const {
    const std::size_t n = lanes.n;
    const auto& F = m_.faces[f];
    const std::uint32_t v[3] = {F[0].vertex, F[1].vertex, F[2].vertex};
#ifdef CMGEOM_CM_SIMD_ROWS
    if (simd::has_avx()) {
      // Maps that move some corner are applied by the kernel to the points it has in registers
      // (apply_vertex_maps_lanes(), the same operations as apply_shared_vertex_maps()'s), where
      // a second pass read them back from the output and wrote them again.
      if (maps_ && level_weights(n).face_weights_positive && !level_weights(n).face_lanes.empty()) {
        const Corner_maps<3> corners(*maps_, v);
        along_normal_face_avx(f, lanes, scratch, pts, nrm, corners.moved ? &corners : nullptr,
                              level_weights(n).face_lanes.data());
        return;
      }
      along_normal_face_avx(f, lanes, scratch, pts, nrm);
    } else
#endif
      for (std::size_t j = 1, k = 0; j + 1 < n; k += n - 1 - j, ++j) along_normal_row_scalar(f, j, n, pts + k, nrm + k);
    if (!maps_) return;
    // The maps with apply_face_maps()'s weights (the level's table).
    apply_shared_vertex_maps<3>(*maps_, v, level_weights(n).face.data(), (n - 1) * (n - 2) / 2, pts, nrm, pts, nrm);
  }

  // The weight tables of step 1/n (given to the constructor).
  const Map_weight_tables& level_weights(std::size_t n) const {
    assert(map_weights_ != nullptr && map_weights_->n == n);
    return *map_weights_;
  }

  // on_edge() at t = k / n, k = 1 .. n-1, of base edge ei, written to pts[k - 1] and nrm[k - 1]
  // (the points of a base edge in regular reconstruction); along N, on an edge smooth at both
  // ends, four at a time in AVX registers with the same bits.
  void edge_points(std::uint32_t ei, std::size_t n, Vec3* pts, Vec3* nrm) const {
#ifdef CMGEOM_CM_SIMD_ROWS
    const Base_topology::Edge& e = topo_.edges[ei];
    if (proj_ == Projection::along_normal && simd::has_avx() && !sharp_at_an_end(e)) {
      // Maps that move an end are applied in the kernel (as along_normal_face() does).
      const std::uint32_t v[2] = {e.a, e.b};
      if (maps_ && level_weights(n).edge_weights_positive) {
        const Corner_maps<2> corners(*maps_, v);
        along_normal_edge_avx(ei, n, pts, nrm, corners.moved ? &corners : nullptr, level_weights(n).edge.data());
        return;
      }
      along_normal_edge_avx(ei, n, pts, nrm);
      if (maps_) apply_shared_vertex_maps<2>(*maps_, v, level_weights(n).edge.data(), n - 1, pts, nrm, pts, nrm);
      return;
    }
#endif
    for (std::size_t k = 1; k < n; ++k) {
      const Sample s = on_edge(ei, double(k) / double(n));
      pts[k - 1] = s.point;
      nrm[k - 1] = s.normal;
    }
  }

  void along_normal_row_scalar(std::uint32_t f, std::size_t j, std::size_t n, Vec3* pts, Vec3* nrm) const {
    const Local_frame* fr[3] = {&topo_.frames[3 * f], &topo_.frames[3 * f + 1], &topo_.frames[3 * f + 2]};
    const Local_surface* sf[3] = {&m_.surfaces[m_.faces[f][0].surface], &m_.surfaces[m_.faces[f][1].surface],
                                  &m_.surfaces[m_.faces[f][2].surface]};
    const std::array<Vec3, 3>* L[3] = {&topo_.corner_local[3 * f], &topo_.corner_local[3 * f + 1],
                                       &topo_.corner_local[3 * f + 2]};
    const double step = 1. / double(n);  // n is a power of two: k * step == k / n exactly
    const double a2 = double(j) * step;
    for (std::size_t i = 1; i + j < n; ++i) {
      const double a1 = double(i) * step, a0 = double(n - i - j) * step;
      const double w[3] = {a0 * a0 * a0, a1 * a1 * a1, a2 * a2 * a2};
      const double inv = 1. / (w[0] + w[1] + w[2]);
      Vec3 p, q;
      for (int c = 0; c < 3; ++c) add_along_normal(*fr[c], *sf[c], *L[c], a0, a1, a2, w[c], inv, p, q);
      pts[i - 1] = p;
      nrm[i - 1] = normalized(q);
    }
  }

#ifdef CMGEOM_CM_SIMD_ROWS
  // traits_.height(s, x, y, d) in four lanes: h and d[0], d[1]. Quadrics and cones (of the
  // quadric and cubic traits) are evaluated lane-wise with evaluate_height()'s operations in its
  // order; other models lane by lane through the traits.
  __attribute__((target("avx"))) CMGEOM_ALWAYS_INLINE void height_lanes(const Local_surface& s, simd::d4 x, simd::d4 y,
                                                                        simd::d4& h, simd::d4& d0, simd::d4& d1) const {
    using D = simd::d4;
    using M = simd::m4;
    constexpr bool quadric_traits =
        std::is_same<Traits, Quadric_surface_traits>::value || std::is_same<Traits, Cubic_surface_traits>::value;
    if (quadric_traits && (s.model == QUADRIC_MODEL || s.model == CONE_MODEL)) {
      // a cone is s sqrt of the quadric, with derivatives s q_x / (2 sqrt q) (NaN where q <= 0,
      // as evaluate_height() gives)
      const auto& k = s.c;
      h = simd::splat(k[0]) * x * x + simd::splat(k[1]) * x * y + simd::splat(k[2]) * y * y + simd::splat(k[3]) * x +
          simd::splat(k[4]) * y;
      d0 = simd::splat(2 * k[0]) * x + simd::splat(k[1]) * y + simd::splat(k[3]);
      d1 = simd::splat(k[1]) * x + simd::splat(2 * k[2]) * y + simd::splat(k[4]);
      if (s.model == CONE_MODEL) {
        const D zero = simd::splat(0.), one = simd::splat(1.);
        const D sgn = simd::splat(k[5] < 0 ? -1. : 1.), two = simd::splat(2.);
        const D nan = simd::splat(std::numeric_limits<double>::quiet_NaN());
        const M inside = ~(h <= zero);  // NaN stays NaN, as in evaluate_height()
        const D r = simd::sqrt(simd::select(inside, h, one));
        d0 = simd::select(inside, sgn * d0 / (two * r), nan);
        d1 = simd::select(inside, sgn * d1 / (two * r), nan);
        h = simd::select(inside, sgn * r, zero);
      }
    } else {
      for (int l = 0; l < 4; ++l) {
        double d[5];
        h[l] = traits_.height(s, x[l], y[l], d);
        d0[l] = d[0];
        d1[l] = d[1];
      }
    }
  }

  // S-bar along N of four world points (px, py, pz) on corner c of face f: project()'s
  // along-normal branch lane by lane (to_local, one height, to_world, the unit normal where the
  // derivatives are finite, N elsewhere).
  __attribute__((target("avx"))) CMGEOM_ALWAYS_INLINE void project_along_normal_lanes(std::uint32_t f, int c,
                                                                                      simd::d4 px, simd::d4 py,
                                                                                      simd::d4 pz,
                                                                                      simd::d4 (&out)[6]) const {
    using D = simd::d4;
    using M = simd::m4;
    const Local_frame& fr = topo_.frames[3 * f + c];
    const D dx = px - simd::splat(fr.origin.x), dy = py - simd::splat(fr.origin.y), dz = pz - simd::splat(fr.origin.z);
    const D x = dx * simd::splat(fr.U.x) + dy * simd::splat(fr.U.y) + dz * simd::splat(fr.U.z);
    const D y = dx * simd::splat(fr.V.x) + dy * simd::splat(fr.V.y) + dz * simd::splat(fr.V.z);
    D h, d0, d1;
    height_lanes(m_.surfaces[m_.faces[f][c].surface], x, y, h, d0, d1);
    out[0] = ((simd::splat(fr.origin.x) + x * simd::splat(fr.U.x)) + y * simd::splat(fr.V.x)) + h * simd::splat(fr.N.x);
    out[1] = ((simd::splat(fr.origin.y) + x * simd::splat(fr.U.y)) + y * simd::splat(fr.V.y)) + h * simd::splat(fr.N.y);
    out[2] = ((simd::splat(fr.origin.z) + x * simd::splat(fr.U.z)) + y * simd::splat(fr.V.z)) + h * simd::splat(fr.N.z);
    const D zero = simd::splat(0.), one = simd::splat(1.);
    const D Nx = simd::splat(fr.N.x), Ny = simd::splat(fr.N.y), Nz = simd::splat(fr.N.z);
    const D gx = (Nx - d0 * simd::splat(fr.U.x)) - d1 * simd::splat(fr.V.x);
    const D gy = (Ny - d0 * simd::splat(fr.U.y)) - d1 * simd::splat(fr.V.y);
    const D gz = (Nz - d0 * simd::splat(fr.U.z)) - d1 * simd::splat(fr.V.z);
    const D len = simd::sqrt(gx * gx + gy * gy + gz * gz);
    const M pos = len > zero;
    const D r = simd::select(pos, one / len, one);
    const M finite = (d0 - d0 == zero) & (d1 - d1 == zero);  // std::isfinite of both
    out[3] = simd::select(finite, simd::select(pos, gx * r, gx), Nx);
    out[4] = simd::select(finite, simd::select(pos, gy * r, gy), Ny);
    out[5] = simd::select(finite, simd::select(pos, gz * r, gz), Nz);
  }

  // on_edge() at t = k / n, k = 1 .. n-1, of base edge ei along N, written to pts[k - 1] and
  // nrm[k - 1], four points at a time with on_edge()'s operations in its order (bit-identical).
  // Only for an edge that is smooth at both ends (edge_end_projection() is then project()).
  // With `maps` (of a and b, some moving) and `map_weights` (Map_weight_tables::edge), every
  // point is mapped before it is stored (apply_edge_maps()'s operations, lane-wise).
  __attribute__((target("avx"))) void along_normal_edge_avx(std::uint32_t ei, std::size_t n, Vec3* pts, Vec3* nrm,
                                                            const Corner_maps<2>* maps = nullptr,
                                                            const double* map_weights = nullptr) const {
    using D = simd::d4;
    using M = simd::m4;
    const Base_topology::Edge& e = topo_.edges[ei];
    const std::uint32_t f0 = e.face[0];
    const int ca = corner_of(f0, e.a), cb = corner_of(f0, e.b);
    const Vec3 A = m_.vertices[e.a], B = m_.vertices[e.b];
    const D zero = simd::splat(0.), one = simd::splat(1.);
    for (std::size_t k0 = 1; k0 < n; k0 += 4) {
      D t;
      for (int l = 0; l < 4; ++l) t[l] = double(std::min(k0 + std::size_t(l), n - 1)) / double(n);
      const D u = one - t;
      // p = (1 - t) A + t B
      const D px = u * simd::splat(A.x) + t * simd::splat(B.x), py = u * simd::splat(A.y) + t * simd::splat(B.y),
              pz = u * simd::splat(A.z) + t * simd::splat(B.z);
      const D wa = u * u * u, wb = t * t * t, sum = wa + wb;
      D sa[6], sb[6];
      project_along_normal_lanes(f0, ca, px, py, pz, sa);
      project_along_normal_lanes(f0, cb, px, py, pz, sb);
      const D ka = wa / sum, kb = wb / sum;
      D r[6];
      for (int i = 0; i < 6; ++i) r[i] = (zero + ka * sa[i]) + kb * sb[i];  // r starts at 0, as in on_edge()
      const D len = simd::sqrt(r[3] * r[3] + r[4] * r[4] + r[5] * r[5]);
      const M pos = len > zero;
      const D inv = simd::select(pos, one / len, one);
      r[3] = simd::select(pos, r[3] * inv, r[3]);
      r[4] = simd::select(pos, r[4] * inv, r[4]);
      r[5] = simd::select(pos, r[5] * inv, r[5]);
      if (maps) {
        D wl[2];
        for (int l = 0; l < 4; ++l) {
          const double* w = map_weights + 2 * (std::min(k0 + std::size_t(l), n - 1) - 1);
          wl[0][l] = w[0];
          wl[1][l] = w[1];
        }
        apply_vertex_maps_lanes<2>(simd::Shared_maps<2>{maps->T, maps->O}, wl, r);
      }
      const int valid = int(std::min<std::size_t>(4, n - k0));
      for (int l = 0; l < valid; ++l) {
        pts[k0 + l - 1] = Vec3(r[0][l], r[1][l], r[2][l]);
        nrm[k0 + l - 1] = Vec3(r[3][l], r[4][l], r[5][l]);
      }
    }
  }

  // along_normal_row_scalar() on 4 consecutive interior points of face f at a time, in the
  // order of along_normal_face() (the lanes of `table`: packing the rows instead of padding each
  // one saves a tenth of the lanes at level 5). Every lane performs the same operations in the
  // same order (Vec3 arithmetic spelled out component-wise, left to right), so the bits are the
  // scalar path's. The points go in chunks of `chunk` groups, and within a chunk the corners are
  // the outer loop: a corner's terms of all the chunk's points are added to sums in `scratch`, so
  // the groups of one corner do not wait on one another and their square roots and divisions
  // overlap, where a group's three corners, one after the other, left them waiting on the latency
  // (1.35x the points per second of that loop, level 6, one thread). Lanes past the last point
  // are not stored. With `maps` (of the face's corners, some moving) and `map_lanes`
  // (Map_weight_tables::face_lanes), every point is mapped before it is stored.
  __attribute__((target("avx"))) void along_normal_face_avx(std::uint32_t f, const Face_lane_table& table,
                                                            std::vector<double>& scratch, Vec3* pts, Vec3* nrm,
                                                            const Corner_maps<3>* maps = nullptr,
                                                            const double* map_lanes = nullptr) const {
    using D = simd::d4;
    using M = simd::m4;
    constexpr std::size_t chunk = 128, per_group = Face_lane_table::per_group;
    const std::size_t count = table.count, groups = table.groups;
    if (count == 0) return;
    if (scratch.size() < 24 * chunk) scratch.resize(24 * chunk);  // px, py, pz, qx, qy, qz of a group
    const D zero = simd::splat(0.), one = simd::splat(1.), big = simd::splat(DBL_MAX);
    for (std::size_t g0 = 0; g0 < groups; g0 += chunk) {
      const std::size_t gn = (std::min)(chunk, groups - g0);
      for (int c = 0; c < 3; ++c) {
        const Local_frame& fr = topo_.frames[3 * f + c];
        const Local_surface& s = m_.surfaces[m_.faces[f][c].surface];
        const std::array<Vec3, 3>& L = topo_.corner_local[3 * f + c];
        const D L0x = simd::splat(L[0].x), L1x = simd::splat(L[1].x), L2x = simd::splat(L[2].x);
        const D L0y = simd::splat(L[0].y), L1y = simd::splat(L[1].y), L2y = simd::splat(L[2].y);
        const D Ox = simd::splat(fr.origin.x), Oy = simd::splat(fr.origin.y), Oz = simd::splat(fr.origin.z);
        const D Ux = simd::splat(fr.U.x), Uy = simd::splat(fr.U.y), Uz = simd::splat(fr.U.z);
        const D Vx = simd::splat(fr.V.x), Vy = simd::splat(fr.V.y), Vz = simd::splat(fr.V.z);
        const D Nx = simd::splat(fr.N.x), Ny = simd::splat(fr.N.y), Nz = simd::splat(fr.N.z);
        for (std::size_t k = 0; k < gn; ++k) {
          const double* lane = &table.lanes[per_group * (g0 + k)];
          double* sum = &scratch[24 * k];
          const D a0 = simd::load(lane), a1 = simd::load(lane + 4), a2 = simd::load(lane + 8);
          const D w = simd::load(lane + 12 + 4 * c);
          const D x = a0 * L0x + a1 * L1x + a2 * L2x;
          const D y = a0 * L0y + a1 * L1y + a2 * L2y;
          D h, d0, d1;
          height_lanes(s, x, y, h, d0, d1);
          // p += (w inv) to_world(x, y, h); to_world = ((origin + x U) + y V) + h N; p starts at 0.
          const D wi = w * simd::load(lane + 24);
          const D px = c == 0 ? zero : simd::load(sum), py = c == 0 ? zero : simd::load(sum + 4),
                  pz = c == 0 ? zero : simd::load(sum + 8);
          simd::store(sum, px + wi * (((Ox + x * Ux) + y * Vx) + h * Nx));
          simd::store(sum + 4, py + wi * (((Oy + x * Uy) + y * Vy) + h * Ny));
          simd::store(sum + 8, pz + wi * (((Oz + x * Uz) + y * Vz) + h * Nz));
          // g = (N - d0 U) - d1 V; q += (w / |g|) g, or w N when |g|^2 is not finite and positive.
          const D gx = (Nx - d0 * Ux) - d1 * Vx;
          const D gy = (Ny - d0 * Uy) - d1 * Vy;
          const D gz = (Nz - d0 * Uz) - d1 * Vz;
          const D g2 = gx * gx + gy * gy + gz * gz;
          const M ok = (g2 > zero) & (g2 <= big);
          const D scale = simd::select(ok, w / simd::sqrt(g2), w);
          const D qx = c == 0 ? zero : simd::load(sum + 12), qy = c == 0 ? zero : simd::load(sum + 16),
                  qz = c == 0 ? zero : simd::load(sum + 20);
          simd::store(sum + 12, qx + scale * simd::select(ok, gx, Nx));
          simd::store(sum + 16, qy + scale * simd::select(ok, gy, Ny));
          simd::store(sum + 20, qz + scale * simd::select(ok, gz, Nz));
        }
      }
      for (std::size_t k = 0; k < gn; ++k) {
        const double* sum = &scratch[24 * k];
        const D qx = simd::load(sum + 12), qy = simd::load(sum + 16), qz = simd::load(sum + 20);
        // normalized(q) = q * (1 / |q|) when |q| > 0.
        const D len = simd::sqrt(qx * qx + qy * qy + qz * qz);
        const M pos = len > zero;
        const D r = simd::select(pos, one / len, one);
        D s[6] = {simd::load(sum),
                  simd::load(sum + 4),
                  simd::load(sum + 8),
                  simd::select(pos, qx * r, qx),
                  simd::select(pos, qy * r, qy),
                  simd::select(pos, qz * r, qz)};
        if (maps) {
          const double* wg = map_lanes + 12 * (g0 + k);
          const D wl[3] = {simd::load(wg), simd::load(wg + 4), simd::load(wg + 8)};
          apply_vertex_maps_lanes<3>(simd::Shared_maps<3>{maps->T, maps->O}, wl, s);
        }
        const std::size_t k0 = 4 * (g0 + k);
        const int valid = int((std::min)(std::size_t(4), count - k0));
        for (int l = 0; l < valid; ++l) {
          pts[k0 + l] = Vec3(s[0][l], s[1][l], s[2][l]);
          nrm[k0 + l] = Vec3(s[3][l], s[4][l], s[5][l]);
        }
      }
    }
  }
#endif

  // Phi at barycentric (a0, a1, a2) of face f (a point not on a base edge, or on a smooth one).
  Sample interior(std::uint32_t f, double a0, double a1, double a2) const {
    const auto& F = m_.faces[f];
    const double w[3] = {a0 * a0 * a0, a1 * a1 * a1, a2 * a2 * a2};
    const double sum = w[0] + w[1] + w[2];
    Sample r{Vec3(), Vec3()};
    if (proj_ == Projection::along_normal) {
      // The normal is normalised at the end, so it is blended with w[c] (no division by sum).
      const double inv = 1. / sum;
      for (int c = 0; c < 3; ++c)
        if (w[c] != 0.)
          add_along_normal(topo_.frames[3 * f + c], m_.surfaces[F[c].surface], topo_.corner_local[3 * f + c], a0, a1,
                           a2, w[c], inv, r.point, r.normal);
    } else {
      const Vec3 p = a0 * m_.vertices[F[0].vertex] + a1 * m_.vertices[F[1].vertex] + a2 * m_.vertices[F[2].vertex];
      for (int c = 0; c < 3; ++c) {
        if (w[c] == 0.) continue;
        const Sample s = project(f, c, p);
        r.point += (w[c] / sum) * s.point;
        r.normal += (w[c] / sum) * s.normal;
      }
    }
    r.normal = normalized(r.normal);
    if (maps_) apply_face_maps(f, a0, a1, a2, r);
    return r;
  }

  // The vertex maps at the point of barycentric (a0, a1, a2) of face f (weights alpha_i^3,
  // normalised, as the blend uses them), applied to r.
  void apply_face_maps(std::uint32_t f, double a0, double a1, double a2, Sample& r) const {
    const auto& F = m_.faces[f];
    const std::uint32_t v[3] = {F[0].vertex, F[1].vertex, F[2].vertex};
    double wn[3];
    face_map_weights(a0, a1, a2, wn);
    apply_vertex_maps(*maps_, 3, v, wn, r);
  }

  // The vertex maps at parameter t of base edge e (on_edge()'s weights), applied to r.
  void apply_edge_maps(const Base_topology::Edge& e, double t, Sample& r) const {
    const std::uint32_t v[2] = {e.a, e.b};
    double wn[2];
    edge_map_weights(t, wn);
    apply_vertex_maps(*maps_, 2, v, wn, r);
  }

  // Whether base edge e is sharp at its endpoint v (its two faces' corners at v differ in
  // surface or normal); S-bar there is then the sharp-edge point, else the first face's S-bar.
  bool sharp_end(const Base_topology::Edge& e, std::uint32_t v) const {
    if (e.face[1] == Base_topology::npos) return false;
    const Corner& k0 = m_.faces[e.face[0]][corner_of(e.face[0], v)];
    const Corner& k1 = m_.faces[e.face[1]][corner_of(e.face[1], v)];
    return k0.surface != k1.surface || k0.normal != k1.normal;
  }
  // Whether base edge e is sharp at either end (its points are then sharp-edge points, one at a time).
  bool sharp_at_an_end(const Base_topology::Edge& e) const { return sharp_end(e, e.a) || sharp_end(e, e.b); }

  // S-bar at endpoint `end` (0: a, 1: b) of base edge e for the point p (sharp-aware).
  Sample edge_end_projection(const Base_topology::Edge& e, int end, const Vec3& p) const {
    const std::uint32_t v = end == 0 ? e.a : e.b;
    const std::uint32_t f0 = e.face[0];
    const int c0 = corner_of(f0, v);
    if (!sharp_end(e, v)) return project(f0, c0, p);
    const std::uint32_t f1 = e.face[1];
    const int c1 = corner_of(f1, v);
    const Local_frame& fr0 = topo_.frames[3 * f0 + c0];
    const Local_frame& fr1 = topo_.frames[3 * f1 + c1];
    const Vec3 t = normalized(m_.vertices[e.b] - m_.vertices[e.a]);
    const Local_surface& s0 = m_.surfaces[m_.faces[f0][c0].surface];
    const Local_surface& s1 = m_.surfaces[m_.faces[f1][c1].surface];
    const Vec3 q = sharp_edge_point(fr0, s0, fr1, s1, p, t, traits_);
    const Vec3 l0 = fr0.to_local(q), l1 = fr1.to_local(q);
    return {q, normalized(surface_normal(fr0, s0, l0.x, l0.y, traits_) + surface_normal(fr1, s1, l1.x, l1.y, traits_))};
  }

  // Phi at parameter t in [0, 1] along base edge e (from a to b).
  Sample on_edge(std::uint32_t ei, double t) const {
    const Base_topology::Edge& e = topo_.edges[ei];
    const Vec3 p = (1. - t) * m_.vertices[e.a] + t * m_.vertices[e.b];
    const double wa = (1. - t) * (1. - t) * (1. - t), wb = t * t * t, sum = wa + wb;
    Sample r{Vec3(), Vec3()};
    if (wa > 0.) {
      const Sample s = edge_end_projection(e, 0, p);
      r.point += (wa / sum) * s.point;
      r.normal += (wa / sum) * s.normal;
    }
    if (wb > 0.) {
      const Sample s = edge_end_projection(e, 1, p);
      r.point += (wb / sum) * s.point;
      r.normal += (wb / sum) * s.normal;
    }
    r.normal = normalized(r.normal);
    if (maps_) apply_edge_maps(e, t, r);
    return r;
  }

  // A base vertex seen from corner c of face f: the point itself, the sector's surface normal.
  Sample vertex(std::uint32_t f, int c) const {
    const Local_frame& fr = topo_.frames[3 * f + c];
    Sample r{m_.vertices[m_.faces[f][c].vertex],
             surface_normal(fr, m_.surfaces[m_.faces[f][c].surface], 0., 0., traits_)};
    if (maps_) {
      const std::uint32_t v = m_.faces[f][c].vertex;
      const double w = 1.;
      apply_vertex_maps(*maps_, 1, &v, &w, r);
    }
    return r;
  }

  int corner_of(std::uint32_t f, std::uint32_t v) const {
    const auto& F = m_.faces[f];
    return F[0].vertex == v ? 0 : (F[1].vertex == v ? 1 : 2);
  }

private:
  const Compact_model& m_;
  const Base_topology& topo_;
  Traits traits_;
  Projection proj_;
  const std::vector<Vertex_affine_map>* maps_;
  const Map_weight_tables* map_weights_;
};

// body(begin, end) over consecutive blocks of [0, n): per-block scratch memory lives in the body.
// `progress` (optional) counts the elements done, a block at a time.
template <class Body>
void for_blocks(std::size_t n, bool parallel, const Body& body,
                CMGeom::internal::Progress_reporter* progress = nullptr) {
  if (parallel) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
      body(r.begin(), r.end());
      if (progress) progress->add(r.size());
    });
  } else if (!progress || !progress->active()) {
    body(std::size_t(0), n);
  } else {
    for (std::size_t b = 0; b < n; b += 256) {  // serial: report every 256 elements
      body(b, std::min(n, b + 256));
      progress->add(std::min(n, b + 256) - b);
    }
  }
}

template <class Body>
void for_range(std::size_t n, bool parallel, const Body& body,
               CMGeom::internal::Progress_reporter* progress = nullptr) {
  for_blocks(
      n, parallel,
      [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i != end; ++i) body(i);
      },
      progress);
}

// The base vertices of a reconstruction (its first m.vertices.size() points): Phi(v) = v (mapped
// when the evaluator has maps), with the normal of the first corner that uses v, or zero for a
// base vertex no face uses. Regular and adaptive reconstructions alike.
template <class Traits>
void put_base_vertices(const Compact_model& m, const Evaluator<Traits>& ev, Vec3* points, Vec3* normals) {
  const std::size_t V = m.vertices.size();
  std::vector<std::uint8_t> seen(V, 0);
  for (std::size_t i = 0; i < V; ++i) points[i] = ev.base_point(i);
  for (std::uint32_t f = 0; f < m.faces.size(); ++f)
    for (int c = 0; c < 3; ++c)
      if (!seen[m.faces[f][c].vertex]) {
        seen[m.faces[f][c].vertex] = 1;
        normals[m.faces[f][c].vertex] = ev.vertex(f, c).normal;
      }
  for (std::size_t i = 0; i < V; ++i)
    if (!seen[i]) normals[i] = Vec3();
}

inline std::array<float, 2> interpolate_uv(const Face_uvs& uv, double a0, double a1, double a2) {
  return {float(a0 * uv[0][0] + a1 * uv[1][0] + a2 * uv[2][0]), float(a0 * uv[0][1] + a1 * uv[1][1] + a2 * uv[2][1])};
}

// The triangles, base faces and texture coordinates of a large regular reconstruction are written
// once and not read back by it: they go out with non-temporal stores (from a face's block built
// in cache), which skip reading every cache line of the output before writing it. Igea, 2,000
// base faces, level 5, one thread: the connectivity's 32 MB took 4.9 ms written in place and
// 3.6 ms so. (The points and normals, written four at a time as 96-byte groups that split cache
// lines, became four times slower so, and are stored as before.)
constexpr std::size_t stream_output_bytes = std::size_t(16) << 20;  // outputs from this size
constexpr std::size_t stream_max_n = 128;  // faces of at most this many rows (the block: <= 393 kB)

// to[0 .. count-1] = from[0 .. count-1], with non-temporal stores when both are 16-byte aligned
// and the bytes a multiple of 16 (finish_streaming() before another thread reads them).
template <class T>
void copy_streaming(const T* from, std::size_t count, T* to) {
  const std::size_t bytes = count * sizeof(T);
#ifdef CMGEOM_CM_SIMD_ROWS
  if (((reinterpret_cast<std::uintptr_t>(to) | reinterpret_cast<std::uintptr_t>(from)) & 15) == 0 && bytes % 16 == 0) {
    const __m128i* f = reinterpret_cast<const __m128i*>(from);
    __m128i* t = reinterpret_cast<__m128i*>(to);
    for (std::size_t i = 0; i < bytes / 16; ++i) _mm_stream_si128(t + i, _mm_load_si128(f + i));
    return;
  }
#endif
  std::copy(from, from + count, to);
}

// std::fill_n(to, count, value), with non-temporal stores as copy_streaming().
inline void fill_streaming(std::uint32_t* to, std::size_t count, std::uint32_t value) {
#ifdef CMGEOM_CM_SIMD_ROWS
  if ((reinterpret_cast<std::uintptr_t>(to) & 15) == 0 && count % 4 == 0) {
    const __m128i v = _mm_set1_epi32(int(value));
    __m128i* t = reinterpret_cast<__m128i*>(to);
    for (std::size_t i = 0; i < count / 4; ++i) _mm_stream_si128(t + i, v);
    return;
  }
#endif
  std::fill_n(to, count, value);
}

// Orders the non-temporal stores made so far before the stores that follow (a task's end).
inline void finish_streaming() {
#ifdef CMGEOM_CM_SIMD_ROWS
  _mm_sfence();
#endif
}

// Whether a Regular_reconstructor keeps the points of the base edges sharp at an end.
struct Keep_sharp_edges {
  bool value;
};
}  // namespace internal

/// The regular reconstruction of one model at one level (§4.5.2), made again and again: the
/// base's topology, its corner frames and the level's weight tables are computed once, by the
/// constructor, instead of by every call (on a 4,000-face base at level 4 they are about a
/// fifth of a reconstruction's time, with the page faults of their fresh memory), and so are the
/// points of the base edges sharp at an end (Newton solves; a fifth of a mapped call's time on
/// igea's CM of 4,000 base faces at level 4), which every call copies and maps. reconstruct()
/// writes the whole output; reconstruct_points() only the points and normals of an output that
/// already holds this reconstruction, since its triangles, base faces and texture coordinates
/// depend on the model and the level alone: one call per deformation frame (with
/// Reconstruction_options::vertex_maps, §6.4). Both give what reconstruct_regular() gives, bit
/// for bit. Keeps a reference to the model, which must outlive the reconstructor and not
/// change. The calls are const: several may run at once into different outputs.
template <class Traits = Quadric_surface_traits>
class Regular_reconstructor {
public:
  /// The projection is `opt.projection`; with `opt.vertex_maps` set, the blend's weight tables of
  /// the level are kept too (a call with maps on a reconstructor made without them builds its
  /// own). The points of base edges sharp at an end are computed here and kept (see
  /// number_of_kept_edges()). \throws Invalid_input if `level` is not in [0, 12] or the model is
  /// invalid.
  Regular_reconstructor(const Compact_model& m, int level, const Reconstruction_options& opt = Reconstruction_options(),
                        const Traits& traits = Traits())
      : Regular_reconstructor(internal::Keep_sharp_edges{true}, m, level, opt, traits) {}

  /// The same, keeping the sharp edges' points or not (reconstruct_regular(), one call, does not:
  /// it computes them into its output).
  Regular_reconstructor(internal::Keep_sharp_edges keep, const Compact_model& m, int level,
                        const Reconstruction_options& opt, const Traits& traits)
      : m_(m),
        traits_(traits),
        projection_(opt.projection),
        level_(checked_level(level)),
        n_(std::size_t(1) << level),
        topo_(validated(m)),
        lanes_(opt.projection == Projection::along_normal ? n_ : 0) {
    if (opt.vertex_maps) map_weights_.emplace(n_, projection_ == Projection::along_normal);
    if (keep.value) keep_sharp_edges(opt.parallel);
  }

  const Compact_model& model() const { return m_; }
  int level() const { return level_; }
  Projection projection() const { return projection_; }
  /// Points of the output (base vertices, then the points of every base edge and face).
  std::size_t number_of_points() const {
    return m_.vertices.size() + topo_.edges.size() * (n_ - 1) + m_.faces.size() * ((n_ - 1) * (n_ - 2) / 2);
  }
  std::size_t number_of_triangles() const { return m_.faces.size() * n_ * n_; }
  /// Memory held (topology, frames, tables), bytes.
  std::size_t bytes() const {
    return topo_.edges.size() * sizeof(internal::Base_topology::Edge) +
           topo_.face_edges.size() * sizeof(topo_.face_edges[0]) + topo_.frames.size() * sizeof(Local_frame) +
           topo_.corner_local.size() * sizeof(topo_.corner_local[0]) + lanes_.lanes.size() * sizeof(double) +
           (map_weights_ ? map_weights_->bytes() : 0) + sharp_slot_.size() * sizeof(std::uint32_t) +
           (sharp_points_.size() + sharp_normals_.size()) * sizeof(Vec3);
  }
  /// Base edges sharp at an end, whose points the reconstructor keeps (see keep_sharp_edges()).
  std::size_t number_of_kept_edges() const { return n_ > 1 ? sharp_points_.size() / (n_ - 1) : 0; }

  /// The whole reconstruction into `r`, reusing its memory: every array is resized and
  /// overwritten (a buffer of the right size is not reallocated). `opt.projection` must be the
  /// constructor's. \throws Invalid_input otherwise, or if `opt.vertex_maps` does not hold one
  /// map per base vertex.
  void reconstruct(Reconstruction& r, const Reconstruction_options& opt = Reconstruction_options()) const {
    check_projection(opt);
    run(r, opt, true);
  }

  /// The points and normals of `r`, which must hold this reconstruction already (from
  /// reconstruct() or reconstruct_regular() of the same model at the same level, possibly with
  /// other vertex maps); its triangles, base faces and texture coordinates are left as they are.
  /// \throws Invalid_input if the sizes of `r` are not this level's, or as reconstruct().
  void reconstruct_points(Reconstruction& r, const Reconstruction_options& opt = Reconstruction_options()) const {
    check_projection(opt);
    if (r.points.size() != number_of_points() || r.normals.size() != r.points.size() ||
        r.triangles.size() != number_of_triangles() || r.base_face.size() != number_of_triangles() ||
        r.corner_uvs.size() != (m_.has_uvs() ? 3 * number_of_triangles() : 0))
      throw Invalid_input("reconstruction: the output does not hold this model's regular reconstruction at level " +
                          std::to_string(level_) + " (" + std::to_string(r.points.size()) + " points, " +
                          std::to_string(r.triangles.size()) + " triangles; expected " +
                          std::to_string(number_of_points()) + " and " + std::to_string(number_of_triangles()) + ")");
    run(r, opt, false);
  }

private:
  static const Compact_model& validated(const Compact_model& m) {
    m.validate();
    return m;
  }
  static int checked_level(int level) {
    if (level < 0 || level > 12)
      throw Invalid_input("reconstruction level must be in [0, 12], got " + std::to_string(level));
    return level;
  }
  void check_projection(const Reconstruction_options& opt) const {
    if (opt.projection != projection_)
      throw Invalid_input("reconstruction: the options' projection is not the reconstructor's");
  }

  // The points of a base edge sharp at an end are Newton solves (sharp_edge_point(), §4.5.1),
  // each one costing as much as dozens of smooth points: a few edges took a fifth of a mapped
  // reconstruction's time (igea, 4,000 base faces, level 4). Their unmapped points and normals
  // are computed once here and every call copies them, mapped through the vertex maps with the
  // weights Evaluator::edge_points() gives them (the same bits); 48 bytes per point kept.
  void keep_sharp_edges(bool parallel) {
    const std::size_t E = topo_.edges.size(), per = n_ - 1;
    if (per == 0) return;
    const internal::Evaluator<Traits> ev(m_, topo_, traits_, projection_);
    std::vector<std::uint32_t> slot(E, internal::Base_topology::npos);
    std::uint32_t kept = 0;
    for (std::size_t e = 0; e < E; ++e) {
      if (ev.sharp_at_an_end(topo_.edges[e])) slot[e] = kept++;
    }
    if (kept == 0) return;
    sharp_points_.resize(kept * per);
    sharp_normals_.resize(kept * per);
    internal::for_range(E, parallel, [&](std::size_t e) {
      if (slot[e] != internal::Base_topology::npos)
        ev.edge_points(std::uint32_t(e), n_, &sharp_points_[slot[e] * per], &sharp_normals_[slot[e] * per]);
    });
    sharp_slot_ = std::move(slot);
  }

  // Points and normals; with `connectivity` the arrays of `r` are sized first and the triangles,
  // base faces and texture coordinates written too (without it they have their sizes already).
  void run(Reconstruction& r, const Reconstruction_options& opt, bool connectivity) const {
    const Compact_model& m = m_;
    const internal::Base_topology& topo = topo_;
    const std::size_t n = n_, V = m.vertices.size(), E = topo.edges.size(), F = m.faces.size();
    std::optional<internal::Map_weight_tables> own_weights;
    if (opt.vertex_maps && !map_weights_) own_weights.emplace(n, opt.projection == Projection::along_normal);
    const internal::Evaluator<Traits> ev(m, topo, traits_, opt.projection, opt.vertex_maps,
                                         !opt.vertex_maps ? nullptr
                                         : map_weights_   ? &*map_weights_
                                                          : &*own_weights);
    if (connectivity) {  // after the evaluator's checks: a refused call leaves `r` as it was
      // Large outputs fault in huge pages where the kernel gives them (internal/huge_pages.h).
      // (every element is written below: an Output_array's resize() writes none)
      CMGeom::internal::resize_on_huge_pages(r.points, number_of_points());
      CMGeom::internal::resize_on_huge_pages(r.normals, r.points.size());
      CMGeom::internal::resize_on_huge_pages(r.triangles, number_of_triangles());
      CMGeom::internal::resize_on_huge_pages(r.base_face, number_of_triangles());
      if (m.has_uvs())
        CMGeom::internal::resize_on_huge_pages(r.corner_uvs, 3 * number_of_triangles());
      else
        r.corner_uvs.clear();
    }
    const bool along_n_rows = opt.projection == Projection::along_normal;
    const std::size_t connectivity_bytes = number_of_triangles() * (sizeof(r.triangles[0]) + sizeof(r.base_face[0]) +
                                                                    (m.has_uvs() ? 3 * sizeof(r.corner_uvs[0]) : 0));
    const bool stream =
        connectivity && n >= 2 && n <= internal::stream_max_n && connectivity_bytes >= internal::stream_output_bytes;
    const internal::Face_lane_table& lanes = lanes_;
    const std::size_t per_edge = n - 1, per_face = (n - 1) * (n - 2) / 2;
    const std::size_t edge_base = V, face_base = V + E * per_edge;
    internal::put_base_vertices(m, ev, r.points.data(), r.normals.data());
    // Progress: the edges' and the faces' shares are those of the points they compute (plus a
    // quarter of a point per output triangle, and one per element for its fixed cost).
    CMGeom::internal::Progress_reporter progress(opt.progress);
    const double edge_cost = double(E) * double(per_edge + 1), face_cost = double(F) * double(per_face + n * n / 4 + 1);
    const double edge_share = edge_cost + face_cost > 0. ? edge_cost / (edge_cost + face_cost) : 0.;
    progress.phase(0., edge_share, E);
    internal::for_range(
        E, opt.parallel,
        [&](std::size_t e) {
          if (n <= 1) return;
          Vec3* P = &r.points[edge_base + e * per_edge];
          Vec3* N = &r.normals[edge_base + e * per_edge];
          if (sharp_slot_.empty() || sharp_slot_[e] == internal::Base_topology::npos) {
            ev.edge_points(std::uint32_t(e), n, P, N);
            return;
          }
          const Vec3* kept_p = &sharp_points_[sharp_slot_[e] * per_edge];
          const Vec3* kept_n = &sharp_normals_[sharp_slot_[e] * per_edge];
          if (opt.vertex_maps) {
            const std::uint32_t v[2] = {topo.edges[e].a, topo.edges[e].b};
            internal::apply_shared_vertex_maps<2>(*opt.vertex_maps, v, ev.level_weights(n).edge.data(), per_edge,
                                                  kept_p, kept_n, P, N);
          } else {
            std::copy(kept_p, kept_p + per_edge, P);
            std::copy(kept_n, kept_n + per_edge, N);
          }
        },
        &progress);
    progress.phase(edge_share, 1., F);
    internal::for_blocks(
        F, opt.parallel,
        [&](std::size_t f_begin, std::size_t f_end) {
          std::vector<std::uint32_t> grid(connectivity ? (n + 1) * (n + 2) / 2 : 0);
          std::vector<std::array<float, 2>> grid_uv(connectivity && m.has_uvs() ? grid.size() : 0);
          std::vector<double> scratch;
          // (with `stream`, a face's triangles and texture coordinates, then copied out)
          std::vector<std::array<std::uint32_t, 3>> face_triangles(stream ? n * n : 0);
          std::vector<std::array<float, 2>> face_uvs(stream && m.has_uvs() ? 3 * n * n : 0);
          for (std::size_t f = f_begin; f != f_end; ++f) {
            const auto& Fc = m.faces[f];
            // Output index of grid point (i, j): corner 0 at (0,0), corner 1 at (n,0), corner 2 at (0,n).
            auto on_side = [&](int side, std::size_t k_from_start) -> std::uint32_t {
              const auto& e = topo.edges[topo.face_edges[f][side]];
              const std::size_t k = (Fc[side].vertex == e.a) ? k_from_start : n - k_from_start;
              return std::uint32_t(edge_base + topo.face_edges[f][side] * per_edge + k - 1);
            };
            auto index = [&](std::size_t i, std::size_t j) -> std::uint32_t {
              if (i == 0 && j == 0) return Fc[0].vertex;
              if (i == n && j == 0) return Fc[1].vertex;
              if (i == 0 && j == n) return Fc[2].vertex;
              if (j == 0) return on_side(0, i);
              if (i + j == n) return on_side(1, j);
              if (i == 0) return on_side(2, n - j);
              // interior, rows j = 1..n-2, i = 1..n-1-j
              const std::size_t before = (j - 1) * (n - 2) - (j - 1) * (j - 2) / 2;
              return std::uint32_t(face_base + f * per_face + before + (i - 1));
            };
            // Interior points, row by row; a face's are consecutive (see index()).
            if (along_n_rows) {
              if (n >= 3)
                ev.along_normal_face(std::uint32_t(f), lanes, scratch, &r.points[index(1, 1)], &r.normals[index(1, 1)]);
            } else {
              for (std::size_t j = 1; j + 1 < n; ++j) {
                const std::uint32_t id = index(1, j);
                for (std::size_t i = 1; i + j < n; ++i) {
                  const double a1 = double(i) / double(n), a2 = double(j) / double(n),
                               a0 = double(n - i - j) / double(n);
                  const Sample s = ev.interior(std::uint32_t(f), a0, a1, a2);
                  r.points[id + i - 1] = s.point;
                  r.normals[id + i - 1] = s.normal;
                }
              }
            }
            if (!connectivity) continue;
            // The output id (and texture coordinates) of every grid point, computed once, then the
            // triangles: grid point (i, j) is entry row(j) + i.
            auto row = [n](std::size_t j) { return j * (n + 1) - j * (j - 1) / 2; };
            for (std::size_t j = 0; j <= n; ++j) {
              std::uint32_t* g = grid.data() + row(j);
              const std::size_t last = n - j;  // row j holds i = 0 .. last
              g[0] = index(0, j);
              g[last] = index(last, j);
              if (j == 0) {
                for (std::size_t i = 1; i < last; ++i) g[i] = index(i, 0);
              } else if (last >= 2) {  // interior ids of a row are consecutive
                const std::uint32_t first = index(1, j);
                for (std::size_t i = 1; i < last; ++i) g[i] = first + std::uint32_t(i - 1);
              }
            }
            // Triangles (i,j) (i+1,j) (i,j+1) and (i+1,j) (i+1,j+1) (i,j+1), row by row.
            std::array<std::uint32_t, 3>* T = stream ? face_triangles.data() : r.triangles.data() + f * n * n;
            for (std::size_t j = 0; j < n; ++j) {
              const std::uint32_t* g0 = grid.data() + row(j);
              const std::uint32_t* g1 = grid.data() + row(j + 1);
              const std::size_t last = n - 1 - j;  // i = 0 .. last
              for (std::size_t i = 0; i < last; ++i) {
                *T++ = {g0[i], g0[i + 1], g1[i]};
                *T++ = {g0[i + 1], g1[i + 1], g1[i]};
              }
              *T++ = {g0[last], g0[last + 1], g1[last]};
            }
            if (stream) {
              internal::copy_streaming(face_triangles.data(), n * n, r.triangles.data() + f * n * n);
              internal::fill_streaming(r.base_face.data() + f * n * n, n * n, std::uint32_t(f));
            } else {
              std::fill_n(r.base_face.data() + f * n * n, n * n, std::uint32_t(f));
            }
            if (m.has_uvs()) {
              for (std::size_t j = 0; j <= n; ++j)
                for (std::size_t i = 0; i + j <= n; ++i)
                  grid_uv[row(j) + i] = internal::interpolate_uv(m.uvs[f], double(n - i - j) / double(n),
                                                                 double(i) / double(n), double(j) / double(n));
              std::array<float, 2>* U = stream ? face_uvs.data() : r.corner_uvs.data() + 3 * f * n * n;
              auto put = [&](std::size_t a, std::size_t b, std::size_t c) {
                *U++ = grid_uv[a];
                *U++ = grid_uv[b];
                *U++ = grid_uv[c];
              };
              for (std::size_t j = 0; j < n; ++j) {
                const std::size_t r0 = row(j), r1 = row(j + 1);
                for (std::size_t i = 0; i + j < n; ++i) {
                  put(r0 + i, r0 + i + 1, r1 + i);
                  if (i + j + 2 <= n) put(r0 + i + 1, r1 + i + 1, r1 + i);
                }
              }
              if (stream) internal::copy_streaming(face_uvs.data(), 3 * n * n, r.corner_uvs.data() + 3 * f * n * n);
            }
          }
          if (stream) internal::finish_streaming();
        },
        &progress);
    progress.finish();
  }

  const Compact_model& m_;
  Traits traits_;
  Projection projection_;
  int level_;
  std::size_t n_;
  internal::Base_topology topo_;
  internal::Face_lane_table lanes_;
  std::optional<internal::Map_weight_tables> map_weights_;
  // keep_sharp_edges(): per base edge the index of its kept points (npos: not kept; empty: none
  // kept), and those points and normals, n - 1 per edge, unmapped.
  std::vector<std::uint32_t> sharp_slot_;
  std::vector<Vec3> sharp_points_, sharp_normals_;
};

/// Regular reconstruction at `level` (§4.5.2) into `r`, reusing its memory: every array is
/// resized and overwritten (a buffer of the right size is not reallocated, so repeated
/// reconstructions, e.g. one per deformation frame, pay no allocation and no page faults;
/// Regular_reconstructor also keeps the base's topology and frames between calls).
template <class Traits = Quadric_surface_traits>
void reconstruct_regular(const Compact_model& m, int level, Reconstruction& r,
                         const Reconstruction_options& opt = Reconstruction_options(),
                         const Traits& traits = Traits()) {
  Regular_reconstructor<Traits>(internal::Keep_sharp_edges{false}, m, level, opt, traits).reconstruct(r, opt);
}

/// Regular reconstruction at `level` (§4.5.2): 4^level triangles per base triangle.
template <class Traits = Quadric_surface_traits>
Reconstruction reconstruct_regular(const Compact_model& m, int level,
                                   const Reconstruction_options& opt = Reconstruction_options(),
                                   const Traits& traits = Traits()) {
  Reconstruction r;
  reconstruct_regular(m, level, r, opt, traits);
  return r;
}

namespace internal {

// Fixed-point barycentric coordinates: a point of a base face is (u1, u2) / 2^kBits (u0 implied);
// every subdivision point is a midpoint, so these stay exact.
constexpr int kBits = 40;
constexpr std::int64_t kOne = std::int64_t(1) << kBits;

struct Bary {
  std::int64_t u1, u2;
  std::int64_t u0() const { return kOne - u1 - u2; }
  bool operator==(const Bary& o) const { return u1 == o.u1 && u2 == o.u2; }
};
inline Bary midpoint(const Bary& a, const Bary& b) { return {(a.u1 + b.u1) / 2, (a.u2 + b.u2) / 2}; }
struct Bary_hash {
  std::size_t operator()(const Bary& b) const {
    return std::size_t(std::uint64_t(b.u1) * 0x9E3779B97F4A7C15ull ^ (std::uint64_t(b.u2) + 0x632BE59BD9B4E019ull));
  }
};

}  // namespace internal

/// Adaptive reconstruction (§4.5.2): edges selected by `criterion` (see the file comment) are
/// halved, recursively, up to `max_level` halvings of a base edge.
template <class Criterion, class Traits = Quadric_surface_traits>
Reconstruction reconstruct_adaptive(const Compact_model& m, const Criterion& criterion, int max_level,
                                    const Reconstruction_options& opt = Reconstruction_options(),
                                    const Traits& traits = Traits()) {
  using internal::Bary;
  using internal::kOne;
  if (max_level < 0 || max_level > 20)
    throw Invalid_input("adaptive reconstruction level must be in [0, 20], got " + std::to_string(max_level));
  m.validate();
  const internal::Base_topology topo(m);
  const internal::Evaluator<Traits> ev(m, topo, traits, opt.projection, opt.vertex_maps);
  const std::size_t V = m.vertices.size(), E = topo.edges.size(), F = m.faces.size();

  // Progress: edges 30 %, faces 65 %, assembly 5 % (see the file comment).
  CMGeom::internal::Progress_reporter progress(opt.progress);
  progress.phase(0., 0.3, E);

  // 1. Base edges: sorted split parameters (fixed point along a -> b) and their samples.
  struct Edge_points {
    std::vector<std::int64_t> t;  // interior parameters, ascending
    std::vector<Sample> s;
  };
  std::vector<Edge_points> ep(E);
  internal::for_range(
      E, opt.parallel,
      [&](std::size_t e) {
        const auto& ed = topo.edges[e];
        const std::uint32_t f0 = ed.face[0];
        const Sample sa = ev.vertex(f0, ev.corner_of(f0, ed.a)), sb = ev.vertex(f0, ev.corner_of(f0, ed.b));
        // Depth-first over segments, left to right, so t comes out sorted.
        struct Item {
          std::int64_t t0, t1;
          Sample s0, s1;
          int level;
        };
        std::vector<Item> stack{{0, kOne, sa, sb, 0}};
        while (!stack.empty()) {
          const Item it = stack.back();
          stack.pop_back();
          if (it.level >= max_level ||
              !internal::ask_criterion(
                  criterion, it.s0, it.s1,
                  Split_site{{f0, ed.face[1] == internal::Base_topology::npos ? f0 : ed.face[1]}, it.level}))
            continue;
          const std::int64_t tm = (it.t0 + it.t1) / 2;
          const Sample sm = ev.on_edge(std::uint32_t(e), double(tm) / double(kOne));
          // Right half pushed first so the left one is processed (and its points emitted) first;
          // points are emitted in order by an in-order traversal below.
          stack.push_back({tm, it.t1, sm, it.s1, it.level + 1});
          stack.push_back({it.t0, tm, it.s0, sm, it.level + 1});
          ep[e].t.push_back(tm);
          ep[e].s.push_back(sm);
        }
        // Sort by parameter (the pre-order above is not sorted).
        std::vector<std::size_t> order(ep[e].t.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return ep[e].t[x] < ep[e].t[y]; });
        Edge_points sorted;
        for (std::size_t i : order) {
          sorted.t.push_back(ep[e].t[i]);
          sorted.s.push_back(ep[e].s[i]);
        }
        ep[e] = std::move(sorted);
      },
      &progress);
  std::vector<std::size_t> edge_offset(E + 1, V);
  for (std::size_t e = 0; e < E; ++e) edge_offset[e + 1] = edge_offset[e] + ep[e].t.size();

  // 2. Faces: recursive splitting into per-face buffers.
  struct Face_out {
    std::vector<Sample> interior;
    std::vector<std::array<std::int64_t, 3>> tri;  // >= 0: global index; < 0: -(1 + local interior index)
    std::vector<std::array<Bary, 3>> bary;
  };
  std::vector<Face_out> fo(F);
  progress.phase(0.3, 0.95, F);
  internal::for_range(
      F, opt.parallel,
      [&](std::size_t fi) {
        const std::uint32_t f = std::uint32_t(fi);
        const auto& Fc = m.faces[f];
        Face_out& out = fo[f];
        struct Node {
          std::int64_t id;
          Sample s;
        };
        std::unordered_map<Bary, Node, internal::Bary_hash> memo;
        const Bary corner[3] = {{0, 0}, {kOne, 0}, {0, kOne}};
        for (int c = 0; c < 3; ++c) memo.emplace(corner[c], Node{std::int64_t(Fc[c].vertex), ev.vertex(f, c)});
        // Side k of the face holds points with u_{k+2} = 0; its parameter from corner k is u_{k+1}.
        auto coord = [](const Bary& b, int k) { return k == 0 ? b.u0() : (k == 1 ? b.u1 : b.u2); };
        auto side_of = [&](const Bary& b) -> int {
          for (int k = 0; k < 3; ++k)
            if (coord(b, (k + 2) % 3) == 0) return k;
          return -1;
        };
        auto edge_lookup = [&](int side, const Bary& b) -> const Node* {
          const std::uint32_t e = topo.face_edges[f][side];
          const auto& ed = topo.edges[e];
          const std::int64_t from_start = coord(b, (side + 1) % 3);
          const std::int64_t t = Fc[side].vertex == ed.a ? from_start : kOne - from_start;
          const auto it = std::lower_bound(ep[e].t.begin(), ep[e].t.end(), t);
          if (it == ep[e].t.end() || *it != t) return nullptr;
          const std::size_t k = std::size_t(it - ep[e].t.begin());
          auto ins = memo.emplace(b, Node{std::int64_t(edge_offset[e] + k), ep[e].s[k]});
          return &ins.first->second;
        };
        auto node = [&](const Bary& b) -> const Node& {
          auto it = memo.find(b);
          if (it != memo.end()) return it->second;
          const int side = side_of(b);
          if (side >= 0) {
            const Node* n = edge_lookup(side, b);
            CGAL_assertion(n != nullptr);
            return *n;
          }
          const Sample s =
              ev.interior(f, double(b.u0()) / double(kOne), double(b.u1) / double(kOne), double(b.u2) / double(kOne));
          out.interior.push_back(s);
          return memo.emplace(b, Node{-std::int64_t(out.interior.size()), s}).first->second;
        };
        // Does sub-edge (p, q) get split? Base-edge segments: the edge decided (its point exists).
        auto split = [&](const Bary& p, const Bary& q, int level) -> bool {
          const Bary mid = midpoint(p, q);
          for (int k = 0; k < 3; ++k) {
            const int opp = (k + 2) % 3;
            if (coord(p, opp) == 0 && coord(q, opp) == 0) return memo.count(mid) || edge_lookup(k, mid) != nullptr;
          }
          return level < max_level &&
                 internal::ask_criterion(criterion, node(p).s, node(q).s, Split_site{{f, f}, level});
        };
        struct Tri {
          Bary p[3];
          int level[3];  // level of edge p[k] p[k+1]
        };
        std::vector<Tri> stack{{{corner[0], corner[1], corner[2]}, {0, 0, 0}}};
        while (!stack.empty()) {
          const Tri T = stack.back();
          stack.pop_back();
          bool sp[3];
          int nsplit = 0;
          for (int k = 0; k < 3; ++k) nsplit += (sp[k] = split(T.p[k], T.p[(k + 1) % 3], T.level[k]));
          if (nsplit == 0) {
            std::array<std::int64_t, 3> ids;
            for (int k = 0; k < 3; ++k) ids[k] = node(T.p[k]).id;
            out.tri.push_back(ids);
            out.bary.push_back({T.p[0], T.p[1], T.p[2]});
            continue;
          }
          const int ln = std::max({T.level[0], T.level[1], T.level[2]}) + 1;
          Bary M[3];
          for (int k = 0; k < 3; ++k)
            if (sp[k]) {
              M[k] = midpoint(T.p[k], T.p[(k + 1) % 3]);
              node(M[k]);
            }
          // Children are pushed in reverse so they are processed (and their triangles emitted) in
          // the listed order; the order only matters for determinism, which any fixed order gives.
          std::vector<Tri> kids;
          if (nsplit == 3) {
            kids.push_back({{T.p[0], M[0], M[2]}, {T.level[0] + 1, ln, T.level[2] + 1}});
            kids.push_back({{M[0], T.p[1], M[1]}, {T.level[0] + 1, T.level[1] + 1, ln}});
            kids.push_back({{M[2], M[1], T.p[2]}, {ln, T.level[1] + 1, T.level[2] + 1}});
            kids.push_back({{M[0], M[1], M[2]}, {ln, ln, ln}});
          } else if (nsplit == 1) {
            const int k = sp[0] ? 0 : (sp[1] ? 1 : 2);
            const Bary &a = T.p[k], &b = T.p[(k + 1) % 3], &c = T.p[(k + 2) % 3];
            kids.push_back({{a, M[k], c}, {T.level[k] + 1, ln, T.level[(k + 2) % 3]}});
            kids.push_back({{M[k], b, c}, {T.level[k] + 1, T.level[(k + 1) % 3], ln}});
          } else {
            // Two split edges k and k+1 (cyclically); the unsplit one is k+2.
            const int u = !sp[0] ? 0 : (!sp[1] ? 1 : 2);
            const int k = (u + 1) % 3, k1 = (u + 2) % 3;
            const Bary &a = T.p[k], &b = T.p[k1], &c = T.p[u];  // edges a-b (k) and b-c (k1) split
            const Bary &mab = M[k], &mbc = M[k1];
            kids.push_back({{mab, b, mbc}, {T.level[k] + 1, T.level[k1] + 1, ln}});
            // Quad a, mab, mbc, c: cut along the shorter reconstructed diagonal (ties: a-mbc).
            const double d1 = internal::squared_length(node(a).s.point - node(mbc).s.point);
            const double d2 = internal::squared_length(node(mab).s.point - node(c).s.point);
            if (d1 <= d2) {
              kids.push_back({{a, mab, mbc}, {T.level[k] + 1, ln, ln}});
              kids.push_back({{a, mbc, c}, {ln, T.level[k1] + 1, T.level[u]}});
            } else {
              kids.push_back({{a, mab, c}, {T.level[k] + 1, ln, T.level[u]}});
              kids.push_back({{mab, mbc, c}, {ln, T.level[k1] + 1, ln}});
            }
          }
          for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back(*it);
        }
      },
      &progress);
  progress.phase(0.95, 1., 0);

  // 3. Assemble in order: base vertices, edge points, face interiors; triangles by face.
  std::vector<std::size_t> face_offset(F + 1, edge_offset[E]);
  for (std::size_t f = 0; f < F; ++f) face_offset[f + 1] = face_offset[f] + fo[f].interior.size();
  Reconstruction r;
  CMGeom::internal::resize_on_huge_pages(r.points, face_offset[F]);
  CMGeom::internal::resize_on_huge_pages(r.normals, face_offset[F]);
  internal::put_base_vertices(m, ev, r.points.data(), r.normals.data());
  for (std::size_t e = 0; e < E; ++e)
    for (std::size_t k = 0; k < ep[e].s.size(); ++k) {
      r.points[edge_offset[e] + k] = ep[e].s[k].point;
      r.normals[edge_offset[e] + k] = ep[e].s[k].normal;
    }
  for (std::size_t f = 0; f < F; ++f) {
    for (std::size_t k = 0; k < fo[f].interior.size(); ++k) {
      r.points[face_offset[f] + k] = fo[f].interior[k].point;
      r.normals[face_offset[f] + k] = fo[f].interior[k].normal;
    }
    for (std::size_t t = 0; t < fo[f].tri.size(); ++t) {
      std::array<std::uint32_t, 3> tri;
      for (int c = 0; c < 3; ++c) {
        const std::int64_t id = fo[f].tri[t][c];
        tri[c] = std::uint32_t(id >= 0 ? id : std::int64_t(face_offset[f]) + (-id - 1));
      }
      r.triangles.push_back(tri);
      r.base_face.push_back(std::uint32_t(f));
      if (m.has_uvs())
        for (int c = 0; c < 3; ++c) {
          const Bary& b = fo[f].bary[t][c];
          r.corner_uvs.push_back(internal::interpolate_uv(m.uvs[f], double(b.u0()) / double(kOne),
                                                          double(b.u1) / double(kOne), double(b.u2) / double(kOne)));
        }
    }
  }
  progress.finish();
  return r;
}

#ifdef CMGEOM_COMPACT_MODEL_PRECOMPILED
// Compiled once in CMGeom::Compact_model (src/Compact_model/compact_model_instantiations.cpp);
// linking that library defines the macro.
extern template class Regular_reconstructor<Quadric_surface_traits>;
extern template void reconstruct_regular<Quadric_surface_traits>(const Compact_model&, int, Reconstruction&,
                                                                 const Reconstruction_options&,
                                                                 const Quadric_surface_traits&);
extern template Reconstruction reconstruct_regular<Quadric_surface_traits>(const Compact_model&, int,
                                                                           const Reconstruction_options&,
                                                                           const Quadric_surface_traits&);
extern template Reconstruction reconstruct_adaptive<Edge_length_criterion, Quadric_surface_traits>(
    const Compact_model&, const Edge_length_criterion&, int, const Reconstruction_options&,
    const Quadric_surface_traits&);
extern template Reconstruction reconstruct_adaptive<Region_of_interest_criterion, Quadric_surface_traits>(
    const Compact_model&, const Region_of_interest_criterion&, int, const Reconstruction_options&,
    const Quadric_surface_traits&);
extern template Reconstruction reconstruct_adaptive<Silhouette_criterion, Quadric_surface_traits>(
    const Compact_model&, const Silhouette_criterion&, int, const Reconstruction_options&,
    const Quadric_surface_traits&);
#endif

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_RECONSTRUCT_H
