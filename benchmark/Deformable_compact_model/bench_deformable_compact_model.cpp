// Deformable Compact Models against the alternatives (thesis Tables 6.1-6.3, Fig. 6.4): for each
// model and cage, the memory (mesh + stored coordinates) and the time per deformation of
//   (a) the original mesh deformed directly (coordinates of every vertex),
//   (b) the simplified base deformed directly,
//   (c) the CM reconstructed at level L once, then deformed (coordinates of every reconstructed
//       point; "CM reconstruction" in Fig. 6.4),
//   (d) the deformable CM at level L: base deformed, local maps, deformed reconstruction per
//       pose ("CM deformation" in Fig. 6.4), closest-point and along-N projections,
//   (e) the same with the rest reconstruction kept (Deformable_reconstruction): base deformed,
//       local maps, blend of the maps at every point (the cost model of §6.5),
// and the Metro error (Metrics package) of (b)-(e) against (a), in % of (a)'s diagonal.
// Memory: `mesh` = the geometry held (mesh, or CM file + kept rest points/normals/triangles),
// `coordinates` = the cage coordinates, `maps` = the local-deformation data (1-rings, inverses,
// maps, and for (e) the base edges and faces and the weight tables of the blend).
// Cages are made here from the model's bounding box: `box` = the box itself (8 vertices, mean
// value coordinates), `grid` = its surface cut in 4 x 4 x 4 cells (98 vertices, Green
// coordinates, K = 98 + 192), `system` = a *Cages grid of 3 x 2 x 2 box cells (Cage_system, mean
// value coordinates, joined with h = 0.6). The pose twists the cage by 40 degrees about the longest axis and
// bends it along the shortest, progressively from one end to the other.
// --write-cages dir writes <model>_<cage>_rest.obj, _deformed.obj and _system.json (for
// `cmgeom deform` / `cmgeom cm deform`).
#include <CMGeom/Cage_deformation.h>
#include <CMGeom/Compact_model.h>
#include <CMGeom/Deformable_compact_model.h>
#include <CMGeom/Deformable_compact_model/Cage_system_deformer.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <CMGeom/Metrics/approximation_error.h>

#include "cmgeom_bench_support.h"

#include <tbb/info.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace {

namespace CM = CMGeom::CM;
namespace CD = CMGeom::Cage_deformation;
namespace DCM = CMGeom::DCM;
namespace fs = std::filesystem;

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Bind and set-up times: minimum and median of `n` runs.
template <class F>
cmgeom_bench::Timing timed(int n, const F& f) {
  return cmgeom_bench::time_runs(n, f);
}

// Per-pose times: one pose first, untimed (it allocates the output that an animation then
// reuses, and brings the data into the caches), then minimum and median of `n` timed poses.
// Every method of a table is timed this way.
constexpr int timed_poses = 15;
template <class F>
cmgeom_bench::Timing timed_per_pose(int n, const F& f) {
  f();
  return cmgeom_bench::time_runs(n, f);
}

struct Box {
  CD::Vec3 lo, hi;
  int axis[3];  // longest, middle, shortest
};

Box box_of(const std::vector<CD::Vec3>& P) {
  Box b{P[0], P[0], {0, 1, 2}};
  for (const auto& p : P)
    for (int i = 0; i < 3; ++i) {
      b.lo[i] = std::min(b.lo[i], p[i]);
      b.hi[i] = std::max(b.hi[i], p[i]);
    }
  std::sort(b.axis, b.axis + 3, [&](int x, int y) { return b.hi[x] - b.lo[x] > b.hi[y] - b.lo[y]; });
  return b;
}

// Surface of the box (enlarged by 10%) cut in n^3 cells, quads oriented outwards.
void grid_cage(const Box& b, int n, std::vector<std::array<double, 3>>& P, std::vector<std::vector<std::uint32_t>>& Q) {
  std::map<std::array<int, 3>, std::uint32_t> index;
  auto vertex = [&](std::array<int, 3> g) {
    auto it = index.find(g);
    if (it != index.end()) return it->second;
    std::array<double, 3> p;
    for (int i = 0; i < 3; ++i) {
      const double c = 0.5 * (b.lo[i] + b.hi[i]), h = 0.55 * (b.hi[i] - b.lo[i]);
      p[i] = c + h * (-1. + 2. * g[i] / n);
    }
    P.push_back(p);
    return index[g] = std::uint32_t(P.size() - 1);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side <= 1; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          auto at = [&](int a, int c) {
            std::array<int, 3> g;
            g[axis] = side * n;
            g[u] = a;
            g[w] = c;
            return vertex(g);
          };
          if (side)
            Q.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
          else
            Q.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
        }
    }
}

