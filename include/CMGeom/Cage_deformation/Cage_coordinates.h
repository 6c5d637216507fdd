// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The two concepts every cage coordinate type of this package models (thesis §5.3.1: "most
// cage-based deformation methods express a point p in C_i as an affine combination of cage
// vertices, p = sum_v w_i(v, p) v, and deform it by T_i(p) = sum_v w_i(v, p) T(v)"; Green
// coordinates add face terms), and the vertex deformation rule shared by the barycentric types.
//
// Concept CageCoordinates (models: Mean_value_coordinates_3, Green_coordinates_3,
// Harmonic_coordinates_3). A function object bound at construction to a closed, outward-oriented
// Triangle_cage (validate_cage()), copyable, and whose const members are thread-safe:
//
//   std::size_t number_of_coordinates() const;     // K: n for barycentric types, n + m for Green
//   template <class Point, class OutputIterator>
//   Coordinate_status operator()(const Point& q, OutputIterator out) const;
//       // writes exactly K values: first one per cage vertex (cage-vertex order), then, for
//       // Green, one per cage triangle (triangle order). Point: a CGAL Point_3 or any type
//       // indexable by [0..2].
//   Rule deformation_rule() const;                  // a model of CageDeformationRule
//   const Triangle_cage& cage() const;
//
// Concept CageDeformationRule. Turns a deformed cage (same connectivity as the rest cage) into K
// basis vectors B_k so that a bound point with coordinates w deforms to  x' = sum_k w_k B_k.
// For barycentric coordinates B is the deformed vertex list; for Green coordinates B also holds
// the scaled deformed normals s_j n'_j. Linearity in w is what lets binding precompute w once and
// deform with one matrix product per frame (Cage_binding.h), and what the multi-cage join of
// §5.3.2 builds on.
//
//   std::size_t number_of_coordinates() const;
//   template <class OutputIterator>  // value type Vec3
//   void operator()(const std::vector<Vec3>& deformed_vertices, OutputIterator basis) const;
//
// Complexity: the rule below is O(n).
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_COORDINATES_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_COORDINATES_H

#include <CMGeom/Cage_deformation/Triangle_cage.h>

#include <CGAL/assertions.h>

#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// How the coordinates of one query were obtained. Values are ordered by how much a caller
/// should worry: everything from `approximate` on is worth reporting.
enum class Coordinate_status : unsigned char {
  regular = 0,      ///< the general formula, inside (or, for MVC, outside) the cage
  on_boundary = 1,  ///< the point lies on the cage (within the tolerance): boundary values
  extended = 2,     ///< Green: outside the cage, continued through an exit face
  approximate = 3,  ///< harmonic: near the cage, the grid stencil leaves the solved domain
  undefined = 4     ///< harmonic: outside the cage; the values written are zeros
};

inline const char* to_string(Coordinate_status s) {
  switch (s) {
    case Coordinate_status::regular: return "regular";
    case Coordinate_status::on_boundary: return "on_boundary";
    case Coordinate_status::extended: return "extended";
    case Coordinate_status::approximate: return "approximate";
    case Coordinate_status::undefined: return "undefined";
  }
  return "?";
}

/// CageDeformationRule of barycentric coordinates: B_k = deformed vertex k.
class Vertex_deformation_rule {
public:
  explicit Vertex_deformation_rule(std::size_t n = 0) : n_(n) {}
  std::size_t number_of_coordinates() const { return n_; }
  template <class OutputIterator>
  void operator()(const std::vector<Vec3>& deformed_vertices, OutputIterator basis) const {
    CGAL_precondition(deformed_vertices.size() == n_);
    for (const Vec3& p : deformed_vertices) *basis++ = p;
  }

private:
  std::size_t n_;
};

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_COORDINATES_H
