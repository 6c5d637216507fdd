// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Fuzz target for the CMGeom file formats that are not meshes: the CM file (thesis §4.4.3,
// include/CMGeom/Compact_model/cm_io.h) and the *Cages system JSON (thesis §5.3,
// include/CMGeom/Cage_deformation/Cage_system_io.h).
//
// The first input byte selects the reader, the rest is the file content:
//   0  CM file, bytes as given (most mutations stop at the checksum);
//   1  CM file whose trailing FNV-1a checksum is recomputed first, so that mutations reach the
//      index, number and cone-list validation behind it;
//   2  cage-system JSON, parsed with a directory holding two small cage files (so that file
//      references resolve) as its base directory.
// Acceptable outcomes are a CMGeom::Error or a model that survives its own round trip:
//   CM:   cm_bytes(m) parses back to a model with the same bytes, and a regular reconstruction at
//         level 1 (serial) runs without error or crash;
//   JSON: cage_system_to_json(d) parses back to a description with the same JSON text.
// Anything else (another exception, a failed round trip, a crash, a sanitizer report, a hang) is
// a finding: the input is saved to fuzz-finding.bin and the program aborts.
//
// Two ways to run it, as test/Mesh_IO/fuzz_readers.cpp: coverage-guided with libFuzzer
// (CMGEOM_LIBFUZZER, scripts/fuzz.sh), or `fuzz_model_readers --smoke N --seed S DIR...`, which
// runs every seed of DIR... (*.cm as readers 0 and 1, *.json as reader 2, plus a textured copy
// of every CM seed made here) and N deterministic mutations of them (what CTest runs).
#include <CMGeom/Cage_deformation/Cage_system_io.h>
#include <CMGeom/Compact_model/cm_compact_io.h>
#include <CMGeom/Compact_model/cm_io.h>
#include <CMGeom/Compact_model/reconstruct.h>

#include "fuzz_mutate.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <string>
#include <unistd.h>
#include <vector>

