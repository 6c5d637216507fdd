// A cmgeom progress bar driven by the collapse engine (simplify, lod): faces removed so far over
// faces to remove, redrawn every 1024 collapses. The visitor is the library's
// Removed_faces_visitor, with which the simplification functions are precompiled
// (CMGeom::Textured_simplification), so the tool does not compile the engine again.
#ifndef CMGEOM_TOOLS_COLLAPSE_PROGRESS_H
#define CMGEOM_TOOLS_COLLAPSE_PROGRESS_H

#include "cli_common.h"

#include <CMGeom/Textured_simplification/Removed_faces_visitor.h>

#include <cstddef>

namespace cmgeom_cli {

struct Collapse_progress {
  Progress* bar;
  double faces_to_remove;

  /// The visitor to hand to the simplification (it updates `bar`).
  CMGeom::Textured_simplification::Removed_faces_visitor visitor() const {
    Progress* b = bar;
    const double total = faces_to_remove;
    return CMGeom::Textured_simplification::Removed_faces_visitor([b, total](std::size_t removed) {
      if (total > 0) b->update(double(removed) / total);
    });
  }
  // Ends the bar; its final line gives the faces actually removed (fewer than planned when a
  // bound, the charts or the mesh stopped the run first, or every face but one when the run had
  // no face target).
  void done(std::size_t faces_in, std::size_t faces_out) const {
    bar->set_total(double(faces_in > faces_out ? faces_in - faces_out : 0), "faces removed");
    bar->done();
  }
};

}  // namespace cmgeom_cli

#endif  // CMGEOM_TOOLS_COLLAPSE_PROGRESS_H
