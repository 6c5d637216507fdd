// *Cages benchmark in the style of thesis Table 5.2 (never run by CTest): memory, bind time and
// deform time per frame of a Cage_system (grid systems 2x1x1, 2x2x1, 3x3x3 around shared models,
// and the twisted prism of Fig. 5.6 in 4 stacked cages) against one cage that is the union of the
// cages (same surface vertices), for h in {1, 0.6, 0.5, 0.2} (0.5: the targets of the issue), mean value and Green
// coordinates (cage and join transformations: the join cages always use mean value coordinates), 1 and 2 threads.
// Prints Markdown.
//
//   bench_Cage_system [--quick] [data dir]       tables
//   bench_Cage_system --write-prism <dir>         writes prism.obj and the cage systems of the
//                                                 Fig. 5.6 pictures (doc/Cage_deformation)
#include <CMGeom/Cage_deformation.h>

#include "cmgeom_test_config.h"
#include "cmgeom_bench_support.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

using namespace CMGeom::Cage_deformation;
namespace CDI = CMGeom::Cage_deformation::internal;

namespace {

// Surface of the box [-0.5, 0.5]^2 x [0, 4] as a watertight triangle mesh on an a x a x c lattice.
void prism_mesh(int a, int c, std::vector<Vec3>& pts, std::vector<std::array<std::uint32_t, 3>>& tris) {
  const int n[3] = {a, a, c};
  std::map<std::array<int, 3>, std::uint32_t> id;
  auto vertex = [&](std::array<int, 3> q) {
    auto [it, fresh] = id.emplace(q, std::uint32_t(pts.size()));
    if (fresh) pts.push_back({-0.5 + double(q[0]) / a, -0.5 + double(q[1]) / a, 4.0 * q[2] / c});
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (int i = 0; i < n[u]; ++i)
        for (int j = 0; j < n[v]; ++j) {
          std::array<int, 3> p0{}, p1{}, p2{}, p3{};
          p0[axis] = p1[axis] = p2[axis] = p3[axis] = side * n[axis];
          p0[u] = i, p0[v] = j;
          p1[u] = i + 1, p1[v] = j;
          p2[u] = i + 1, p2[v] = j + 1;
          p3[u] = i, p3[v] = j + 1;
          std::uint32_t q[4] = {vertex(p0), vertex(p1), vertex(p2), vertex(p3)};
          if (side == 0) std::swap(q[1], q[3]);  // (u, v, axis) right-handed: flip on the low side
          tris.push_back({q[0], q[1], q[2]});
          tris.push_back({q[0], q[2], q[3]});
        }
    }
}

// Rotation about the prism axis by an angle growing with height: the cage vertex levels z_k
// (k = 0..4) turn by k * step (our reading of Fig. 5.6, "each cage level is rotated").
Vec3 twist(const Vec3& p, double zmin, double zmax, double total) {
  const double t = total * (p[2] - zmin) / (zmax - zmin);
  const double c = std::cos(t), s = std::sin(t);
  return {c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]};
}

// The *Cages system of the prism (4 stacked cages) and the single union cage, both twisted.
void prism_systems(const std::vector<Vec3>& pts, Coordinate_type type, double h, double total,
                   Cage_system_description& stars, Cage_system_description& single) {
  stars = make_grid_cage_system(pts, 1, 1, 4, 0.02, type, h);
  double zmin = 1e300, zmax = -1e300;
  for (const auto& c : stars.cages)
    for (const Vec3& v : c.rest.vertices) {
      zmin = std::min(zmin, v[2]);
      zmax = std::max(zmax, v[2]);
    }
  for (auto& c : stars.cages)
    for (std::size_t k = 0; k < c.deformed.size(); ++k) c.deformed[k] = twist(c.rest.vertices[k], zmin, zmax, total);
  single = Cage_system_description();
  Cage_description u;
  u.name = "union";
  u.rest = Cage_system(stars).union_cage();
  validate_cage(u.rest, "union cage", Cage_orientation::require_outward);
  for (const Vec3& v : u.rest.vertices) u.deformed.push_back(twist(v, zmin, zmax, total));
  u.coordinates = type;
  single.cages.push_back(u);
}

// A smooth non-affine pose of the grid cages (timings do not depend on it).
void bend_all(Cage_system_description& d) {
  double L = 0;
  for (const auto& c : d.cages) L = std::max(L, c.rest.bbox_diagonal());
  for (auto& c : d.cages)
    for (std::size_t k = 0; k < c.deformed.size(); ++k) {
      const Vec3& p = c.rest.vertices[k];
      c.deformed[k] = {p[0] + 0.05 * L * std::sin(3 * p[1] / L + 2 * p[2] / L),
                       p[1] + 0.05 * L * std::cos(2 * p[2] / L + 3 * p[0] / L),
                       p[2] + 0.05 * L * std::sin(4 * p[0] / L)};
    }
}

