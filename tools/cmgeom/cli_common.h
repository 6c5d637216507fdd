// Shared plumbing of the cmgeom sub-commands: registration, errors, JSON output, progress.
#ifndef CMGEOM_TOOLS_CLI_COMMON_H
#define CMGEOM_TOOLS_CLI_COMMON_H

#include <CLI/CLI.hpp>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Mesh_IO/mesh_io.h>
#include <nlohmann/json.hpp>

#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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

// Prints a JSON document on stdout (2-space indentation, keys in insertion order).
void print_json(const nlohmann::ordered_json& j);

// Parses a picture size "WxH" (1 to 16384 each); Invalid_input naming the option otherwise.
std::pair<int, int> parse_picture_size(const std::string& size);

// Seconds since an arbitrary origin (steady clock).
double now_seconds();

// A progress bar on stderr, drawn only when stderr is a terminal and the job is long.
class Progress {
public:
  explicit Progress(std::string label);
  ~Progress();
  void update(double fraction);  // 0..1
  void done();

private:
  std::string label_;
  double start_;
  int last_ = -1;
  bool tty_;
  bool finished_ = false;
};

}  // namespace cmgeom_cli

// Registers a sub-command from a .cpp file: CMGEOM_CLI_COMMAND(info, "…") { return [&]{...}; }
#define CMGEOM_CLI_CONCAT2(a, b) a##b
#define CMGEOM_CLI_CONCAT(a, b) CMGEOM_CLI_CONCAT2(a, b)
#define CMGEOM_CLI_COMMAND(NAME, DESCRIPTION)                                                 \
  static cmgeom_cli::Runner CMGEOM_CLI_CONCAT(cmgeom_setup_, NAME)(CLI::App & app);            \
  static const cmgeom_cli::Command_registration CMGEOM_CLI_CONCAT(cmgeom_reg_, NAME)(          \
      #NAME, DESCRIPTION, &CMGEOM_CLI_CONCAT(cmgeom_setup_, NAME));                            \
  static cmgeom_cli::Runner CMGEOM_CLI_CONCAT(cmgeom_setup_, NAME)(CLI::App & app)

#endif
