// Speed of the Cage_deformation package on the mesh/cage pairs of the shared data (never run by
// CTest). Prints Markdown tables:
//   1. STREAM-style memory bandwidth (copy, triad, read-only sum) on 1 and 2 threads;
//   2. binding throughput in (point x cage triangle)/s for mean value and Green coordinates on 1
//      and 2 threads (wall clock, and CPU time, which is what a loaded shared machine distorts
//      least), and the harmonic solve + lookup time;
//   3. deformation time per frame (minimum and median frame), vertices/s and effective bandwidth for dense double,
//   dense
//      float and sparse weights, against the measured bandwidth.
// Every timing is repeated; tables give the minimum and the median of the runs ("min / median";
// for a rate, the rate of the fastest run, then of the median run).
// Usage: bench_Cage_deformation [--quick] [data_dir]
#include <CMGeom/Cage_deformation.h>

#include "cmgeom_test_config.h"
#include "cmgeom_bench_support.h"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace CMGeom::Cage_deformation;

namespace {

double wall() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
double cpu() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

bool read_obj(const std::string& path, std::vector<Vec3>& pts, std::vector<std::vector<std::size_t>>& polys) {
  const std::string file = cmgeom_bench::readable_model(path, CMGEOM_TEST_TMP_DIR, "bench_cage_");
  if (file.empty()) return false;
  try {
    read_polygons(file, pts, polys);
  } catch (const CMGeom::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return false;
  }
  return !pts.empty();
}

// ------------------------------------------------------------------ STREAM-style bandwidth
constexpr int stream_runs = 6;

struct Bandwidth {
  cmgeom_bench::Timing copy, triad, read;  // seconds of one pass
  double copy_bytes = 0, triad_bytes = 0, read_bytes = 0;
  // GB/s of the fastest pass of any kind (the reference of the deformation table)
  double best() const {
    return std::max({copy_bytes / copy.min, triad_bytes / triad.min, read_bytes / read.min}) / 1e9;
  }
};

Bandwidth stream(int threads, std::size_t n) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  std::vector<double> a(n), b(n), c(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    a[i] = 1.0;
    b[i] = 2.0;
    c[i] = 0.5;
  });
  Bandwidth bw;
  bw.copy_bytes = 16.0 * double(n);
  bw.triad_bytes = 24.0 * double(n);
  bw.read_bytes = 8.0 * double(n);
  std::vector<double> tc, tt, tr;
  const std::size_t grain = n / (8 * std::size_t(threads));
  for (int rep = 0; rep < stream_runs; ++rep) {
    double t0 = wall();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i < r.end(); ++i) c[i] = a[i];
    });
    double t = wall() - t0;
    tc.push_back(t);
    t0 = wall();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i < r.end(); ++i) a[i] = b[i] + 3.0 * c[i];
    });
    t = wall() - t0;
    tt.push_back(t);
    std::vector<double> partial(64, 0.0);
    t0 = wall();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
      double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
      std::size_t i = r.begin();
      for (; i + 4 <= r.end(); i += 4) {
        s0 += a[i];
        s1 += a[i + 1];
        s2 += a[i + 2];
        s3 += a[i + 3];
      }
      for (; i < r.end(); ++i) s0 += a[i];
      partial[(r.begin() / grain) % 64] += s0 + s1 + s2 + s3;
    });
    t = wall() - t0;
    tr.push_back(t);
    if (partial[0] == -1) std::printf("?");
  }
  bw.copy = cmgeom_bench::summarize(tc);
  bw.triad = cmgeom_bench::summarize(tt);
  bw.read = cmgeom_bench::summarize(tr);
  return bw;
}

// ------------------------------------------------------------------ binding
struct Bind_result {
  cmgeom_bench::Timing wall1, cpu1, wall2, cpu2;
};

// `reps` runs of each; on a shared machine the minimum is the run least disturbed by others.
template <class Coords>
Bind_result time_bind(const Coords& c, const std::vector<Vec3>& pts, int reps) {
  std::vector<double> w1, c1, w2, c2;
  for (int rep = 0; rep < reps; ++rep) {
    {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
      const double w0 = wall(), c0 = cpu();
      Cage_binding<double> b = bind_points(c, pts);
      w1.push_back(wall() - w0);
      c1.push_back(cpu() - c0);
    }
    {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
      const double w0 = wall(), c0 = cpu();
      Cage_binding<double> b = bind_points(c, pts);
      w2.push_back(wall() - w0);
      c2.push_back(cpu() - c0);
    }
  }
  return {cmgeom_bench::summarize(w1), cmgeom_bench::summarize(c1), cmgeom_bench::summarize(w2),
          cmgeom_bench::summarize(c2)};
}

