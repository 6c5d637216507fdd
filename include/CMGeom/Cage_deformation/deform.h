// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// deform(): deforms a set of points by the cages of a Cage_system_description in one call, as
// the description says: one cage with its own coordinates (make_cage_coordinates, bind_points,
// the cage's deformation rule), several as the *Cages system of thesis §5.3 (Cage_system, its
// binding and the basis of the deformed leaf vertices, parent links followed). The result holds
// the deformed points, what the binding counted and the time of each stage. A caller that poses
// the cages many times keeps the binding instead (Cage_binding, Cage_system_binding): see
// "*Cages" and "`cmgeom deform`" in doc/Cage_deformation/README.md.
//
// Complexity: one cage, O(N (n + m)) to bind and O(N K) (dense) or O(nnz) to deform; a system,
// that of Cage_system (construction, binding, one frame).
#ifndef CMGEOM_CAGE_DEFORMATION_DEFORM_H
#define CMGEOM_CAGE_DEFORMATION_DEFORM_H

#include <CMGeom/Cage_deformation/Any_cage_coordinates.h>
#include <CMGeom/Cage_deformation/Cage_binding.h>
#include <CMGeom/Cage_deformation/Cage_system.h>
#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Progress.h>

#include <array>
#include <chrono>
#include <functional>
#include <iterator>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

/// The stages of deform(), in their order.
enum class Deform_stage {
  setup,  ///< the coordinates (harmonic ones solve a grid per cage) or the Cage_system
  bind,   ///< the weights of every point
  deform  ///< the deformed points from the deformed cages
};

struct Deform_options {
  /// Weight storage of a single cage's binding; a cage system always groups its rows.
  Weight_storage storage = Weight_storage::dense;
  /// Several cages: apply each cage's own coordinates alone, S_i = T_i (Piecewise_smoothing, the
  /// C⁰ / discontinuous deformation of thesis Fig. 5.2(a, b), for comparisons). One cage: unused.
  bool piecewise = false;
  /// Optional: called from the calling thread as each stage starts (to label or time it).
  std::function<void(Deform_stage)> stage;
  /// Optional progress hook of the bind stage (CMGeom/Progress.h): the fraction of the points
  /// bound. The setup and deform stages report nothing.
  Progress_callback progress;
};

struct Deform_result {
  std::vector<Vec3> positions;  ///< the deformed points, in input order
  bool cage_system = false;     ///< evaluated as a *Cages system (several cages)
  /// Columns of the binding: the coordinates of the cage, or the global basis of the system.
  std::size_t coordinates = 0;
  std::size_t weights_bytes = 0;
  std::size_t joined_points = 0;        ///< a system: points with join terms (d_i < 1)
  std::size_t outside_points = 0;       ///< a system: points outside every leaf cage
  std::array<std::size_t, 5> status{};  ///< points per Coordinate_status (see count())
  double setup_seconds = 0, bind_seconds = 0, deform_seconds = 0;

  std::size_t count(Coordinate_status s) const { return status[std::size_t(s)]; }
};

namespace internal {

inline double deform_clock_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Tells the caller a stage begins (Deform_options::stage) and returns the clock at its start.
inline double start_stage(const Deform_options& o, Deform_stage s) {
  if (o.stage) o.stage(s);
  return deform_clock_seconds();
}

template <class Binding>
void count_statuses(const Binding& b, Deform_result& r) {
  for (Coordinate_status s : {Coordinate_status::regular, Coordinate_status::on_boundary, Coordinate_status::extended,
                              Coordinate_status::approximate, Coordinate_status::undefined})
    r.status[std::size_t(s)] = b.count(s);
}

template <class Weight, class PointRange>
void deform_by_one_cage(const PointRange& points, const Cage_description& c, const Deform_options& o,
                        Deform_result& r) {
  double t0 = start_stage(o, Deform_stage::setup);
  const Any_cage_coordinates coords = make_cage_coordinates(c.coordinates, c.rest, c.harmonic);
  r.setup_seconds = deform_clock_seconds() - t0;
  t0 = start_stage(o, Deform_stage::bind);
  Binding_options bo;
  bo.storage = o.storage;
  bo.progress = o.progress;
  const Cage_binding<Weight> b = bind_points<Weight>(coords, points, bo);
  r.bind_seconds = deform_clock_seconds() - t0;
  t0 = start_stage(o, Deform_stage::deform);
  std::vector<Vec3> basis;
  coords.deformation_rule()(c.deformed, std::back_inserter(basis));
  b.deform(basis, r.positions);
  r.deform_seconds = deform_clock_seconds() - t0;
  r.weights_bytes = b.weights_bytes();
  r.coordinates = b.number_of_coordinates();
  count_statuses(b, r);
}

template <class Weight, class PointRange>
void deform_by_cage_system(const PointRange& points, const Cage_system_description& d, const Deform_options& o,
                           Deform_result& r) {
  r.cage_system = true;
  double t0 = start_stage(o, Deform_stage::setup);
  const Cage_system sys(d);
  r.setup_seconds = deform_clock_seconds() - t0;
  t0 = start_stage(o, Deform_stage::bind);
  const Cage_system_binding<Weight> b =
      o.piecewise ? sys.template bind<Weight>(points, Sine_smoothing(), Piecewise_smoothing(), o.progress)
                  : sys.template bind<Weight>(points, Sine_smoothing(), Sine_h_smoothing(), o.progress);
  r.bind_seconds = deform_clock_seconds() - t0;
  t0 = start_stage(o, Deform_stage::deform);
  b.deform(sys.basis(sys.deformed_leaf_vertices()), r.positions);
  r.deform_seconds = deform_clock_seconds() - t0;
  r.weights_bytes = b.weights_bytes();
  r.coordinates = sys.number_of_coordinates();
  r.joined_points = b.joined_points();
  r.outside_points = b.outside();
  count_statuses(b.weights(), r);
}

}  // namespace internal

/// Deforms `points` (a range of CGAL points or 3-arrays) by the deformed poses of `d`: one cage
/// by its own coordinates, several (or a hierarchy) as a Cage_system. `Weight` (double or
/// float) is the precision of the stored weights. Throws Invalid_input as Cage_system does for
/// a system it refuses; points where a cage's coordinates are undefined (outside a harmonic
/// cage) are counted in Deform_result::status, not refused.
template <class Weight = double, class PointRange>
Deform_result deform(const PointRange& points, const Cage_system_description& d,
                     const Deform_options& options = Deform_options()) {
  Deform_result r;
  if (d.cages.size() == 1)
    internal::deform_by_one_cage<Weight>(points, d.cages[0], options, r);
  else
    internal::deform_by_cage_system<Weight>(points, d, options, r);
  return r;
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_DEFORM_H
