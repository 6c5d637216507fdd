// Fuzz target for every mesh reader (OBJ, MTL, OFF, PLY, STL, glTF, GLB).
//
// The first input byte selects the format, the rest is the file content. Each input goes through
// read_polygon_soup -> analyze_soup -> build_textured_mesh and build_surface_mesh, with and without
// repair. The only acceptable outcomes are success or a CMGeom::Error, the same from both builds
// (the same message, or meshes of as many halfedges). Anything else (another exception, a crash,
// a sanitizer report, a hang, the two builds disagreeing) is a finding.
//
// Two ways to run it:
//  * with clang and -fsanitize=fuzzer (CMGEOM_LIBFUZZER): a coverage-guided libFuzzer target,
//    see scripts/fuzz.sh;
//  * as a plain program (any compiler, what CTest runs): `fuzz_readers --smoke N --seed S DIR...`
//    applies N deterministic random mutations (test/Reliability/fuzz_mutate.h) to the seed files
//    of DIR... and runs each one.
#include <CMGeom/Mesh_IO.h>

#include "../Reliability/fuzz_mutate.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

// ".mtl": the input is a material library, read through a fixed OBJ that names it (mtllib,
// usemtl of several names, texture coordinates), so the MTL parser is fuzzed as the OBJ reader uses it.
const char* const formats[] = {".obj", ".off", ".ply", ".gltf", ".glb", ".mtl", ".stl"};
constexpr int n_formats = 7;
constexpr int mtl_format = 5;

const char* const mtl_host_obj =
    "mtllib input.mtl\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
    "usemtl material\nf 1/1 2/2 5/5\nf 2/2 3/3 5/5\n"
    "usemtl Material_MR\nf 3/3 4/4 5/5\n"
    "usemtl spot\nf 4/4 1/1 5/5\nf 1/1 4/4 3/3 2/2\n";

std::string scratch_path(int format) {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("cmgeom_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir + "/input" + formats[format];
}

int run_one(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int format = data[0] % n_formats;
  std::string path = scratch_path(format);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
  }
  if (format == mtl_format) {  // read the OBJ that names the fuzzed MTL
    path = (std::filesystem::path(path).parent_path() / "mtl_host.obj").string();
    std::ofstream(path, std::ios::binary | std::ios::trunc) << mtl_host_obj;
  }
  try {
    const CMGeom::Polygon_soup soup = CMGeom::IO::read_polygon_soup(path);
    const CMGeom::Mesh_statistics st = CMGeom::analyze_soup(soup);
    (void)st;
    for (bool repair : {false, true}) {
      CMGeom::IO::Read_options opt;
      opt.repair = repair;
      opt.allow_degenerate_faces = repair;
      opt.drop_repeated_vertex_faces = repair;
      const auto finding = [&](const char* what) {
        std::ofstream("fuzz-finding.bin", std::ios::binary)
            .write(reinterpret_cast<const char*>(data), std::streamsize(size));
        std::fprintf(stderr, "finding: %s (repair=%d); input saved to fuzz-finding.bin\n", what, int(repair));
        std::abort();
      };
      std::string textured_error, geometry_error;
      std::size_t textured_halfedges = 0, geometry_halfedges = 0;
      try {
        CMGeom::Textured_mesh tm;
        CMGeom::IO::build_textured_mesh(soup, tm, opt);
        if (!tm.mesh().is_valid(false)) finding("build_textured_mesh produced an invalid mesh");
        textured_halfedges = tm.mesh().number_of_halfedges();
      } catch (const CMGeom::Error& e) {
        textured_error = e.what();
      }
      // the geometry-only build checks the same and builds the same mesh
      try {
        CMGeom::Surface_mesh g;
        CMGeom::IO::build_surface_mesh(soup, g, opt);
        geometry_halfedges = g.number_of_halfedges();
      } catch (const CMGeom::Error& e) {
        geometry_error = e.what();
      }
      if (geometry_error != textured_error || geometry_halfedges != textured_halfedges)
        finding("build_surface_mesh and build_textured_mesh disagree");
    }
  } catch (const CMGeom::Error&) {
    // a clear error is a correct answer to bad input
  }
  return 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { return run_one(data, size); }

#ifndef CMGEOM_LIBFUZZER
int main(int argc, char** argv) {
  std::size_t runs = 2000;
  std::uint64_t seed = 1;
  std::vector<std::string> dirs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--smoke" && i + 1 < argc)
      runs = std::stoul(argv[++i]);
    else if (a == "--seed" && i + 1 < argc)
      seed = std::stoull(argv[++i]);
    else
      dirs.push_back(a);
  }
  std::vector<std::vector<std::uint8_t>> pool;
  for (const std::string& d : dirs) {
    if (!std::filesystem::is_directory(d)) {
      std::cerr << "fuzz_readers: skipping missing corpus directory " << d << "\n";
      continue;
    }
    for (const auto& e : std::filesystem::directory_iterator(d)) {
      if (!e.is_regular_file() || e.file_size() > 300000) continue;  // keep runs quick
      const std::string ext = CMGeom::IO::extension(e.path().string());
      int f = -1;
      for (int k = 0; k < n_formats; ++k)
        if (ext == formats[k]) f = k;
      if (f < 0) continue;
      std::ifstream in(e.path(), std::ios::binary);
      std::vector<std::uint8_t> bytes(1, std::uint8_t(f));
      bytes.insert(bytes.end(), std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      pool.push_back(std::move(bytes));
    }
  }
  if (pool.empty()) {
    std::cerr << "fuzz_readers: no seed files found\n";
    return 1;
  }
  std::sort(pool.begin(), pool.end());  // directory order is not deterministic
  std::mt19937_64 rng(seed);
  for (const auto& s : pool) run_one(s.data(), s.size());
  for (std::size_t i = 0; i < runs; ++i) {
    const auto input = cmgeom_fuzz::mutate(pool[rng() % pool.size()], rng, pool);
    run_one(input.data(), input.size());
  }
  std::filesystem::remove_all(std::filesystem::path(scratch_path(0)).parent_path());
  std::cout << "fuzz_readers: " << pool.size() << " seeds, " << runs << " mutated inputs, 0 findings\n";
  return 0;
}
#endif