// Twist about the longest axis and bend along the shortest, growing from one end (t = 0) to
// the other (t = 1).
CD::Vec3 pose(const Box& b, const CD::Vec3& p) {
  const int a = b.axis[0], m = b.axis[1], s = b.axis[2];
  const double L = b.hi[a] - b.lo[a];
  const double t = std::clamp((p[a] - (b.lo[a] - 0.05 * L)) / (1.1 * L), 0., 1.);
  const double th = 0.7 * t;  // 40 degrees at the far end
  const double cm = 0.5 * (b.lo[m] + b.hi[m]), cs = 0.5 * (b.lo[s] + b.hi[s]);
  const double y = p[m] - cm, z = p[s] - cs;
  CD::Vec3 q = p;
  q[m] = cm + std::cos(th) * y - std::sin(th) * z;
  q[s] = cs + std::sin(th) * y + std::cos(th) * z + 0.25 * L * t * t;
  return q;
}

void write_obj(const std::string& path, const std::vector<CD::Vec3>& P,
               const std::vector<std::vector<std::uint32_t>>& Q) {
  std::ofstream o(path);
  o.precision(17);
  for (const auto& p : P) o << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  for (const auto& q : Q) {
    o << 'f';
    for (auto i : q) o << ' ' << i + 1;
    o << '\n';
  }
}

// (T: a std::vector or a Reconstruction's CM::Output_array of triangles)
template <class Triangles>
CMGeom::Surface_mesh mesh_of(const std::vector<CD::Vec3>& P, const Triangles& T) {
  CMGeom::Surface_mesh m;
  for (const auto& p : P) m.add_vertex(CMGeom::Point_3(p[0], p[1], p[2]));
  for (const auto& t : T)
    m.add_face(CMGeom::Surface_mesh::Vertex_index(t[0]), CMGeom::Surface_mesh::Vertex_index(t[1]),
               CMGeom::Surface_mesh::Vertex_index(t[2]));
  return m;
}
template <class Points>
std::vector<CD::Vec3> to_cd(const Points& P) {
  std::vector<CD::Vec3> r;
  r.reserve(P.size());
  for (const auto& p : P) r.push_back({p.x, p.y, p.z});
  return r;
}

struct Row {
  std::string method;
  std::size_t points = 0, mesh_bytes = 0, coord_bytes = 0, other_bytes = 0;
  cmgeom_bench::Timing bind;  // minimum and median of three bindings
  double hausdorff = -1, rms = -1;
  cmgeom_bench::Timing per_deformation;
};

// One cage: coordinates, the basis of the pose, and the posed BaseDeformer of the deformable CM.
template <class Coords>
struct Single_cage_setup {
  Coords coords;
  std::vector<CD::Vec3> posed, basis_;
  Single_cage_setup(const Coords& c, const std::vector<CD::Vec3>& p) : coords(c), posed(p) {
    coords.deformation_rule()(posed, std::back_inserter(basis_));
  }
  std::size_t K() const { return coords.number_of_coordinates(); }
  CD::Cage_binding<double> bind(const std::vector<CD::Vec3>& pts) const { return CD::bind_points(coords, pts); }
  const std::vector<CD::Vec3>& basis() const { return basis_; }
  DCM::Cage_deformer<Coords> deformer() const {
    DCM::Cage_deformer<Coords> d(coords);
    d.set_pose(posed);
    return d;
  }
};

