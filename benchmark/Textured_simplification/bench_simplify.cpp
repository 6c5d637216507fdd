// Benchmark of the Textured_simplification geometry part (thesis §3.4): time and Metro-like error
// of CMGeom's weighted and plain quadric policies on CMGeom's engine and on CGAL's engine, against
// CGAL's GarlandHeckbert_plane_policies and Lindstrom-Turk, meshoptimizer's meshopt_simplify and
// OpenMesh's Decimater + ModQuadric. Prints one Markdown table (and writes it with --out).
//
//   bench_simplify [--data DIR] [--tmp DIR] [--models a,b,...] [--ratios 0.1,0.01]
//                  [--tools t1,t2,...] [--samples N] [--min-weight w] [--repeat R] [--out FILE]
//                  [--max-errors E1,E2,...]
//
// Models: bunny, armadillo, igea, nefertiti, max-planck, fandisk, ogre (shared/data/classic),
// igea-sub (igea after one 1-to-4 midpoint subdivision) and ogre-sub2 (ogre after two, as in
// shared/research/baselines-simplify.md); or any mesh file by its path under --data (a name with a
// '/', e.g. classic/horse.ply), named by its file name in the table. A file CGAL cannot read as a
// polygon mesh (e.g. one that needs repair) is skipped with a message.
//
// --max-errors: instead of the ratio table, the guaranteed-error table: for each model and bound
// E (fraction of the diagonal), `simplify_mesh` with `max_error` = E (CMGeom's defaults
// otherwise), its face count and measured Hausdorff H; then, for each peer of --tools (default
// cgal-gh, cgal-lt, meshopt, openmesh), the smallest face count found (bisection on the target
// count, to 3 %) at which the peer's measured Hausdorff is <= H.
//
// Timing: process CPU seconds of the simplification call alone (set-up of the policy included,
// mesh IO and format conversion excluded); with --repeat R each configuration runs R times and
// the minimum and the median time are reported, "min / median" (the outputs are deterministic;
// the ratios to GH and the input triangles per second use the medians). The R repetitions are interleaved
// (all tools once, then all tools again), and the last column is the median over repetitions of
// GH's time divided by the tool's time in the same repetition: a drift of the machine's load
// between repetitions cancels in it. Error: Metro convention —
// N uniform area samples (fixed seed) on each surface, distance to the other surface (AABB tree),
// symmetric Hausdorff = max of both directions over the samples and every vertex of each surface,
// RMS = the larger of the two directional RMS of the samples, both divided by the input's
// bounding-box diagonal.
#include <CMGeom/Textured_simplification.h>

#include "cmgeom_bench_support.h"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/GarlandHeckbert_plane_policies.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <CGAL/boost/graph/IO/polygon_mesh_io.h>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <limits>
#include <optional>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace TS = CMGeom::Textured_simplification;
namespace SMS = CGAL::Surface_mesh_simplification;
namespace fs = std::filesystem;
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using OMesh = OpenMesh::TriMesh_ArrayKernelT<>;

