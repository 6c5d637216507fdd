// Benchmark of the Compact_model package (thesis chapter 4, Table 4.1 style): for each model,
// CM build time and bytes, reconstruction time and output vertices/s at levels 1-3 (projection
// along N and closest point), Metro error (Hausdorff and RMS, % of the bounding-box diagonal)
// against the original; side by side with the plain simplified mesh of equal storage in bytes
// (float32 coordinates + uint32 indices, 12 V + 12 F bytes) and with PN triangles (Vlachos et al.
// 2001) on the same base, same level. Each model is built three times: with the thesis' independent
// local fits (fit `thesis`), with CMGeom's joint refit (fit `joint`, Build_options::joint_fit), and
// with the joint refit, cubic surfaces and error control at level 3 with a bound of 0.3 % of the
// diagonal (fit `joint+cubic+ec`), and by build_selected_compact_model() with its default
// candidates measured at level 3 (fit `selected`: what `cmgeom cm build` does by default; its build
// time includes the candidates' builds and measures).
// Prints a Markdown table. Never run by CTest.
//
// Usage: bench_compact_model [data_dir] [model:faces ...]   (default: the six models below)
//        bench_compact_model --adaptive [data_dir] [model:faces ...]
// The second form compares, at equal output vertex counts, the regular reconstruction of levels
// 2-4 with the adaptive one driven by Chord_error_criterion (error_criterion.h: the tolerance
// chosen by reconstruct_to_vertex_budget for the regular level's vertex count, at most 3 more
// halvings) and with the length criterion of §4.5.2 (its threshold bisected to the same budget);
// the CM is built with the default Build_options. Beside them, the adaptive output placed by the
// model's level error table (level_errors.h, measured to depth 5 against the input; the measure's
// time and the table's bytes in a version 2 / version 3 file) for the same budget, at most level 5.
// Environment: CMGEOM_CM_CONE_RATIO overrides Build_options::cone_error_ratio.
#include <CMGeom/Compact_model.h>
#include <CMGeom/Compact_model/error_criterion.h>
#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/level_errors.h>
#include <CMGeom/Compact_model/select_compact_model.h>
#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>

#include <random>
#include <CMGeom/Mesh_IO/mesh_io.h>

#include "cmgeom_bench_support.h"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

namespace CM = CMGeom::CM;
using CM::Vec3;
constexpr int reconstruction_runs = 5;
constexpr int build_runs = 3;  // a build takes up to seconds

struct Model {
  std::string file;
  std::size_t base_faces;
};

// PN triangle (cubic Bezier patch from corner positions and normals) evaluated on the regular
// level-L grid of every base face; per-corner normals are the CM's frame normals of the corner,
// so creases open (PN triangles have no crease handling) -- the baseline the issue compares to.
CMGeom::Surface_mesh pn_triangles(const CM::Compact_model& m, int level) {
  using CM::internal::dot;
  const int n = 1 << level;
  CMGeom::Surface_mesh out;
  for (const auto& F : m.faces) {
    Vec3 P[3], N[3];
    for (int k = 0; k < 3; ++k) {
      P[k] = m.vertices[F[k].vertex];
      const CM::Local_frame fr = m.frame(F[k]);
      N[k] = CM::surface_normal(fr, m.surfaces[F[k].surface], 0, 0);
    }
    auto w = [&](int i, int j) { return dot(P[j] - P[i], N[i]); };
    const Vec3 b300 = P[0], b030 = P[1], b003 = P[2];
    const Vec3 b210 = (2 * P[0] + P[1] - w(0, 1) * N[0]) * (1. / 3),
               b120 = (2 * P[1] + P[0] - w(1, 0) * N[1]) * (1. / 3);
    const Vec3 b021 = (2 * P[1] + P[2] - w(1, 2) * N[1]) * (1. / 3),
               b012 = (2 * P[2] + P[1] - w(2, 1) * N[2]) * (1. / 3);
    const Vec3 b102 = (2 * P[2] + P[0] - w(2, 0) * N[2]) * (1. / 3),
               b201 = (2 * P[0] + P[2] - w(0, 2) * N[0]) * (1. / 3);
    const Vec3 E = (b210 + b120 + b021 + b012 + b102 + b201) * (1. / 6), V = (P[0] + P[1] + P[2]) * (1. / 3);
    const Vec3 b111 = E + 0.5 * (E - V);
    std::vector<CMGeom::Surface_mesh::Vertex_index> id;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i + j <= n; ++i) {
        const double v = double(i) / n, x = double(j) / n, u = 1 - v - x;  // weights of P0, P1, P2
        const Vec3 p = b300 * (u * u * u) + b030 * (v * v * v) + b003 * (x * x * x) + b210 * (3 * u * u * v) +
                       b120 * (3 * u * v * v) + b201 * (3 * u * u * x) + b021 * (3 * v * v * x) +
                       b102 * (3 * u * x * x) + b012 * (3 * v * x * x) + b111 * (6 * u * v * x);
        id.push_back(out.add_vertex(CMGeom::Point_3(p.x, p.y, p.z)));
      }
    auto at = [&](int i, int j) { return id[std::size_t(j * (n + 1) - j * (j - 1) / 2 + i)]; };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        out.add_face(at(i, j), at(i + 1, j), at(i, j + 1));
        if (i + j + 2 <= n) out.add_face(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
      }
  }
  return out;
}