// A *Cages system (Cage_system, §5.3): sparse rows over the global basis, join where d_i < 1.
struct Cage_system_setup {
  const CD::Cage_system& sys;
  std::vector<std::vector<CD::Vec3>> pose;
  std::vector<CD::Vec3> basis_;
  Cage_system_setup(const CD::Cage_system& s, const std::vector<std::vector<CD::Vec3>>& p)
      : sys(s), pose(p), basis_(s.basis(s.deformed_leaf_vertices(p))) {}
  std::size_t K() const { return sys.number_of_coordinates(); }
  CD::Cage_system_binding<double> bind(const std::vector<CD::Vec3>& pts) const { return sys.bind<double>(pts); }
  const std::vector<CD::Vec3>& basis() const { return basis_; }
  DCM::Cage_system_deformer<> deformer() const {
    DCM::Cage_system_deformer<> d(sys);
    d.set_pose(pose);
    return d;
  }
};

template <class Setup>
void run(const std::string& name, const std::string& cage_name, const Setup& setup,
         const std::vector<CD::Vec3>& orig_pts, const std::vector<std::array<std::uint32_t, 3>>& orig_tris,
         const CM::Compact_model& model) {
  const std::size_t K = setup.K();
  const std::vector<CD::Vec3>& basis = setup.basis();
  std::vector<Row> rows;
  CMGeom::Metrics::Error_options eo;
  eo.vertex_field = false;
  // (a) direct
  Row a{"(a) original, direct"};
  a.points = orig_pts.size();
  a.mesh_bytes = orig_pts.size() * 24 + orig_tris.size() * 12;
  std::optional<decltype(setup.bind(orig_pts))> ba;
  a.bind = timed(3, [&] { ba.emplace(setup.bind(orig_pts)); });
  a.coord_bytes = ba->weights_bytes();
  std::vector<CD::Vec3> da;
  a.per_deformation = timed_per_pose(timed_poses, [&] { ba->deform(basis, da); });
  const CMGeom::Surface_mesh ref = mesh_of(da, orig_tris);
  rows.push_back(a);
  // (b) base
  {
    Row r{"(b) simplified base, direct"};
    const auto bp = to_cd(model.vertices);
    std::vector<std::array<std::uint32_t, 3>> bt;
    for (const auto& f : model.faces) bt.push_back({f[0].vertex, f[1].vertex, f[2].vertex});
    r.points = bp.size();
    r.mesh_bytes = bp.size() * 24 + bt.size() * 12;
    std::optional<decltype(setup.bind(bp))> bb;
    r.bind = timed(3, [&] { bb.emplace(setup.bind(bp)); });
    r.coord_bytes = bb->weights_bytes();
    std::vector<CD::Vec3> d;
    r.per_deformation = timed_per_pose(timed_poses, [&] { bb->deform(basis, d); });
    const auto e = CMGeom::Metrics::approximation_error(ref, mesh_of(d, bt), eo);
    r.hausdorff = 100 * e.hausdorff;
    r.rms = 100 * e.rms;
    rows.push_back(r);
  }
  const std::size_t cm_bytes = CM::cm_bytes(model).size();  // the CM file (float32)
  DCM::Deformable_compact_model dcm(model);
  for (int level : {1, 2}) {
    // (c) reconstruct once, then deform every reconstructed point.
    Row c{"(c) CM level " + std::to_string(level) + ", reconstruct then deform"};
    const CM::Reconstruction rec = CM::reconstruct_regular(model, level);
    const auto rp = to_cd(rec.points);
    c.points = rp.size();
    c.mesh_bytes = rp.size() * 24 + rec.triangles.size() * 12;
    std::optional<decltype(setup.bind(rp))> bc;
    c.bind = timed(3, [&] { bc.emplace(setup.bind(rp)); });
    c.coord_bytes = bc->weights_bytes();
    std::vector<CD::Vec3> dc;
    c.per_deformation = timed_per_pose(timed_poses, [&] { bc->deform(basis, dc); });
    const auto ec = CMGeom::Metrics::approximation_error(ref, mesh_of(dc, rec.triangles), eo);
    c.hausdorff = 100 * ec.hausdorff;
    c.rms = 100 * ec.rms;
    rows.push_back(c);
    // (d) deformable CM: only the base is bound.
    for (CM::Projection proj : {CM::Projection::closest_point, CM::Projection::along_normal}) {
      Row d{"(d) deformable CM level " + std::to_string(level) +
            (proj == CM::Projection::closest_point ? "" : ", projection along N")};
      auto cd = setup.deformer();
      CM::Reconstruction_options ro;
      ro.projection = proj;
      ro.vertex_maps = &dcm.vertex_maps();  // the reconstructor keeps the blend's tables
      // Bind: the base's binding and the reconstructor (topology, frames, tables of the level).
      std::optional<CM::Regular_reconstructor<>> rc;
      d.bind = timed(3, [&] {
        cd.bind(dcm.base_vertices());
        rc.emplace(model, level, ro);
      });
      d.coord_bytes = cd.weights_bytes();
      d.other_bytes = dcm.bytes() + rc->bytes();
      d.mesh_bytes = cm_bytes;
      CM::Reconstruction out;
      dcm.reconstruct_regular(*rc, out, ro);  // the triangles, base faces and uvs, once
      d.per_deformation = timed_per_pose(timed_poses, [&] {
        dcm.deform(cd);
        dcm.reconstruct_regular_points(*rc, out, ro);
      });
      d.points = out.points.size();
      const auto ed = CMGeom::Metrics::approximation_error(ref, mesh_of(to_cd(out.points), out.triangles), eo);
      d.hausdorff = 100 * ed.hausdorff;
      d.rms = 100 * ed.rms;
      rows.push_back(d);
    }
    // (e) deformable CM with the rest reconstruction kept (Deformable_reconstruction): a pose
    // costs the base deformation, the local maps and the blend of the maps at every point.
    {
      Row e{"(e) deformable CM level " + std::to_string(level) + ", rest reconstruction kept"};
      auto cd = setup.deformer();
      std::optional<DCM::Deformable_reconstruction> kept;
      e.bind = timed(3, [&] {
        cd.bind(dcm.base_vertices());
        kept.emplace(model, level);
      });
      const DCM::Deformable_reconstruction& cache = *kept;
      e.coord_bytes = cd.weights_bytes();
      e.other_bytes = dcm.bytes() + cache.bytes() - cache.number_of_points() * 2 * sizeof(CM::Vec3);
      e.mesh_bytes = cm_bytes + cache.number_of_points() * 2 * sizeof(CM::Vec3) + rec.triangles.size() * 12;
      CM::Reconstruction out;
      e.per_deformation = timed_per_pose(timed_poses, [&] {
        dcm.deform(cd);
        cache.deform(dcm, out);
      });
      e.points = out.points.size();
      const auto ee = CMGeom::Metrics::approximation_error(ref, mesh_of(to_cd(out.points), out.triangles), eo);
      e.hausdorff = 100 * ee.hausdorff;
      e.rms = 100 * ee.rms;
      rows.push_back(e);
    }
  }
  for (const Row& r : rows) {
    std::printf("| %s | %s (K=%zu) | %s | %zu | %.3f | %.3f | %.3f | %s | %s | %.2f |", name.c_str(), cage_name.c_str(),
                K, r.method.c_str(), r.points, r.mesh_bytes / 1e6, r.coord_bytes / 1e6, r.other_bytes / 1e6,
                cmgeom_bench::min_median(r.bind, "%.3f").c_str(),
                cmgeom_bench::min_median(r.per_deformation, "%.5f").c_str(),
                a.per_deformation.median / r.per_deformation.median);
    if (r.hausdorff >= 0)
      std::printf(" %.3f | %.4f |\n", r.hausdorff, r.rms);
    else
      std::printf(" - | - |\n");
    std::fflush(stdout);
  }
}

