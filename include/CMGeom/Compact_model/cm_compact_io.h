// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The compact CM file (format version 3, a CMGeom addition to §4.4.3): write_compact_cm(),
// compact_cm_bytes(), quantized_model(), Compact_encoding and CM_file_parts. A Compact Model is
// quantized to a tolerance and entropy coded (connectivity, sectors, predicted positions,
// octahedral normals, coefficients, uvs, and a model's level error table if it has one; LEB128
// varints, zstd; then its reconstruction level, one byte, if it has one), for shipping a model in
// as few bytes as its error allows. Versions 1 and 2
// (cm_io.h) stay exact; version 3 is lossy by design
// and bounded: each coefficient list is refitted in the decoded frame, then rounded so that the
// height moves by at most tolerance / 2 within its sector. parse_cm() and read_cm() of cm_io.h
// read all three versions; reading validates everything and returns no partial model.
// These functions are compiled in the CMGeom::Compact_model library (zstd); with the headers
// alone parse_cm() refuses a version 3 file.
//
// Manual: doc/Compact_model/README.md, "Version 3 byte layout".
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
  /// times the bounding-box diagonal of the base vertices (the one box a model knows). The writer
  /// halves it while a base face with an area would lie flat on the grid (two vertices closer
  /// than a step), so that no reconstructed face degenerates.
  /// `cmgeom cm build --compact` sets 1e-4 times the input mesh's diagonal instead (`--tolerance`),
  /// a grid as coarse or coarser, whose step is the same for every base size of one input.
  double tolerance = 0.;
  /// Bits per octahedral coordinate of the frame normals, in [6, 20].
  int normal_bits = 12;
  /// zstd compression level of the streams, in [1, 22].
  int zstd_level = 19;
};

/// Stored bytes of each part of a version 3 file (stream headers included).
struct CM_file_parts {
  std::size_t header = 0, connectivity = 0, sectors = 0, positions = 0, normals = 0, coefficients = 0, uvs = 0,
              level_errors = 0, checksum = 0;
  std::size_t total() const {
    return header + connectivity + sectors + positions + normals + coefficients + uvs + level_errors + checksum;
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
inline std::size_t write_compact_cm(const std::string& path, const Compact_model& m, const Compact_encoding& encoding,
                                    IO::Atomic_output& out, CM_file_parts* parts = nullptr) {
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
