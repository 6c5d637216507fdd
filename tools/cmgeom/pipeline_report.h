// The report of `cmgeom pipeline`: sections with a text, a table, pictures and the commands that
// made them, written both as report.md and as report.html (pictures embedded as <img>), so the
// two never disagree. Both files are written together or not at all (Atomic_output).
#ifndef CMGEOM_TOOLS_PIPELINE_REPORT_H
#define CMGEOM_TOOLS_PIPELINE_REPORT_H

#include <filesystem>
#include <string>
#include <vector>

namespace cmgeom_cli {

class Report {
public:
  struct Table {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
  };
  struct Picture {
    std::string file;  // relative to the output directory
    std::string caption;
  };
  struct Section {
    std::string title;
    double seconds = 0;
    std::string text;
    Table table;
    std::vector<Picture> pictures;
    std::vector<std::string> commands;
  };

  explicit Report(std::string title) : title_(std::move(title)) {}
  Section& add_section(const std::string& title, double seconds);

  // Writes report.md and report.html into `dir`. A non-empty `failure` is shown at the top: the
  // run stopped there and the sections are those of the finished stages.
  void finish(const std::filesystem::path& dir, const std::string& failure) const;

private:
  std::string markdown(const std::string& failure) const;
  std::string html(const std::string& failure) const;

  std::string title_;
  std::vector<Section> sections_;
};

}  // namespace cmgeom_cli

#endif