namespace {

double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// Flat arrays: the common input of every tool (built outside the timed region).
struct Soup {
  std::vector<float> xyz;
  std::vector<unsigned> tris;
};

Soup to_soup(const Mesh& m) {
  Soup s;
  std::vector<unsigned> id(m.number_of_vertices() + m.number_of_removed_vertices(), 0);
  unsigned k = 0;
  for (auto v : m.vertices()) {
    id[v] = k++;
    const Point& p = m.point(v);
    s.xyz.insert(s.xyz.end(), {float(p.x()), float(p.y()), float(p.z())});
  }
  for (auto f : m.faces())
    for (auto v : CGAL::vertices_around_face(m.halfedge(f), m)) s.tris.push_back(id[v]);
  return s;
}

Mesh from_indices(const Soup& s, const unsigned* tris, std::size_t n_idx) {
  Mesh m;
  std::vector<Mesh::Vertex_index> map(s.xyz.size() / 3, Mesh::null_vertex());
  for (std::size_t i = 0; i < n_idx; i += 3) {
    Mesh::Vertex_index v[3];
    for (int c = 0; c < 3; ++c) {
      const unsigned j = tris[i + c];
      if (map[j] == Mesh::null_vertex()) map[j] = m.add_vertex(Point(s.xyz[3 * j], s.xyz[3 * j + 1], s.xyz[3 * j + 2]));
      v[c] = map[j];
    }
    if (m.add_face(v[0], v[1], v[2]) == Mesh::null_face()) {
      // a face the halfedge structure cannot take (non-manifold output): it still counts in the
      // error computation, added as a separate triangle (its corners copied first: add_vertex may
      // move the points that m.point() refers to)
      const Point p0 = m.point(v[0]), p1 = m.point(v[1]), p2 = m.point(v[2]);
      const Mesh::Vertex_index a = m.add_vertex(p0), b = m.add_vertex(p1), c = m.add_vertex(p2);
      m.add_face(a, b, c);
    }
  }
  return m;
}

// Midpoint subdivision 1 -> 4 (the >= 1M-face input from igea).
Mesh subdivide_midpoint(const Mesh& in) {
  Mesh out;
  std::map<std::pair<unsigned, unsigned>, Mesh::Vertex_index> mid;
  std::vector<Mesh::Vertex_index> vmap(in.number_of_vertices() + in.number_of_removed_vertices());
  for (auto v : in.vertices()) vmap[v] = out.add_vertex(in.point(v));
  auto midpoint = [&](Mesh::Vertex_index a, Mesh::Vertex_index b) {
    // a pair of values: std::minmax returns references, which would dangle here
    const std::pair<unsigned, unsigned> key = std::minmax(unsigned(a), unsigned(b));
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    const auto v = out.add_vertex(CGAL::midpoint(in.point(a), in.point(b)));
    mid.emplace(key, v);
    return v;
  };
  for (auto f : in.faces()) {
    auto h = in.halfedge(f);
    const auto a = in.source(h), b = in.target(h), c = in.target(in.next(h));
    const auto ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    out.add_face(vmap[a], ab, ca);
    out.add_face(ab, vmap[b], bc);
    out.add_face(ca, bc, vmap[c]);
    out.add_face(ab, bc, ca);
  }
  return out;
}

class Distance {
public:
  using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_face_graph_triangle_primitive<Mesh>>>;
  explicit Distance(const Mesh& m) : tree_(faces(m).first, faces(m).second, m) { tree_.accelerate_distance_queries(); }
  double operator()(const Point& p) const { return std::sqrt(tree_.squared_distance(p)); }

private:
  Tree tree_;
};

std::vector<Point> samples(const Mesh& m, std::size_t n, unsigned seed) {
  std::vector<Mesh::Face_index> fs_;
  std::vector<double> cdf;
  double total = 0;
  for (auto f : m.faces()) {
    auto h = m.halfedge(f);
    const Point &a = m.point(m.source(h)), &b = m.point(m.target(h)), &c = m.point(m.target(m.next(h)));
    total += std::sqrt(CGAL::cross_product(b - a, c - a).squared_length()) / 2;
    fs_.push_back(f);
    cdf.push_back(total);
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0, 1);
  std::vector<Point> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k =
        std::min<std::size_t>(std::lower_bound(cdf.begin(), cdf.end(), U(rng) * total) - cdf.begin(), fs_.size() - 1);
    auto h = m.halfedge(fs_[k]);
    const Point &a = m.point(m.source(h)), &b = m.point(m.target(h)), &c = m.point(m.target(m.next(h)));
    double s = U(rng), t = U(rng);
    if (s + t > 1) {
      s = 1 - s;
      t = 1 - t;
    }
    out.push_back(a + s * (b - a) + t * (c - a));
  }
  return out;
}

struct Row {
  std::string model, tool;
  std::size_t faces_in = 0, target = 0, faces_out = 0;
  double ratio = 0, seconds = 0, hausdorff = 0, rms = 0;  // seconds: median of the repetitions
  double seconds_min = 0;
  double paired_speedup = 0;  // median over repetitions of (cgal-gh's time / this tool's time); 0: no GH
};

struct Model {
  std::string name;
  Mesh mesh;
  Soup soup;
  double diagonal = 0;
  std::vector<Point> samples;  // on the input
  std::unique_ptr<Distance> to_input;
};

