// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Stop predicates (models of CGAL's `StopPredicate` concept, usable with both CGAL's and CMGeom's
// `edge_collapse`): target face count, face ratio, target vertex count, maximum cost.
//
// Why not CGAL's: CGAL 5.5.1 only counts edges, and the face-count predicates of later releases
// scan the mesh (O(F) per call, CGAL issues #5720/#8158). These run in O(1) per call: on
// CGAL::Surface_mesh they read its live counts (which also see a pruned component,
// parameters::prune_components); on other graphs the face and vertex counts are measured once
// (O(F + V), on the first call, after the engine's set-up) and then tracked from the edge count the
// engine passes. Between two calls an engine performs at most one collapse (true of both engines),
// and a collapse that removes k edges removes k - 1 faces (3 edges / 2 faces inside, 2 edges / 1
// face on a border) and one vertex.
//
// The predicates share their counters between copies (engines copy them), so use one predicate
// object per simplification run.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_STOP_PREDICATES_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_STOP_PREDICATES_H

#include <CGAL/Surface_mesh/Surface_mesh_fwd.h>
#include <CGAL/boost/graph/iterator.h>
#include <CGAL/number_utils.h>
#include <boost/graph/graph_traits.hpp>

#include <cmath>
#include <cstddef>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

/// Whether a graph is a CGAL::Surface_mesh (live element counts, indices that are positions).
template <class TM>
struct is_surface_mesh : std::false_type {};
template <class P>
struct is_surface_mesh<CGAL::Surface_mesh<P>> : std::true_type {};

/// The live faces of `g`: Surface_mesh knows them (number_of_faces() excludes removed elements,
/// while BGL's num_faces() does not); other graphs are counted by iteration.
template <class P>
std::size_t live_face_count(const CGAL::Surface_mesh<P>& m) {
  return m.number_of_faces();
}
template <class G>
std::size_t live_face_count(const G& g) {
  const auto r = faces(g);
  return static_cast<std::size_t>(std::distance(r.begin(), r.end()));
}
/// The live vertices of `g` (as live_face_count()).
template <class P>
std::size_t live_vertex_count(const CGAL::Surface_mesh<P>& m) {
  return m.number_of_vertices();
}
template <class G>
std::size_t live_vertex_count(const G& g) {
  const auto r = vertices(g);
  return static_cast<std::size_t>(std::distance(r.begin(), r.end()));
}

/// Tracks the live face and vertex counts of a mesh being simplified, in O(1) per call.
template <class TriangleMesh>
class Mesh_size_tracker {
public:
  explicit Mesh_size_tracker(const TriangleMesh& tm) : state_(std::make_shared<State>()) { state_->tm = &tm; }

  void update(std::size_t current_edge_count) const {
    State& s = *state_;
    if constexpr (knows_live_counts) {
      // Surface_mesh's live counts also follow removals that are not collapses (a pruned
      // component, parameters::prune_components)
      s.faces = live_face_count(*s.tm);
      s.vertices = live_vertex_count(*s.tm);
      s.edges = current_edge_count;
      s.started = true;
      return;
    }
    if (!s.started) {
      // first call: count the live elements once
      s.faces = live_face_count(*s.tm);
      s.vertices = live_vertex_count(*s.tm);
      s.edges = current_edge_count;
      s.started = true;
      return;
    }
    if (current_edge_count < s.edges) {
      const std::size_t removed = s.edges - current_edge_count;
      s.faces -= (removed - 1);
      s.vertices -= 1;
      s.edges = current_edge_count;
    }
  }
  std::size_t face_count() const { return state_->faces; }
  std::size_t vertex_count() const { return state_->vertices; }

private:
  static constexpr bool knows_live_counts = is_surface_mesh<TriangleMesh>::value;

  struct State {
    const TriangleMesh* tm = nullptr;
    std::size_t faces = 0, vertices = 0, edges = 0;
    bool started = false;
  };
  std::shared_ptr<State> state_;
};

}  // namespace internal

