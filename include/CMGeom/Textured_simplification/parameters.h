// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Named parameters of the Textured_simplification package that CGAL does not know. They are
// CGAL-compatible tags: each function returns a genuine `CGAL::Named_function_parameters` pack,
// which CGAL's own options can follow (`edge_flips(true).get_cost(p).get_placement(p)`), or
// which can be prepended to an existing pack (`edge_flips(true, CGAL::parameters::visitor(v))`).
// CGAL's member chaining only knows CGAL's tags, so CMGeom parameters come first.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_PARAMETERS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_PARAMETERS_H

#include <CGAL/Named_function_parameters.h>

#include <cstddef>

namespace CMGeom {
namespace internal_np {
enum edge_flips_t { edge_flips };
enum surface_memory_t { surface_memory };
enum prune_components_t { prune_components };
}  // namespace internal_np

namespace parameters {

/// Enables the edge flips of thesis §3.5.1 after each collapse (default: false).
inline CGAL::Named_function_parameters<bool, internal_np::edge_flips_t> edge_flips(bool b) {
  return CGAL::Named_function_parameters<bool, internal_np::edge_flips_t>(b);
}
template <class T, class Tag, class Base>
CGAL::Named_function_parameters<bool, internal_np::edge_flips_t, CGAL::Named_function_parameters<T, Tag, Base>>
edge_flips(bool b, const CGAL::Named_function_parameters<T, Tag, Base>& base) {
  return CGAL::Named_function_parameters<bool, internal_np::edge_flips_t,
                                         CGAL::Named_function_parameters<T, Tag, Base>>(b, base);
}

/// A `Surface_memory` (Surface_memory.h) that CMGeom's engine consults before each collapse:
/// its memoryful cost re-orders the collapses (a cost, not a bound: it refuses none; default: no
/// memory). The object must outlive the call.
template <class Memory>
CGAL::Named_function_parameters<Memory*, internal_np::surface_memory_t> surface_memory(Memory* m) {
  return CGAL::Named_function_parameters<Memory*, internal_np::surface_memory_t>(m);
}
template <class Memory, class T, class Tag, class Base>
CGAL::Named_function_parameters<Memory*, internal_np::surface_memory_t, CGAL::Named_function_parameters<T, Tag, Base>>
surface_memory(Memory* m, const CGAL::Named_function_parameters<T, Tag, Base>& base) {
  return CGAL::Named_function_parameters<Memory*, internal_np::surface_memory_t,
                                         CGAL::Named_function_parameters<T, Tag, Base>>(m, base);
}

/// Lets CMGeom's engine remove whole connected components (on `CGAL::Surface_mesh` only; other
/// graphs ignore it): a component goes when its price is at most the cost of the collapse on top
/// of the queue, or when no collapse is left; cheapest first; never the component of largest area,
/// and never when fewer than `min_faces_left` faces would remain. 0 (the default) removes none.
/// The price, in the quadric's unit (area x squared distance), is sum over the component's faces of
/// area x mean squared distance of its corners to the component's area centroid: what collapsing
/// the whole component to its centroid would cost, taken once from the mesh the run starts with.
/// It does not look at how far the component lies from the rest of the surface (a small part
/// floating away goes as early as one lying on the surface), as meshoptimizer's pruning, which
/// compares a part's size with the error, does not. The memory's points on the removed faces are
/// dropped (Surface_memory::drop_faces()) and the visitor's `OnFacesRemoved(tm, faces)` is called.
/// Meant for face-count stops: a Hausdorff_bound_filter's bound does not cover the removed parts
/// (simplify_mesh() refuses max_error with it), and a cost bound is compared with collapse costs only.
inline CGAL::Named_function_parameters<std::size_t, internal_np::prune_components_t> prune_components(
    std::size_t min_faces_left) {
  return CGAL::Named_function_parameters<std::size_t, internal_np::prune_components_t>(min_faces_left);
}
template <class T, class Tag, class Base>
CGAL::Named_function_parameters<std::size_t, internal_np::prune_components_t,
                                CGAL::Named_function_parameters<T, Tag, Base>>
prune_components(std::size_t min_faces_left, const CGAL::Named_function_parameters<T, Tag, Base>& base) {
  return CGAL::Named_function_parameters<std::size_t, internal_np::prune_components_t,
                                         CGAL::Named_function_parameters<T, Tag, Base>>(min_faces_left, base);
}

}  // namespace parameters
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_PARAMETERS_H
