// A progress display for the simplification of a large mesh: simplify_mesh() with a
// Removed_faces_visitor, whose callback gets the number of faces removed so far. On an input of
// 262,144 faces or more simplify_mesh() first simplifies parts of the mesh on all cores; their
// collapses reach no visitor, but the parts' stage tells Removed_faces_visitor how many faces it
// has removed (OnPartsProgress()), so the display moves through that stage too, then through the
// collapses on the whole mesh. When stderr is a terminal the display is one line redrawn in place
// (percent and rate); otherwise it prints a line at every tenth of the work.
//
//   simplify_with_progress [mesh.off|obj|ply] [ratio]   (default: data/spot/spot.obj, 0.01)
// An input under 262,144 faces is first refined by Loop subdivision until it has that many (the
// bundled Spot: 5,856 -> 374,784 faces), a stand-in for a large scan. Writes
// simplified_with_progress.off in the current directory.
#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Textured_simplification.h>
// once per program: its blocks of 8 MB or more on transparent huge pages (see the header)
#include <CMGeom/huge_page_new.h>

#include <CGAL/Subdivision_method_3/subdivision_methods_3.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace TS = CMGeom::Textured_simplification;
using Clock = std::chrono::steady_clock;

// Draws the progress of removing `to_remove` faces on stderr.
class Progress_display {
public:
  explicit Progress_display(std::size_t to_remove)
      : to_remove_(double(std::max<std::size_t>(1, to_remove))),
        terminal_(isatty(STDERR_FILENO) != 0),
        start_(Clock::now()) {}

  void operator()(std::size_t removed) {
    const double fraction = std::min(1.0, double(removed) / to_remove_);
    const double seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    const double rate = seconds > 0 ? double(removed) / seconds : 0.0;
    if (terminal_) {  // one line, redrawn at most every 1/100 of the work
      const int percent = int(100 * fraction);
      if (percent == last_percent_) return;
      last_percent_ = percent;
      std::fprintf(stderr, "\rsimplifying: %3d %% (%zu faces removed, %.1f M faces/s)", percent, removed, rate / 1e6);
    } else {  // a line at every tenth
      const int tenth = int(10 * fraction);
      if (tenth == last_tenth_) return;
      last_tenth_ = tenth;
      std::fprintf(stderr, "simplifying: %d %% after %.2f s\n", 10 * tenth, seconds);
    }
  }
  void done() const {
    if (terminal_ && last_percent_ >= 0) std::fputc('\n', stderr);
  }

private:
  double to_remove_;
  bool terminal_;
  Clock::time_point start_;
  int last_percent_ = -1, last_tenth_ = -1;
};

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : "data/spot/spot.obj";
  const double ratio = argc > 2 ? std::atof(argv[2]) : 0.01;
  if (!(ratio > 0 && ratio < 1)) {
    std::cerr << "simplify_with_progress: the ratio must be in (0, 1)\n";
    return EXIT_FAILURE;
  }
  CMGeom::Surface_mesh mesh;
  try {
    CMGeom::IO::read_mesh(path, mesh);  // validated: manifold, oriented, finite, no degenerate face
  } catch (const CMGeom::Error& e) {
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }
  // the inputs simplify_mesh() simplifies in parts first (262,144 faces by default)
  const std::size_t large = TS::Mesh_simplification_options().parts_min_faces;
  int rounds = 0;
  while (mesh.number_of_faces() < large) {
    CGAL::Subdivision_method_3::Loop_subdivision(mesh, CGAL::parameters::number_of_iterations(1));
    ++rounds;
  }
  const std::size_t faces_in = mesh.number_of_faces();
  std::cout << path << ": " << faces_in << " faces";
  if (rounds > 0) std::cout << " after " << rounds << " rounds of Loop subdivision";
  std::cout << "\n";

  TS::Mesh_simplification_options options;
  options.target_ratio = ratio;
  const std::size_t target = TS::target_faces_for_ratio(faces_in, ratio);
  Progress_display display(faces_in > target ? faces_in - target : 0);
  // Every count the callback gets, to check the display's input below.
  std::vector<std::size_t> reports;
  const TS::Removed_faces_visitor visitor([&](std::size_t removed) {
    reports.push_back(removed);
    display(removed);
  });
  TS::Mesh_simplification_result r;
  try {
    r = TS::simplify_mesh(mesh, options, visitor);  // the visitor is copied; copies share the count
    CMGeom::IO::write_mesh("simplified_with_progress.off", CMGeom::Textured_mesh(std::move(mesh)));  // atomic
  } catch (const std::exception& e) {
    display.done();
    std::cerr << e.what() << "\n";
    return EXIT_FAILURE;
  }
  display.done();

  std::cout << faces_in << " -> " << r.faces_out << " faces in " << r.seconds << " s, " << reports.size()
            << " progress reports\n";
  if (r.parts > 0)
    std::cout << "  " << r.parts << " parts on all cores removed " << visitor.removed_in_parts() << " faces ("
              << r.seconds_parts << " s), then " << visitor.collapses() << " collapses on the whole mesh removed "
              << visitor.removed() - visitor.removed_in_parts() << "\n";
  std::cout << "  written: simplified_with_progress.off\n";

  // What a display may rely on: the counts never decrease, the visitor's total is the faces the
  // simplification removed, the parts' share is what they removed before being put back
  // together, and the display heard from the parts' stage while it ran (a report below its final
  // count) as well as from the collapses on the whole mesh after it.
  const bool sorted = std::is_sorted(reports.begin(), reports.end());
  const bool total =
      visitor.removed() == faces_in - r.faces_out && !reports.empty() && reports.back() <= visitor.removed();
  bool parts = r.parts == 0;
  if (r.parts > 0) {
    const std::size_t in_parts = visitor.removed_in_parts();
    parts = in_parts == faces_in - r.faces_after_parts && reports.front() < in_parts &&
            std::count(reports.begin(), reports.end(), in_parts) >= 1 &&
            (visitor.collapses() < 1024 || reports.back() > in_parts);  // (a report every 1024 collapses)
  }
  if (!(sorted && total && parts)) {
    std::cerr << "simplify_with_progress: inconsistent progress (sorted " << sorted << ", total " << total << ", parts "
              << parts << ")\n";
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