// The points and triangles of `mesh` as arrays (vertex indices as in the mesh, which has no
// removed elements after reading).
void flatten(const CMGeom::Surface_mesh& mesh, std::vector<CD::Vec3>& pts,
             std::vector<std::array<std::uint32_t, 3>>& tris) {
  for (auto v : mesh.vertices()) pts.push_back({mesh.point(v).x(), mesh.point(v).y(), mesh.point(v).z()});
  for (auto f : mesh.faces()) {
    std::array<std::uint32_t, 3> t;
    int k = 0;
    for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) t[k++] = std::uint32_t(v);
    tris.push_back(t);
  }
}

// --scale: a large mesh (e.g. igea subdivided once, >= 1M faces) posed by the lattice cage
// (grid 4 x 4 x 4, Green and mean value coordinates); the deformable CM with `base_faces` base
// faces reconstructed at `level` against the full mesh deformed by the same cage. Per pose: (a)
// every vertex of the mesh; (d) base deformed, local maps, the points and normals of the deformed
// reconstruction along N by a Regular_reconstructor made at binding (the output's triangles are
// written once); (e) base deformed, local maps, blend of the kept rest reconstruction. Memory:
// (a) mesh + coordinates of every vertex + posed points; (d) CM file + base coordinates + local-map data +
// reconstructor + output; (e) CM file + base coordinates + local-map data + output, and the kept rest
// points, normals and triangles, and the blend's tables.
void run_scale(const std::string& path, std::size_t base_faces, int level) {
  CMGeom::Textured_mesh tm;
  CMGeom::IO::read_mesh(path, tm);
  const CMGeom::Surface_mesh& mesh = tm.mesh();
  std::vector<CD::Vec3> pts;
  std::vector<std::array<std::uint32_t, 3>> tris;
  flatten(mesh, pts, tris);
  double t0 = now();
  const CM::Compact_model model = CM::build_compact_model(mesh, base_faces);
  const double build_s = now() - t0;
  const std::size_t cm_bytes = CM::cm_bytes(model).size();
  std::printf(
      "Scale: %s, %zu vertices, %zu faces; CM %zu base faces (build %.1f s, one run: not a figure of this table, file "
      "%.3f MB), level %d\n\n",
      fs::path(path).filename().string().c_str(), pts.size(), tris.size(), model.faces.size(), build_s, cm_bytes / 1e6,
      level);
  std::printf(
      "| cage | method | points | memory MB | bind s min / median | s per pose min / median | speed-up vs (a) "
      "(medians) | memory ratio (a)/row | Hausdorff %% vs (a) | RMS %% vs (a) |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
  const Box b = box_of(pts);
  std::vector<std::array<double, 3>> P;
  std::vector<std::vector<std::uint32_t>> Q;
  grid_cage(b, 4, P, Q);
  CD::Triangle_cage cage = CD::make_triangle_cage(P, Q);
  CD::validate_cage(cage, "lattice");
  std::vector<CD::Vec3> posed;
  for (const auto& p : cage.vertices) posed.push_back(pose(b, p));
  CMGeom::Metrics::Error_options eo;
  eo.vertex_field = false;
  eo.sample_edges = false;
  eo.samples = 2000000;
  auto one = [&](const std::string& cage_name, const auto& setup) {
    const auto& basis = setup.basis();
    // (a) every vertex.
    std::size_t a_bytes, a_K;
    cmgeom_bench::Timing a_bind, a_pose;
    std::vector<CD::Vec3> da;
    {
      std::optional<decltype(setup.bind(pts))> ba;
      a_bind = timed(3, [&] { ba.emplace(setup.bind(pts)); });  // emplace frees the previous binding first
      a_bytes = 2 * pts.size() * 24 + tris.size() * 12 + ba->weights_bytes();  // rest and posed points
      a_K = setup.K();
      a_pose = timed_per_pose(timed_poses, [&] { ba->deform(basis, da); });
    }  // the coordinates of every vertex are freed here
    const CMGeom::Surface_mesh ref = mesh_of(da, tris);
    std::printf("| %s (K=%zu) | (a) full mesh, direct | %zu | %.1f | %s | %s | 1.00 | 1.0 | - | - |\n",
                cage_name.c_str(), a_K, pts.size(), a_bytes / 1e6, cmgeom_bench::min_median(a_bind, "%.2f").c_str(),
                cmgeom_bench::min_median(a_pose).c_str());
    std::fflush(stdout);
    DCM::Deformable_compact_model dcm(model);
    auto cd = setup.deformer();
    CM::Reconstruction_options ro;
    ro.projection = CM::Projection::along_normal;
    ro.vertex_maps = &dcm.vertex_maps();  // the reconstructor keeps the blend's tables
    // Bind of (d): the base's binding and the reconstructor (topology, frames, tables of the level).
    std::optional<CM::Regular_reconstructor<>> rc;
    const cmgeom_bench::Timing d_bind = timed(3, [&] {
      cd.bind(dcm.base_vertices());
      rc.emplace(model, level, ro);
    });
    const cmgeom_bench::Timing base_bind = timed(3, [&] { cd.bind(dcm.base_vertices()); });
    auto report = [&](const std::string& method, const CM::Reconstruction& out, std::size_t bytes,
                      const cmgeom_bench::Timing& bind, const cmgeom_bench::Timing& per_pose) {
      const auto e = CMGeom::Metrics::approximation_error(ref, mesh_of(to_cd(out.points), out.triangles), eo);
      std::printf("| %s (K=%zu) | %s | %zu | %.1f | %s | %s | %.2f | %.1f | %.3f | %.4f |\n", cage_name.c_str(), a_K,
                  method.c_str(), out.points.size(), bytes / 1e6, cmgeom_bench::min_median(bind, "%.2f").c_str(),
                  cmgeom_bench::min_median(per_pose).c_str(), a_pose.median / per_pose.median,
                  double(a_bytes) / double(bytes), 100 * e.hausdorff, 100 * e.rms);
      std::fflush(stdout);
    };
    {
      CM::Reconstruction out;
      dcm.reconstruct_regular(*rc, out, ro);  // the triangles, base faces and uvs, once
      const cmgeom_bench::Timing per_pose = timed_per_pose(timed_poses, [&] {
        dcm.deform(cd);
        dcm.reconstruct_regular_points(*rc, out, ro);
      });
      const std::size_t out_bytes = out.points.size() * 48 + out.triangles.size() * 16;
      report("(d) deformable CM level " + std::to_string(level) + ", along N", out,
             cm_bytes + cd.weights_bytes() + dcm.bytes() + rc->bytes() + out_bytes, d_bind, per_pose);
    }
    {
      // Bind: the base's binding, then the rest reconstruction kept (each min / median of 3, summed).
      std::optional<DCM::Deformable_reconstruction> kept;
      const cmgeom_bench::Timing keep = timed(3, [&] { kept.emplace(model, level); });
      const DCM::Deformable_reconstruction& cache = *kept;
      const cmgeom_bench::Timing bind{base_bind.min + keep.min, base_bind.median + keep.median, 3};
      CM::Reconstruction out;
      const cmgeom_bench::Timing per_pose = timed_per_pose(timed_poses, [&] {
        dcm.deform(cd);
        cache.deform(dcm, out);
      });
      const std::size_t out_bytes = out.points.size() * 48 + out.triangles.size() * 16;
      // cache.bytes(): rest points, normals, base edges and faces, weight tables; plus its triangles.
      report("(e) deformable CM level " + std::to_string(level) + ", rest reconstruction kept", out,
             cm_bytes + cd.weights_bytes() + dcm.bytes() + cache.bytes() + out.triangles.size() * 16 + out_bytes, bind,
             per_pose);
    }
  };
  one("lattice 4x4x4 Green", Single_cage_setup<CD::Green_coordinates_3>(CD::Green_coordinates_3(cage), posed));
  one("lattice 4x4x4 MVC", Single_cage_setup<CD::Mean_value_coordinates_3>(CD::Mean_value_coordinates_3(cage), posed));
}

}  // namespace