void measure(const Model& in, const Mesh& out, std::size_t n_samples, Row& r) {
  // an output with a non-finite coordinate (a peer's placement can give one on degenerate
  // input) is infinitely far: reported as inf, never measured (the distance queries need
  // finite points)
  for (auto v : out.vertices()) {
    const Point& p = out.point(v);
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
      r.hausdorff = r.rms = std::numeric_limits<double>::infinity();
      return;
    }
  }
  Distance to_out(out);
  double mx = 0, s2 = 0;
  for (const Point& p : in.samples) {
    const double d = to_out(p);
    mx = std::max(mx, d);
    s2 += d * d;
  }
  double rms = std::sqrt(s2 / double(in.samples.size()));
  // the maxima also over every vertex of each mesh (where a spike or a vertex off the surface
  // puts them; area samples alone miss them: on ogre at 10 %, 100k samples gave 1.26e-3 where
  // 2M gave 1.62e-3); the RMS over the area samples alone
  for (auto v : in.mesh.vertices()) mx = std::max(mx, to_out(in.mesh.point(v)));
  double mx2 = 0, s22 = 0;
  const auto so = samples(out, n_samples, 1234567);
  for (const Point& p : so) {
    const double d = (*in.to_input)(p);
    mx2 = std::max(mx2, d);
    s22 += d * d;
  }
  for (auto v : out.vertices()) mx2 = std::max(mx2, (*in.to_input)(out.point(v)));
  const double rms2 = std::sqrt(s22 / double(so.size()));
  r.hausdorff = std::max(mx, mx2) / in.diagonal;
  r.rms = std::max(rms, rms2) / in.diagonal;
}

// ------------------------------------------------------------------------- the tools

// --min-weight: the floor of the weights (Quadric_options::min_weight) for CMGeom's weighted
// policies on CMGeom's engine; 0 keeps the default.
double g_min_weight = 0;

Mesh run_cmgeom(const Mesh& in, std::size_t target, bool weighted, bool flips, double& secs,
                TS::Quadric_merge merge = TS::Quadric_merge::weighted_average) {
  Mesh m = in;
  const double t0 = cpu_seconds();
  TS::Quadric_options o;
  o.weighted = weighted;
  o.merge = merge;
  if (g_min_weight > 0) o.min_weight = g_min_weight;
  TS::Area_weighted_quadric_policies<Mesh> policy(m, o);
  TS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, target),
                    CMGeom::parameters::edge_flips(flips, CGAL::parameters::get_cost(policy).get_placement(policy)));
  secs = cpu_seconds() - t0;
  m.collect_garbage();
  return m;
}

// What `cmgeom simplify` runs (simplify_mesh: plain quadrics, the memoryful cost, large inputs in
// parts on all cores, the final fit of the vertices); `parts` false: the whole mesh at once
// whatever its size; `fit` false: no final fit (--fit-rounds 0).
Mesh run_cmgeom_default(const Mesh& in, std::size_t target, bool parts, double& secs, bool fit = true,
                        bool flips = false, double gap_weight = 1.0, std::size_t max_points = 0) {
  Mesh m = in;
  const double t0 = cpu_seconds();
  TS::Mesh_simplification_options o;
  o.quadric.weighted = false;
  if (!parts) o.parts_min_faces = 0;
  if (!fit) o.memory.fit.rounds = 0;
  o.flips = flips;
  o.memory.vertex_gap_weight = gap_weight;
  o.memory.max_points = max_points;
  TS::simplify_mesh(m, target, o);
  secs = cpu_seconds() - t0;
  return m;
}

Mesh run_cmgeom_policy_on_cgal(const Mesh& in, std::size_t target, bool weighted, double& secs) {
  Mesh m = in;
  const double t0 = cpu_seconds();
  TS::Quadric_options o;
  o.weighted = weighted;
  TS::Area_weighted_quadric_policies<Mesh> policy(m, o);
  SMS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, target),
                     CGAL::parameters::get_cost(policy).get_placement(policy).filter(TS::No_normal_flip_filter<>()));
  secs = cpu_seconds() - t0;
  m.collect_garbage();
  return m;
}

