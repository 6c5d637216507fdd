#include "pipeline_report.h"

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace cmgeom_cli {

namespace {

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f s", s);
  return buf;
}

std::string md_cell(const std::string& s) {
  std::string r;
  for (char c : s) r += (c == '|') ? std::string("\\|") : std::string(1, c);
  return r;
}

std::string escape(const std::string& s) {
  std::string r;
  for (char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      default:
        r += c;
    }
  }
  return r;
}

void write_file(const std::string& path, const std::string& content) {
  std::ofstream f(path, std::ios::binary);
  f << content;
  f.close();
  if (!f) throw CMGeom::IO_error(path, "cannot write the report");
}

}  // namespace

Report::Section& Report::add_section(const std::string& title, double seconds) {
  sections_.push_back(Section{});
  sections_.back().title = title;
  sections_.back().seconds = seconds;
  return sections_.back();
}

std::string Report::markdown(const std::string& failure) const {
  std::ostringstream m;
  m << "# " << title_ << "\n\n";
  if (!failure.empty()) m << "**The run did not finish:** " << failure << "\n\n";
  m << "Made by `cmgeom pipeline`; every picture and number below comes from the command listed "
       "under its section (output files are named relative to this report's directory).\n";
  for (const auto& s : sections_) {
    m << "\n## " << s.title << "\n\n";
    m << "Stage time: " << seconds_text(s.seconds) << ".\n\n";
    if (!s.text.empty()) m << s.text << "\n\n";
    if (!s.table.header.empty() && !s.table.rows.empty()) {
      m << "|";
      for (const auto& h : s.table.header) m << " " << md_cell(h) << " |";
      m << "\n|";
      for (std::size_t i = 0; i < s.table.header.size(); ++i) m << "---|";
      m << "\n";
      for (const auto& row : s.table.rows) {
        m << "|";
        for (const auto& c : row) m << " " << md_cell(c) << " |";
        m << "\n";
      }
      m << "\n";
    }
    for (const auto& p : s.pictures) m << "![" << p.caption << "](" << p.file << ")\n*" << p.caption << "*\n\n";
    if (!s.commands.empty()) {
      m << "<details><summary>commands</summary>\n\n```\n";
      for (const auto& c : s.commands) m << c << "\n";
      m << "```\n</details>\n";
    }
  }
  return m.str();
}

std::string Report::html(const std::string& failure) const {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" << escape(title_) << "</title>\n"
    << "<style>body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em}"
       "table{border-collapse:collapse}td,th{border:1px solid #999;padding:3px 8px;text-align:right}"
       "th{background:#eee}figure{display:inline-block;margin:4px;vertical-align:top}"
       "img{max-width:520px;border:1px solid #ccc}figcaption{font-size:90%;max-width:520px}"
       "pre{background:#f4f4f4;padding:6px;overflow-x:auto}.failure{color:#a00;font-weight:bold}</style>\n"
    << "</head><body>\n<h1>" << escape(title_) << "</h1>\n";
  if (!failure.empty()) h << "<p class=\"failure\">The run did not finish: " << escape(failure) << "</p>\n";
  h << "<p>Made by <code>cmgeom pipeline</code>; every picture and number below comes from the command "
       "listed under its section.</p>\n";
  for (const auto& s : sections_) {
    h << "<h2>" << escape(s.title) << "</h2>\n<p>Stage time: " << seconds_text(s.seconds) << ".</p>\n";
    if (!s.text.empty()) h << "<p>" << escape(s.text) << "</p>\n";
    if (!s.table.header.empty() && !s.table.rows.empty()) {
      h << "<table><tr>";
      for (const auto& c : s.table.header) h << "<th>" << escape(c) << "</th>";
      h << "</tr>\n";
      for (const auto& row : s.table.rows) {
        h << "<tr>";
        for (const auto& c : row) h << "<td>" << escape(c) << "</td>";
        h << "</tr>\n";
      }
      h << "</table>\n";
    }
    for (const auto& p : s.pictures)
      h << "<figure><img src=\"" << escape(p.file) << "\" alt=\"" << escape(p.caption) << "\"><figcaption>"
        << escape(p.caption) << "</figcaption></figure>\n";
    if (!s.commands.empty()) {
      h << "<details><summary>commands</summary><pre>";
      for (const auto& c : s.commands) h << escape(c) << "\n";
      h << "</pre></details>\n";
    }
  }
  h << "</body></html>\n";
  return h.str();
}

void Report::finish(const std::filesystem::path& dir, const std::string& failure) const {
  CMGeom::IO::Atomic_output out;
  const std::string md = out.add((dir / "report.md").string());
  const std::string html_path = out.add((dir / "report.html").string());
  write_file(md, markdown(failure));  // the destructor removes the temporaries on a throw
  write_file(html_path, html(failure));
  out.commit();
}

}  // namespace cmgeom_cli
