// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CMGeom::CM::Compact_model: the data of a Compact Model (thesis §4.4.3): the base (simplified)
// mesh's vertices, the lists of local-surface coefficients, the frame normals, and faces given
// as three (vertex, coefficient list, normal) triples. Sharp edges are implicit, as in the
// thesis: an edge is sharp when its two faces use different coefficient lists at an endpoint
// (the faces on either side belong to different sectors of that vertex). A vertex whose only
// surface is conical is a cone-type vertex. Textured models carry one texture coordinate per
// face corner and the path of the texture image (§4.5.4). A model may carry Level_errors: the
// error of its regular reconstruction measured against the input, per base face and level (a
// CMGeom addition: the error control of §4.5.3 measured once at build time, for adaptive
// reconstruction to a vertex budget, error_criterion.h).
//
// Every stored number is float-representable (build_compact_model rounds them, and the CM file
// stores float32), so writing and reading a model gives back exactly the same model.
//
// Complexity: sharp_edges() and validate() are O(F log F).
#ifndef CMGEOM_COMPACT_MODEL_COMPACT_MODEL_H
#define CMGEOM_COMPACT_MODEL_COMPACT_MODEL_H

#include <CMGeom/Compact_model/Local_surface_traits.h>
#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace CM {

/// One corner of a base face: indices of its vertex, coefficient list and normal (§4.4.3).
struct Corner {
  std::uint32_t vertex = 0, surface = 0, normal = 0;
  bool operator==(const Corner& o) const { return vertex == o.vertex && surface == o.surface && normal == o.normal; }
};

/// Texture coordinates of the three corners of a face.
using Face_uvs = std::array<std::array<float, 2>, 3>;

/// Errors of the regular reconstruction against the input, per base face and level (see the file
/// comment; measure_level_errors() in level_errors.h computes them). For level l in [0, depth] and
/// face f, entry l * F + f of `rms` is the RMS distance of the samples attributed to f (both
/// directions, area-weighted), of `max` their largest distance. Both are stored as 8-bit codes on
/// a log scale: code 0 is 0, code c > 0 is unit * 2^((c - 1) / 16) (steps of 4.4 %, 16 octaves).
struct Level_errors {
  int depth = -1;                      ///< deepest level measured; -1: no table
  double unit = 0.;                    ///< the distance of code 1 (float-representable)
  std::vector<std::uint8_t> rms, max;  ///< codes, (depth + 1) x F each

  bool empty() const { return depth < 0; }
  static double decode(std::uint8_t code, double unit) {
    return code == 0 ? 0. : unit * std::exp2(double(code - 1) / 16.);
  }
  /// The nearest code of `distance` on the log scale; distances below unit / 2^(1/32) give 0,
  /// those above the largest code give 255.
  static std::uint8_t encode(double distance, double unit) {
    if (!(distance > 0.) || !(unit > 0.)) return 0;
    const double c = std::round(16. * std::log2(distance / unit)) + 1.;
    return c < 1. ? 0 : std::uint8_t(std::min(c, 255.));
  }
  double rms_at(int level, std::size_t face, std::size_t F) const {
    return decode(rms[std::size_t(level) * F + face], unit);
  }
  double max_at(int level, std::size_t face, std::size_t F) const {
    return decode(max[std::size_t(level) * F + face], unit);
  }
  bool operator==(const Level_errors& o) const {
    return depth == o.depth && (depth < 0 || (unit == o.unit && rms == o.rms && max == o.max));
  }
};

/// The Compact Model (see the file comment).
struct Compact_model {
  std::vector<Vec3> vertices;           ///< base vertices (original points, §4.3)
  std::vector<Vec3> normals;            ///< unit frame normals N (§4.4.1)
  std::vector<Local_surface> surfaces;  ///< coefficient lists with their model id
  std::vector<std::array<Corner, 3>> faces;
  std::vector<Face_uvs> uvs;  ///< empty, or one entry per face (§4.5.4)
  std::string texture;        ///< texture image path of a textured model ("" otherwise)
  Level_errors level_errors;  ///< empty, or measured errors per face and level (see above)
  /// The regular reconstruction level the model was chosen for, -1 when none: the level at which
  /// build_compact_model_for() (rate_distortion.h) measured it within its target. Stored in the
  /// file (flag bit 3); `cmgeom cm reconstruct` and `cm deform` reconstruct at it when no level is
  /// asked for.
  int reconstruction_level = -1;

  bool has_uvs() const { return !uvs.empty(); }
  std::size_t number_of_vertices() const { return vertices.size(); }
  std::size_t number_of_faces() const { return faces.size(); }

  /// The local frame of a corner's surface.
  Local_frame frame(const Corner& c) const { return Local_frame(vertices[c.vertex], normals[c.normal]); }

  /// Cone-type vertices (§4.4.3): vertices using a conical coefficient list, ascending.
  std::vector<std::uint32_t> cone_vertices() const {
    std::vector<std::uint32_t> r;
    for (const auto& f : faces)
      for (const Corner& c : f)
        if (surfaces[c.surface].is_cone()) r.push_back(c.vertex);
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    return r;
  }