// Metro-style symmetric error (thesis §2.3.2.2): every vertex plus 10 x F area-uniform random
// samples of each mesh measured against the other with an AABB tree; Hausdorff = max, RMS over
// the pooled samples, both as fractions of the reference's bounding-box diagonal. (Self-contained
// so that the benchmark does not depend on the Metrics package's build state.)
struct Error {
  double hausdorff = 0, rms = 0;
};
Error metro(const CMGeom::Surface_mesh& ref, const CMGeom::Surface_mesh& app) {
  using Mesh = CMGeom::Surface_mesh;
  using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<CMGeom::Kernel, Primitive>>;
  double mx = 0, sum = 0;
  std::size_t n = 0;
  std::mt19937_64 rng(20110101);
  std::uniform_real_distribution<double> u(0, 1);
  for (int side = 0; side < 2; ++side) {
    const Mesh& from = side ? app : ref;
    const Mesh& to = side ? ref : app;
    Tree tree(faces(to).first, faces(to).second, to);
    tree.accelerate_distance_queries();
    std::vector<CMGeom::Point_3> samples;
    for (auto v : from.vertices()) samples.push_back(from.point(v));
    std::vector<double> cumulative;
    std::vector<std::array<CMGeom::Point_3, 3>> tris;
    double area = 0;
    for (auto f : from.faces()) {
      auto h = from.halfedge(f);
      const std::array<CMGeom::Point_3, 3> t = {from.point(from.source(h)), from.point(from.target(h)),
                                                from.point(from.target(from.next(h)))};
      area += std::sqrt(CGAL::to_double(CGAL::squared_area(t[0], t[1], t[2])));
      cumulative.push_back(area);
      tris.push_back(t);
    }
    const std::size_t count = 10 * std::max(ref.number_of_faces(), app.number_of_faces());
    for (std::size_t i = 0; i < count && area > 0; ++i) {
      const std::size_t f =
          std::size_t(std::lower_bound(cumulative.begin(), cumulative.end(), u(rng) * area) - cumulative.begin());
      const auto& t = tris[std::min(f, tris.size() - 1)];
      double a = u(rng), b = u(rng);
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      samples.push_back(CGAL::barycenter(t[0], 1 - a - b, t[1], a, t[2], b));
    }
    for (const auto& p : samples) {
      const double d2 = CGAL::to_double(tree.squared_distance(p));
      mx = std::max(mx, d2);
      sum += d2;
      ++n;
    }
  }
  const double diag = cmgeom_bench::diagonal(CGAL::Polygon_mesh_processing::bbox(ref));
  return {std::sqrt(mx) / diag, std::sqrt(sum / double(n)) / diag};
}

// Reads model `md` of the data directory (gunzipped into `tmp` when needed); false, with a line on
// stderr, when it is missing.
bool read_model(const std::string& data, const Model& md, const std::string& tmp, CMGeom::Textured_mesh& tm) {
  std::string path = data + "/" + md.file;
  if (!std::filesystem::exists(path)) {
    std::fprintf(stderr, "skipping %s (not found)\n", path.c_str());
    return false;
  }
  path = cmgeom_bench::readable_model(path, tmp);
  if (path.empty()) return false;
  CMGeom::IO::read_mesh(path, tm);
  return true;
}