int g_runs = 3;  // repetitions of the set-up, the binding and the 20-frame deformation batch

struct Timing {
  cmgeom_bench::Timing setup, bind, deform;  // deform: per frame
  std::size_t bytes = 0, joined = 0;
  std::vector<Vec3> out;
};

// Seconds per frame: minimum and median over g_runs batches of `frames` frames.
cmgeom_bench::Timing time_deform(const std::function<void()>& f, int frames) {
  return cmgeom_bench::time_runs(g_runs,
                                 [&] {
                                   for (int i = 0; i < frames; ++i) f();
                                 })
      .scaled(1.0 / frames);
}

Timing run_stars(const Cage_system_description& d, const std::vector<Vec3>& pts, int threads) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  Timing t;
  std::optional<Cage_system> sys;
  t.setup = cmgeom_bench::time_runs(g_runs, [&] { sys.emplace(d); });
  const Cage_system& s = *sys;
  std::optional<Cage_system_binding<double>> bound;
  t.bind = cmgeom_bench::time_runs(g_runs, [&] { bound.emplace(s.bind(pts)); });
  const Cage_system_binding<double>& b = *bound;
  t.bytes = b.weights_bytes();
  t.joined = b.joined_points();
  // Per frame: propagate the cage poses, build the global basis, one sparse product.
  std::vector<std::vector<Vec3>> poses;
  for (const auto& c : d.cages) poses.push_back(c.deformed);
  t.deform = time_deform([&] { b.deform(s.basis(s.deformed_leaf_vertices(poses)), t.out); }, 20);
  return t;
}

Timing run_single(const Cage_description& c, const std::vector<Vec3>& pts, int threads) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  Timing t;
  std::optional<Any_cage_coordinates> made;
  t.setup = cmgeom_bench::time_runs(g_runs, [&] { made.emplace(make_cage_coordinates(c.coordinates, c.rest)); });
  const Any_cage_coordinates& coords = *made;
  std::optional<Cage_binding<double>> bound;
  t.bind = cmgeom_bench::time_runs(g_runs, [&] { bound.emplace(bind_points(coords, pts)); });
  const Cage_binding<double>& b = *bound;
  t.bytes = b.weights_bytes();
  std::vector<Vec3> basis;
  t.deform = time_deform(
      [&] {
        coords.basis(c.deformed, basis);
        b.deform(basis, t.out);
      },
      20);
  return t;
}

struct Case {
  std::string model;
  std::vector<Vec3> pts;
  int grid[3];
  bool prism;
};

