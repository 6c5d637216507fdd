// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// internal::Edge_collapse_engine, the engine behind CMGeom::Textured_simplification::edge_collapse
// (edge_collapse.h): an edge-collapse engine for the policy concepts of CGAL's
// Surface_mesh_simplification (GetCost, GetPlacement, PlacementFilter, StopPredicate,
// EdgeCollapseSimplificationVisitor, and the Update_tag hook of cost policies), built for speed.
// It drives the weighted quadric simplification of thesis §3.4 and the edge flips of §3.5.1, and
// calls policies and visitor in the order CGAL 5.5.1's engine does. Deliberate differences: its
// own fold-over test, cost updates around the kept vertex only for FastCollapseCostPolicy models,
// re-costing when a filter moves the placement, the light Collapse_profile. Layout: one 16-byte
// record per edge, an indexed 8-ary heap updated in place, nothing allocated in the collapse loop.
// With a memory (Surface_memory.h) the memoryful cost found for an edge is kept until a collapse
// or a flip changes the faces its own collapse would change (a stamp per vertex), and on two
// threads or more a pop that needs one prices the next edges of the queue as well, on all cores
// (price_ahead()): the collapses are the same on any number of cores.
// Complexity: O(E log E) set-up, O(d log E) per collapse (d = vertex degree).
//
// Manual: doc/Textured_simplification/README.md, "The visitor and filter hooks (for the textured part)".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_EDGE_COLLAPSE_ENGINE_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_EDGE_COLLAPSE_ENGINE_H

#include <CMGeom/config.h>
#include <CMGeom/Compact_model/internal/Vec3.h>
#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Collapse_profile.h>
#include <CMGeom/Textured_simplification/No_normal_flip_filter.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/internal/Indexed_heap.h>
#include <CMGeom/Textured_simplification/internal/collapse_checks.h>
#include <CMGeom/Textured_simplification/internal/edge_flip.h>
#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>

#include <CGAL/Named_function_parameters.h>
#include <CGAL/Surface_mesh/Surface_mesh_fwd.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/named_params_helper.h>
#include <CGAL/property_map.h>

#include <boost/mpl/has_xxx.hpp>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

namespace internal {

BOOST_MPL_HAS_XXX_TRAIT_DEF(Update_tag)
BOOST_MPL_HAS_XXX_TRAIT_DEF(Cost_depends_on_endpoints_only)

template <class C, bool = has_Update_tag<C>::value>
struct has_update : std::false_type {};
template <class C>
struct has_update<C, true> : std::integral_constant<bool, C::Update_tag::value> {};

// Policies that must read the endpoints' data before the collapse frees a vertex provide
// before_collapse(profile) -> token and update_after_collapse(profile, v_kept, token).
template <class C, class P, class = void>
struct has_before_collapse : std::false_type {};
template <class C, class P>
struct has_before_collapse<C, P,
                           std::void_t<decltype(std::declval<const C&>().before_collapse(std::declval<const P&>()))>>
    : std::true_type {};

// The token a cost policy's before_collapse returns (No_collapse_token when it has none), found
// outside the engine's class so that the class need not be complete to name it.
struct No_collapse_token {};
template <class C, class P, bool = has_before_collapse<C, P>::value>
struct collapse_token {
  using type = No_collapse_token;
};
template <class C, class P>
struct collapse_token<C, P, true> {
  using type = std::decay_t<decltype(std::declval<const C&>().before_collapse(std::declval<const P&>()))>;
};

template <class C, bool = has_Cost_depends_on_endpoints_only<C>::value>
struct endpoint_cost : std::false_type {};
template <class C>
struct endpoint_cost<C, true> : std::integral_constant<bool, C::Cost_depends_on_endpoints_only::value> {};

// A cost policy that can also compute its own placement's cost in one pass (see
// Area_weighted_quadric_policies::cost_at_own_placement).
template <class C, class P, class Profile, class = void>
struct has_fused_cost : std::false_type {};
template <class C, class P, class Profile>
struct has_fused_cost<
    C, P, Profile,
    std::void_t<decltype(std::declval<const C&>().cost_at_own_placement(std::declval<const Profile&>())),
                decltype(std::declval<const C&>().shares_state_with(std::declval<const P&>()))>> : std::true_type {};

// A visitor told of the faces a component removal takes (OnFacesRemoved(tm, faces), called once
// they are removed; see parameters::prune_components).
template <class V, class TM, class Faces, class = void>
struct has_on_faces_removed : std::false_type {};
template <class V, class TM, class Faces>
struct has_on_faces_removed<
    V, TM, Faces,
    std::void_t<decltype(std::declval<V&>().OnFacesRemoved(std::declval<const TM&>(), std::declval<const Faces&>()))>>
    : std::true_type {};

// A cost policy whose update_after_collapse can take the kept vertex's star normal, which the
// engine's fold-over test computes anyway (see Area_weighted_quadric_policies).
template <class C, class P, class V, class T, class = void>
struct has_normal_hint : std::false_type {};
template <class C, class P, class V, class T>
struct has_normal_hint<
    C, P, V, T,
    std::void_t<decltype(std::declval<const C&>().update_after_collapse(
        std::declval<const P&>(), std::declval<V>(), std::declval<const T&>(), std::declval<const Vec3&>()))>>
    : std::true_type {};

// A cost policy with a prefetch(vertex) hint (see Area_weighted_quadric_policies::prefetch).
template <class C, class V, class = void>
struct has_prefetch : std::false_type {};
template <class C, class V>
struct has_prefetch<C, V, std::void_t<decltype(std::declval<const C&>().prefetch(std::declval<V>()))>>
    : std::true_type {};

// A filter that also rules on edge flips (allows_flip(tm, h) before, flipped(tm, h) after; see
// Hausdorff_bound_filter).
template <class F, class TM, class H, class = void>
struct has_flip_check : std::false_type {};
template <class F, class TM, class H>
struct has_flip_check<
    F, TM, H,
    std::void_t<decltype(std::declval<const F&>().allows_flip(std::declval<const TM&>(), std::declval<H>())),
                decltype(std::declval<const F&>().flipped(std::declval<const TM&>(), std::declval<H>()))>>
    : std::true_type {};

// The scratch space of a memory's cost() (Surface_memory::Pricing_scratch), for pricing on
// several threads at once; none without a memory.
template <class M, class = void>
struct Pricing_scratch_of {
  struct type {};
};
template <class M>
struct Pricing_scratch_of<M*, std::void_t<typename M::Pricing_scratch>> {
  using type = typename M::Pricing_scratch;
};

template <class V, class TM, class H, class = void>
struct has_on_flipped : std::false_type {};
template <class V, class TM, class H>
struct has_on_flipped<V, TM, H,
                      std::void_t<decltype(std::declval<V&>().OnFlipped(std::declval<const TM&>(), std::declval<H>()))>>
    : std::true_type {};

template <class TM, class VPM, class GT, class ECM, class GetCost, class GetPlacement, class Filter, class Visitor,
          class StopPredicate, class Memory = std::nullptr_t>
class Edge_collapse_engine {
  using GTraits = boost::graph_traits<TM>;
  using vertex_descriptor = typename GTraits::vertex_descriptor;
  using halfedge_descriptor = typename GTraits::halfedge_descriptor;
  using edge_descriptor = typename GTraits::edge_descriptor;
  using face_descriptor = typename GTraits::face_descriptor;
  using Profile = Collapse_profile<TM, VPM, GT>;
  using FT = typename GT::FT;
  using Point = typename boost::property_traits<VPM>::value_type;
  using Cost = CMGeom::internal::optional<FT>;
  using Placement = CMGeom::internal::optional<Point>;