namespace {

namespace CM = CMGeom::CM;
namespace CD = CMGeom::Cage_deformation;

// Inputs run and inputs accepted, per reader (the smoke run prints them: a mutation engine that
// never gets past the first check would show here).
std::size_t g_runs[3], g_accepted[3];

[[noreturn]] void finding(const std::uint8_t* data, std::size_t size, const std::string& what) {
  std::ofstream("fuzz-finding.bin", std::ios::binary).write(reinterpret_cast<const char*>(data), std::streamsize(size));
  std::fprintf(stderr, "finding: %s; input saved to fuzz-finding.bin\n", what.c_str());
  std::abort();
}

// A scratch directory with the cage files that JSON inputs may name ("cube.obj", "cube2.off").
const std::string& cage_dir() {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("cmgeom_fuzz_cages_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    const char* v = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";
    const char* f = "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    std::ofstream(d / "cube.obj") << v << f;
    std::ofstream(d / "cube2.off") << "OFF\n8 6 0\n-2 -2 -2\n2 -2 -2\n2 2 -2\n-2 2 -2\n-2 -2 2\n2 -2 2\n2 2 2\n-2 2 2\n"
                                      "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
    return d.string();
  }();
  return dir;
}

void run_cm(const std::uint8_t* data, std::size_t size, bool fix_checksum) {
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if (fix_checksum && bytes.size() >= 8) {
    std::uint64_t h = CM::internal::fnv1a64(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size() - 8);
    for (int i = 0; i < 8; ++i) bytes[bytes.size() - 8 + std::size_t(i)] = char((h >> (8 * i)) & 0xffu);
  }
  CMGeom::CM::Compact_model m;
  try {
    m = CM::parse_cm(bytes, "fuzz.cm");
  } catch (const CMGeom::Error&) {
    return;  // a clear error is a correct answer to bad input
  }
  ++g_accepted[fix_checksum ? 1 : 0];
  const std::string again = CM::cm_bytes(m);
  if (CM::cm_bytes(CM::parse_cm(again, "again.cm")) != again) finding(data, size, "CM round trip changed the bytes");
  try {
    CM::Reconstruction_options opt;
    opt.parallel = false;
    (void)CM::reconstruct_regular(m, 1, opt);
  } catch (const CMGeom::Error&) {}
}

void run_cage_system(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  CD::Cage_system_description d;
  try {
    d = CD::parse_cage_system(text, "fuzz.json", cage_dir());
  } catch (const CMGeom::Error&) {
    return;
  }
  ++g_accepted[2];
  const std::string once = CD::cage_system_to_json(d).dump();
  std::string twice;
  try {
    twice = CD::cage_system_to_json(CD::parse_cage_system(once, "again.json", cage_dir())).dump();
  } catch (const CMGeom::Error& e) {
    finding(data, size, std::string("the written cage system does not read back: ") + e.what());
  }
  if (once != twice) finding(data, size, "cage-system round trip changed the JSON");
}

int run_one(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  ++g_runs[data[0] % 3];
  try {
    switch (data[0] % 3) {
      case 0:
        run_cm(data, size, false);
        break;
      case 1:
        run_cm(data, size, true);
        break;
      default:
        run_cage_system(data, size);
    }
  } catch (const std::exception& e) {
    finding(data, size, std::string("exception that is not a CMGeom::Error: ") + e.what());
  }
  return 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { return run_one(data, size); }

#ifndef CMGEOM_LIBFUZZER
namespace {

// A textured copy of a CM seed (the CLI writes untextured models only): UVs from the vertex
// positions, texture path "texture.png".
std::vector<std::uint8_t> textured_copy(const std::vector<std::uint8_t>& seed) {
  const std::string bytes(seed.begin() + 1, seed.end());
  CM::Compact_model m = CM::parse_cm(bytes, "seed.cm");
  m.texture = "texture.png";
  m.uvs.resize(m.faces.size());
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto& p = m.vertices[m.faces[f][std::size_t(k)].vertex];
      m.uvs[f][std::size_t(k)] = {float(0.5 + 0.25 * p.x), float(0.5 + 0.25 * p.y)};
    }
  const std::string out = CM::cm_bytes(m);
  std::vector<std::uint8_t> r(1, seed[0]);
  r.insert(r.end(), out.begin(), out.end());
  return r;
}

// The same model as a compact file (format version 3, cm_compact_io.h), so that mutations reach
// its decoder too.
std::vector<std::uint8_t> compact_copy(const std::vector<std::uint8_t>& seed) {
  const std::string bytes(seed.begin() + 1, seed.end());
  const std::string out = CM::compact_cm_bytes(CM::parse_cm(bytes, "seed.cm"));
  std::vector<std::uint8_t> r(1, seed[0]);
  r.insert(r.end(), out.begin(), out.end());
  return r;
}

}  // namespace

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
  std::vector<cmgeom_fuzz::Bytes> pool;
  for (const std::string& d : dirs) {
    if (!std::filesystem::is_directory(d)) {
      std::cerr << "fuzz_model_readers: skipping missing corpus directory " << d << "\n";
      continue;
    }
    for (const auto& e : std::filesystem::directory_iterator(d)) {
      const std::string ext = e.path().extension().string();
      if (!e.is_regular_file() || e.file_size() > 300000 || (ext != ".cm" && ext != ".json")) continue;
      std::ifstream in(e.path(), std::ios::binary);
      const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      for (std::uint8_t f : ext == ".cm" ? std::vector<std::uint8_t>{0, 1} : std::vector<std::uint8_t>{2}) {
        cmgeom_fuzz::Bytes bytes(1, f);
        bytes.insert(bytes.end(), content.begin(), content.end());
        pool.push_back(bytes);
        if (f == 1) {
          pool.push_back(textured_copy(bytes));
          pool.push_back(compact_copy(bytes));
          pool.push_back(compact_copy(textured_copy(bytes)));
        }
      }
    }
  }
  if (pool.empty()) {
    std::cerr << "fuzz_model_readers: no seed files found\n";
    return 1;
  }
  std::sort(pool.begin(), pool.end());  // directory order is not deterministic
  std::mt19937_64 rng(seed);
  for (const auto& s : pool) run_one(s.data(), s.size());
  for (std::size_t i = 0; i < runs; ++i) {
    const auto input = cmgeom_fuzz::mutate(pool[rng() % pool.size()], rng, pool, /*binary_integers=*/true);
    run_one(input.data(), input.size());
  }
  std::filesystem::remove_all(cage_dir());
  std::cout << "fuzz_model_readers: " << pool.size() << " seeds, " << runs << " mutated inputs, 0 findings"
            << " (accepted/run: CM " << g_accepted[0] << "/" << g_runs[0] << ", CM with checksum fixed "
            << g_accepted[1] << "/" << g_runs[1] << ", cage systems " << g_accepted[2] << "/" << g_runs[2] << ")\n";
  return 0;
}
#endif
