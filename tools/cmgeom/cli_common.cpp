#include "cli_common.h"

#include <CMGeom/Cage_deformation/Cage_system_io.h>
#include <CMGeom/Cage_deformation/Grid_cage_system.h>
#include <CMGeom/Mesh_IO/image_io.h>

#include <CGAL/Polygon_mesh_processing/connected_components.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
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
  app.fallthrough();  // global options (--threads, --quiet) may follow the sub-command
  app.set_version_flag("--version", std::string("cmgeom 0.1.0"));
  int threads = 0;
  app.add_option("--threads", threads,
                 "Worker threads for parallel stages (default: all cores); results do not depend on it")
      ->check(CLI::NonNegativeNumber);
  bool quiet = false;
  app.add_flag("--quiet", quiet, "No progress output on stderr (warnings and errors are still printed)");

  // Sorted by name so that --help lists the sub-commands alphabetically, whatever the link order.
  std::vector<const Registered_command*> commands;
  for (const auto& c : registry()) commands.push_back(&c);
  std::sort(commands.begin(), commands.end(), [](const auto* a, const auto* b) { return a->name < b->name; });
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
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
  // --quiet holds for this command and the commands it runs in-process (the pipeline's stages,
  // whose arguments do not repeat it); the previous setting comes back when it returns.
  struct Quiet_scope {
    bool previous = Progress::quiet();
    explicit Quiet_scope(bool quiet) { Progress::set_quiet(previous || quiet); }
    ~Quiet_scope() { Progress::set_quiet(previous); }
  } quiet_scope(quiet);
  for (auto& [sub, named] : runners) {
    if (!sub->parsed()) continue;
    try {
      return named.second();
    } catch (const std::exception& e) {
      *error = one_line(e.what());
      // (the full path of a nested command, "cm build", as its warnings name it)
      std::string name = named.first;
      for (const CLI::App* nested = sub; !nested->get_subcommands().empty();) {
        nested = nested->get_subcommands().front();
        name += " " + nested->get_name();
      }
      std::cerr << "cmgeom " << name << ": error: " << *error << std::endl;
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

void print_warnings(const std::string& command, const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::cerr << "cmgeom " << command << ": warning: " << w << "\n";
}

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

void add_allow_degenerate_option(CLI::App& app, bool& allow_degenerate_faces) {
  app.add_flag("--allow-degenerate", allow_degenerate_faces, "Keep zero-area faces instead of refusing the file");
}

void add_drop_repeated_option(CLI::App& app, bool& drop_repeated_vertex_faces) {
  app.add_flag("--drop-repeated", drop_repeated_vertex_faces,
               "Drop faces that repeat a vertex (a, a, b) instead of refusing the file");
}

void add_repair_option(CLI::App& app, bool& repair) {
  app.add_flag("--repair", repair,
               "Split non-manifold edges, duplicate non-manifold vertices and fix the orientation while reading "
               "(CGAL's orient_polygon_soup) instead of refusing the file");
}

void add_repair_by_default_options(CLI::App& app, bool& no_repair) {
  auto* yes = app.add_flag("--repair", "Repair while reading (the default; kept for compatibility)");
  auto* no = app.add_flag("--no-repair", no_repair,
                          "Refuse non-manifold or inconsistently oriented input instead of repairing it");
  yes->excludes(no);
}

void apply_texture_option(CMGeom::Textured_mesh& tm, const std::string& input, const std::string& texture) {
  if (texture.empty()) return;
  if (!tm.has_uvs()) throw CMGeom::Invalid_input(input + ": --texture given but the mesh has no texture coordinates");
  if (tm.materials().empty()) tm.materials().emplace_back();
  for (auto& m : tm.materials()) {
    if (m.name.empty()) m.name = "material";
    m.diffuse_texture = std::filesystem::absolute(texture).string();
    m.diffuse_texture_blob.clear();
  }
  for (auto f : tm.mesh().faces()) tm.material_map()[f] = 0;
}

std::string no_collapse_reason(const CMGeom::Surface_mesh& output, bool prune_available) {
  std::string reason = "no valid collapse left";
  if (output.number_of_faces() == 0) return reason;
  std::vector<std::size_t> component(output.num_faces(), 0);
  const std::size_t components = CGAL::Polygon_mesh_processing::connected_components(
      output, boost::make_iterator_property_map(component.begin(), get(boost::face_index, output)));
  if (components < 2) return reason;
  reason += ": each of the " + std::to_string(components) + " connected components keeps a few faces";
  if (prune_available) reason += "; --prune removes whole components to reach the target";
  return reason;
}

bool names_a_texture(const CMGeom::Textured_mesh& tm) {
  for (const auto& m : tm.materials())
    if (m.has_diffuse_texture() || !m.normal_texture.empty()) return true;
  return false;
}

void refuse_unnamed_texture(const CMGeom::Textured_mesh& tm, const std::string& input, const std::string& textured_use,
                            bool offer_no_texture) {
  if (!tm.has_uvs() || names_a_texture(tm)) return;
  std::vector<std::string> images;
  std::error_code ec;
  const auto dir = std::filesystem::absolute(input).parent_path();
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    std::string ext = e.path().extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".tga" || ext == ".bmp")
      images.push_back(e.path().filename().string());
  }
  std::sort(images.begin(), images.end());
  std::string beside;
  for (const auto& name : images) beside += (beside.empty() ? "" : ", ") + name;
  if (!beside.empty())
    throw CMGeom::Invalid_input(input + ": has texture coordinates but names no texture (its folder holds " + beside +
                                "); pass --texture FILE " + textured_use +
                                (offer_no_texture ? ", or --no-texture for geometry only" : ""));
}

