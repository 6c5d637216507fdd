#include "cli_common.h"

#include <CMGeom/Mesh_IO/image_io.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace cmgeom_cli {

std::vector<Registered_command>& registry() {
  static std::vector<Registered_command> commands;
  return commands;
}

Command_registration::Command_registration(const char* name, const char* description, Setup setup) {
  registry().push_back({name, description, std::move(setup)});
}

namespace {

std::string one_line(std::string msg) {
  std::replace(msg.begin(), msg.end(), '\n', ' ');
  return msg;
}

// The shared body of run() and run_captured(): `error` receives the message that is also
// printed on stderr.
int run_impl(const std::vector<std::string>& args, std::string* error) {
  CLI::App app{"cmgeom - simplification, approximation and deformation of large models"};
  app.require_subcommand(1);
  app.fallthrough();  // global options (--threads) may follow the sub-command
  app.set_version_flag("--version", std::string("cmgeom 0.1.0"));
  int threads = 0;
  app.add_option("--threads", threads,
                 "Worker threads for parallel stages (default: all cores); results do not depend on it")
      ->check(CLI::NonNegativeNumber);

  // Sorted by name so that --help lists the sub-commands alphabetically, whatever the link order.
  std::vector<const Registered_command*> commands;
  for (const auto& c : registry()) commands.push_back(&c);
  std::sort(commands.begin(), commands.end(),
            [](const auto* a, const auto* b) { return a->name < b->name; });
  std::map<CLI::App*, std::pair<std::string, Runner>> runners;
  for (const auto* c : commands) {
    CLI::App* sub = app.add_subcommand(c->name, c->description);
    runners[sub] = {c->name, c->setup(*sub)};
  }

  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 wants them reversed
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    *error = "usage error: " + one_line(e.what());
    std::cerr << "cmgeom: " << *error << " (see cmgeom --help)" << std::endl;
    return 2;
  }

  std::unique_ptr<tbb::global_control> limit;
  if (threads > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  std::size_t(threads));
  for (auto& [sub, named] : runners) {
    if (!sub->parsed()) continue;
    try {
      return named.second();
    } catch (const std::exception& e) {
      *error = one_line(e.what());
      std::cerr << "cmgeom " << named.first << ": error: " << *error << std::endl;
      return 1;
    }
  }
  return 2;
}

}  // namespace

int run(const std::vector<std::string>& args) {
  std::string error;
  return run_impl(args, &error);
}

Command_result run_captured(const std::vector<std::string>& args) {
  Command_result result;
  std::ostringstream captured;
  std::streambuf* const saved = std::cout.rdbuf(captured.rdbuf());
  try {
    result.exit_code = run_impl(args, &result.error);
  } catch (...) {
    std::cout.rdbuf(saved);
    throw;
  }
  std::cout.rdbuf(saved);
  result.output = captured.str();
  return result;
}

void load_soup_textures(CMGeom::Polygon_soup& soup) {
  for (CMGeom::Material& m : soup.materials) {
    if (!m.diffuse_image.empty()) continue;
    if (!m.diffuse_texture.empty()) {
      m.diffuse_image = CMGeom::IO::read_image(m.diffuse_texture);
    } else if (!m.diffuse_texture_blob.empty()) {
      m.diffuse_image =
          CMGeom::IO::read_image_from_memory(m.diffuse_texture_blob, soup.source + " (material '" + m.name + "')");
    }
  }
}

void print_json(const nlohmann::ordered_json& j) { std::cout << j.dump(2) << std::endl; }

std::pair<int, int> parse_picture_size(const std::string& size) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(size.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 1 || h < 1 ||
      w > 16384 || h > 16384)
    throw CMGeom::Invalid_input("bad --size '" + size + "': expected WxH, e.g. 1024x768");
  return {w, h};
}

double now_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}

void add_gltf_options(CLI::App& app, CMGeom::IO::Gltf_options& options) {
  app.add_flag("--quantize", options.quantize,
               "glTF/GLB output: 16-bit positions and texture coordinates, 8-bit normals (KHR_mesh_quantization)");
}

Progress::Progress(std::string label)
    : label_(std::move(label)), start_(now_seconds()), tty_(::isatty(2) != 0) {}

Progress::~Progress() { done(); }

void Progress::update(double fraction) {
  // Only long jobs get a bar, and only on a terminal: logs and pipes stay clean.
  if (!tty_ || now_seconds() - start_ < 0.5) return;
  int pct = static_cast<int>(fraction * 100.0 + 0.5);
  pct = pct < 0 ? 0 : (pct > 100 ? 100 : pct);
  if (pct == last_) return;
  last_ = pct;
  const int width = 30, filled = pct * width / 100;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", label_.c_str(), filled,
               "##############################", width - filled, "", pct);
  std::fflush(stderr);
}

void Progress::done() {
  if (finished_) return;
  finished_ = true;
  if (last_ >= 0) {
    std::fprintf(stderr, "\r%s done in %.2f s%*s\n", label_.c_str(), now_seconds() - start_, 30, "");
  }
}

}  // namespace cmgeom_cli