  enum : std::uint8_t { HAS_COST = 1, DEAD = 2, CONSTRAINED = 4, REJECTED = 8 };

public:
  Edge_collapse_engine(TM& tm, const StopPredicate& stop, const VPM& vpm, const GT& gt, const ECM& ecm,
                       const GetCost& cost, const GetPlacement& placement, const Filter& filter, Visitor& visitor,
                       bool flips, Memory memory = Memory(), std::size_t prune_min_faces = 0)
      : tm_(tm),
        stop_(stop),
        vpm_(vpm),
        gt_(gt),
        ecm_(ecm),
        get_cost_(cost),
        get_placement_(placement),
        filter_(filter),
        visitor_(visitor),
        flips_(flips),
        memory_(memory),
        vim_(CGAL::get_initialized_vertex_index_map(tm)),
        eim_(CGAL::get_initialized_edge_index_map(tm)) {
    if constexpr (fused_cost) fused_ = get_cost_.shares_state_with(get_placement_);
    if constexpr (edge_index_is_position) prune_min_faces_ = prune_min_faces;
    if constexpr (has_memory) {
      // (on the threads the arena has and the global limit allows)
      const std::size_t threads =
          (std::min)(std::size_t(tbb::this_task_arena::max_concurrency()),
                     tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
      if (memory_ && memory_->parallel_pricing() && threads > 1) price_ahead_ = price_ahead_edges;
    }
  }

  int run() {
    visitor_.OnStarted(tm_);
    initialize_cost(std::integral_constant<bool, has_update<GetCost>::value>());
    collect();
    loop();
    visitor_.OnFinished(tm_);
    return static_cast<int>(initial_edges_ - current_edges_);
  }

private:
  template <class B>
  void initialize_cost(B) {}
  void initialize_cost(std::true_type) { get_cost_.initialize(tm_, vpm_, gt_); }
  void after_collapse(const Profile&, vertex_descriptor, std::false_type) {}
  using No_token = No_collapse_token;
  No_token before_collapse(const Profile&, std::false_type) const { return {}; }
  auto before_collapse(const Profile& p, std::true_type) const { return get_cost_.before_collapse(p); }
  void after_collapse(const Profile& p, vertex_descriptor v, No_token) {
    after_collapse(p, v, std::integral_constant<bool, has_update<GetCost>::value>());
  }
  template <class Token>
  void after_collapse(const Profile& p, vertex_descriptor v, const Token& t) {
    get_cost_.update_after_collapse(p, v, t);
  }
  void after_collapse(const Profile& p, vertex_descriptor v, std::true_type) { get_cost_.update_after_collapse(p, v); }

  std::uint32_t id(edge_descriptor e) const { return static_cast<std::uint32_t>(get(eim_, e)); }
  /// The edge of index i. On Surface_mesh the index is the edge's position, so no table (whose
  /// lookup would add one cache miss to the chain of dependent loads behind every pop).
  edge_descriptor edge_at(std::uint32_t i) const {
    if constexpr (edge_index_is_position)
      return edge_descriptor(i);
    else
      return edge_of_[i];
  }
  std::uint32_t& flags(std::uint32_t i) { return heap_.user(i); }

  Profile profile_of(edge_descriptor e) const { return Profile(halfedge(e, tm_), tm_, vpm_, gt_); }

  void prefetch_point(vertex_descriptor v) const {
#if defined(__GNUC__)
    if constexpr (std::is_lvalue_reference<decltype(get(vpm_, v))>::value)
      __builtin_prefetch(&get(vpm_, v));
    else
      (void)v;
#else
    (void)v;
#endif
  }
  void prefetch_vertex(vertex_descriptor v) const {
    if constexpr (has_prefetch<GetCost, vertex_descriptor>::value)
      get_cost_.prefetch(v);
    else
      (void)v;
  }

  /// The cost of the edge at the placement policy's placement.
  Cost cost_of(const Profile& p) const {
    if constexpr (fused_cost) {
      if (fused_) return get_cost_.cost_at_own_placement(p);
    }
    return get_cost_(p, get_placement_(p));
  }

  /// (Re)computes the cost of edge e and puts it in the queue (or takes it out if absent).
  void evaluate(edge_descriptor e) {
    const std::uint32_t i = id(e);
    if (flags(i) & (DEAD | CONSTRAINED)) return;
    forget_memory_cost(i);
    requeue(i, cost_of(profile_of(e)));
  }

  /// Edge i is about to be re-costed because its surroundings changed: the memoryful cost found
  /// when it was last popped no longer holds.
  void forget_memory_cost(std::uint32_t i) {
    if constexpr (has_memory) {
      if (memory_) {
        memory_cost_[i] = 0.;
        priced_at_[i] = 0;
      }
    } else {
      (void)i;
    }
  }

  /// Stores the new cost (or its absence) of live edge i and updates the queue.
  void requeue(std::uint32_t i, const Cost& c) {
    std::uint32_t& f = flags(i);
    f &= ~std::uint32_t(REJECTED);
    if (c) {
      f |= HAS_COST;
      double cost = CGAL::to_double(*c);
      if constexpr (has_memory) {
        // the memoryful cost last found for this edge stands in for the current one until the
        // edge comes up again (see loop())
        if (memory_ && memory_->active()) cost = (std::max)(cost, memory_cost_[i]);
      }
      if (!heap_.contains(i) || cost != heap_.key(i)) heap_.set(i, cost);
    } else {
      f &= ~std::uint32_t(HAS_COST);
      heap_.remove(i);
    }
  }

  void collect() {
    // Graphs whose edge index is derived from halfedge ids (Polyhedron_3 with ids) need those
    // initialised first; on Surface_mesh this is a no-op.
    (void)CGAL::get_initialized_halfedge_index_map(tm_);
    eim_ = CGAL::get_initialized_edge_index_map(tm_);
    std::size_t max_e = 0, max_v = 0;
    for (edge_descriptor e : edges(tm_)) max_e = (std::max)(max_e, std::size_t(get(eim_, e)) + 1);
    for (vertex_descriptor v : vertices(tm_)) max_v = (std::max)(max_v, std::size_t(get(vim_, v)) + 1);
    if constexpr (!edge_index_is_position) edge_of_.assign(max_e, edge_descriptor());
    mark_.assign(max_v, 0u);
    rejected_near_.assign((max_v + 63) / 64, 0u);
    heap_.reset(max_e);
    if constexpr (has_memory) {
      memory_cost_.assign(memory_ ? max_e : 0, 0.);
      priced_at_.assign(memory_ ? max_e : 0, 0u);
      changed_at_.assign(memory_ ? max_v : 0, 0u);
      change_count_ = 1;
    }
    initial_edges_ = 0;
    for (edge_descriptor e : edges(tm_)) {
      const std::uint32_t i = id(e);
      if constexpr (!edge_index_is_position) edge_of_[i] = e;
      CGAL_assertion(edge_at(i) == e);
      ++initial_edges_;
      if (get(ecm_, e)) {
        flags(i) |= CONSTRAINED;
        continue;
      }
      evaluate(e);
      if (std::is_same<Visitor, Edge_collapse_visitor_base>::value) continue;
      const Profile p = profile_of(e);
      visitor_.OnCollected(p, (flags(i) & HAS_COST) ? Cost(FT(heap_.key(i))) : Cost());
    }
    current_edges_ = initial_edges_;
    if (prune_min_faces_ > 0) collect_components();
  }

  /// Component pruning (parameters::prune_components): the connected components of the live faces,
  /// each priced once by sum over its faces of area x mean squared distance of the corners to the
  /// component's area centroid, ordered by price (then by first face, for a fixed order).
  void collect_components() {
    if constexpr (edge_index_is_position) {
      using V3 = CM::internal::Vec3;
      const auto v3 = [](const Point& p) {
        return V3(CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z()));
      };
      // a face's corners and area
      const auto triangle = [&](face_descriptor f, std::array<V3, 3>& t) {
        const halfedge_descriptor h = halfedge(f, tm_);
        t = {v3(get(vpm_, source(h, tm_))), v3(get(vpm_, target(h, tm_))), v3(get(vpm_, target(next(h, tm_), tm_)))};
        return 0.5 * CM::internal::length(CM::internal::cross(t[1] - t[0], t[2] - t[0]));
      };
      const auto corner = [this](face_descriptor f) { return std::size_t(get(vim_, target(halfedge(f, tm_), tm_))); };
      const std::size_t nv = mark_.size();
      std::vector<std::uint32_t> parent(nv);
      for (std::size_t v = 0; v < nv; ++v) parent[v] = std::uint32_t(v);
      auto find = [&parent](std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
      };
      for (edge_descriptor e : edges(tm_)) {
        const std::uint32_t a = find(std::uint32_t(get(vim_, source(halfedge(e, tm_), tm_))));
        const std::uint32_t b = find(std::uint32_t(get(vim_, target(halfedge(e, tm_), tm_))));
        if (a != b) parent[(std::max)(a, b)] = (std::min)(a, b);
      }
      // components numbered in the order of their first face; their areas, centroids, face counts
      constexpr std::uint32_t none = 0xffffffffu;
      std::vector<std::uint32_t> label(nv, none);
      std::vector<V3> weighted_sum;
      std::vector<double> area;
      std::array<V3, 3> t;
      for (face_descriptor f : faces(tm_)) {
        const std::uint32_t root = find(std::uint32_t(corner(f)));
        if (label[root] == none) {
          label[root] = std::uint32_t(area.size());
          area.push_back(0.);
          weighted_sum.emplace_back(0., 0., 0.);
          component_faces_.push_back(0);
        }
        const std::uint32_t c = label[root];
        const double a = triangle(f, t);
        area[c] += a;
        weighted_sum[c] = weighted_sum[c] + (a / 3.) * (t[0] + t[1] + t[2]);
        ++component_faces_[c];
      }
      const std::size_t nc = area.size();
      if (nc < 2) {
        prune_min_faces_ = 0;
        return;
      }
      component_of_vertex_.resize(nv);
      for (std::size_t v = 0; v < nv; ++v) component_of_vertex_[v] = label[find(std::uint32_t(v))];
      std::vector<V3> centroid(nc);
      for (std::size_t c = 0; c < nc; ++c)
        centroid[c] = area[c] > 0. ? (1. / area[c]) * weighted_sum[c] : weighted_sum[c];
      // the prices, and each component's faces (in face order) at its offset of component_face_list_
      component_price_.assign(nc, 0.);
      component_start_.assign(nc + 1, 0);
      for (std::size_t c = 0; c < nc; ++c) component_start_[c + 1] = component_start_[c] + component_faces_[c];
      component_face_list_.resize(component_start_[nc]);
      std::vector<std::uint32_t> fill(component_start_.begin(), component_start_.end() - 1);
      for (face_descriptor f : faces(tm_)) {
        const std::uint32_t c = component_of_vertex_[corner(f)];
        const double a = triangle(f, t);
        component_price_[c] +=
            a *
            (CM::internal::squared_length(t[0] - centroid[c]) + CM::internal::squared_length(t[1] - centroid[c]) +
             CM::internal::squared_length(t[2] - centroid[c])) /
            3.;
        component_face_list_[fill[c]++] = f;
      }
      // the largest component (by area, the first of equals) is never removed
      std::size_t largest = 0;
      for (std::size_t c = 1; c < nc; ++c)
        if (area[c] > area[largest]) largest = c;
      prune_order_.clear();
      for (std::uint32_t c = 0; c < nc; ++c)
        if (c != largest) prune_order_.push_back(c);
      std::stable_sort(prune_order_.begin(), prune_order_.end(),
                       [this](std::uint32_t a, std::uint32_t b) { return component_price_[a] < component_price_[b]; });
      prune_next_ = 0;
    }
  }