CLI::Option* add_memory_points_option(CLI::App& app, std::size_t& max_points) {
  return app
      .add_option("--memory-points", max_points,
                  "At most N of the input's vertices as the memoryful term's points, every k-th of a larger "
                  "input (0 = all, the default): faster on inputs of more than N vertices, but a vertex no "
                  "point stands for is seen by no distance")
      ->check(CLI::NonNegativeNumber);
}

CLI::Option* add_fit_min_points_option(CLI::App& app, double& min_points_per_face) {
  // (a finite number >= 0, said in one short line: CLI::NonNegativeNumber prints the largest double
  // in full and lets "nan" through)
  const CLI::Validator finite_non_negative(
      [](std::string& text) -> std::string {
        std::size_t used = 0;
        double v = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != text.size() || !std::isfinite(v) || v < 0)
          return "expected a finite number >= 0, got '" + text + "'";
        return std::string();
      },
      "NUMBER>=0");
  return app
      .add_option("--fit-min-points", min_points_per_face,
                  "Fit only when the input has at least this many points per face of the result (of each "
                  "level, for lod); 0 = always. Surface_fit_options::min_points_per_face. Default 3")
      ->check(finite_non_negative);
}

namespace {

std::atomic<bool> quiet_progress{false};

// "1.2 M", "850 k", "37", "0.8": at most three significant digits, for the terminal's rate.
std::string rate_text(double x) {
  const char* prefix[] = {"", " k", " M", " G"};
  int p = 0;
  while (x >= 999.5 && p < 3) {
    x /= 1000.;
    ++p;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, x < 9.95 ? "%.1f%s" : "%.0f%s", x, prefix[p]);
  return buf;
}

std::string stage_seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", s);
  return buf;
}

}  // namespace

void Progress::set_quiet(bool quiet) { quiet_progress.store(quiet); }
bool Progress::quiet() { return quiet_progress.load(); }

Progress::Progress(std::string label)
    : label_(std::move(label)), start_(now_seconds()), uncaught_(std::uncaught_exceptions()), tty_(::isatty(2) != 0) {}

Progress::Progress(std::string label, double total, std::string unit) : Progress(std::move(label)) {
  set_total(total, std::move(unit));
}

Progress::~Progress() {
  if (std::uncaught_exceptions() > uncaught_) {
    // Left by an exception: the stage did not finish. Erase a drawn bar so that the error
    // message that follows starts a clean line.
    finished_ = true;
    if (drawn_width_ > 0) std::fprintf(stderr, "\r%*s\r", int(drawn_width_), "");
    return;
  }
  done();
}

void Progress::set_total(double total, std::string unit) {
  total_ = total;
  unit_ = std::move(unit);
}

std::function<void(double)> Progress::hook() {
  return [this](double fraction) { update(fraction); };
}

void Progress::update(double fraction) {
  // The animation is for terminals and for stages long enough to be waited for: logs, pipes
  // and short jobs stay clean.
  if (!tty_ || quiet()) return;
  const double elapsed = now_seconds() - start_;
  if (elapsed < 0.5) return;
  if (busy_.test_and_set(std::memory_order_acquire)) return;  // another thread is drawing
  if (!finished_) draw(fraction, elapsed);
  busy_.clear(std::memory_order_release);
}

