// Fuzz target for every mesh reader (OBJ+MTL, OFF, PLY, glTF, GLB).
//
// The first input byte selects the format, the rest is the file content. Each input goes through
// read_polygon_soup -> analyze_soup -> build_textured_mesh (with and without repair); the only
// acceptable outcomes are success or a CMGeom::Error. Anything else (another exception, a crash,
// a sanitizer report, a hang) is a finding.
//
// Two ways to run it:
//  * with clang and -fsanitize=fuzzer (CMGEOM_LIBFUZZER): a coverage-guided libFuzzer target,
//    see scripts/fuzz.sh;
//  * as a plain program (any compiler, what CTest runs): `fuzz_readers --smoke N --seed S DIR...`
//    applies N deterministic random mutations (bit flips, byte insert/erase, truncation, line
//    duplication, digit changes, splices) to the seed files of DIR... and runs each one.
#include <CMGeom/Mesh_IO.h>

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

const char* const formats[] = {".obj", ".off", ".ply", ".gltf", ".glb"};
constexpr int n_formats = 5;

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
  const std::string path = scratch_path(format);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
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
      try {
        CMGeom::Textured_mesh tm;
        CMGeom::IO::build_textured_mesh(soup, tm, opt);
        if (!tm.mesh().is_valid(false)) {
          std::ofstream("fuzz-finding.bin", std::ios::binary)
              .write(reinterpret_cast<const char*>(data), std::streamsize(size));
          std::fprintf(stderr, "finding: build_textured_mesh produced an invalid mesh (repair=%d); "
                               "input saved to fuzz-finding.bin\n", int(repair));
          std::abort();
        }
      } catch (const CMGeom::Error&) {
      }
    }
  } catch (const CMGeom::Error&) {
    // a clear error is a correct answer to bad input
  }
  return 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { return run_one(data, size); }

#ifndef CMGEOM_LIBFUZZER
namespace {

std::vector<std::uint8_t> mutate(std::vector<std::uint8_t> s, std::mt19937_64& rng,
                                 const std::vector<std::vector<std::uint8_t>>& pool) {
  auto pick = [&](std::size_t n) { return n ? std::size_t(rng() % n) : 0; };
  const int rounds = 1 + int(rng() % 4);
  for (int r = 0; r < rounds; ++r) {
    switch (rng() % 9) {
      case 0: if (s.size() > 1) s[1 + pick(s.size() - 1)] ^= std::uint8_t(1u << (rng() % 8)); break;
      case 1: if (s.size() > 1) s.erase(s.begin() + std::ptrdiff_t(1 + pick(s.size() - 1))); break;
      case 2: s.insert(s.begin() + std::ptrdiff_t(1 + pick(s.size())), std::uint8_t(rng())); break;
      case 3: if (s.size() > 2) s.resize(1 + pick(s.size() - 1)); break;  // truncation
      case 4: {  // change a digit, or a whole number into a huge or negative one
        std::vector<std::size_t> digits;
        for (std::size_t i = 1; i < s.size(); ++i) if (s[i] >= '0' && s[i] <= '9') digits.push_back(i);
        if (digits.empty()) break;
        const std::size_t at = digits[pick(digits.size())];
        static const char* const repl[] = {"0", "-1", "4294967295", "99999999999", "nan", "inf", "1e308", "-0"};
        const std::string w = repl[rng() % 8];
        s.erase(s.begin() + std::ptrdiff_t(at));
        s.insert(s.begin() + std::ptrdiff_t(at), w.begin(), w.end());
        break;
      }
      case 5: {  // duplicate or drop a line
        std::vector<std::size_t> nl;
        for (std::size_t i = 1; i < s.size(); ++i) if (s[i] == '\n') nl.push_back(i);
        if (nl.size() < 2) break;
        const std::size_t k = pick(nl.size() - 1);
        std::vector<std::uint8_t> line(s.begin() + std::ptrdiff_t(nl[k] + 1), s.begin() + std::ptrdiff_t(nl[k + 1] + 1));
        if (rng() % 2) s.insert(s.begin() + std::ptrdiff_t(nl[k] + 1), line.begin(), line.end());
        else s.erase(s.begin() + std::ptrdiff_t(nl[k] + 1), s.begin() + std::ptrdiff_t(nl[k + 1] + 1));
        break;
      }
      case 6: if (!s.empty()) s[0] = std::uint8_t(rng()); break;  // same bytes, another reader
      case 7: {  // splice with another seed
        const auto& o = pool[pick(pool.size())];
        if (o.size() < 2 || s.size() < 2) break;
        const std::size_t a = 1 + pick(s.size() - 1), b = 1 + pick(o.size() - 1);
        s.resize(a);
        s.insert(s.end(), o.begin() + std::ptrdiff_t(b), o.end());
        break;
      }
      default: {  // overwrite a few bytes with interesting values
        if (s.size() < 5) break;
        static const std::uint8_t vals[] = {0, 0xff, 0x7f, 0x80, '/', ' ', '\n', '-'};
        const std::size_t at = 1 + pick(s.size() - 1);
        for (std::size_t i = at; i < std::min(s.size(), at + 4); ++i) s[i] = vals[rng() % 8];
      }
    }
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t runs = 2000;
  std::uint64_t seed = 1;
  std::vector<std::string> dirs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--smoke" && i + 1 < argc) runs = std::stoul(argv[++i]);
    else if (a == "--seed" && i + 1 < argc) seed = std::stoull(argv[++i]);
    else dirs.push_back(a);
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
      for (int k = 0; k < n_formats; ++k) if (ext == formats[k]) f = k;
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
    const auto input = mutate(pool[rng() % pool.size()], rng, pool);
    run_one(input.data(), input.size());
  }
  std::filesystem::remove_all(std::filesystem::path(scratch_path(0)).parent_path());
  std::cout << "fuzz_readers: " << pool.size() << " seeds, " << runs << " mutated inputs, 0 findings\n";
  return 0;
}
#endif
