// Shared plumbing of the cmgeom sub-commands: registration, errors, JSON output, progress, the
// cage-source options.
#ifndef CMGEOM_TOOLS_CLI_COMMON_H
#define CMGEOM_TOOLS_CLI_COMMON_H

#include <CLI/CLI.hpp>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <nlohmann/json.hpp>

#include <array>
#include <atomic>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {
struct Cage_system_description;
}
}  // namespace CMGeom

namespace cmgeom_cli {

// A sub-command adds its options to `app` and returns the function that runs it.
// The function returns the process exit code; it reports user errors by throwing.
using Runner = std::function<int()>;
using Setup = std::function<Runner(CLI::App& app)>;

struct Command_registration {
  Command_registration(const char* name, const char* description, Setup setup);
};

struct Registered_command {
  std::string name;
  std::string description;
  Setup setup;
};
std::vector<Registered_command>& registry();

// Builds the whole command line (global options and every registered sub-command), parses
// `args` (without the program name) and runs the chosen sub-command. Errors are reported on
// stderr as one line; returns the exit code (0 success, 1 error, 2 usage error). `main` is this
// function; the pipeline command calls it again in-process for each stage.
int run(const std::vector<std::string>& args);

// Runs one sub-command in-process as `run` does, with its standard output captured.
struct Command_result {
  int exit_code = 0;
  std::string output;  // what the command printed on stdout
  std::string error;   // the one-line error message, when exit_code != 0
};
Command_result run_captured(const std::vector<std::string>& args);

// Decodes the diffuse textures of the soup's materials (files or embedded glTF images) that are
// not decoded yet. Throws IO_error when an image cannot be read.
void load_soup_textures(CMGeom::Polygon_soup& soup);

// Adds --quantize (KHR_mesh_quantization) to a command that can write glTF.
void add_gltf_options(CLI::App& app, CMGeom::IO::Gltf_options& options);

// Adds --allow-degenerate (Read_options::allow_degenerate_faces, the option the reader's refusal
// of zero-area faces names) to a command that reads a mesh.
void add_allow_degenerate_option(CLI::App& app, bool& allow_degenerate_faces);

// Adds --drop-repeated (Read_options::drop_repeated_vertex_faces, the option the reader's refusal
// of a face that repeats a vertex names: STL files from CAD tools often hold such slivers once
// their equal corners are merged) to a command that reads a mesh.
void add_drop_repeated_option(CLI::App& app, bool& drop_repeated_vertex_faces);

// Adds --repair (Read_options::repair, the option the reader's refusal of non-manifold or
// inconsistently oriented input names) to a command that reads a mesh and does not repair by
// default: those that keep the input's elements as they are (convert, deform: the output's
// vertices are the input's, in its order).
void add_repair_option(CLI::App& app, bool& repair);

// Adds --no-repair (refuse instead) and --repair (the default, accepted: the reader's refusal
// under --no-repair names it) to a command that repairs its input by default: those that
// approximate it (simplify, lod, cm build). Read_options::repair is then !no_repair (--repair
// changes nothing and binds no variable).
void add_repair_by_default_options(CLI::App& app, bool& no_repair);

// Gives every material of `tm` (one is made when it has none, and every face takes it) the diffuse
// texture `texture` (the --texture option of an input whose file names none, e.g. spot.obj);
// nothing when `texture` is empty. Invalid_input when the mesh has no texture coordinates.
void apply_texture_option(CMGeom::Textured_mesh& tm, const std::string& input, const std::string& texture);

// Why a simplification with no valid collapse left stopped above its face target, for its
// message: "no valid collapse left", and when `output` has several connected components (each
// keeps a few faces: a closed one at least 4), how many, and that --prune can remove whole ones
// (when `prune_available`: the command has --prune and it was not given).
std::string no_collapse_reason(const CMGeom::Surface_mesh& output, bool prune_available);

// Whether a material of `tm` names a texture (diffuse or normal map).
bool names_a_texture(const CMGeom::Textured_mesh& tm);

// Invalid_input when `tm` has texture coordinates, no material names a texture and the input's
// folder holds images: a texture is never guessed, the message names those images and the options
// (--texture FILE, or --no-texture; `textured_use` says what --texture is for, e.g. "to simplify it
// textured"; `offer_no_texture` false for a command without --no-texture).
void refuse_unnamed_texture(const CMGeom::Textured_mesh& tm, const std::string& input, const std::string& textured_use,
                            bool offer_no_texture = true);

// Adds --memory-points N (Surface_memory_options::max_points) to a command that simplifies with the
// memoryful term; returns the option (its count() tells whether it was given).
CLI::Option* add_memory_points_option(CLI::App& app, std::size_t& max_points);

// --fit-min-points F of `simplify` and `lod`: the final fit only with at least F input points per
// face of the result (Surface_fit_options::min_points_per_face; 0 = always).
CLI::Option* add_fit_min_points_option(CLI::App& app, double& min_points_per_face);

// Prints each warning on stderr as "cmgeom <command>: warning: <text>" (the reader's repairs,
// skipped statements, ...).
void print_warnings(const std::string& command, const std::vector<std::string>& warnings);

// Prints a JSON document on stdout (2-space indentation, keys in insertion order).
void print_json(const nlohmann::ordered_json& j);

// Parses a picture size "WxH" (1 to 16384 each); Invalid_input naming the option otherwise.
std::pair<int, int> parse_picture_size(const std::string& size);

// Seconds since an arbitrary origin (steady clock).
double now_seconds();

// The progress of one stage of a command, on stderr only (stdout holds the results and --json):
//   * stderr is a terminal: once the stage has run 0.5 s, one line redrawn in place ('\r') with
//     the label, the percentage and the rate ("1.2 M faces/s" when the stage's count is known,
//     otherwise the time left), at most 20 times a second; when the stage ends, if it
//     took 0.5 s or more, the line becomes "<label> done in X s (<count> <unit>)";
//   * stderr is not a terminal (pipe, log file): nothing while the stage runs; when it ends, if
//     it took 0.5 s or more, one line "cmgeom: <label>: done in X s (<count> <unit>)";
//   * --quiet (Progress::set_quiet): nothing at all.
// A stage left by an exception prints no "done" line (a drawn bar is erased, so the error
// message starts a clean line). update() may be called from any thread; a call made while
// another one draws is dropped.
class Progress {
public:
  explicit Progress(std::string label);
  // `total`: what the whole stage counts, in `unit` (e.g. 1e6, "faces"), for the rate and the
  // final line.
  Progress(std::string label, double total, std::string unit);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Sets (or corrects, e.g. once an adaptive reconstruction knows its size) the stage's count.
  void set_total(double total, std::string unit);
  void update(double fraction);  // 0..1
  void done();
  // The library's progress hook (CMGeom::Progress_callback) forwarding to update().
  std::function<void(double)> hook();

