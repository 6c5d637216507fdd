// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The OpenGL entry points the OSMesa backends use, loaded through a get-proc-address callback
// (OSMesaGetProcAddress; an EGL provider would pass eglGetProcAddress). We never call the gl*
// symbols directly: libOSMesa exports them, but so does libGL, and whichever comes first on the
// link line wins — with libGL first every call silently becomes a no-op.
// Note: OSMesaGetProcAddress never returns null (unknown names get a generated stub), so
// availability is checked through GL_VERSION, not through the pointers.
#ifndef CMGEOM_SRC_GL_CONTEXT_GL_FUNCTIONS_H
#define CMGEOM_SRC_GL_CONTEXT_GL_FUNCTIONS_H

#define GL_GLEXT_PROTOTYPES 1  // only for decltype(&::glFoo) below; nothing is linked against
#include <GL/gl.h>
#include <GL/glext.h>

// The GL entry points the package loads, several per line.
// clang-format off
#define CMGEOM_GL_FUNCTIONS(X)                                                                    \
  X(GetString) X(GetIntegerv) X(GetError) X(Viewport) X(Clear) X(ClearColor) X(ClearDepth)        \
  X(Enable) X(Disable) X(DepthFunc) X(Finish) X(PixelStorei) X(ReadPixels) X(GenTextures)        \
  X(DeleteTextures) X(BindTexture) X(TexImage2D) X(TexParameteri) X(ActiveTexture)               \
  X(GenerateMipmap) X(GenFramebuffers) X(DeleteFramebuffers) X(BindFramebuffer)                  \
  X(FramebufferTexture2D) X(FramebufferRenderbuffer) X(CheckFramebufferStatus)                   \
  X(GenRenderbuffers) X(DeleteRenderbuffers) X(BindRenderbuffer)                                 \
  X(RenderbufferStorageMultisample) X(BlitFramebuffer) X(CreateShader) X(ShaderSource)           \
  X(CompileShader) X(GetShaderiv) X(GetShaderInfoLog) X(CreateProgram) X(AttachShader)           \
  X(LinkProgram) X(GetProgramiv) X(GetProgramInfoLog) X(UseProgram) X(DeleteShader)              \
  X(DeleteProgram) X(GetUniformLocation) X(Uniform1i) X(Uniform1f) X(Uniform2f) X(Uniform3f)     \
  X(UniformMatrix4fv) X(GenVertexArrays) X(BindVertexArray) X(DeleteVertexArrays) X(GenBuffers)  \
  X(BindBuffer) X(BufferData) X(DeleteBuffers) X(VertexAttribPointer) X(EnableVertexAttribArray) \
  X(DisableVertexAttribArray) X(VertexAttrib1f) X(VertexAttrib2f) X(VertexAttrib3f)              \
  X(DrawArrays) X(PolygonOffset) X(LineWidth) X(Scissor) X(CopyImageSubData) X(BindBufferBase)     \
  X(VertexAttribIPointer) X(GetTexImage)
// clang-format on

namespace CMGeom {
namespace internal {

struct GL_functions {
#define CMGEOM_GL_MEMBER(name) decltype(&::gl##name) name = nullptr;
  CMGEOM_GL_FUNCTIONS(CMGEOM_GL_MEMBER)
#undef CMGEOM_GL_MEMBER

  /// Fills the table; returns false if a name could not be resolved.
  template <class GetProc>
  bool load(GetProc getproc) {
    bool ok = true;
#define CMGEOM_GL_LOAD(name)                                    \
  name = reinterpret_cast<decltype(name)>(getproc("gl" #name)); \
  ok = ok && name != nullptr;
    CMGEOM_GL_FUNCTIONS(CMGEOM_GL_LOAD)
#undef CMGEOM_GL_LOAD
    return ok;
  }
};

}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_SRC_GL_CONTEXT_GL_FUNCTIONS_H
