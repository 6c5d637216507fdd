// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Edge_collapse_visitor_base: the do-nothing model of CGAL's EdgeCollapseSimplificationVisitor
// concept (plus CMGeom's OnFlipped and OnFacesRemoved) to derive visitors from, for both engines.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_EDGE_COLLAPSE_VISITOR_BASE_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_EDGE_COLLAPSE_VISITOR_BASE_H

namespace CMGeom {
namespace Textured_simplification {

/// A visitor that does nothing; derive from it and override what you need (the member functions
/// are templates on the profile type, so one visitor serves both engines).
struct Edge_collapse_visitor_base {
  template <class TM>
  void OnStarted(TM&) const {}
  template <class TM>
  void OnFinished(TM&) const {}
  template <class Profile>
  void OnStopConditionReached(const Profile&) const {}
  template <class Profile, class OFT>
  void OnCollected(const Profile&, const OFT&) const {}
  template <class Profile, class OFT, class S>
  void OnSelected(const Profile&, const OFT&, S, S) const {}
  template <class Profile, class OP>
  void OnCollapsing(const Profile&, const OP&) const {}
  template <class Profile, class V>
  void OnCollapsed(const Profile&, const V&) const {}
  template <class Profile>
  void OnNonCollapsable(const Profile&) const {}
  /// CMGeom extension (not in CGAL's concept): called after an edge flip; `h` is the new edge.
  template <class TM, class H>
  void OnFlipped(const TM&, const H&) const {}
  /// CMGeom extension: called after the engine removed a whole connected component
  /// (parameters::prune_components); `faces` are its faces, removed already (on Surface_mesh their
  /// indices stay valid until collect_garbage()).
  template <class TM, class FaceRange>
  void OnFacesRemoved(const TM&, const FaceRange&) const {}
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_EDGE_COLLAPSE_VISITOR_BASE_H