  /// Removes, cheapest first, the components priced at most `cost` (any, when no collapse is
  /// left: `cost` infinite) whose removal leaves at least prune_min_faces_ faces.
  void prune_up_to(double cost) {
    if constexpr (edge_index_is_position) {
      while (prune_next_ < prune_order_.size()) {
        const std::uint32_t c = prune_order_[prune_next_];
        if (component_price_[c] > cost) return;
        ++prune_next_;
        const std::size_t live = component_faces_[c];
        const std::size_t faces_now = tm_.number_of_faces();
        if (live == 0 || faces_now < prune_min_faces_ + live) continue;
        remove_component(c);
      }
    } else {
      (void)cost;
    }
  }

  void remove_component(std::uint32_t c) {
    if constexpr (edge_index_is_position) {
      std::vector<face_descriptor> gone;
      for (std::uint32_t j = component_start_[c]; j < component_start_[c + 1]; ++j)
        if (!tm_.is_removed(component_face_list_[j])) gone.push_back(component_face_list_[j]);
      std::size_t edges_gone = 0;
      for (face_descriptor f : gone)
        for (halfedge_descriptor h : CGAL::halfedges_around_face(halfedge(f, tm_), tm_)) {
          const std::uint32_t i = id(edge(h, tm_));
          if (flags(i) & DEAD) continue;
          kill(edge(h, tm_));
          ++edges_gone;
        }
      if constexpr (has_memory) {
        if (memory_) memory_->drop_faces(gone);
      }
      for (face_descriptor f : gone) CGAL::Euler::remove_face(halfedge(f, tm_), tm_);
      current_edges_ -= edges_gone;
      component_faces_[c] = 0;
      if constexpr (has_on_faces_removed<Visitor, TM, std::vector<face_descriptor>>::value)
        visitor_.OnFacesRemoved(tm_, gone);
    } else {
      (void)c;
    }
  }