void write_obj(const std::string& path, const std::vector<Vec3>& pts,
               const std::vector<std::array<std::uint32_t, 3>>& tris) {
  std::ofstream o(path);
  o.precision(17);
  for (const Vec3& p : pts) o << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
  for (const auto& t : tris) o << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string data = CMGEOM_DATA_DIR, prism_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else if (a == "--write-prism" && i + 1 < argc)
      prism_dir = argv[++i];
    else
      data = a;
  }
  const double total_twist = 3.14159265358979323846 / 2;
  std::vector<Vec3> prism;
  std::vector<std::array<std::uint32_t, 3>> prism_tris;
  prism_mesh(32, 128, prism, prism_tris);  // 18,434 vertices
  if (!prism_dir.empty()) {
    std::filesystem::create_directories(prism_dir);
    std::vector<Vec3> small;
    std::vector<std::array<std::uint32_t, 3>> small_tris;
    prism_mesh(16, 64, small, small_tris);
    write_obj(prism_dir + "/prism.obj", small, small_tris);
    for (Coordinate_type t : {Coordinate_type::mean_value, Coordinate_type::green}) {
      Cage_system_description stars, single;
      prism_systems(small, t, 0.5, total_twist, stars, single);
      write_cage_system(prism_dir + "/prism_stars_" + to_string(t) + ".json", stars);
      write_cage_system(prism_dir + "/prism_single_" + to_string(t) + ".json", single);
    }
    std::printf("wrote %s/prism.obj (%zu vertices) and the cage systems\n", prism_dir.c_str(), small.size());
    return 0;
  }

  std::vector<Case> cases;
  cases.push_back({"prism (Fig. 5.6 twist)", prism, {1, 1, 4}, true});
  struct M {
    const char* name;
    const char* path;
  };
  const std::string tmp = CMGEOM_TEST_TMP_DIR;
  for (const M& m : {M{"FireHydrant", "cages/qmvc/FireHydrant.obj.gz"},
                     M{"armadilloman", "cages/pgc/armadilloman/armadilloman.obj"}}) {
    const std::string file = cmgeom_bench::readable_model(data + "/" + m.path, tmp, "bench_cages_");
    if (file.empty()) continue;
    std::vector<Vec3> pts;
    std::vector<std::vector<std::uint32_t>> polys;
    try {
      read_polygons(file, pts, polys);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "skipping %s: %s\n", m.name, e.what());
      continue;
    }
    for (const auto& g : {std::array<int, 3>{2, 1, 1}, std::array<int, 3>{2, 2, 1}, std::array<int, 3>{3, 3, 3}})
      cases.push_back({m.name, pts, {g[0], g[1], g[2]}, false});
    if (quick) break;
  }

  std::printf("## *Cages (Cage_system) benchmark\n\n");
  {
    std::ifstream la("/proc/loadavg");
    std::string l;
    std::getline(la, l);
    std::printf("Load average at start: %s\n\n", l.c_str());
  }
  std::printf(
      "*Cages: memory = grouped sparse weights (double values, column patterns stored once per "
      "group of rows, point indices or runs), "
      "*setup* = system construction (borders, join cages), *bind* = coordinates of every "
      "vertex, *deform* = one frame (hierarchy propagation + basis + grouped product), per "
      "frame of a batch of 20. Times are \"min / median\" of %d runs (of the set-up, of the "
      "binding, of the 20-frame batch); *mem x* and *deform x* use the medians. *single*: one cage that is the union "
      "of the cages (the same "
      "surface vertices), dense double weights. *joined* = vertices with d_i < 1 (join data stored). "
      "*mem x*, *deform x* = *Cages / single. "
      "*err* = max / RMS distance between the *Cages and single-cage results, relative to "
      "the bounding-box diagonal of the cages.\n\n",
      g_runs);
  std::printf(
      "| model | cages | coords | h | thr | vertices | joined | *Cages MB | single MB | setup ms | "
      "*Cages bind ms | single bind ms | *Cages deform ms | single deform ms | mem x | deform x | err max / RMS |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Case& c : cases) {
    for (Coordinate_type type : {Coordinate_type::mean_value, Coordinate_type::green}) {
      for (double h : {1.0, 0.6, 0.5, 0.2}) {
        Cage_system_description stars, single;
        if (c.prism) {
          prism_systems(c.pts, type, h, total_twist, stars, single);
        } else {
          stars = make_grid_cage_system(c.pts, c.grid[0], c.grid[1], c.grid[2], 0.05, type, h);
          bend_all(stars);
          const Cage_system s(stars);
          Cage_description u;
          u.rest = s.union_cage();
          validate_cage(u.rest, "union cage", Cage_orientation::require_outward);
          const std::vector<Vec3> leaf = s.deformed_leaf_vertices();
          // union_cage() vertices are leaf vertices: map them back by rest position.
          std::map<Vec3, std::size_t> gid;
          for (std::size_t v = 0; v < s.leaf_vertices().size(); ++v) gid[s.leaf_vertices()[v]] = v;
          for (const Vec3& p : u.rest.vertices) u.deformed.push_back(leaf[gid.at(p)]);
          u.coordinates = type;
          single.cages.push_back(u);
        }
        const double L = single.cages[0].rest.bbox_diagonal();
        for (int threads : {1, 2}) {
          const Timing a = run_stars(stars, c.pts, threads);
          const Timing b = run_single(single.cages[0], c.pts, threads);
          double emax = 0, esum = 0;
          for (std::size_t i = 0; i < c.pts.size(); ++i) {
            const double e = CDI::norm(CDI::sub(a.out[i], b.out[i])) / L;
            emax = std::max(emax, e);
            esum += e * e;
          }
          const auto ms = [](const cmgeom_bench::Timing& t, const char* f) {
            return cmgeom_bench::min_median(t.scaled(1e3), f);
          };
          std::printf(
              "| %s | %dx%dx%d | %s | %.1f | %d | %zu | %zu | %.2f | %.2f | %s | %s | %s | %s | %s | %.4f | %.2f | "
              "%.2g / %.2g |\n",
              c.model.c_str(), c.grid[0], c.grid[1], c.grid[2], type == Coordinate_type::green ? "Green" : "MVC", h,
              threads, c.pts.size(), a.joined, a.bytes / 1048576.0, b.bytes / 1048576.0, ms(a.setup, "%.1f").c_str(),
              ms(a.bind, "%.1f").c_str(), ms(b.bind, "%.1f").c_str(), ms(a.deform, "%.3f").c_str(),
              ms(b.deform, "%.3f").c_str(), double(a.bytes) / double(b.bytes), a.deform.median / b.deform.median, emax,
              std::sqrt(esum / double(c.pts.size())));
          std::fflush(stdout);
        }
      }
    }
  }
  return 0;
}