Mesh run_cgal_gh(const Mesh& in, std::size_t target, double& secs) {
  Mesh m = in;
  const double t0 = cpu_seconds();
  SMS::GarlandHeckbert_plane_policies<Mesh, K> gh(m);
  SMS::edge_collapse(m, TS::Face_count_stop_predicate<Mesh>(m, target),
                     CGAL::parameters::get_cost(gh.get_cost()).get_placement(gh.get_placement()));
  secs = cpu_seconds() - t0;
  m.collect_garbage();
  return m;
}

// `cmgeom simplify --max-error E`: simplify_mesh with a guaranteed bound and no face target.
Mesh run_cmgeom_bounded(const Mesh& in, double max_error, double& secs, double& bound) {
  Mesh m = in;
  const double t0 = cpu_seconds();
  TS::Mesh_simplification_options o;
  o.max_error = max_error;
  const TS::Mesh_simplification_result r = TS::simplify_mesh(m, o);
  secs = cpu_seconds() - t0;
  bound = r.error_bound;
  return m;
}

Mesh run_cgal_lt(const Mesh& in, std::size_t target, double& secs) {
  Mesh m = in;
  const double t0 = cpu_seconds();
  SMS::edge_collapse(
      m, TS::Face_count_stop_predicate<Mesh>(m, target),
      CGAL::parameters::get_cost(SMS::LindstromTurk_cost<Mesh>()).get_placement(SMS::LindstromTurk_placement<Mesh>()));
  secs = cpu_seconds() - t0;
  m.collect_garbage();
  return m;
}

Mesh run_meshopt(const Soup& s, std::size_t target, double& secs) {
  std::vector<unsigned> dst(s.tris.size());
  const double t0 = cpu_seconds();
  const std::size_t n = meshopt_simplify(dst.data(), s.tris.data(), s.tris.size(), s.xyz.data(), s.xyz.size() / 3,
                                         3 * sizeof(float), 3 * target, 1e30f, 0, nullptr);
  secs = cpu_seconds() - t0;
  return from_indices(s, dst.data(), n);
}

Mesh run_openmesh(const Soup& s, std::size_t target, double& secs) {
  OMesh om;
  std::vector<OMesh::VertexHandle> vh;
  for (std::size_t i = 0; i < s.xyz.size(); i += 3)
    vh.push_back(om.add_vertex(OMesh::Point(s.xyz[i], s.xyz[i + 1], s.xyz[i + 2])));
  for (std::size_t i = 0; i < s.tris.size(); i += 3) om.add_face(vh[s.tris[i]], vh[s.tris[i + 1]], vh[s.tris[i + 2]]);
  const double t0 = cpu_seconds();
  OpenMesh::Decimater::DecimaterT<OMesh> dec(om);
  OpenMesh::Decimater::ModQuadricT<OMesh>::Handle hq;
  dec.add(hq);
  dec.initialize();
  dec.decimate_to_faces(0, target);
  secs = cpu_seconds() - t0;
  om.garbage_collection();
  Soup o;
  for (auto v : om.vertices()) {
    const auto p = om.point(v);
    o.xyz.insert(o.xyz.end(), {p[0], p[1], p[2]});
  }
  for (auto f : om.faces())
    for (auto v : om.fv_range(f)) o.tris.push_back(unsigned(v.idx()));
  return from_indices(o, o.tris.data(), o.tris.size());
}

// The tools by name (the default list and "cmgeom-plain-flips"). cmgeom-default is what
// `cmgeom simplify` does without options: plain quadrics and the memoryful cost (Surface_memory.h).
const char* const all_tools[] = {"cmgeom-default",
                                 "cmgeom-default-whole",
                                 "cmgeom-default-nofit",
                                 "cmgeom-default-flips",
                                 "cmgeom-default-nogap",
                                 "cmgeom-default-stride",
                                 "cmgeom-weighted",
                                 "cmgeom-weighted-sum",
                                 "cmgeom-plain",
                                 "cmgeom-weighted-flips",
                                 "cmgeom-plain-flips",
                                 "cgal-engine-weighted",
                                 "cgal-engine-plain",
                                 "cgal-gh",
                                 "cgal-lt",
                                 "meshopt",
                                 "openmesh"};

