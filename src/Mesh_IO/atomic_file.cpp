#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unistd.h>

namespace CMGeom {
namespace IO {

namespace fs = std::filesystem;

Atomic_output::~Atomic_output() {
  if (!committed_) rollback();
}

std::string Atomic_output::add(const std::string& final_path) {
  static std::atomic<unsigned> counter{0};
  const fs::path p(final_path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw IO_error(final_path, "cannot write: directory '" + dir.string() + "' does not exist");
  if (fs::is_directory(p, ec)) throw IO_error(final_path, "cannot write: it is a directory");
  std::string tmp = final_path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
  files_.emplace_back(tmp, final_path);
  return tmp;
}

void Atomic_output::commit() {
  for (auto& [tmp, final_path] : files_) {
    std::error_code ec;
    if (!fs::exists(tmp, ec)) {
      rollback();
      throw IO_error(final_path, "internal error: temporary file was never written");
    }
  }
  for (auto& [tmp, final_path] : files_) {
    if (std::rename(tmp.c_str(), final_path.c_str()) != 0) {
      const std::string why = std::strerror(errno);
      rollback();
      throw IO_error(final_path, "cannot write: " + why);
    }
  }
  committed_ = true;
  files_.clear();
}

void Atomic_output::rollback() noexcept {
  for (auto& f : files_) std::remove(f.first.c_str());
  files_.clear();
}

std::string write_file(const std::string& path, const std::string& content, Atomic_output& out) {
  const std::string tmp = out.add(path);
  std::ofstream os(tmp, std::ios::binary);
  if (!os) throw IO_error(path, std::string("cannot write: ") + std::strerror(errno));
  os.write(content.data(), std::streamsize(content.size()));
  os.flush();
  if (!os) throw IO_error(path, "write failed (disk full?)");
  return tmp;
}

void write_file_atomically(const std::string& path, const std::string& content) {
  Atomic_output out;
  write_file(path, content, out);
  out.commit();
}

}  // namespace IO
}  // namespace CMGeom
