// The collapse engine's visitor that drives a cmgeom progress bar (simplify, lod): faces removed so
// far over faces to remove, redrawn every 1024 collapses.
#ifndef CMGEOM_TOOLS_COLLAPSE_PROGRESS_H
#define CMGEOM_TOOLS_COLLAPSE_PROGRESS_H

#include "cli_common.h"

#include <CMGeom/Textured_simplification/Edge_collapse_visitor_base.h>

#include <cstddef>

namespace cmgeom_cli {

struct Collapse_progress_visitor : CMGeom::Textured_simplification::Edge_collapse_visitor_base {
  struct State {
    Progress* bar;
    double faces_to_remove;
    std::size_t removed = 0, calls = 0;
    // Ends the bar; its final line gives the faces actually removed (fewer than planned when a
    // bound, the charts or the mesh stopped the run first, or every face but one when the run
    // had no face target).
    void done(std::size_t faces_in, std::size_t faces_out) const {
      bar->set_total(double(faces_in > faces_out ? faces_in - faces_out : 0), "faces removed");
      bar->done();
    }
  };
  State* s;
  explicit Collapse_progress_visitor(State* st) : s(st) {}
  template <class Profile, class V>
  void OnCollapsed(const Profile& p, const V&) const {
    s->removed += std::size_t(p.left_face_exists()) + std::size_t(p.right_face_exists());
    if ((++s->calls & 1023u) == 0 && s->faces_to_remove > 0) s->bar->update(double(s->removed) / s->faces_to_remove);
  }
};

}  // namespace cmgeom_cli

#endif  // CMGEOM_TOOLS_COLLAPSE_PROGRESS_H
