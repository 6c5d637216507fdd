// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// All-or-nothing output of one or several files (an OBJ with its MTL and PNG textures, say).
// Each file is written to a temporary sibling "<name>.tmp-<pid>-<n>"; commit() renames them all
// into place once every one is complete; if commit() is never reached (an exception, a failed
// write) the destructor removes the temporaries, so no truncated or half-written output is left.
// A rename within one directory is atomic on POSIX file systems.
#ifndef CMGEOM_MESH_IO_ATOMIC_OUTPUT_H
#define CMGEOM_MESH_IO_ATOMIC_OUTPUT_H

#include <string>
#include <utility>
#include <vector>

namespace CMGeom {
namespace IO {

class Atomic_output {
public:
  Atomic_output() = default;
  Atomic_output(const Atomic_output&) = delete;
  Atomic_output& operator=(const Atomic_output&) = delete;
  ~Atomic_output();

  /// Registers `final_path` and returns the temporary path to write it to.
  /// Throws IO_error when the directory of `final_path` does not exist.
  std::string add(const std::string& final_path);

  /// Renames every temporary file into place. Throws IO_error on failure (temporaries removed).
  void commit();

  /// Removes the temporaries (also done by the destructor when commit() was not called).
  void rollback() noexcept;

private:
  std::vector<std::pair<std::string, std::string>> files_;  // (temporary, final)
  bool committed_ = false;
};

/// Writes `content` to `path` atomically.
void write_file_atomically(const std::string& path, const std::string& content);

/// Same, but the file is registered in `out` (committed with its other files) instead of
/// committed at once; returns the temporary path that was written.
std::string write_file(const std::string& path, const std::string& content, Atomic_output& out);

}  // namespace IO
}  // namespace CMGeom

#endif  // CMGEOM_MESH_IO_ATOMIC_OUTPUT_H
