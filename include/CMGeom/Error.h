// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Exceptions thrown for bad user input (files, meshes, parameters). Library preconditions that
// only a programming error can break use CGAL_precondition instead. Every message is one line
// naming the file (when there is one), the line (when it applies) and what is wrong.
#ifndef CMGEOM_ERROR_H
#define CMGEOM_ERROR_H

#include <cstddef>
#include <stdexcept>
#include <string>

namespace CMGeom {

/// Base of every CMGeom input error.
class Error : public std::runtime_error {
public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A file could not be read or written, or its content is malformed.
/// `what()` reads "<file>:<line>: <message>" (or "<file>: <message>" when no line applies).
class IO_error : public Error {
public:
  IO_error(std::string file, std::size_t line, std::string message)
      : Error(format(file, line, message)), file_(std::move(file)), line_(line), message_(std::move(message)) {}
  IO_error(std::string file, std::string message) : IO_error(std::move(file), 0, std::move(message)) {}

  const std::string& file() const { return file_; }
  std::size_t line() const { return line_; }  ///< 0 when no line applies
  const std::string& message() const { return message_; }

private:
  static std::string format(const std::string& f, std::size_t l, const std::string& m) {
    return l ? f + ":" + std::to_string(l) + ": " + m : f + ": " + m;
  }
  std::string file_;
  std::size_t line_;
  std::string message_;
};

/// A mesh or parameter is valid as data but unusable for the requested operation
/// (non-manifold where a manifold is required, target out of range, ...).
class Invalid_input : public Error {
public:
  explicit Invalid_input(const std::string& what) : Error(what) {}
};

}  // namespace CMGeom

#endif  // CMGEOM_ERROR_H
