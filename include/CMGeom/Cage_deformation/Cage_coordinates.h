// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The two concepts every cage coordinate type of this package models, CageCoordinates and
// CageDeformationRule, with Coordinate_status and Vertex_deformation_rule, the rule shared by the
// barycentric types (thesis §5.3.1: a point is an affine combination of cage vertices and deforms
// by the same combination of the deformed vertices; Green coordinates add face terms). A
// CageCoordinates model is bound at construction to a closed, outward-oriented Triangle_cage,
// copyable, with thread-safe const members, and writes K values per point (one per cage vertex,
// then for Green one per cage triangle). A CageDeformationRule turns a deformed cage into K basis
// vectors B_k with x' = sum_k w_k B_k. Key choice: linearity in w, which lets binding compute w
// once and deform with one matrix product per frame (Cage_binding.h), and which the join of §5.3.2
// builds on. Complexity: Vertex_deformation_rule is O(n).
//
// Manual: doc/Cage_deformation/README.md, "The concepts".
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
    case Coordinate_status::regular:
      return "regular";
    case Coordinate_status::on_boundary:
      return "on_boundary";
    case Coordinate_status::extended:
      return "extended";
    case Coordinate_status::approximate:
      return "approximate";
    case Coordinate_status::undefined:
      return "undefined";
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