void Progress::draw(double fraction, double elapsed) {
  fraction = fraction < 0 ? 0 : (fraction > 1 ? 1 : fraction);
  const int percent = static_cast<int>(fraction * 100.0);
  // At most 20 redraws a second, and one at least every 0.25 s for the rate.
  const double since = elapsed - last_draw_;
  if (last_draw_ >= 0 && !(percent != last_percent_ ? since >= 0.05 : since >= 0.25)) return;
  last_draw_ = elapsed;
  last_percent_ = percent;
  std::string rate;
  if (total_ > 0) {
    rate = rate_text(fraction * total_ / elapsed) + " " + unit_ + "/s";
  } else if (fraction >= 0.02) {
    const double left = elapsed * (1 - fraction) / fraction;
    rate =
        left < 1 ? std::string("under 1 s left") : "about " + std::to_string(static_cast<long>(left + 0.5)) + " s left";
  }
  char head[32];
  std::snprintf(head, sizeof head, " %3d%%", percent);
  std::string line = label_ + head + (rate.empty() ? "" : "  " + rate);
  const std::size_t width = line.size();
  if (width < drawn_width_) line.append(drawn_width_ - width, ' ');  // erase the longer line before
  std::fprintf(stderr, "\r%s", line.c_str());
  std::fflush(stderr);
  drawn_width_ = width;
}

void Progress::done() {
  if (finished_) return;
  while (busy_.test_and_set(std::memory_order_acquire)) {}
  finished_ = true;
  busy_.clear(std::memory_order_release);
  if (quiet()) return;
  const double elapsed = now_seconds() - start_;
  if (elapsed < 0.5 && drawn_width_ == 0) return;  // short stages stay silent
  char count[64] = "";
  if (total_ >= 0) std::snprintf(count, sizeof count, " (%.0f %s)", total_, unit_.c_str());
  if (tty_) {
    std::string line = label_ + " done in " + stage_seconds_text(elapsed) + count;
    if (line.size() < drawn_width_) line.append(drawn_width_ - line.size(), ' ');
    std::fprintf(stderr, "\r%s\n", line.c_str());
  } else {
    std::fprintf(stderr, "cmgeom: %s: done in %s%s\n", label_.c_str(), stage_seconds_text(elapsed).c_str(), count);
  }
  std::fflush(stderr);
}

void read_mesh_with_progress(const std::string& path, CMGeom::Textured_mesh& out,
                             const CMGeom::IO::Read_options& options) {
  Progress stage("read " + std::filesystem::path(path).filename().string());
  CMGeom::IO::read_mesh(path, out, options);
  stage.set_total(double(out.mesh().number_of_faces()), "faces");
}

CMGeom::Polygon_soup read_polygon_soup_with_progress(const std::string& path) {
  Progress stage("read " + std::filesystem::path(path).filename().string());
  CMGeom::Polygon_soup soup = CMGeom::IO::read_polygon_soup(path);
  stage.set_total(double(soup.number_of_faces()), "faces");
  return soup;
}

void Cage_source::require() const {
  if (file.empty() && grid.empty()) throw CMGeom::Invalid_input("give --cages <system.json> or --grid nx,ny,nz");
}

void Cage_source::check_h() const {
  if (!(h > 0 && h <= 1)) throw CMGeom::Invalid_input("--h must be in (0, 1]");
}

CMGeom::Cage_deformation::Cage_system_description Cage_source::description(
    const std::vector<std::array<double, 3>>& points) const {
  namespace CD = CMGeom::Cage_deformation;
  if (grid.empty()) return CD::read_cage_system(file);
  int n[3];
  char extra = 0;
  if (std::sscanf(grid.c_str(), "%d,%d,%d%c", &n[0], &n[1], &n[2], &extra) != 3)
    throw CMGeom::Invalid_input("bad --grid '" + grid + "': expected nx,ny,nz, e.g. 2,2,1");
  const CD::Coordinate_type type = coordinates == "green"      ? CD::Coordinate_type::green
                                   : coordinates == "harmonic" ? CD::Coordinate_type::harmonic
                                                               : CD::Coordinate_type::mean_value;
  return CD::make_grid_cage_system(points, n[0], n[1], n[2], margin, type, h);
}

CLI::Option* add_cage_source_options(CLI::App& app, Cage_source& source, Cage_grid_options grid) {
  CLI::Option* cages = app.add_option("--cages", source.file, "Cage-system JSON file (one cage or a *Cages system)");
  if (grid == Cage_grid_options::none) return cages;
  cages->excludes(app.add_option("--grid", source.grid, "A grid of nx,ny,nz box cages around the mesh"));
  if (grid == Cage_grid_options::any_coordinates)
    app.add_option("--coordinates", source.coordinates, "With --grid: coordinates of every cage")
        ->check(CLI::IsMember({"mean_value", "green", "harmonic"}));
  app.add_option("--h", source.h, "With --grid: h of every cage, in (0, 1] (default 1)");
  app.add_option("--margin", source.margin,
                 "With --grid: margin around the mesh, times its bbox diagonal (default 0.05)");
  return cages;
}

}  // namespace cmgeom_cli
