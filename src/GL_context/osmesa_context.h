// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Osmesa_context: one headless OpenGL core context (OSMesa, Mesa llvmpipe) with CMGeom's GL
// function table, shared by the OSMesa backends (Rendering's Renderer and Textured_simplification's
// index-texture resampler), which include it as "GL_context/osmesa_context.h" (target
// cmgeom_gl_context, src/GL_context/CMakeLists.txt).
// Its own framebuffer is a 16x16 dummy that only makes it current: OSMesa's buffer is not usable
// for data (glReadPixels clamps to [0, 1] and the buffer is only updated on flush), so every
// backend renders into framebuffer objects.
//
// Threads: a context is current in one thread at a time; call make_current() before GL work
// (several contexts may live in one thread, e.g. a Renderer next to a resampler).
#ifndef CMGEOM_SRC_GL_CONTEXT_OSMESA_CONTEXT_H
#define CMGEOM_SRC_GL_CONTEXT_OSMESA_CONTEXT_H

#include "GL_context/gl_functions.h"  // first: defines GL_GLEXT_PROTOTYPES before any GL header

#include <string>

namespace CMGeom {
namespace internal {

class Osmesa_context {
public:
  /// Creates a core context of at least version `major`.`minor` and makes it current. Throws
  /// CMGeom::Error when OSMesa cannot create one (`who` names the backend in the message).
  Osmesa_context(int major, int minor, const char* who);
  ~Osmesa_context();
  Osmesa_context(const Osmesa_context&) = delete;
  Osmesa_context& operator=(const Osmesa_context&) = delete;

  void make_current();
  /// Throws CMGeom::Error naming `where` if GL reported an error.
  void check(const char* where);
  /// Compiles and links a program; throws with the compiler's log.
  GLuint program(const char* vertex_source, const char* fragment_source);
  /// "renderer, GL version", e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6".
  const std::string& description() const { return description_; }

  GL_functions gl;

private:
  GLuint compile(GLenum type, const char* source);

  void* context_ = nullptr;  // OSMesaContext (kept opaque: GL/osmesa.h stays in the .cpp)
  unsigned char dummy_[16 * 16 * 4] = {};
  std::string description_;
};

}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_SRC_GL_CONTEXT_OSMESA_CONTEXT_H
