// Helpers of the end-to-end tests of the cmgeom tool: file bytes and lines, GLB containers and
// their nodes, the Khronos glTF validator (test/Mesh_IO/gltf_validator, run when Node.js and its
// npm package are present), a build without a renderer. Included by the test_cli_*.cpp files.
#ifndef CMGEOM_TEST_CLI_UTIL_H
#define CMGEOM_TEST_CLI_UTIL_H

#include "cmgeom_test_meshes.h"
#include "cmgeom_test_support.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <pty.h>
#include <regex>
#include <set>
#include <sstream>
#include <termios.h>
#include <vector>

namespace {

namespace fs = std::filesystem;

inline std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

inline std::string quoted(const std::string& s) { return "'" + s + "'"; }

// Points and triangles as OFF text (full precision).
inline std::string off_text(const std::vector<std::array<double, 3>>& p,
                            const std::vector<std::array<std::size_t, 3>>& f) {
  std::ostringstream s;
  s.precision(17);
  s << "OFF\n" << p.size() << " " << f.size() << " 0\n";
  for (const auto& q : p) s << q[0] << " " << q[1] << " " << q[2] << "\n";
  for (const auto& t : f) s << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  return s.str();
}

// The JSON chunk of a GLB file (glTF 2.0 binary container: a 12-byte header, magic "glTF",
// version 2 and the file's length; then chunks of length, type and data, the JSON chunk first).
// A malformed container is a test failure (null returned).
inline nlohmann::json glb_json(const std::string& path) {
  const std::string b = bytes_of(path);
  auto u32 = [&](std::size_t at) {  // little-endian, as the container stores every integer
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) v |= std::uint32_t(static_cast<unsigned char>(b[at + k])) << (8 * k);
    return v;
  };
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0) {
    ADD_FAILURE() << path << ": not a GLB file (" << b.size() << " bytes)";
    return nullptr;
  }
  EXPECT_EQ(u32(4), 2u) << path << ": container version";
  EXPECT_EQ(u32(8), b.size()) << path << ": the header's length is not the file's";
  const std::size_t length = u32(12);
  if (u32(16) != 0x4E4F534Au || 20 + length > b.size()) {  // "JSON"
    ADD_FAILURE() << path << ": the first chunk is not a JSON chunk within the file";
    return nullptr;
  }
  return nlohmann::json::parse(b.substr(20, length));
}

// The images node `n` draws as base colour (through its mesh's primitives and their materials).
inline std::set<int> images_of_node(const nlohmann::json& j, std::size_t n) {
  std::set<int> images;
  for (const auto& p : j["meshes"][j["nodes"][n]["mesh"].get<std::size_t>()]["primitives"]) {
    if (!p.contains("material")) continue;
    const auto& m = j["materials"][p["material"].get<std::size_t>()];
    if (!m.contains("pbrMetallicRoughness") || !m["pbrMetallicRoughness"].contains("baseColorTexture")) continue;
    const std::size_t t = m["pbrMetallicRoughness"]["baseColorTexture"]["index"].get<std::size_t>();
    images.insert(j["textures"][t]["source"].get<int>());
  }
  return images;
}

// The triangles of node `n`: its primitives' index counts / 3.
inline std::size_t triangles_of_node(const nlohmann::json& j, std::size_t n) {
  std::size_t indices = 0;
  for (const auto& p : j["meshes"][j["nodes"][n]["mesh"].get<std::size_t>()]["primitives"])
    indices += j["accessors"][p["indices"].get<std::size_t>()]["count"].get<std::size_t>();
  return indices / 3;
}

// Faces of an OBJ file: its "f" lines.
inline std::size_t obj_faces(const std::string& path) {
  std::size_t n = 0;
  for (const std::string& l : lines_of(bytes_of(path))) n += l.compare(0, 2, "f ") == 0;
  return n;
}

// Why the Khronos glTF validator (test/Mesh_IO/gltf_validator) cannot run here ("" when it can).
inline std::string gltf_validator_missing() {
  const fs::path dir = CMGEOM_GLTF_VALIDATOR_DIR;
  if (std::system("command -v node > /dev/null 2>&1") != 0)
    return "node is not on PATH: install Node.js and npm, then run 'npm install' in " + dir.string();
  std::error_code ec;
  if (!fs::is_directory(dir / "node_modules" / "gltf-validator", ec))
    return "the glTF validator is not installed: run 'npm install' in " + dir.string() + " (scripts/test.sh does)";
  return std::string();
}

// The validator's report on `file`: its first line "errors=N warnings=N infos=N hints=N", then one
// line per issue. `errors` and `warnings` stay -1 (a test failure) when it could not validate.
struct Validation {
  int errors = -1, warnings = -1, infos = -1, hints = -1;
  std::string report;
};

inline Validation validate_gltf(const std::string& file) {
  const std::string report_file = file + ".validation.txt";
  const std::string cmd = "node " + quoted((fs::path(CMGEOM_GLTF_VALIDATOR_DIR) / "validate.js").string()) + " " +
                          quoted(file) + " > " + quoted(report_file) + " 2>&1";
  const int status = std::system(cmd.c_str());
  Validation v;
  v.report = bytes_of(report_file);
  fs::remove(report_file);
  if (status != 0 || std::sscanf(v.report.c_str(), "errors=%d warnings=%d infos=%d hints=%d", &v.errors, &v.warnings,
                                 &v.infos, &v.hints) != 4)
    ADD_FAILURE() << "the validator could not validate " << file << ":\n" << v.report;
  return v;
}

// The rendering commands' refusal in a build without a renderer (rendering_unavailable_message()).
inline bool renderer_missing(const cmgeom_test::Cli_result& r) {
  return r.exit_code != 0 && r.err.find("has no renderer") != std::string::npos;
}

}  // namespace

#endif  // CMGEOM_TEST_CLI_UTIL_H