  bool is_constrained_vertex(vertex_descriptor v) const {
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm_))
      if (get(ecm_, edge(h, tm_))) return true;
    return false;
  }

  void loop() {
    for (;;) {
      if (prune_min_faces_ > 0) prune_up_to(heap_.empty() ? std::numeric_limits<double>::infinity() : heap_.top_key());
      if (heap_.empty()) break;
      const std::uint32_t i = heap_.pop();
      const edge_descriptor e = edge_at(i);
      const Profile p = profile_of(e);
      const Cost c = Cost(FT(heap_.key(i)));
      visitor_.OnSelected(p, c, initial_edges_, current_edges_);
      if (stop_(*c, p, initial_edges_, current_edges_)) {
        visitor_.OnStopConditionReached(p);
        break;
      }
      Placement pl;
      bool have_placement = false;
      if constexpr (has_memory) {
        if (memory_) {
          // the memoryful cost (Surface_memory.h) at the policy's placement, before the tests
          // (an edge it sends back to the queue needs none): if it ranks the edge behind the
          // next one, the edge goes back with it
          pl = get_placement_(p);
          have_placement = true;
          if (pl) {
            // (a cost found at an earlier pop stands while nothing around the edge has changed:
            // the queue brings an edge the cost sent back up again once the edges before it are
            // done, most often with its surroundings as they were)
            const bool active = memory_->active();
            bool fresh = active && priced_since_change(i, p.v0(), p.v1());
            if (active && !fresh && price_ahead_ > 0) {
              if (price_ahead_skip_ > 0)
                --price_ahead_skip_;
              else
                fresh = price_ahead(i, p.v0_v1(), *pl);
            }
            const double m = fresh ? memory_cost_[i] : memory_->cost(tm_, p.v0_v1(), *pl);
            memory_cost_[i] = m;
            if (active) priced_at_[i] = change_count_;
            if (m > heap_.key(i) && !heap_.empty() && m > heap_.key(heap_.top())) {
              requeue(i, Cost(FT(m)));
              continue;
            }
          }
        }
      }
      // the link test walks the stars of v0 and v1: it asks for the neighbours' points on the way,
      // which the fold-over test reads next, and walks the stars of the edge now on top of the
      // queue alongside (most often the next one popped; see is_collapse_topologically_valid)
      const halfedge_descriptor next_top =
          heap_.empty() ? GTraits::null_halfedge() : halfedge(edge_at(heap_.top()), tm_);
      const bool ok_topo =
          internal::is_collapse_topologically_valid(
              tm_, vim_, p.v0_v1(), mark_, stamp_, [this](vertex_descriptor n) { prefetch_point(n); }, next_top) &&
          !(has_constraints_ && is_constrained_vertex(p.v0()) && is_constrained_vertex(p.v1()));
      if (next_top != GTraits::null_halfedge()) {
        // its halfedge records are in the cache now: ask for its endpoints' points and data
        const vertex_descriptor a = source(next_top, tm_), b = target(next_top, tm_);
        prefetch_point(a);
        prefetch_point(b);
        prefetch_vertex(a);
        prefetch_vertex(b);
      }
      if (!ok_topo) {
        reject(i, p);
        visitor_.OnNonCollapsable(p);
        continue;
      }
      if (!have_placement) pl = get_placement_(p);
      if (!pl) {
        reject(i, p);
        continue;
      }
      const internal::Vec3 x = internal::to_vec3(*pl);
      internal::Vec3 star_normal;
      if (internal::collapse_flips_a_face(tm_, vpm_, p.v0_v1(), x, normal_hint ? &star_normal : nullptr)) {
        reject(i, p);
        continue;
      }
      pl = filter_(p, pl);
      if (!pl) {
        reject(i, p);
        visitor_.OnNonCollapsable(p);
        continue;
      }
      const bool moved_placement = internal::to_vec3(*pl) != x;
      if constexpr (!std::is_same<Filter, Identity_filter>::value) {
        // The filter moved the placement (e.g. a half-edge collapse onto a chart boundary): the
        // fold-over test above was for the policy's placement, so it is run again at the new one;
        // and the queue held the cost at the policy's placement. If the cost at the new one is
        // higher than the next edge's, the edge goes back with it and comes up again in its turn
        // (its key then equals its cost and it is collapsed, so this cannot repeat without a
        // change).
        if (moved_placement) {
          if (internal::collapse_flips_a_face(tm_, vpm_, p.v0_v1(), internal::to_vec3(*pl))) {
            reject(i, p);
            continue;
          }
          const Cost moved = get_cost_(p, pl);
          if (moved && !heap_.empty()) {
            const double m = CGAL::to_double(*moved);
            if (m > heap_.key(i) && m > heap_.key(heap_.top())) {
              requeue(i, moved);
              continue;
            }
          }
        }
      }
      // the normal holds for the tested placement only (a filter may move it)
      collapse(p, *pl, normal_hint && !moved_placement ? &star_normal : nullptr);
    }
  }

  /// A popped edge that cannot be collapsed now leaves the queue; it comes back when a collapse
  /// next to it changes its neighbourhood (see update_neighbours). The per-vertex bits let that
  /// test skip vertices with no rejected edge around them (a bit may be set with none, never
  /// clear with one).
  void reject(std::uint32_t i, const Profile& p) {
    flags(i) |= REJECTED;
    set_rejected_near(std::size_t(get(vim_, p.v0())));
    set_rejected_near(std::size_t(get(vim_, p.v1())));
  }
  bool rejected_near(std::size_t v) const { return (rejected_near_[v >> 6] >> (v & 63)) & 1u; }
  void set_rejected_near(std::size_t v) { rejected_near_[v >> 6] |= std::uint64_t(1) << (v & 63); }
  void clear_rejected_near(std::size_t v) { rejected_near_[v >> 6] &= ~(std::uint64_t(1) << (v & 63)); }

  void kill(edge_descriptor e) {
    const std::uint32_t i = id(e);
    heap_.remove(i);
    flags(i) |= DEAD;
  }

  /// `star_normal`: the kept vertex's normal at `placement` from the fold-over test, or null.
  void collapse(const Profile& p, const Point& placement, const internal::Vec3* star_normal) {
    p.load_apexes();  // the halfedges they come from are about to disappear
    visitor_.OnCollapsing(p, Placement(placement));
    const edge_descriptor e = edge(p.v0_v1(), tm_);
    const halfedge_descriptor h = halfedge(e, tm_);
    const halfedge_descriptor o = opposite(h, tm_);
    // Euler::collapse_edge(e) removes e and, for each incident face, the edge of prev() of
    // halfedge(e) / of its opposite (see its documentation) — or, with constraints, the
    // unconstrained edge of the pair; the other edges survive.
    kill(e);
    for (halfedge_descriptor side : {h, o}) {
      if (is_border(side, tm_)) continue;
      const edge_descriptor ep = edge(prev(side, tm_), tm_);
      kill(has_constraints_ && get(ecm_, ep) ? edge(next(side, tm_), tm_) : ep);
    }
    current_edges_ -= 1 + std::size_t(p.left_face_exists()) + std::size_t(p.right_face_exists());
    if (prune_min_faces_ > 0)
      component_faces_[component_of_vertex_[std::size_t(get(vim_, p.v0()))]] -=
          std::size_t(p.left_face_exists()) + std::size_t(p.right_face_exists());
    // Vertex ids are read before the collapse: graphs such as Polyhedron_3 free the removed
    // vertex, and its id lives in the vertex record.
    const std::size_t id0 = std::size_t(get(vim_, p.v0())), id1 = std::size_t(get(vim_, p.v1()));
    auto token = before_collapse(p, std::integral_constant < bool,
                                 has_update<GetCost>::value&& has_before_collapse<GetCost, Profile>::value > ());
    if constexpr (has_memory) {
      if (memory_) memory_->before_collapse(tm_, p.v0_v1());
    }
    vertex_descriptor v_kept =
        has_constraints_ ? CGAL::Euler::collapse_edge(e, tm_, ecm_) : CGAL::Euler::collapse_edge(e, tm_);
    {
      const bool kept_v0 = v_kept == p.v0();
      if (rejected_near(kept_v0 ? id1 : id0)) set_rejected_near(kept_v0 ? id0 : id1);
    }
    put(vpm_, v_kept, placement);
    if constexpr (has_memory) {
      if (memory_) memory_->after_collapse(tm_, v_kept);
    }
    visitor_.OnCollapsed(p, v_kept);
    if constexpr (normal_hint) {
      if (star_normal)
        get_cost_.update_after_collapse(p, v_kept, token, *star_normal);
      else
        after_collapse(p, v_kept, token);
    } else {
      (void)star_normal;
      after_collapse(p, v_kept, token);
    }
    update_neighbours(v_kept, std::integral_constant<bool, endpoint_cost<GetCost>::value>());
    if constexpr (has_memory) {
      if (memory_) {  // (the faces around v_kept and the points on them have changed)
        changed_at_[std::size_t(get(vim_, v_kept))] = ++change_count_;
        for (halfedge_descriptor g : CGAL::halfedges_around_target(v_kept, tm_))
          changed_at_[std::size_t(get(vim_, source(g, tm_)))] = change_count_;
      }
    }
    if (flips_) flip_around(v_kept);
  }

  /// Whether the memoryful cost of edge i (ends a and b) in memory_cost_ still holds: it was found
  /// after the last change of the faces around a and around b (the faces its collapse changes)
  /// and of their points. A collapse changes the faces around the kept vertex, i.e. the stars of
  /// that vertex and of its neighbours; a flip, the stars of the four corners of its quad.
  bool priced_since_change(std::uint32_t i, vertex_descriptor a, vertex_descriptor b) const {
    const std::uint32_t t = priced_at_[i];
    return t != 0 && t >= changed_at_[std::size_t(get(vim_, a))] && t >= changed_at_[std::size_t(get(vim_, b))];
  }

  /// On two cores or more: the memoryful costs of popped edge i (halfedge h, placement pl) and of
  /// the edges the queue gives next (those whose cost does not stand) are found at once, on all
  /// cores. Each stands until something around its edge changes (priced_since_change()), and a
  /// pop takes it as if found then: the result is the same on any number of cores. Returns
  /// whether edge i was priced.
  bool price_ahead(std::uint32_t i, halfedge_descriptor h, const Point& pl) {
    jobs_.clear();
    jobs_.push_back(Pricing_job{i, h, pl, 0.});
    heap_.for_each_first(price_ahead_ - 1, [&](std::uint32_t j) {
      if (flags(j) & (DEAD | CONSTRAINED)) return;
      const halfedge_descriptor hj = halfedge(edge_at(j), tm_);
      if (priced_since_change(j, source(hj, tm_), target(hj, tm_))) return;
      const Profile pj = profile_of(edge_at(j));
      const Placement plj = get_placement_(pj);
      if (plj) jobs_.push_back(Pricing_job{j, pj.v0_v1(), *plj, 0.});
    });
    if (jobs_.size() < 2) return false;  // (the pop prices its edge itself)
    // (isolated: while it waits for the other cores, this thread must not take up unrelated work,
    // such as the atlas preparation simplify_textured_mesh() runs beside the collapses)
    const int caller = tbb::this_task_arena::current_thread_index();
    const std::size_t slots = std::size_t(tbb::this_task_arena::max_concurrency());
    if (scratch_.size() < slots) scratch_.resize(slots);  // (one per thread slot of the arena)
    std::atomic<bool> helped{false};
    tbb::this_task_arena::isolate([&] {
      tbb::parallel_for(
          tbb::blocked_range<std::size_t>(0, jobs_.size()), [&](const tbb::blocked_range<std::size_t>& r) {
            if (tbb::this_task_arena::current_thread_index() != caller) helped.store(true, std::memory_order_relaxed);
            Pricing_scratch& scratch = scratch_[std::size_t(tbb::this_task_arena::current_thread_index())];
            for (std::size_t k = r.begin(); k != r.end(); ++k)
              jobs_[k].cost = memory_->cost(tm_, jobs_[k].h, jobs_[k].placement, scratch);
          });
    });
    // no other core took part (they are busy elsewhere): the edges priced ahead are work this
    // thread would mostly not have done, so the next pops price their own edge, for twice as
    // many pops each time this repeats (the collapses are the same either way)
    if (helped.load(std::memory_order_relaxed)) {
      price_ahead_backoff_ = 1;
    } else {
      price_ahead_skip_ = price_ahead_backoff_;
      price_ahead_backoff_ = (std::min)(2 * price_ahead_backoff_, std::size_t(4096));
    }
    for (const Pricing_job& job : jobs_) {
      memory_cost_[job.id] = job.cost;
      priced_at_[job.id] = change_count_;
    }
    return true;
  }

  void update_neighbours(vertex_descriptor v, std::true_type) {
    // The records of the edges around v and the policy's data of v's neighbours are scattered in
    // memory: request them all first, so that their cache misses overlap, then evaluate.
    constexpr int ring_max = 64;
    halfedge_descriptor ring[ring_max];
    int n = 0;
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm_)) {
      if (n < ring_max) ring[n] = h;
      ++n;
      heap_.prefetch(id(edge(h, tm_)));
      prefetch_vertex(source(h, tm_));
    }
    if (n <= ring_max) {
      // costs first (they do not depend on the queue), asking for each edge's heap node on the
      // way; then the queue updates, in the same order as evaluate() would do them
      // (plain arrays: 64 default-constructed optionals cost more than the degree-6 loop below)
      FT costs[ring_max];
      bool has_cost[ring_max];
      std::uint32_t ids[ring_max];
      for (int k = 0; k < n; ++k) {
        const edge_descriptor e = edge(ring[k], tm_);
        ids[k] = id(e);
        if (flags(ids[k]) & (DEAD | CONSTRAINED)) continue;
        const Cost c = cost_of(profile_of(e));
        has_cost[k] = bool(c);
        if (c) costs[k] = *c;
        heap_.prefetch_node(ids[k]);
      }
      for (int k = 0; k < n; ++k) {
        if (flags(ids[k]) & (DEAD | CONSTRAINED)) continue;
        forget_memory_cost(ids[k]);
        requeue(ids[k], has_cost[k] ? Cost(costs[k]) : Cost());
      }
    } else {
      for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm_)) evaluate(edge(h, tm_));
    }
    // one ring farther: costs are unchanged, but edges rejected earlier may have become valid
    clear_rejected_near(std::size_t(get(vim_, v)));
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm_)) {
      const std::size_t n = std::size_t(get(vim_, source(h, tm_)));
      if (!rejected_near(n)) continue;
      clear_rejected_near(n);
      const vertex_descriptor vn = source(h, tm_);
      for (halfedge_descriptor h2 : CGAL::halfedges_around_target(vn, tm_)) {
        const std::uint32_t i = id(edge(h2, tm_));
        std::uint32_t& f = flags(i);
        if ((f & (REJECTED | DEAD | CONSTRAINED)) == REJECTED) {
          f &= ~std::uint32_t(REJECTED);
          if (f & HAS_COST) heap_.restore(i);
        }
      }
    }
  }
  void update_neighbours(vertex_descriptor v, std::false_type) {
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm_)) {
      const vertex_descriptor n = source(h, tm_);
      for (halfedge_descriptor h2 : CGAL::halfedges_around_target(n, tm_)) evaluate(edge(h2, tm_));
    }
  }

  /// §3.5.1: flip-tests the edges of the triangles around the kept vertex.
  void flip_around(vertex_descriptor v) {
    // Edges opposite to v (the link) and the edges incident to v. Collect first: flipping
    // changes the circulation around v. A fixed-size buffer: vertex degrees above 64 skip flips.
    halfedge_descriptor buf[128];
    int n = 0;
    for (halfedge_descriptor h : CGAL::halfedges_around_target(v, tm_)) {
      if (n + 2 > 128) return;
      buf[n++] = h;
      if (!is_border(h, tm_)) buf[n++] = prev(h, tm_);  // the link edge of face(h)
    }
    for (int k = 0; k < n; ++k) {
      const halfedge_descriptor h = buf[k];
      const edge_descriptor e = edge(h, tm_);
      const std::uint32_t i = id(e);
      if (flags(i) & (DEAD | CONSTRAINED)) continue;
      if (!internal::should_flip(tm_, vpm_, h, get_cost_, vim_, mark_, stamp_)) continue;
      if constexpr (has_flip_check<Filter, TM, halfedge_descriptor>::value) {
        if (!filter_.allows_flip(tm_, h)) continue;
      }
      CGAL::Euler::flip_edge(h, tm_);
      if constexpr (has_flip_check<Filter, TM, halfedge_descriptor>::value) filter_.flipped(tm_, h);
      if constexpr (has_memory) {
        if (memory_) {
          memory_->after_flip(tm_, h);
          // (the two faces of the quad and their points changed)
          ++change_count_;
          for (halfedge_descriptor g : {h, opposite(h, tm_)}) {
            changed_at_[std::size_t(get(vim_, target(g, tm_)))] = change_count_;
            if (!is_border(g, tm_)) changed_at_[std::size_t(get(vim_, target(next(g, tm_), tm_)))] = change_count_;
          }
        }
      }
      if constexpr (has_on_flipped<Visitor, TM, halfedge_descriptor>::value) visitor_.OnFlipped(tm_, h);
      // the flipped edge has new endpoints; rim edges are re-evaluated for policies whose cost
      // depends on more than the endpoints
      evaluate(e);
      if constexpr (!endpoint_cost<GetCost>::value) {
        evaluate(edge(next(h, tm_), tm_));
        evaluate(edge(prev(h, tm_), tm_));
        evaluate(edge(next(opposite(h, tm_), tm_), tm_));
        evaluate(edge(prev(opposite(h, tm_), tm_), tm_));
      }
    }
  }

  TM& tm_;
  const StopPredicate& stop_;
  VPM vpm_;
  const GT& gt_;
  ECM ecm_;
  const GetCost& get_cost_;
  const GetPlacement& get_placement_;
  const Filter& filter_;
  Visitor& visitor_;
  bool flips_;
  Memory memory_;
  static constexpr bool has_memory = !std::is_same<Memory, std::nullptr_t>::value;
  static constexpr bool fused_cost = has_fused_cost<GetCost, GetPlacement, Profile>::value;
  static constexpr bool edge_index_is_position = is_surface_mesh<TM>::value;
  using Token_type =
      std::conditional_t<has_update<GetCost>::value, typename collapse_token<GetCost, Profile>::type, No_token>;
  static constexpr bool normal_hint =
      has_update<GetCost>::value && has_normal_hint<GetCost, Profile, vertex_descriptor, Token_type>::value;
  bool fused_ = false;  // the cost policy computes the placement policy's placement itself
  bool has_constraints_ = !std::is_same<ECM, CGAL::Constant_property_map<edge_descriptor, bool>>::value;
  typename CGAL::GetInitializedVertexIndexMap<TM>::const_type vim_;
  typename CGAL::GetInitializedEdgeIndexMap<TM>::const_type eim_;

  std::vector<edge_descriptor> edge_of_;
  std::vector<unsigned> mark_;
  std::vector<std::uint64_t> rejected_near_;  // one bit per vertex, see reject()
  std::vector<double> memory_cost_;           // per edge: its memoryful cost when last found
  // when the faces a collapse changes last changed (per vertex, see priced_since_change()) and
  // when an edge was last priced (0: not since its cost was last forgotten), in changes so far
  std::vector<std::uint32_t> changed_at_, priced_at_;
  std::uint32_t change_count_ = 1;
  // pricing ahead on several cores (price_ahead()): edges priced per batch (0: none)
  static constexpr std::size_t price_ahead_edges = 16;
  std::size_t price_ahead_ = 0;
  std::size_t price_ahead_skip_ = 0, price_ahead_backoff_ = 1;  // pops left without, and the next such run
  using Pricing_scratch = typename Pricing_scratch_of<Memory>::type;
  struct Pricing_job {
    std::uint32_t id;
    halfedge_descriptor h;
    Point placement;
    double cost;
  };
  std::vector<Pricing_job> jobs_;
  std::vector<Pricing_scratch> scratch_;  // by thread slot of the arena
  unsigned stamp_ = 0;
  Indexed_heap heap_;
  std::size_t initial_edges_ = 0, current_edges_ = 0;
  // component pruning (collect_components())
  std::size_t prune_min_faces_ = 0;
  std::vector<std::uint32_t> component_of_vertex_, component_start_, prune_order_;
  std::vector<std::size_t> component_faces_;
  std::vector<double> component_price_;
  std::vector<face_descriptor> component_face_list_;
  std::size_t prune_next_ = 0;
};

}  // namespace internal

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_EDGE_COLLAPSE_ENGINE_H
