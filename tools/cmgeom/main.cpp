// cmgeom: the command-line face of CMGeom. Every sub-command lives in its own cmd_<name>.cpp
// and registers itself (see cli_common.h), so adding one never touches this file.
//
// Errors: a sub-command throws; the message is printed on stderr as one line, prefixed with
// "cmgeom <sub-command>: error: ", and the exit code is 1 (2 for command-line usage errors).
#include "cli_common.h"

#include <tbb/global_control.h>

#include <algorithm>
#include <memory>
#include <exception>
#include <iostream>
#include <map>

int main(int argc, char** argv) {
  CLI::App app{"cmgeom - simplification, approximation and deformation of large models"};
  app.require_subcommand(1);
  app.fallthrough();  // global options (--threads) may follow the sub-command
  app.set_version_flag("--version", std::string("cmgeom 0.1.0"));
  int threads = 0;
  app.add_option("--threads", threads,
                 "Worker threads for parallel stages (default: all cores); results do not depend on it")
      ->check(CLI::NonNegativeNumber);

  auto& commands = cmgeom_cli::registry();
  std::sort(commands.begin(), commands.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<CLI::App*, std::pair<std::string, cmgeom_cli::Runner>> runners;
  for (auto& c : commands) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    runners[sub] = {c.name, c.setup(*sub)};
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string msg = e.what();
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    std::cerr << "cmgeom: usage error: " << msg << " (see cmgeom --help)" << std::endl;
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
      std::string msg = e.what();
      std::replace(msg.begin(), msg.end(), '\n', ' ');
      std::cerr << "cmgeom " << named.first << ": error: " << msg << std::endl;
      return 1;
    }
  }
  return 2;
}
