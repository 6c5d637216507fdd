#include "cli_common.h"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace cmgeom_cli {

std::vector<Registered_command>& registry() {
  static std::vector<Registered_command> commands;
  return commands;
}

Command_registration::Command_registration(const char* name, const char* description, Setup setup) {
  registry().push_back({name, description, std::move(setup)});
}

void print_json(const nlohmann::ordered_json& j) { std::cout << j.dump(2) << std::endl; }

double now_seconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
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
