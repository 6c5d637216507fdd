// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The compact CM file (format version 3): a Compact Model quantized to a tolerance and entropy
// coded, for shipping a model in as few bytes as its error allows. Versions 1 and 2 (cm_io.h)
// store every number as float32 and stay exact; version 3 is lossy by design and bounded: every
// point of the reconstruction moves by about the tolerance at most (see "Error" below). parse_cm()
// and read_cm() of cm_io.h read all three versions.
//
// What is stored (thesis §4.4.3 lists vertices, coefficient lists, normals and faces; the coding
// below is a CMGeom addition, not in the thesis):
//   * connectivity: faces in breadth-first order over shared edges; a face is coded as the edge
//     of an earlier face it hangs on (one symbol: which edge, same or flipped orientation) plus
//     its third vertex (0 = a new vertex, else the distance back from the next new index); a face
//     not reachable from earlier ones starts a component with three vertex codes. Vertices are
//     renumbered in the order they appear (unreferenced base vertices are dropped).
//   * sectors: per vertex its number of (coefficient list, normal) pairs (most have one), and for
//     corners of vertices with several, the pair's number in order of first appearance. The
//     decoded model has one normal and one coefficient list per sector (the layout
//     build_compact_model produces).
//   * positions on a grid of step `tolerance` over the bounding box, each predicted by the
//     parallelogram rule across the edge its face hangs on (the previous vertex for a component's
//     first face), the integer residual stored.
//   * frame normals in octahedral coordinates with `normal_bits` per coordinate, predicted by the
//     area-weighted normal of the sector's faces (computed from the decoded positions).
//   * coefficients: each list is first refitted (same model, Local_surface_traits' fits) in the
//     decoded frame to samples of the original surface over the sector's faces, so that the
//     quantization of the vertex and the normal does not tilt or shift the surface; then
//     coefficient j of monomial degree d_j is stored as an integer multiple of
//     2 t / (k r^d_j) (k coefficients, r = distance from the vertex to the farthest corner of
//     the sector's faces, t = tolerance / 2): the height changes by at most t within radius r.
//     Cone lists (h = ±sqrt(q)) use step 2 t^2 / (5 r^d_j) for q (then |dh| <= sqrt|dq| <= t)
//     and one sign.
//   * texture coordinates (textured models) on a 16-bit grid over their bounding box, each
//     corner predicted by the last corner seen at the same vertex; and the texture path.
// Each part is a stream of LEB128 varints compressed by zstd (level 19) unless that is not
// smaller; CM_file_parts reports the bytes of each.
//
// Layout (little endian): "CMGEOMCM", u32 version 3, u32 flags (bit 0 textured), u32 V, u32 F,
// u32 K (sectors), f64 x 3 grid origin, f64 grid step, u8 normal bits, f64 t, then the streams
// (u8 method 0 raw / 1 zstd, u32 decoded size, u32 stored size, bytes) in the order
// connectivity, sectors, positions, normals, coefficients, uvs, then u64 FNV-1a of every
// preceding byte.
//
// Error: positions move by at most step / 2 per axis; the coefficient rounding changes heights by
// at most t = tolerance / 2 within each sector's radius; the refit adds its own least-squares
// residual (small against the tolerance when the normal bits are enough, measured in
// test_compact_model and benchmark/Compact_model/RESULTS.md).
//
// Reading checks counts against bounds before allocating, every index and symbol while decoding,
// then the checksum and Compact_model::validate; it throws IO_error (file, what) on the first
// failure and returns no partial model.
//
// These functions are compiled in the CMGeom::Compact_model library (they use zstd); with the
// headers alone, parse_cm() refuses a version 3 file with a clear message.
#ifndef CMGEOM_COMPACT_MODEL_CM_COMPACT_IO_H
#define CMGEOM_COMPACT_MODEL_CM_COMPACT_IO_H

#include <CMGeom/Compact_model/Compact_model.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>

#include <cstddef>
#include <string>

namespace CMGeom {
namespace CM {

/// How a Compact Model is quantized in a version 3 file.
struct Compact_encoding {
  /// Grid step of the positions and twice the coefficient tolerance, in model units; 0 = 1e-4
  /// times the bounding-box diagonal of the base vertices.
  double tolerance = 0.;
  /// Bits per octahedral coordinate of the frame normals, in [6, 20].
  int normal_bits = 12;
  /// zstd compression level of the streams, in [1, 22].
  int zstd_level = 19;
};

/// Stored bytes of each part of a version 3 file (stream headers included).
struct CM_file_parts {
  std::size_t header = 0, connectivity = 0, sectors = 0, positions = 0, normals = 0, coefficients = 0,
              uvs = 0, checksum = 0;
  std::size_t total() const {
    return header + connectivity + sectors + positions + normals + coefficients + uvs + checksum;
  }
};

/// The bytes of a version 3 file for `m` (see the file comment). Throws Invalid_input if `m` is
/// invalid, has no face, or has a vertex with more than 255 sectors, or if the encoding is out of
/// range. `parts`, when given, receives the bytes per part.
std::string compact_cm_bytes(const Compact_model& m, const Compact_encoding& encoding = Compact_encoding(),
                             CM_file_parts* parts = nullptr);

/// The model a version 3 file of `m` decodes to (what read_cm returns for it).
Compact_model quantized_model(const Compact_model& m, const Compact_encoding& encoding = Compact_encoding());

/// Writes `m` as a version 3 file atomically; returns its size in bytes.
inline std::size_t write_compact_cm(const std::string& path, const Compact_model& m,
                                    const Compact_encoding& encoding = Compact_encoding(),
                                    CM_file_parts* parts = nullptr) {
  const std::string bytes = compact_cm_bytes(m, encoding, parts);
  IO::write_file_atomically(path, bytes);
  return bytes.size();
}

/// Same, registered in `out` (the file appears when `out` is committed).
inline std::size_t write_compact_cm(const std::string& path, const Compact_model& m,
                                    const Compact_encoding& encoding, IO::Atomic_output& out,
                                    CM_file_parts* parts = nullptr) {
  const std::string bytes = compact_cm_bytes(m, encoding, parts);
  IO::write_file(path, bytes, out);
  return bytes.size();
}

namespace internal {
/// Decodes a version 3 file (called by parse_cm; `file` names it in error messages).
Compact_model parse_compact_cm(const std::string& bytes, const std::string& file);
}  // namespace internal

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_CM_COMPACT_IO_H