  // Global switch of the --quiet option (set by run() for the whole command, pipeline stages
  // included).
  static void set_quiet(bool quiet);
  static bool quiet();

private:
  void draw(double fraction, double elapsed);
  std::string label_, unit_;
  double total_ = -1;  // < 0: not known
  double start_;
  double last_draw_ = -1;
  int last_percent_ = -1;
  std::size_t drawn_width_ = 0;  // characters of the line on screen, 0 when none
  int uncaught_;
  bool tty_;
  bool finished_ = false;
  std::atomic_flag busy_ = ATOMIC_FLAG_INIT;
};

// Where the cage commands (deform, influence, cm deform) take their cages from: a cage-system
// JSON file (--cages: one cage or a *Cages system, CMGeom::Cage_deformation::read_cage_system())
// or a grid of box cages around the input (--grid nx,ny,nz with --h, --margin and, where the
// command lets the coordinates be chosen, --coordinates; make_grid_cage_system()).
struct Cage_source {
  std::string file, grid, coordinates = "mean_value";
  double h = 1.0, margin = 0.05;

  // Invalid_input unless --cages or --grid is given.
  void require() const;
  // Invalid_input unless --h is in (0, 1].
  void check_h() const;
  // The file read, or the grid around `points` (Invalid_input on a malformed --grid).
  CMGeom::Cage_deformation::Cage_system_description description(const std::vector<std::array<double, 3>>& points) const;
};

// Which grid options a cage command offers besides --cages.
enum class Cage_grid_options {
  none,            // --cages only
  mean_value,      // --grid, --h, --margin (mean value coordinates)
  any_coordinates  // the same and --coordinates mean_value|green|harmonic
};

// Adds the cage-source options to `app` (--grid excludes --cages); returns the --cages option.
CLI::Option* add_cage_source_options(CLI::App& app, Cage_source& source, Cage_grid_options grid);

// Reads a mesh (CMGeom::IO::read_mesh) or a polygon soup as the progress stage "read <file
// name>", counting its faces (the readers have no progress hook: the stage reports its end only).
void read_mesh_with_progress(const std::string& path, CMGeom::Textured_mesh& out,
                             const CMGeom::IO::Read_options& options = CMGeom::IO::Read_options());
CMGeom::Polygon_soup read_polygon_soup_with_progress(const std::string& path);

}  // namespace cmgeom_cli

// Registers a sub-command from a .cpp file: CMGEOM_CLI_COMMAND(info, "…") { return [&]{...}; }
#define CMGEOM_CLI_CONCAT2(a, b) a##b
#define CMGEOM_CLI_CONCAT(a, b) CMGEOM_CLI_CONCAT2(a, b)
#define CMGEOM_CLI_COMMAND(NAME, DESCRIPTION)                                         \
  static cmgeom_cli::Runner CMGEOM_CLI_CONCAT(cmgeom_setup_, NAME)(CLI::App & app);   \
  static const cmgeom_cli::Command_registration CMGEOM_CLI_CONCAT(cmgeom_reg_, NAME)( \
      #NAME, DESCRIPTION, &CMGEOM_CLI_CONCAT(cmgeom_setup_, NAME));                   \
  static cmgeom_cli::Runner CMGEOM_CLI_CONCAT(cmgeom_setup_, NAME)(CLI::App & app)

#endif