int main(int argc, char** argv) {
  std::string data = CMGEOM_BENCH_DATA_DIR, cage_dir;
  std::vector<std::string> cages = {"box", "grid", "system"};
  std::vector<std::pair<std::string, std::size_t>> models;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--scale" && i + 1 < argc) {  // --scale <mesh file>:<base faces>:<level>
      const std::string a = argv[++i];
      const auto c2 = a.rfind(':'), c1 = a.rfind(':', c2 - 1);
      std::printf("Threads: %d (TBB default concurrency)\n\n", tbb::info::default_concurrency());
      run_scale(a.substr(0, c1), std::stoul(a.substr(c1 + 1, c2 - c1 - 1)), std::stoi(a.substr(c2 + 1)));
      return 0;
    } else if (s == "--write-cages" && i + 1 < argc) {
      cage_dir = argv[++i];
    } else if (s == "--cages" && i + 1 < argc) {  // comma-separated subset of box,grid,system
      cages.clear();
      std::string list = argv[++i], item;
      for (std::size_t p = 0; p <= list.size(); ++p)
        if (p == list.size() || list[p] == ',') {
          cages.push_back(item);
          item.clear();
        } else {
          item += list[p];
        }
    } else if (s.find(':') != std::string::npos) {
      models.emplace_back(s.substr(0, s.find(':')), std::stoul(s.substr(s.find(':') + 1)));
    } else {
      data = s;
    }
  }
  if (models.empty()) models = {{"camel.off", 1000}, {"horse.ply", 2000}, {"igea.ply.gz", 4000}};
  const fs::path tmp = fs::temp_directory_path() / ("cmgeom_bench_dcm_" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  std::printf("Threads: %d (TBB default concurrency)\n\n", tbb::info::default_concurrency());
  std::printf(
      "| model | cage | method | points | mesh MB | coordinates MB | maps MB | bind s min / median | s per deformation "
      "min / median "
      "| "
      "speed-up vs (a) | Hausdorff %% vs (a) | RMS %% vs (a) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [file, base_faces] : models) {
    std::string path = (fs::path(data) / "classic" / file).string();
    if (!fs::exists(path)) {
      std::fprintf(stderr, "missing %s, skipped\n", path.c_str());
      continue;
    }
    path = cmgeom_bench::readable_model(path, tmp.string());
    if (path.empty()) return 1;
    const std::string name = fs::path(path).filename().string();
    CMGeom::Textured_mesh tm;
    CMGeom::IO::read_mesh(path, tm);
    const CMGeom::Surface_mesh& mesh = tm.mesh();
    std::vector<CD::Vec3> pts;
    std::vector<std::array<std::uint32_t, 3>> tris;
    flatten(mesh, pts, tris);
    const CM::Compact_model model = CM::build_compact_model(mesh, base_faces);
    const Box b = box_of(pts);
    for (const std::string& cage_name : cages) {
      if (cage_name == "system") {
        // *Cages: 3 x 2 x 2 box cells (mean value, joined, h = 0.6), the same pose on every cell.
        const CD::Cage_system sys(CD::make_grid_cage_system(pts, 3, 2, 2, 0.05, CD::Coordinate_type::mean_value, 0.6));
        std::vector<std::vector<CD::Vec3>> pose_of;
        for (const auto& c : sys.description().cages) {
          pose_of.emplace_back();
          for (const auto& v : c.rest.vertices) pose_of.back().push_back(pose(b, v));
        }
        run(name, "3x2x2 *Cages MVC", Cage_system_setup(sys, pose_of), pts, tris, model);
        continue;
      }
      std::vector<std::array<double, 3>> P;
      std::vector<std::vector<std::uint32_t>> Q;
      grid_cage(b, cage_name == "box" ? 1 : 4, P, Q);
      CD::Triangle_cage cage = CD::make_triangle_cage(P, Q);
      CD::validate_cage(cage, cage_name);
      std::vector<CD::Vec3> posed;
      for (const auto& p : cage.vertices) posed.push_back(pose(b, p));
      const std::string stem = fs::path(name).stem().string() + "_" + cage_name;
      if (!cage_dir.empty()) {
        fs::create_directories(cage_dir);
        write_obj((fs::path(cage_dir) / (stem + "_rest.obj")).string(), cage.vertices, Q);
        write_obj((fs::path(cage_dir) / (stem + "_deformed.obj")).string(), posed, Q);
        std::ofstream((fs::path(cage_dir) / (stem + "_system.json")).string())
            << "{\"cages\": [{\"rest\": \"" << stem << "_rest.obj\", \"deformed\": \"" << stem
            << "_deformed.obj\", \"coordinates\": \"" << (cage_name == "box" ? "mean_value" : "green") << "\"}]}\n";
      }
      if (cage_name == "box")
        run(name, cage_name + " MVC",
            Single_cage_setup<CD::Mean_value_coordinates_3>(CD::Mean_value_coordinates_3(cage), posed), pts, tris,
            model);
      else
        run(name, cage_name + " Green",
            Single_cage_setup<CD::Green_coordinates_3>(CD::Green_coordinates_3(cage), posed), pts, tris, model);
    }
  }
  fs::remove_all(tmp);
  return 0;
}