/// Runs `tool` once on `md` down to `target` faces; false if the name is not one of all_tools.
bool run_tool(const std::string& tool, const Model& md, std::size_t target, Mesh& out, double& secs) {
  if (tool == "cmgeom-default")
    out = run_cmgeom_default(md.mesh, target, true, secs);
  else if (tool == "cmgeom-default-whole")
    out = run_cmgeom_default(md.mesh, target, false, secs);
  else if (tool == "cmgeom-default-nofit")
    out = run_cmgeom_default(md.mesh, target, true, secs, false);
  else if (tool == "cmgeom-default-flips")
    out = run_cmgeom_default(md.mesh, target, true, secs, true, true);
  else if (tool == "cmgeom-default-nogap")
    out = run_cmgeom_default(md.mesh, target, true, secs, true, false, 0.0);
  else if (tool == "cmgeom-default-stride")  // at most 65,536 points: every k-th vertex of a larger input
    out = run_cmgeom_default(md.mesh, target, true, secs, true, false, 1.0, 65536);
  else if (tool == "cmgeom-weighted")
    out = run_cmgeom(md.mesh, target, true, false, secs);
  else if (tool == "cmgeom-plain")
    out = run_cmgeom(md.mesh, target, false, false, secs);
  else if (tool == "cmgeom-weighted-flips")
    out = run_cmgeom(md.mesh, target, true, true, secs);
  else if (tool == "cmgeom-weighted-sum")
    out = run_cmgeom(md.mesh, target, true, false, secs, TS::Quadric_merge::sum);
  else if (tool == "cmgeom-plain-flips")
    out = run_cmgeom(md.mesh, target, false, true, secs);
  else if (tool == "cgal-engine-weighted")
    out = run_cmgeom_policy_on_cgal(md.mesh, target, true, secs);
  else if (tool == "cgal-engine-plain")
    out = run_cmgeom_policy_on_cgal(md.mesh, target, false, secs);
  else if (tool == "cgal-gh")
    out = run_cgal_gh(md.mesh, target, secs);
  else if (tool == "cgal-lt")
    out = run_cgal_lt(md.mesh, target, secs);
  else if (tool == "meshopt")
    out = run_meshopt(md.soup, target, secs);
  else if (tool == "openmesh")
    out = run_openmesh(md.soup, target, secs);
  else
    return false;
  return true;
}

bool load(const std::string& data, const std::string& tmp, const std::string& name, Mesh& m) {
  std::map<std::string, std::string> files = {{"bunny", "classic/stanford-bunny.obj.gz"},
                                              {"armadillo", "classic/armadillo.obj.gz"},
                                              {"igea", "classic/igea.ply.gz"},
                                              {"nefertiti", "classic/nefertiti.obj.gz"},
                                              {"max-planck", "classic/decimated-max.obj"},
                                              {"fandisk", "classic/fandisk.obj"},
                                              {"ogre", "classic/ogre.obj.gz"},
                                              {"igea-sub", "classic/igea.ply.gz"},
                                              {"ogre-sub2", "classic/ogre.obj.gz"}};
  const bool by_path = name.find('/') != std::string::npos;
  if (!by_path && !files.count(name)) return false;
  const std::string path = cmgeom_bench::readable_model(data + "/" + (by_path ? name : files[name]), tmp);
  if (path.empty()) return false;
  if (!CGAL::IO::read_polygon_mesh(path, m) || m.is_empty()) return false;
  if (!CGAL::is_triangle_mesh(m)) CGAL::Polygon_mesh_processing::triangulate_faces(m);
  // unreferenced vertices (stanford-bunny has 1113) play no role in simplification
  std::vector<Mesh::Vertex_index> isolated;
  for (auto v : m.vertices())
    if (m.is_isolated(v)) isolated.push_back(v);
  for (auto v : isolated) m.remove_vertex(v);
  m.collect_garbage();
  if (name == "igea-sub") m = subdivide_midpoint(m);                       // 1,074,744 faces
  if (name == "ogre-sub2") m = subdivide_midpoint(subdivide_midpoint(m));  // 1,984,128 faces, as the baselines
  return true;
}

