// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CMGeom::Textured_simplification::edge_collapse: an edge-collapse engine for the policy concepts
// of CGAL's Surface_mesh_simplification (GetCost, GetPlacement, PlacementFilter, StopPredicate,
// EdgeCollapseSimplificationVisitor), built for speed; it drives the quadric simplification of
// thesis §3.4 and the edge flips of §3.5.1. It calls the policies and the visitor where CGAL 5.5.1's
// engine does; what differs (fold-over test, re-costing of a moved placement, cost updates, the
// memoryful cost of Surface_memory.h) and how it is laid out for speed is told in the manual,
// doc/Textured_simplification/README.md ("The visitor and filter hooks", "The memoryful cost",
// "Speed").
//
// Complexity: O(E log E) set-up, O(d log E) per collapse (d = vertex degree).
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_EDGE_COLLAPSE_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_EDGE_COLLAPSE_H

#include <CMGeom/config.h>
#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>
#include <CMGeom/Textured_simplification/No_normal_flip_filter.h>
#include <CMGeom/Textured_simplification/internal/Edge_collapse_engine.h>
#include <CMGeom/Textured_simplification/parameters.h>

#include <CGAL/Named_function_parameters.h>
#include <CGAL/boost/graph/named_params_helper.h>
#include <CGAL/property_map.h>

#include <cstddef>
#include <type_traits>

namespace CMGeom {
namespace Textured_simplification {

/// Simplifies `tm` in place by edge collapses until `should_stop` says so; returns the number of
/// removed edges (as CGAL's edge_collapse does: 3 per interior collapse, 2 on a border). `tm` keeps removed elements
/// until `collect_garbage()` (Surface_mesh).
///
/// \tparam TriangleMesh a model of `MutableFaceGraph` and `HalfedgeListGraph`, triangulated and
///   2-manifold (with or without boundary)
/// \tparam StopPredicate a model of CGAL's `StopPredicate` (see Stop_predicates.h)
///
/// \cgalNamedParamsBegin
///   \cgalParamNBegin{get_cost}, \cgalParamNBegin{get_placement}: models of `GetCost` / `GetPlacement`
///     (default: one `Area_weighted_quadric_policies<TriangleMesh>` object for both).
///   \cgalParamNBegin{filter}: a model of `PlacementFilter`, called when an edge is about to be
///     collapsed, after CMGeom's fold-over test (default: accepts everything).
///   \cgalParamNBegin{visitor}: a model of `EdgeCollapseSimplificationVisitor` (taken by value,
///     as CGAL does: hold pointers to shared state).
///   \cgalParamNBegin{edge_is_constrained_map}: constrained edges are never collapsed.
///   \cgalParamNBegin{vertex_point_map}, \cgalParamNBegin{geom_traits}: as in CGAL.
///   `CMGeom::parameters::edge_flips(bool)`: flips of §3.5.1 after each collapse (default false).
///   `CMGeom::parameters::prune_components(std::size_t min_faces_left)`: whole connected components
///     may be removed, cheapest first, down to `min_faces_left` faces (default 0: none; on
///     `CGAL::Surface_mesh` only; see parameters.h).
/// \cgalNamedParamsEnd
template <class TriangleMesh, class StopPredicate, class NamedParameters = CGAL::parameters::Default_named_parameters>
int edge_collapse(TriangleMesh& tm, const StopPredicate& should_stop,
                  const NamedParameters& np = CGAL::parameters::default_values()) {
  using CGAL::parameters::choose_parameter;
  using CGAL::parameters::get_parameter;
  using GT = typename CGAL::GetGeomTraits<TriangleMesh, NamedParameters>::type;
  using VPM = typename CGAL::GetVertexPointMap<TriangleMesh, NamedParameters>::type;
  using edge_descriptor = typename boost::graph_traits<TriangleMesh>::edge_descriptor;
  using Default_policy = Area_weighted_quadric_policies<TriangleMesh, GT>;

  const GT gt = choose_parameter<GT>(get_parameter(np, CGAL::internal_np::geom_traits));
  const VPM vpm =
      choose_parameter(get_parameter(np, CGAL::internal_np::vertex_point), get_property_map(CGAL::vertex_point, tm));
  const auto ecm = choose_parameter(get_parameter(np, CGAL::internal_np::edge_is_constrained),
                                    CGAL::Constant_property_map<edge_descriptor, bool>(false));
  const bool flips = choose_parameter(get_parameter(np, CMGeom::internal_np::edge_flips), false);
  const std::size_t prune_min_faces =
      choose_parameter(get_parameter(np, CMGeom::internal_np::prune_components), std::size_t(0));

  using Cost_np = typename CGAL::internal_np::Lookup_named_param_def<CGAL::internal_np::get_cost_policy_t,
                                                                     NamedParameters, Default_policy>::type;
  using Placement_np = typename CGAL::internal_np::Lookup_named_param_def<CGAL::internal_np::get_placement_policy_t,
                                                                          NamedParameters, Default_policy>::type;
  using Filter = typename CGAL::internal_np::Lookup_named_param_def<CGAL::internal_np::filter_t, NamedParameters,
                                                                    Identity_filter>::type;
  using Visitor = typename CGAL::internal_np::Lookup_named_param_def<CGAL::internal_np::visitor_t, NamedParameters,
                                                                     Edge_collapse_visitor_base>::type;

  const Filter filter = choose_parameter<Filter>(get_parameter(np, CGAL::internal_np::filter));
  Visitor visitor = choose_parameter<Visitor>(get_parameter(np, CGAL::internal_np::visitor));
  using ECM = std::decay_t<decltype(ecm)>;
  using Memory = typename CGAL::internal_np::Lookup_named_param_def<CMGeom::internal_np::surface_memory_t,
                                                                    NamedParameters, std::nullptr_t>::type;
  const Memory memory = choose_parameter<Memory>(get_parameter(np, CMGeom::internal_np::surface_memory));
  auto run = [&](const auto& cost, const auto& placement) {
    internal::Edge_collapse_engine<TriangleMesh, VPM, GT, ECM, std::decay_t<decltype(cost)>,
                                   std::decay_t<decltype(placement)>, Filter, Visitor, StopPredicate, Memory>
        engine(tm, should_stop, vpm, gt, ecm, cost, placement, filter, visitor, flips, memory, prune_min_faces);
    return engine.run();
  };

  constexpr bool cost_given =
      !CGAL::parameters::is_default_parameter<NamedParameters, CGAL::internal_np::get_cost_policy_t>::value;
  constexpr bool placement_given =
      !CGAL::parameters::is_default_parameter<NamedParameters, CGAL::internal_np::get_placement_policy_t>::value;
  // A default cost and placement must be one object: they share the quadrics.
  if constexpr (cost_given && placement_given) {
    return run(choose_parameter<Cost_np>(get_parameter(np, CGAL::internal_np::get_cost_policy)),
               choose_parameter<Placement_np>(get_parameter(np, CGAL::internal_np::get_placement_policy)));
  } else if constexpr (cost_given) {
    Default_policy policy(tm);
    return run(choose_parameter<Cost_np>(get_parameter(np, CGAL::internal_np::get_cost_policy)), policy);
  } else if constexpr (placement_given) {
    Default_policy policy(tm);
    return run(policy, choose_parameter<Placement_np>(get_parameter(np, CGAL::internal_np::get_placement_policy)));
  } else {
    Default_policy policy(tm);
    return run(policy, policy);
  }
}

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_EDGE_COLLAPSE_H
