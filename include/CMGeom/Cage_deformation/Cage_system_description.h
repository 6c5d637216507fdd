// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Plain description of a *Cages system (thesis §5.3): the cages, their rest and deformed vertex
// positions, the coordinate type of each cage, the smoothing parameter h_i of §5.3.3, the
// coordinate type of the join cages (§5.3.2), optional per-border h values and the parent links of multi-level systems
// (§5.3.4: an upper-level cage owns vertices of lower-level cages). It is what
// read_cage_system() (Cage_system_io.h) returns and what make_grid_cage_system() builds;
// Cage_system (Cage_system.h) turns it into the deformation. Holding no behaviour, it can be
// filled by hand as well.
//
// Complexity: the types hold data only.
#ifndef CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_DESCRIPTION_H
#define CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_DESCRIPTION_H

#include <CMGeom/Cage_deformation/Harmonic_coordinates_3.h>
#include <CMGeom/Cage_deformation/Triangle_cage.h>

#include <cstdint>
#include <string>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// The coordinate types a cage of a system may use (§5.3.1: MVC, HC, GC).
enum class Coordinate_type { mean_value, green, harmonic };

inline const char* to_string(Coordinate_type t) {
  switch (t) {
    case Coordinate_type::mean_value:
      return "mean_value";
    case Coordinate_type::green:
      return "green";
    case Coordinate_type::harmonic:
      return "harmonic";
  }
  return "?";
}

/// An upper-level cage `cage` owns the listed vertices (indices into the child's rest cage).
struct Cage_parent_link {
  std::size_t cage = 0;
  std::vector<std::uint32_t> vertices;
};

/// h of one border of a cage (§5.5 lets h be chosen per border, per cage or for the whole
/// model): the border this cage shares with leaf cage `cage`.
struct Cage_border_h {
  std::size_t cage = 0;
  double h = 1.0;  ///< in (0, 1]
};

struct Cage_description {
  std::string name;            ///< optional label (for messages and parent references)
  std::string rest_source;     ///< file it was read from, or "inline"
  Triangle_cage rest;          ///< validated, outward oriented
  bool reoriented = false;     ///< the rest cage was given inward and has been flipped
  std::vector<Vec3> deformed;  ///< deformed vertex positions (same order as rest.vertices)
  Coordinate_type coordinates = Coordinate_type::mean_value;
  Harmonic_options harmonic;  ///< used when coordinates == harmonic
  double h = 1.0;             ///< h_i of §5.3.3, in (0, 1]
  /// Borders with their own h (see Cage_system::distance()); the others use h.
  std::vector<Cage_border_h> border_h;
  std::vector<Cage_parent_link> parents;  ///< empty for top-level cages
  std::vector<std::string> warnings;      ///< non-fatal remarks of the reader (one line each)
};

struct Cage_system_description {
  std::vector<Cage_description> cages;
  /// Coordinates of the join cages (§5.3.2): must be C¹ inside, so mean value or harmonic.
  Coordinate_type join_coordinates = Coordinate_type::mean_value;
  Harmonic_options join_harmonic;
  std::string source;  ///< file it was read from (for messages)
};

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_CAGE_SYSTEM_DESCRIPTION_H