/// Stops when the mesh has at most `target` faces. On a closed mesh every collapse removes two
/// faces, so an odd target is reached as target - 1.
template <class TriangleMesh>
class Face_count_stop_predicate {
public:
  Face_count_stop_predicate(const TriangleMesh& tm, std::size_t target) : tracker_(tm), target_(target) {}
  template <class FT, class Profile>
  bool operator()(const FT&, const Profile&, std::size_t, std::size_t current_edge_count) const {
    tracker_.update(current_edge_count);
    return tracker_.face_count() <= target_;
  }
  std::size_t current_face_count() const { return tracker_.face_count(); }

private:
  internal::Mesh_size_tracker<TriangleMesh> tracker_;
  std::size_t target_;
};

/// The face count a ratio of `faces` asks for, the rule of every ratio target in CMGeom
/// (simplify_mesh(), Face_count_ratio_stop_predicate, `cmgeom simplify --ratio`, `cmgeom cm
/// build --ratio`): `ratio` x `faces` rounded to the nearest integer, halves up (std::llround).
/// Throws std::invalid_argument unless 0 < ratio <= 1.
inline std::size_t target_faces_for_ratio(std::size_t faces, double ratio) {
  if (!(ratio > 0.0 && ratio <= 1.0))
    throw std::invalid_argument("target_faces_for_ratio: the ratio must be in (0, 1], got " + std::to_string(ratio));
  return static_cast<std::size_t>(std::llround(ratio * double(faces)));
}

/// Stops when faces <= target_faces_for_ratio(faces at the start, ratio). Throws
/// std::invalid_argument unless 0 < ratio <= 1.
template <class TriangleMesh>
class Face_count_ratio_stop_predicate {
public:
  Face_count_ratio_stop_predicate(const TriangleMesh& tm, double ratio) : tracker_(tm), ratio_(ratio) {
    target_faces_for_ratio(0, ratio);  // checks it
  }
  template <class FT, class Profile>
  bool operator()(const FT&, const Profile&, std::size_t, std::size_t current_edge_count) const {
    const bool first = !target_;
    tracker_.update(current_edge_count);
    if (first) target_ = std::make_shared<std::size_t>(target_faces_for_ratio(tracker_.face_count(), ratio_));
    return tracker_.face_count() <= *target_;
  }

private:
  internal::Mesh_size_tracker<TriangleMesh> tracker_;
  double ratio_;
  mutable std::shared_ptr<std::size_t> target_;
};

/// Stops when the mesh has at most `target` vertices.
template <class TriangleMesh>
class Vertex_count_stop_predicate {
public:
  Vertex_count_stop_predicate(const TriangleMesh& tm, std::size_t target) : tracker_(tm), target_(target) {}
  template <class FT, class Profile>
  bool operator()(const FT&, const Profile&, std::size_t, std::size_t current_edge_count) const {
    tracker_.update(current_edge_count);
    return tracker_.vertex_count() <= target_;
  }

private:
  internal::Mesh_size_tracker<TriangleMesh> tracker_;
  std::size_t target_;
};

/// Stops when the cheapest remaining collapse costs more than `max_cost` (the policy's cost
/// units: for the quadric policies, area times squared distance).
class Max_cost_stop_predicate {
public:
  explicit Max_cost_stop_predicate(double max_cost) : max_cost_(max_cost) {}
  template <class FT, class Profile>
  bool operator()(const FT& cost, const Profile&, std::size_t, std::size_t) const {
    return CGAL::to_double(cost) > max_cost_;
  }

private:
  double max_cost_;
};

/// Stops as soon as either predicate does (both are called, so both keep their counters).
template <class P1, class P2>
class Stop_if_any {
public:
  Stop_if_any(const P1& p1, const P2& p2) : p1_(p1), p2_(p2) {}
  template <class FT, class Profile>
  bool operator()(const FT& c, const Profile& p, std::size_t i, std::size_t e) const {
    const bool a = p1_(c, p, i, e);
    const bool b = p2_(c, p, i, e);
    return a || b;
  }

private:
  P1 p1_;
  P2 p2_;
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_STOP_PREDICATES_H