// Regular against adaptive reconstructions at equal output vertex counts (see the file comment).
int adaptive_table(const std::string& data, const std::vector<Model>& models, const std::string& tmp) {
  constexpr int table_depth = 5;
  std::printf(
      "| model | base V/F | level | regular V | regular Hausdorff %% | regular RMS %% | chord-error V | tolerance %% | "
      "chord-error Hausdorff %% | chord-error RMS %% | length V | length Hausdorff %% | length RMS %% | table V | "
      "table Hausdorff %% | table RMS %% | table s | table bytes (v2 / v3) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Model& md : models) {
    CMGeom::Textured_mesh tm;
    if (!read_model(data, md, tmp, tm)) continue;
    const CMGeom::Surface_mesh& mesh = tm.mesh();
    const double diagonal = cmgeom_bench::diagonal(CGAL::Polygon_mesh_processing::bbox(mesh));
    const CM::Compact_model model = CM::build_compact_model(mesh, md.base_faces);
    CM::Reconstruction_options ro;
    ro.projection = CM::Projection::closest_point;
    CM::Compact_model tabled = model;
    const auto tm0 = std::chrono::steady_clock::now();
    CM::measure_level_errors(tabled, mesh, table_depth, ro);
    const double table_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tm0).count();
    const std::string name = std::filesystem::path(md.file).filename().string();
    CM::CM_file_parts parts;
    CM::compact_cm_bytes(tabled, CM::Compact_encoding(), &parts);
    const std::size_t table_v2 = CM::cm_bytes(tabled).size() - CM::cm_bytes(model).size();
    for (int level = 2; level <= 4; ++level) {
      const CM::Reconstruction reg = CM::reconstruct_regular(model, level, ro);
      const std::size_t budget = reg.points.size();
      const auto er = metro(mesh, CM::to_surface_mesh(reg));
      const CM::Vertex_budget_result ad = CM::reconstruct_to_vertex_budget(model, budget, level + 3, ro);
      const auto ea = metro(mesh, CM::to_surface_mesh(ad.reconstruction));
      // Length criterion at the same budget: bisection on log(length).
      double lo = 1e-6 * diagonal, hi = diagonal;
      CM::Reconstruction len;
      for (int i = 0; i < 30 && hi / lo > 1.0005; ++i) {
        const double mid = std::sqrt(lo * hi);
        CM::Reconstruction r = CM::reconstruct_adaptive(model, CM::Edge_length_criterion{mid}, level + 3, ro);
        if (r.points.size() <= budget) {
          hi = mid;
          if (r.points.size() > len.points.size()) len = std::move(r);
        } else {
          lo = mid;
        }
      }
      const auto el = metro(mesh, CM::to_surface_mesh(len));
      const CM::Vertex_budget_result tb = CM::reconstruct_to_vertex_budget(tabled, budget, table_depth, ro);
      const auto et = metro(mesh, CM::to_surface_mesh(tb.reconstruction));
      std::printf(
          "| %s | %zu/%zu | %d | %zu | %.3f | %.4f | %zu | %.4f | %.3f | %.4f | %zu | %.3f | %.4f | %zu | %.3f | %.4f "
          "| "
          "%.2f | %zu / %zu |\n",
          name.c_str(), model.vertices.size(), model.faces.size(), level, budget, 100 * er.hausdorff, 100 * er.rms,
          ad.reconstruction.points.size(), 100 * ad.tolerance / diagonal, 100 * ea.hausdorff, 100 * ea.rms,
          len.points.size(), 100 * el.hausdorff, 100 * el.rms, tb.reconstruction.points.size(), 100 * et.hausdorff,
          100 * et.rms, table_seconds, table_v2, parts.level_errors);
      std::fflush(stdout);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const bool adaptive = argc > 1 && std::string(argv[1]) == "--adaptive";
  if (adaptive) {
    --argc;
    ++argv;
  }
  const std::string data = argc > 1 ? argv[1] : CMGEOM_BENCH_DATA_DIR;
  std::vector<Model> models = {{"classic/fandisk.obj", 250},        {"classic/trim-star.off", 1000},
                               {"classic/camel.off", 1000},         {"classic/horse.ply", 1000},
                               {"classic/decimated-max.obj", 1000}, {"classic/igea.ply.gz", 2000}};
  if (argc > 2) {
    models.clear();
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      const auto c = a.rfind(':');
      models.push_back({a.substr(0, c), std::size_t(std::stoul(a.substr(c + 1)))});
    }
  }
  const std::string tmp = (std::filesystem::temp_directory_path() / "cmgeom_bench_cm").string();
  std::filesystem::create_directories(tmp);
  if (adaptive) return adaptive_table(data, models, tmp);
  std::printf("Threads: %d (TBB default concurrency)\n\n", tbb::info::default_concurrency());
  std::printf(
      "| model | fit | input V/F | base V/F | sharp | cones | build s min / median | CM bytes | level | rec s (normal) "
      "min / median "
      "| "
      "Mvert/s (normal) at min / median | rec s (closest) min / median | out V | CM Hausdorff %% | CM RMS %% | PN "
      "Hausdorff %% | PN RMS %% | plain F (equal bytes) | "
      "plain Hausdorff %% | plain RMS %% |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Model& md : models) {
    CMGeom::Textured_mesh tm;
    if (!read_model(data, md, tmp, tm)) continue;
    const CMGeom::Surface_mesh& mesh = tm.mesh();
    const double diagonal = cmgeom_bench::diagonal(CGAL::Polygon_mesh_processing::bbox(mesh));
    for (const char* fit : {"thesis", "joint", "joint+cubic+ec", "selected"}) {
      const bool controlled = std::string(fit) == "joint+cubic+ec";
      const bool selected = std::string(fit) == "selected";
      CM::Build_statistics st;
      CM::Build_options bo;
      bo.joint_fit = std::string(fit) != "thesis" && !selected;
      if (controlled) {
        bo.error_bound = 0.003 * diagonal;
        bo.error_control_level = 3;
        bo.error_control_rounds = 4;
      }
      if (const char* r = std::getenv("CMGEOM_CM_CONE_RATIO")) bo.cone_error_ratio = std::atof(r);
      CM::Compact_model model;
      std::string chosen;
      const cmgeom_bench::Timing build_t = cmgeom_bench::time_runs(build_runs, [&] {
        if (selected) {
          CM::Selection_result sr;
          model = CM::build_selected_compact_model(mesh, md.base_faces, bo, CM::Selection_options(), &sr, &st);
          chosen = sr.candidates[sr.chosen].configuration.name;
        } else {
          model = controlled ? CM::build_compact_model(mesh, md.base_faces, bo, CM::Cubic_surface_traits(),
                                                       CM::Weighted_quadric_simplifier(), &st)
                             : CM::build_compact_model(mesh, md.base_faces, bo, CM::Quadric_surface_traits(),
                                                       CM::Weighted_quadric_simplifier(), &st);
        }
      });
      const std::size_t bytes = CM::cm_bytes(model).size();
      // Plain mesh of equal bytes: 12 V + 12 F with F ~ 2 V on closed meshes -> F = bytes / 18.
      const std::size_t plain_faces = std::max<std::size_t>(4, bytes / 18);
      CMGeom::Surface_mesh plain = mesh;
      {
        namespace TS = CMGeom::Textured_simplification;
        TS::Area_weighted_quadric_policies<CMGeom::Surface_mesh> policy(plain);
        TS::Face_count_stop_predicate<CMGeom::Surface_mesh> stop(plain, plain_faces);
        TS::edge_collapse(plain, stop, CGAL::parameters::get_cost(policy).get_placement(policy));
        plain.collect_garbage();
      }
      const auto plain_err = metro(mesh, plain);
      const std::string name = std::filesystem::path(md.file).filename().string();
      for (int level = 1; level <= 3; ++level) {
        CM::Reconstruction_options ro;
        ro.projection = CM::Projection::along_normal;
        // Minimum and median of reconstruction_runs runs (the machine is shared).
        CM::Reconstruction rn, rc;
        const cmgeom_bench::Timing tn =
            cmgeom_bench::time_runs(reconstruction_runs, [&] { rn = CM::reconstruct_regular(model, level, ro); });
        ro.projection = CM::Projection::closest_point;
        const cmgeom_bench::Timing tc =
            cmgeom_bench::time_runs(reconstruction_runs, [&] { rc = CM::reconstruct_regular(model, level, ro); });
        const auto err = metro(mesh, CM::to_surface_mesh(rc));
        const auto pn = metro(mesh, pn_triangles(model, level));
        std::printf(
            "| %s | %s | %zu/%zu | %zu/%zu | %zu | %zu | %s | %zu | %d | %s | %s | %s | %zu | %.3f | %.4f | %.3f | "
            "%.4f | %zu | %.3f | %.4f |\n",
            name.c_str(), (selected ? "selected: " + chosen : std::string(fit)).c_str(), mesh.number_of_vertices(),
            mesh.number_of_faces(), st.base_vertices, st.base_faces, st.sharp_edges, st.cone_vertices,
            cmgeom_bench::min_median(build_t, "%.2f").c_str(), bytes, level, cmgeom_bench::min_median(tn).c_str(),
            cmgeom_bench::rate_min_median(double(rn.points.size()) / 1e6, tn).c_str(),
            cmgeom_bench::min_median(tc).c_str(), rc.points.size(), 100 * err.hausdorff, 100 * err.rms,
            100 * pn.hausdorff, 100 * pn.rms, plain.number_of_faces(), 100 * plain_err.hausdorff, 100 * plain_err.rms);
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