// Reads model `name` and sets up what every tool's run is measured with (its soup, diagonal,
// samples and distance tree); false, with a message, when it cannot be read.
bool prepare_model(const std::string& data, const std::string& tmp, const std::string& name, std::size_t n_samples,
                   Model& md) {
  md.name = name.find('/') == std::string::npos ? name : name.substr(name.rfind('/') + 1);
  if (!load(data, tmp, name, md.mesh)) {
    std::cerr << "skipping " << name << ": cannot read it under " << data << "\n";
    return false;
  }
  md.soup = to_soup(md.mesh);
  md.diagonal = TS::internal::bbox_diagonal(md.mesh);
  md.samples = samples(md.mesh, n_samples, 42);
  md.to_input = std::make_unique<Distance>(md.mesh);
  return true;
}

std::string fmt(double v, int prec = 3) {
  std::ostringstream s;
  s << std::setprecision(prec) << v;
  return s.str();
}
std::string sci(double v) {
  std::ostringstream s;
  s << std::scientific << std::setprecision(2) << v;
  return s.str();
}

// The guaranteed-error table (see --max-errors in the file comment).
struct Bounded_row {
  std::string model;
  std::size_t faces_in = 0;
  double e = 0, seconds = 0, bound = 0, hausdorff = 0, rms = 0;
  std::size_t faces_out = 0;
  std::map<std::string, std::size_t> peer_faces;  // smallest count found within H; 0: none
};

// Smallest target count (to 3 %) at which `tool`'s measured Hausdorff is <= h, starting from
// `start`; 0 if even the input's count is not (cannot happen: no collapse, no error).
std::size_t smallest_count_within(const std::string& tool, const Model& md, std::size_t start, double h,
                                  std::size_t n_samples) {
  const std::size_t faces_in = md.mesh.number_of_faces();
  std::map<std::size_t, bool> memo;
  auto ok = [&](std::size_t t) {
    t = std::clamp<std::size_t>(t, 4, faces_in);
    auto it = memo.find(t);
    if (it != memo.end()) return it->second;
    Mesh out;
    double secs = 0;
    run_tool(tool, md, t, out, secs);
    Row r;
    measure(md, out, n_samples, r);
    if (!std::isfinite(r.hausdorff))
      std::cerr << tool << " on " << md.name << " at " << t << " faces: non-finite coordinates in the output\n";
    return memo[t] = r.hausdorff <= h;
  };
  std::size_t lo, hi;  // ok(hi), !ok(lo)
  if (ok(start)) {
    hi = start;
    lo = hi;
    for (;;) {
      if (lo <= 4) return 4;
      lo = (std::max<std::size_t>)(4, lo / 4);
      if (!ok(lo)) break;
      hi = lo;
    }
  } else {
    lo = start;
    hi = start;
    for (;;) {
      if (hi >= faces_in) return ok(faces_in) ? faces_in : 0;
      hi = (std::min)(faces_in, hi * 2);
      if (ok(hi)) break;
      lo = hi;
    }
  }
  while (double(hi) > 1.03 * double(lo) && hi - lo > 1) {
    const std::size_t mid = std::size_t(std::sqrt(double(lo) * double(hi)));
    if (mid <= lo || mid >= hi) break;
    if (ok(mid))
      hi = mid;
    else
      lo = mid;
  }
  return hi;
}

}  // namespace

