// Speed of the Metrics package against CGAL, and of the renderer. Prints Markdown tables.
//
//   bench_Metrics [data_dir] [repetitions]
//
// 1. Error computation: for each model, the reference is compared with a perturbed copy
//    (every vertex moved by a smooth bump of 0.2 % of the bounding-box diagonal, so that the
//    distances are those of a good approximation). Our approximation_error() on 1 and 2 threads
//    against CGAL's approximate_symmetric_Hausdorff_distance with the SAME numbers of vertex,
//    edge and face samples per direction (Sequential_tag and Parallel_tag), in the same run.
//    Samples per second = samples of both directions / wall time, tree construction included.
// 2. Rendering: time of one 1024 x 1024 4x MSAA picture of a ~100k-face mesh (Nefertiti),
//    renderer reused (context and shaders created once), minimum and median of the repetitions.
#include <CMGeom/Metrics/approximation_error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#ifdef CMGEOM_HAS_OSMESA
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/make_render_mesh.h>
#endif

#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cmgeom_test_config.h"
#include "cmgeom_bench_support.h"

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Reads a model, gunzipping "*.gz" into the temporary directory first.
CMGeom::Textured_mesh load(const std::string& path) {
  const std::string file =
      cmgeom_bench::readable_model(path, std::filesystem::temp_directory_path().string(), "cmgeom_bench_");
  if (file.empty()) throw std::runtime_error("cannot gunzip " + path);
  CMGeom::Textured_mesh tm;
  if (!CGAL::IO::read_polygon_mesh(file, tm.mesh())) throw std::runtime_error("cannot read " + path);
  CGAL::Polygon_mesh_processing::remove_isolated_vertices(tm.mesh());
  tm.mesh().collect_garbage();
  return tm;
}

void bench_error(const std::string& name, const std::string& path, int reps) {
  const CMGeom::Textured_mesh tm = load(path);
  const CMGeom::Surface_mesh& ref = tm.mesh();
  CMGeom::Surface_mesh app = ref;
  const double diag = cmgeom_bench::diagonal(CGAL::Polygon_mesh_processing::bbox(ref));
  for (auto v : app.vertices()) {
    const auto p = app.point(v);
    const double s =
        0.002 * diag * std::sin(40 * p.x() / diag) * std::sin(40 * p.y() / diag) * std::sin(40 * p.z() / diag);
    app.point(v) = CMGeom::Point_3(p.x() + s, p.y() - s, p.z() + s);
  }
  namespace M = CMGeom::Metrics;
  M::Error_options o;
  o.vertex_field = false;
  auto run_ours = [&](int threads, M::Approximation_error& out) {
    o.threads = threads;
    return cmgeom_bench::time_runs(reps, [&] { out = M::approximation_error(ref, app, o); });
  };
  M::Approximation_error e1, e2;
  const cmgeom_bench::Timing t1 = run_ours(1, e1), t2 = run_ours(2, e2);
  const auto& a = e1.reference_to_approximation;
  const auto& b = e1.approximation_to_reference;
  auto np1 = CGAL::parameters::number_of_points_on_faces(a.face_samples)
                 .number_of_points_on_edges(a.edge_samples)
                 .random_seed(1);
  auto np2 = CGAL::parameters::number_of_points_on_faces(b.face_samples)
                 .number_of_points_on_edges(b.edge_samples)
                 .random_seed(1);
  namespace PMP = CGAL::Polygon_mesh_processing;
  auto run_cgal = [&](auto tag, double& h) {
    return cmgeom_bench::time_runs(
        reps, [&] { h = PMP::approximate_symmetric_Hausdorff_distance<decltype(tag)>(ref, app, np1, np2); });
  };
  double hs = 0, hp = 0;
  const cmgeom_bench::Timing ts = run_cgal(CGAL::Sequential_tag(), hs);
  const cmgeom_bench::Timing tp = run_cgal(CGAL::Parallel_if_available_tag(), hp);
  const double n = double(e1.samples);
  // "min / median" seconds, then the samples per second of the median run
  auto cell = [&](const cmgeom_bench::Timing& t) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%s s (%.2f M/s)", cmgeom_bench::min_median(t, "%.3f").c_str(), n / t.median / 1e6);
    return std::string(buf);
  };
  std::printf("| %s | %zu | %.0f | %s | %s | %.2fx | %s | %s | %.4g / %.4g / %.4g |\n", name.c_str(),
              ref.number_of_faces(), n, cell(t1).c_str(), cell(t2).c_str(), t1.median / t2.median, cell(ts).c_str(),
              cell(tp).c_str(), e1.hausdorff * e1.diagonal, hs, hp);
  if (e1.hausdorff != e2.hausdorff || e1.rms != e2.rms) std::printf("| (1 and 2 threads disagree!) |\n");
}

}  // namespace

int main(int argc, char** argv) {
  const std::string data = argc > 1 ? argv[1] : CMGEOM_DATA_DIR;
  const int reps = argc > 2 ? std::max(1, std::atoi(argv[2])) : 3;
  if (!std::filesystem::exists(data + "/classic")) {
    std::fprintf(stderr, "shared data not found: %s\n", data.c_str());
    return 1;
  }
  std::printf("## Geometric error: samples per second (%d runs, both directions, trees included)\n\n", reps);
  std::printf("Times are \"min / median\" of the runs, M/s and the speed-up are of the medians.\n\n");
  std::printf(
      "| model | faces | samples | ours 1 thread | ours 2 threads | speed-up | CGAL sequential | CGAL parallel | "
      "Hausdorff ours / CGAL seq / CGAL par |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  bench_error("bunny (bunny.off)", data + "/classic/bunny.off", reps);
  bench_error("Stanford bunny", data + "/classic/stanford-bunny.obj.gz", reps);
  bench_error("armadillo", data + "/classic/armadillo.obj.gz", reps);
#ifdef CMGEOM_HAS_OSMESA
  namespace R = CMGeom::Rendering;
  const CMGeom::Textured_mesh nef = load(data + "/classic/nefertiti.obj.gz");
  R::Renderer renderer;
  double t0 = now();
  const R::Render_mesh rm = R::make_render_mesh(nef.mesh());
  const double t_flat = now() - t0;
  R::Render_options o;
  o.width = o.height = 1024;
  t0 = now();
  renderer.render(rm, o);  // the first picture pays for the shader JIT
  const double first = now() - t0;
  const cmgeom_bench::Timing t = cmgeom_bench::time_runs(reps, [&] { renderer.render(rm, o); });
  o.wireframe = true;
  const cmgeom_bench::Timing tw = cmgeom_bench::time_runs(reps, [&] { renderer.render(rm, o); });
  std::printf(
      "\n## Rendering (%s)\n\nLast two columns: \"min / median\" of the runs.\n\n"
      "| mesh | faces | make_render_mesh | first picture | picture 1024x1024 4x MSAA | with wireframe "
      "|\n|---|---|---|---|---|---|\n",
      renderer.description().c_str());
  std::printf("| Nefertiti | %zu | %.3f s | %.3f s | %s s | %s s |\n", nef.mesh().number_of_faces(), t_flat, first,
              cmgeom_bench::min_median(t, "%.3f").c_str(), cmgeom_bench::min_median(tw, "%.3f").c_str());
#else
  std::printf("\n(rendering not built: no OSMesa)\n");
#endif
  return 0;
}