  /// Sharp edges (implicit, see the file comment) as (smaller, larger) vertex index pairs, sorted.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sharp_edges() const {
    // (edge, endpoint, surface) for every face side; an edge is sharp when one endpoint sees
    // two different surfaces.
    struct Side {
      std::uint32_t a, b, sa, sb;
    };
    std::vector<Side> sides;
    sides.reserve(faces.size() * 3);
    for (const auto& f : faces)
      for (int i = 0; i < 3; ++i) {
        Corner c0 = f[i], c1 = f[(i + 1) % 3];
        if (c0.vertex > c1.vertex) std::swap(c0, c1);
        sides.push_back({c0.vertex, c1.vertex, c0.surface, c1.surface});
      }
    std::sort(sides.begin(), sides.end(), [](const Side& x, const Side& y) {
      return x.a != y.a ? x.a < y.a : (x.b != y.b ? x.b < y.b : (x.sa != y.sa ? x.sa < y.sa : x.sb < y.sb));
    });
    std::vector<std::pair<std::uint32_t, std::uint32_t>> r;
    for (std::size_t i = 0; i < sides.size();) {
      std::size_t j = i + 1;
      bool sharp = false;
      while (j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b) {
        sharp = sharp || sides[j].sa != sides[i].sa || sides[j].sb != sides[i].sb;
        ++j;
      }
      if (sharp) r.emplace_back(sides[i].a, sides[i].b);
      i = j;
    }
    return r;
  }

  /// Throws Invalid_input (one line) when an index is out of range, a number is not finite, a
  /// normal is zero, a model id is unknown, the uv array does not match the faces, or the
  /// reconstruction level is out of range.
  void validate(const std::string& what = "compact model") const {
    auto fail = [&](const std::string& m) { throw Invalid_input(what + ": " + m); };
    for (std::size_t i = 0; i < vertices.size(); ++i)
      if (!std::isfinite(vertices[i].x + vertices[i].y + vertices[i].z))
        fail("vertex " + std::to_string(i) + " is not finite");
    for (std::size_t i = 0; i < normals.size(); ++i) {
      const double l = internal::length(normals[i]);
      if (!std::isfinite(l) || !(l > 0.)) fail("normal " + std::to_string(i) + " is zero or not finite");
    }
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
      const int k = number_of_coefficients(surfaces[i].model);
      if (k == 0)
        fail("coefficient list " + std::to_string(i) + " has unknown model id " +
             std::to_string(int(surfaces[i].model)));
      for (int j = 0; j < 9; ++j)
        if (!std::isfinite(surfaces[i].c[j]) || (j >= k && surfaces[i].c[j] != 0.))
          fail("coefficient list " + std::to_string(i) + " has an invalid coefficient");
    }
    for (std::size_t i = 0; i < faces.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const Corner& c = faces[i][k];
        if (c.vertex < vertices.size() && c.surface < surfaces.size() && c.normal < normals.size()) continue;
        // the message is only built for a bad corner (this runs before every reconstruction)
        const std::string at = "face " + std::to_string(i) + " corner " + std::to_string(k) + ": ";
        if (c.vertex >= vertices.size()) fail(at + "vertex index " + std::to_string(c.vertex) + " out of range");
        if (c.surface >= surfaces.size())
          fail(at + "coefficient list index " + std::to_string(c.surface) + " out of range");
        fail(at + "normal index " + std::to_string(c.normal) + " out of range");
      }
    for (std::size_t i = 0; i < faces.size(); ++i)
      if (faces[i][0].vertex == faces[i][1].vertex || faces[i][1].vertex == faces[i][2].vertex ||
          faces[i][0].vertex == faces[i][2].vertex)
        fail("face " + std::to_string(i) + " repeats a vertex");
    if (!uvs.empty() && uvs.size() != faces.size()) fail("texture coordinates do not match the faces");
    if (!level_errors.empty()) {
      const std::size_t n = std::size_t(level_errors.depth + 1) * faces.size();
      if (level_errors.depth > 12) fail("level error table deeper than level 12");
      if (!(level_errors.unit > 0.) || !std::isfinite(level_errors.unit)) fail("level error table has an invalid unit");
      if (level_errors.rms.size() != n || level_errors.max.size() != n)
        fail("level error table does not match the faces");
    }
    if (reconstruction_level < -1 || reconstruction_level > 12)
      fail("reconstruction level " + std::to_string(reconstruction_level) + " is not in [0, 12] (or -1: none)");
  }

  bool operator==(const Compact_model& o) const {
    return vertices == o.vertices && normals == o.normals && surfaces == o.surfaces && faces == o.faces &&
           uvs == o.uvs && texture == o.texture && level_errors == o.level_errors &&
           reconstruction_level == o.reconstruction_level;
  }
  bool operator!=(const Compact_model& o) const { return !(*this == o); }
};

/// Rounds every number of the model to the nearest float (what a CM file stores).
inline void round_to_float(Compact_model& m) {
  // Through a volatile float: GCC 12.2 at -O2 (SLP vectoriser) was measured dropping the
  // double -> float -> double round trip of x and y in this loop, leaving them unrounded.
  auto r = [](double x) {
    volatile float f = float(x);
    return double(f);
  };
  for (Vec3& v : m.vertices) v = Vec3(r(v.x), r(v.y), r(v.z));
  for (Vec3& n : m.normals) n = Vec3(r(n.x), r(n.y), r(n.z));
  for (Local_surface& s : m.surfaces)
    for (double& c : s.c) c = r(c);
  m.level_errors.unit = r(m.level_errors.unit);
}

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_COMPACT_MODEL_H