int main(int argc, char** argv) {
  std::string data = CMGEOM_BENCH_DATA_DIR, tmp = "/tmp/cmgeom-bench-simplify", out_file;
  std::vector<std::string> models = {"bunny", "armadillo", "igea", "nefertiti", "max-planck", "igea-sub"};
  std::vector<double> ratios = {0.1, 0.01};
  std::vector<std::string> tools = {"cmgeom-default",
                                    "cmgeom-weighted",
                                    "cmgeom-weighted-sum",
                                    "cmgeom-plain",
                                    "cmgeom-weighted-flips",
                                    "cgal-engine-weighted",
                                    "cgal-engine-plain",
                                    "cgal-gh",
                                    "cgal-lt",
                                    "meshopt",
                                    "openmesh"};
  std::size_t n_samples = 100000, repeat = 1;
  std::vector<double> max_errors;
  bool tools_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "missing value after " << a << "\n";
        std::exit(2);
      }
      return argv[++i];
    };
    // a number in [lo, hi], or a usage error (exit 2), not an exception
    auto number = [&](double lo, double hi) -> double {
      const std::string v = next();
      double x = 0;
      if (!cmgeom_bench::parse_number(v, lo, hi, x)) {
        std::cerr << "bad value '" << v << "' for " << a << ": expected a number in [" << lo << ", " << hi << "]\n";
        std::exit(2);
      }
      return x;
    };
    if (a == "--data")
      data = next();
    else if (a == "--tmp")
      tmp = next();
    else if (a == "--models")
      models = split(next());
    else if (a == "--tools") {
      tools = split(next());
      tools_given = true;
      for (const std::string& t : tools)
        if (std::find(std::begin(all_tools), std::end(all_tools), t) == std::end(all_tools)) {
          std::cerr << "unknown tool '" << t << "' in --tools\n";
          return 2;
        }
    } else if (a == "--samples")
      n_samples = static_cast<std::size_t>(number(1, 1e9));
    else if (a == "--min-weight")
      g_min_weight = number(1e-300, 1);
    else if (a == "--repeat")
      repeat = static_cast<std::size_t>(number(1, 99));
    else if (a == "--out")
      out_file = next();
    else if (a == "--ratios") {
      ratios.clear();
      const std::string list = next();
      for (const auto& r : split(list)) {
        double x = 0;
        if (!cmgeom_bench::parse_number(r, 0, 1, x) || x == 0) {
          std::cerr << "bad ratio '" << r << "' in --ratios " << list << ": expected numbers in (0, 1]\n";
          return 2;
        }
        ratios.push_back(x);
      }
    } else if (a == "--max-errors") {
      const std::string list = next();
      for (const auto& r : split(list)) {
        double x = 0;
        if (!cmgeom_bench::parse_number(r, 0, 1, x) || x == 0) {
          std::cerr << "bad bound '" << r << "' in --max-errors " << list << ": expected numbers in (0, 1]\n";
          return 2;
        }
        max_errors.push_back(x);
      }
    } else {
      std::cerr << "unknown option " << a << "\n";
      return 2;
    }
  }

  if (!max_errors.empty()) {
    if (!tools_given) tools = {"cgal-gh", "cgal-lt", "meshopt", "openmesh"};
    std::vector<Bounded_row> rows;
    for (const std::string& name : models) {
      Model md;
      if (!prepare_model(data, tmp, name, n_samples, md)) continue;
      for (double e : max_errors) {
        Bounded_row b;
        b.model = name;
        b.faces_in = md.mesh.number_of_faces();
        b.e = e;
        const Mesh out = run_cmgeom_bounded(md.mesh, e, b.seconds, b.bound);
        b.faces_out = out.number_of_faces();
        Row r;
        measure(md, out, n_samples, r);
        b.hausdorff = r.hausdorff;
        b.rms = r.rms;
        for (const std::string& tool : tools)
          b.peer_faces[tool] = smallest_count_within(tool, md, b.faces_out, b.hausdorff, n_samples);
        std::cerr << name << " E " << e << ": " << b.faces_out << " faces, H " << b.hausdorff << ", bound " << b.bound
                  << ", " << b.seconds << " s" << std::endl;
        rows.push_back(b);
      }
    }
    std::ostringstream t;
    t << "| model (faces) | E | faces | CPU s | bound | Hausdorff | RMS | H <= E |";
    for (const std::string& tool : tools) t << " " << tool << " faces at <= H |";
    t << " faces / fewest peer's |\n|---|---:|---:|---:|---:|---:|---:|---|";
    for (std::size_t k = 0; k < tools.size(); ++k) t << "---:|";
    t << "---:|\n";
    std::size_t within = 0, held = 0;
    double worst_ratio = 0;
    for (const Bounded_row& b : rows) {
      std::size_t fewest = 0;
      for (const auto& [tool, f] : b.peer_faces)
        if (f > 0 && (fewest == 0 || f < fewest)) fewest = f;
      const double ratio = fewest > 0 ? double(b.faces_out) / double(fewest) : 0.;
      worst_ratio = (std::max)(worst_ratio, ratio);
      within += ratio > 0 && ratio <= 1.5;
      held += b.hausdorff <= b.e;
      t << "| " << b.model << " (" << b.faces_in << ") | " << fmt(100 * b.e) << "% | " << b.faces_out << " | "
        << fmt(b.seconds) << " | " << sci(b.bound) << " | " << sci(b.hausdorff) << " | " << sci(b.rms) << " | "
        << (b.hausdorff <= b.e ? "yes" : "**no**") << " |";
      for (const std::string& tool : tools) t << " " << b.peer_faces.at(tool) << " |";
      t << " " << fmt(ratio) << " |\n";
    }
    t << "\nMeasured Hausdorff <= E in " << held << " of " << rows.size() << " cases; face count within 1.5x of the "
      << "fewest any peer needs for the same measured Hausdorff in " << within << " of " << rows.size()
      << " (largest ratio " << fmt(worst_ratio) << ").\n";
    std::cout << t.str();
    if (!out_file.empty()) {
      std::ofstream f(out_file);
      f << t.str();
    }
    return 0;
  }

  std::vector<Row> rows;
  for (const std::string& name : models) {
    Model md;
    if (!prepare_model(data, tmp, name, n_samples, md)) continue;
    const std::size_t faces_in = md.mesh.number_of_faces();
    for (double ratio : ratios) {
      const std::size_t target = static_cast<std::size_t>(std::llround(ratio * double(faces_in)));
      // Repetitions are interleaved (every tool once, then every tool again, ...), so that a
      // change of machine load hits all tools alike; each repetition pairs a tool's time with GH's.
      std::map<std::string, std::vector<double>> times;
      std::map<std::string, Mesh> outs;
      for (std::size_t rep = 0; rep < repeat; ++rep)
        for (const std::string& tool : tools) {
          Mesh out;
          double secs = 0;
          if (!run_tool(tool, md, target, out, secs)) return 2;  // not reached: --tools is checked
          times[tool].push_back(secs);
          if (rep == 0) outs[tool] = std::move(out);  // outputs are deterministic
        }
      auto median = [](std::vector<double> v) { return cmgeom_bench::summarize(std::move(v)).median; };
      for (const std::string& tool : tools) {
        Row r;
        r.model = name;
        r.tool = tool;
        r.faces_in = faces_in;
        r.target = target;
        r.ratio = ratio;
        const Mesh& out = outs[tool];
        const cmgeom_bench::Timing tt = cmgeom_bench::summarize(times[tool]);
        r.seconds = tt.median;
        r.seconds_min = tt.min;
        if (times.count("cgal-gh")) {
          std::vector<double> q;
          for (std::size_t k = 0; k < repeat; ++k) q.push_back(times["cgal-gh"][k] / std::max(times[tool][k], 1e-9));
          r.paired_speedup = median(q);
        }
        r.faces_out = out.number_of_faces();
        measure(md, out, n_samples, r);
        std::cerr << name << " " << ratio << " " << tool << ": " << r.faces_out << " faces, " << r.seconds
                  << " s, haus " << r.hausdorff << ", rms " << r.rms << std::endl;
        rows.push_back(r);
      }
    }
  }

  std::ostringstream t;
  t << "| model (faces) | target | tool | faces out | CPU s min / median | M input tri/s | Hausdorff | RMS | time / GH "
       "| "
       "Hausdorff / GH | RMS / GH | GH / tool, paired |\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Row& r : rows) {
    const Row* gh = nullptr;
    for (const Row& g : rows)
      if (g.model == r.model && g.ratio == r.ratio && g.tool == "cgal-gh") gh = &g;
    t << "| " << r.model << " (" << r.faces_in << ") | " << fmt(100 * r.ratio) << "% (" << r.target << ") | " << r.tool
      << " | " << r.faces_out << " | " << fmt(r.seconds_min) << " / " << fmt(r.seconds) << " | "
      << fmt(r.faces_in / std::max(r.seconds, 1e-9) / 1e6) << " | " << sci(r.hausdorff) << " | " << sci(r.rms) << " | "
      << (gh ? fmt(r.seconds / gh->seconds) : "-") << " | " << (gh ? fmt(r.hausdorff / gh->hausdorff) : "-") << " | "
      << (gh ? fmt(r.rms / gh->rms) : "-") << " | " << (r.paired_speedup > 0 ? fmt(r.paired_speedup) : "-") << " |\n";
  }
  std::cout << t.str();
  if (!out_file.empty()) {
    std::ofstream f(out_file);
    f << t.str();
  }
  return 0;
}