template <class Binding>
cmgeom_bench::Timing time_deform(const Binding& b, const std::vector<Vec3>& basis, int threads, int frames) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  std::vector<Vec3> out(b.number_of_points());
  b.deform(basis, out.data());  // warm up
  return cmgeom_bench::time_runs(frames, [&] { b.deform(basis, out.data()); });
}

struct Model {
  std::string name, mesh, cage, deformed;
};

}  // namespace

int main(int argc, char** argv) {
  bool quick = false;
  std::string data = CMGEOM_DATA_DIR;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else
      data = a;
  }
  const std::string q = data + "/cages/qmvc/", p = data + "/cages/pgc/";
  std::vector<Model> models = {
      {"Ogre (qmvc)", q + "Ogre.obj", q + "Ogre_Cage.obj", q + "Ogre_Cage_Deformed.obj"},
      {"Beast (qmvc)", q + "Beast.obj", q + "Beast_Cage.obj", q + "Beast_Cage_Deformed.obj"},
      {"FireHydrant (qmvc)", q + "FireHydrant.obj.gz", q + "FireHydrant_Cage.obj", q + "FireHydrant_Cage_Deformed.obj"},
      {"ManHead (qmvc)", q + "ManHead.obj", q + "ManHead_Cage.obj", q + "ManHead_Cage_Deformed.obj"},
      {"armadilloman (pgc)", p + "armadilloman/armadilloman.obj", p + "armadilloman/cage.obj", ""},
      {"horse (pgc)", p + "horse/horse.obj.gz", p + "horse/cage.obj", ""},
      {"cactus (pgc)", p + "cactus/cactus.obj.gz", p + "cactus/cage.obj", ""},
      {"elephant (pgc)", p + "elephant/elephant.obj", p + "elephant/cage.obj", ""},
  };
  if (quick) models.resize(2);

  // (the machine, its threads and its load are described by run.sh, common/describe_run.sh)

  // 1. bandwidth
  const std::size_t sn = quick ? (std::size_t(1) << 23) : (std::size_t(1) << 25);  // 32M doubles = 256 MB/array
  Bandwidth bw1 = stream(1, sn), bw2 = stream(2, sn);
  std::printf(
      "### Memory bandwidth (STREAM-style, %zu MB per array, %d passes: GB/s of the fastest / "
      "of the median pass)\n\n",
      sn * 8 >> 20, stream_runs);
  std::printf("| threads | copy GB/s | triad GB/s | read (sum) GB/s |\n|---|---|---|---|\n");
  for (const Bandwidth* bw : {&bw1, &bw2})
    std::printf("| %d | %s | %s | %s |\n", bw == &bw1 ? 1 : 2,
                cmgeom_bench::rate_min_median(bw->copy_bytes / 1e9, bw->copy).c_str(),
                cmgeom_bench::rate_min_median(bw->triad_bytes / 1e9, bw->triad).c_str(),
                cmgeom_bench::rate_min_median(bw->read_bytes / 1e9, bw->read).c_str());
  std::printf("\n");

  // 2. binding
  const int bind_reps = quick ? 3 : 5;
  std::printf("### Binding: (point x cage triangle) per second (%d runs: fastest / median run)\n\n", bind_reps);
  std::printf(
      "M/s = millions of (mesh vertex x cage triangle) pairs per second, \"fastest / median\". *cpu* divides by the "
      "process CPU time summed over its threads (robust to other jobs on the shared machine), "
      "*wall* by elapsed time. *2T/1T* is the wall-clock speed-up; *2T eff* = (2T cpu rate) / "
      "(1T cpu rate), the work efficiency of the parallel run: on two otherwise idle cores the "
      "speed-up would be about 2 x eff; both ratios are of the medians.\n\n");
  std::printf(
      "| model | vertices | cage V/T | MVC 1T cpu | MVC 1T wall | MVC 2T wall | MVC 2T/1T | MVC 2T eff | "
      "Green 1T cpu | Green 1T wall | Green 2T wall | Green 2T/1T | Green 2T eff |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  struct Deform_row {
    std::string name;
    std::size_t N, K;
    cmgeom_bench::Timing td1, td2, tf1, ts1;
    std::size_t bd, bf, bs;
  };
  std::vector<Deform_row> deform_rows;
  std::vector<std::string> harmonic_rows;
  std::mt19937 rng(1);
  for (const Model& m : models) {
    std::vector<Vec3> mp, cp, dp;
    std::vector<std::vector<std::size_t>> mf, cf, df;
    if (!read_obj(m.mesh, mp, mf) || !read_obj(m.cage, cp, cf)) {
      std::printf("| %s | missing data | | | | | | | | | | | |\n", m.name.c_str());
      continue;
    }
    Triangle_cage cage = make_triangle_cage(cp, cf);
    validate_cage(cage, m.cage);
    std::vector<Vec3> deformed;
    if (!m.deformed.empty() && read_obj(m.deformed, dp, df) && dp.size() == cp.size()) {
      deformed = dp;
    } else {
      deformed = cage.vertices;
      std::normal_distribution<double> N(0, 0.02 * cage.bbox_diagonal());
      for (Vec3& v : deformed)
        for (double& c : v) c += N(rng);
    }
    const double pairs = double(mp.size()) * double(cage.triangles.size());
    Mean_value_coordinates_3 mvc(cage);
    Green_coordinates_3 gc(cage);
    const Bind_result rm = time_bind(mvc, mp, bind_reps), rg = time_bind(gc, mp, bind_reps);
    const auto rate = [&](const cmgeom_bench::Timing& t) { return cmgeom_bench::rate_min_median(pairs / 1e6, t); };
    std::printf("| %s | %zu | %zu/%zu | %s | %s | %s | %.2f | %.2f | %s | %s | %s | %.2f | %.2f |\n", m.name.c_str(),
                mp.size(), cage.vertices.size(), cage.triangles.size(), rate(rm.cpu1).c_str(), rate(rm.wall1).c_str(),
                rate(rm.wall2).c_str(), rm.wall1.median / rm.wall2.median, rm.cpu1.median / rm.cpu2.median,
                rate(rg.cpu1).c_str(), rate(rg.wall1).c_str(), rate(rg.wall2).c_str(),
                rg.wall1.median / rg.wall2.median, rg.cpu1.median / rg.cpu2.median);
    std::fflush(stdout);

    // deformation kernels (MVC weights; Green has n + m per vertex, reported in the same table)
    const auto deform_row = [&](const auto& coordinates, const char* kind) {
      std::vector<Vec3> basis;
      coordinates.deformation_rule()(deformed, std::back_inserter(basis));
      Binding_options so;
      so.storage = Weight_storage::sparse;
      const int frames = quick ? 5 : 21;
      Cage_binding<double> d = bind_points(coordinates, mp);
      Cage_binding<float> f = bind_points<float>(coordinates, mp);
      Cage_binding<double> s = bind_points(coordinates, mp, so);
      deform_rows.push_back({m.name + kind, mp.size(), d.number_of_coordinates(), time_deform(d, basis, 1, frames),
                             time_deform(d, basis, 2, frames), time_deform(f, basis, 1, frames),
                             time_deform(s, basis, 1, frames), d.weights_bytes(), f.weights_bytes(),
                             s.weights_bytes()});
    };
    deform_row(mvc, " MVC");
    deform_row(gc, " Green");

    // harmonic: solve once, then look up (points outside the cage are flagged, not counted)
    if (!quick && harmonic_rows.size() < 3) {
      Harmonic_options ho;
      ho.resolution = 64;
      // Three solves and three lookups: minimum / median of each.
      std::unique_ptr<Harmonic_coordinates_3> hc;
      const cmgeom_bench::Timing solve =
          cmgeom_bench::time_runs(3, [&] { hc = std::make_unique<Harmonic_coordinates_3>(cage, ho); });
      Cage_binding<double> hb;
      const cmgeom_bench::Timing look = cmgeom_bench::time_runs(3, [&] { hb = bind_points(*hc, mp); });
      char buf[512];
      std::snprintf(buf, sizeof buf, "| %s | %d | %zu | %s | %zu | %s | %s | %zu | %zu |", m.name.c_str(),
                    ho.resolution, hc->number_of_interior_nodes(), cmgeom_bench::min_median(solve, "%.2f").c_str(),
                    hc->solver_iterations(), cmgeom_bench::min_median(look, "%.3f").c_str(),
                    cmgeom_bench::rate_min_median(double(mp.size()) / 1e6, look, "%.2f").c_str(),
                    hb.count(Coordinate_status::approximate), hb.count(Coordinate_status::undefined));
      harmonic_rows.push_back(buf);
    }
  }

  std::printf(
      "\n### Harmonic coordinates (2 threads, wall clock; tricubic lookup; min / median of 3 solves and 3 "
      "lookups)\n\n");
  std::printf(
      "| model | resolution | interior nodes | solve s min / median | CG iterations (all coords, levels) | "
      "bind s min / median | M vertices/s (best / median) | approximate | undefined (outside) "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& r : harmonic_rows) std::printf("%s\n", r.c_str());

  // A large binding (weights far beyond the 32 MB L3): mesh vertices jittered inside the cage.
  if (!models.empty()) {
    std::vector<Vec3> mp, cp;
    std::vector<std::vector<std::size_t>> mf, cf;
    if (read_obj(models[0].mesh, mp, mf) && read_obj(models[0].cage, cp, cf)) {
      Triangle_cage cage = make_triangle_cage(cp, cf);
      validate_cage(cage);
      Mean_value_coordinates_3 mvc(cage);
      std::vector<Vec3> big;
      std::normal_distribution<double> N(0, 1e-3 * cage.bbox_diagonal());
      const std::size_t target = quick ? 100000 : 400000;
      while (big.size() < target)
        for (const Vec3& v : mp) {
          big.push_back({v[0] + N(rng), v[1] + N(rng), v[2] + N(rng)});
          if (big.size() == target) break;
        }
      std::vector<Vec3> basis;
      mvc.deformation_rule()(cage.vertices, std::back_inserter(basis));
      Binding_options so;
      so.storage = Weight_storage::sparse;
      Cage_binding<double> d = bind_points(mvc, big);
      Cage_binding<float> f = bind_points<float>(mvc, big);
      Deform_row row{models[0].name + " MVC x" + std::to_string(target / mp.size() + 1) + " points",
                     big.size(),
                     d.number_of_coordinates(),
                     time_deform(d, basis, 1, 11),
                     time_deform(d, basis, 2, 11),
                     time_deform(f, basis, 1, 11),
                     {},
                     d.weights_bytes(),
                     f.weights_bytes(),
                     0};
      {
        Cage_binding<double> s = bind_points(mvc, big, so);
        row.ts1 = time_deform(s, basis, 1, 11);
        row.bs = s.weights_bytes();
      }
      deform_rows.push_back(row);
    }
  }

  std::printf("\n### Deformation per frame (%d frames, 11 for the large case; weights already bound)\n\n",
              quick ? 5 : 21);
  const double best1 = bw1.best(), best2 = bw2.best();
  std::printf(
      "Times are \"min / median\" of the frames; M vert/s and GB/s are of the fastest frame. "
      "GB/s = weight bytes read per second; %% = of the best STREAM figure (copy, triad or "
      "read) with the same thread count: %.1f GB/s (1T), %.1f GB/s (2T). Weights that fit "
      "in the 32 MB L3 exceed 100%%; the last row (weights far beyond L3) is the DRAM-bound "
      "case.\n\n",
      best1, best2);
  std::printf(
      "| binding | vertices | coords/vertex | dense double MB | 1T ms | 1T M vert/s | 1T GB/s (%%) | "
      "2T ms | 2T GB/s (%%) | dense float MB | float 1T ms | float 1T GB/s (%%) | sparse MB | sparse 1T ms |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Deform_row& r : deform_rows) {
    const double gb1 = double(r.bd) / r.td1.min / 1e9, gb2 = double(r.bd) / r.td2.min / 1e9;
    const double gbf = double(r.bf) / r.tf1.min / 1e9;
    const auto ms = [](const cmgeom_bench::Timing& t) { return cmgeom_bench::min_median(t.scaled(1e3), "%.2f"); };
    std::printf(
        "| %s | %zu | %zu | %.1f | %s | %.1f | %.1f (%.0f%%) | %s | %.1f (%.0f%%) | %.1f | "
        "%s | %.1f (%.0f%%) | %.1f | %s |\n",
        r.name.c_str(), r.N, r.K, double(r.bd) / 1e6, ms(r.td1).c_str(), double(r.N) / r.td1.min / 1e6, gb1,
        100 * gb1 / best1, ms(r.td2).c_str(), gb2, 100 * gb2 / best2, double(r.bf) / 1e6, ms(r.tf1).c_str(), gbf,
        100 * gbf / best1, double(r.bs) / 1e6, ms(r.ts1).c_str());
  }
  return 0;
}
