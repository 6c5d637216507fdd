// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Removed_faces_visitor: a collapse visitor that counts the faces the collapses remove and hands
// the count to a callback every 1024 collapses, for progress displays (the cmgeom tool's progress
// bar is one). simplify_mesh(), simplify_textured_mesh() and simplify_to_levels() are compiled
// with it into CMGeom::Textured_simplification, as with the default visitor, so a program that
// shows progress this way does not compile the collapse engine again.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_REMOVED_FACES_VISITOR_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_REMOVED_FACES_VISITOR_H

#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>

#include <cstddef>
#include <functional>
#include <iterator>
#include <memory>
#include <utility>

namespace CMGeom {
namespace Textured_simplification {

/// Counts the faces removed by the collapses it sees (one or two per collapse: a border edge
/// removes one) and calls `callback(removed)` after every 1024th collapse. The collapses of
/// simplify_mesh()'s and simplify_to_levels()'s parts (large meshes, on all cores) are counted too:
/// the parts' stage tells OnPartsProgress() the faces it has removed so far, which the count and
/// the callback then include (the callback also gets each of those updates). Copies share the
/// count (the algorithms copy their visitor into wrappers of their own). The callback is called
/// from the thread that called the algorithm (the collapse engines call their visitor from it
/// only, the parts' stage its progress), must be cheap and must not throw.
class Removed_faces_visitor : public Edge_collapse_visitor_base {
public:
  using Callback = std::function<void(std::size_t removed)>;

  explicit Removed_faces_visitor(Callback callback = Callback())
      : state_(std::make_shared<State>(std::move(callback))) {}

  template <class Profile, class V>
  void OnCollapsed(const Profile& profile, const V&) const {
    State& s = *state_;
    s.removed += std::size_t(profile.left_face_exists()) + std::size_t(profile.right_face_exists());
    if ((++s.collapses & 1023u) == 0 && s.callback) s.callback(s.in_parts + s.removed);
  }

  /// The faces the parts' stage has removed so far (it calls this as it goes, and once at its
  /// end with its whole count).
  void OnPartsProgress(std::size_t removed_in_parts) const {
    State& s = *state_;
    s.in_parts = removed_in_parts;
    if (s.callback) s.callback(s.in_parts + s.removed);
  }

  /// (a pruned component's faces count as removed)
  template <class TM, class FaceRange>
  void OnFacesRemoved(const TM&, const FaceRange& faces) const {
    state_->removed += std::size_t(std::distance(std::begin(faces), std::end(faces)));
  }

  /// Faces removed so far: by the collapses this visitor and its copies saw, and by the parts.
  std::size_t removed() const { return state_->in_parts + state_->removed; }
  /// Of those, the faces the parts' stage removed.
  std::size_t removed_in_parts() const { return state_->in_parts; }
  /// Collapses seen so far (those of the parts not included).
  std::size_t collapses() const { return state_->collapses; }

private:
  struct State {
    explicit State(Callback c) : callback(std::move(c)) {}
    Callback callback;
    std::size_t removed = 0, collapses = 0, in_parts = 0;
  };
  std::shared_ptr<State> state_;
};

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_REMOVED_FACES_VISITOR_H
