// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The two models of the Simplifier concept of build_compact_model() (thesis §4.3): how the base
// mesh is simplified while the Point_gathering_visitor builds the sets R_i.
//
// Simplifier concept: `template <class Visitor> void operator()(Surface_mesh&, std::size_t
// target_faces, Visitor) const` running an edge collapse that calls the visitor.
// Models: Weighted_quadric_simplifier (default), Garland_heckbert_simplifier (CGAL's engine and
// plane quadrics). build_textured_compact_model.h adds Textured_quadric_simplifier.
#ifndef CMGEOM_COMPACT_MODEL_BASE_SIMPLIFIERS_H
#define CMGEOM_COMPACT_MODEL_BASE_SIMPLIFIERS_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Endpoint_placement.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/edge_collapse.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>

#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <cstddef>
#include <string>

namespace CMGeom {
namespace CM {

/// Placement wrapper that keeps base vertices on input vertices (see
/// Textured_simplification/Endpoint_placement.h). Why: §4.3 snaps a new vertex to the closest
/// gathered point afterwards, but snapping can fold or flatten base triangles (measured:
/// collinear base triangles on the flat faces of a box, whose quadrics are degenerate, so their
/// optimal placements are arbitrary); choosing an input vertex during the collapse lets the
/// engine's fold-over test see the final position.
template <class Cost>
using Endpoint_placement = CMGeom::Textured_simplification::Endpoint_placement<Cost>;
/// Weighted quadric simplification (thesis §3.4) on CMGeom's engine; base vertices stay on input
/// vertices unless `optimal_placement` (then §4.3's snapping moves them).
struct Weighted_quadric_simplifier {
  bool weighted = true;
  bool optimal_placement = false;
  template <class Visitor>
  void operator()(CMGeom::Surface_mesh& mesh, std::size_t target_faces, Visitor visitor) const {
    namespace TS = CMGeom::Textured_simplification;
    TS::Mesh_simplification_options so;
    so.target_faces = target_faces;
    so.quadric.weighted = weighted;
    so.surface_memory = false;
    so.endpoint_placement = !optimal_placement;
    so.parts_min_faces = 0;  // the gathering visitor must see every collapse
    TS::simplify_mesh(mesh, so, visitor);
  }
};

/// CGAL's edge_collapse with Garland-Heckbert plane quadrics (optimal placement, then §4.3's
/// snapping). Throws CMGeom::Invalid_input, before any change, on a mesh with a vertex the border
/// passes more than once (fans of faces meeting at one vertex): CGAL's collapse at such a vertex
/// can leave a fan behind (Textured_simplification::internal::pinched_vertex()).
struct Garland_heckbert_simplifier {
  template <class Visitor>
  void operator()(CMGeom::Surface_mesh& mesh, std::size_t target_faces, Visitor visitor) const {
    namespace SMS = CGAL::Surface_mesh_simplification;
    namespace TS = CMGeom::Textured_simplification;
    if (const auto v = TS::internal::pinched_vertex(mesh))
      throw Invalid_input(
          TS::internal::pinch_refusal("Garland_heckbert_simplifier", *v, "Weighted_quadric_simplifier"));
    SMS::GarlandHeckbert_plane_policies<CMGeom::Surface_mesh, CMGeom::Kernel> gh(mesh);
    TS::Face_count_stop_predicate<CMGeom::Surface_mesh> stop(mesh, target_faces);
    SMS::edge_collapse(mesh, stop,
                       CGAL::parameters::get_cost(gh.get_cost()).get_placement(gh.get_placement()).visitor(visitor));
  }
};

}  // namespace CM
}  // namespace CMGeom

#endif  // CMGEOM_COMPACT_MODEL_BASE_SIMPLIFIERS_H
