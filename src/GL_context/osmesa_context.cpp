// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
#include "GL_context/osmesa_context.h"

#include <GL/osmesa.h>
#include <dlfcn.h>

#include <CMGeom/Error.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <vector>

namespace CMGeom {
namespace internal {

namespace {

// libOSMesa's four entry points the context uses, from the library opened when the first context
// is made rather than linked: libOSMesa brings Mesa's llvmpipe and LLVM with it, whose loading
// and static initialisation were most of the cmgeom tool's start-up (70-80 ms of every command,
// rendering or not, on a 2-core VM; 15-20 ms without). The library stays open until the program
// ends (its contexts may live that long). The environment variable CMGEOM_OSMESA_LIBRARY, when set
// and not empty, names the one library to open (another Mesa build), instead of libOSMesa.so.8
// and then the development link found at configure time.
struct Osmesa_api {
  decltype(&OSMesaCreateContextAttribs) create_context = nullptr;
  decltype(&OSMesaGetProcAddress) get_proc_address = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  std::string error;  // why it cannot be used (empty: it can)
};

const Osmesa_api& osmesa() {
  static const Osmesa_api api = [] {
    Osmesa_api a;
    void* library = nullptr;
    std::string tried;
    std::vector<const char*> names = {"libOSMesa.so.8", CMGEOM_OSMESA_LIBRARY};
    const char* chosen = std::getenv("CMGEOM_OSMESA_LIBRARY");
    if (chosen && *chosen) names = {chosen};
    for (const char* name : names) {
      library = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (library) break;
      const char* why = dlerror();
      tried += std::string(tried.empty() ? "" : "; ") + (why ? why : name);
    }
    if (!library) {
      a.error = "cannot load libOSMesa (" + tried + ")";
      return a;
    }
    const auto symbol = [&](auto& f, const char* name) {
      f = reinterpret_cast<std::remove_reference_t<decltype(f)>>(dlsym(library, name));
      if (!f && a.error.empty()) a.error = std::string("libOSMesa has no ") + name;
    };
    symbol(a.create_context, "OSMesaCreateContextAttribs");
    symbol(a.get_proc_address, "OSMesaGetProcAddress");
    symbol(a.destroy_context, "OSMesaDestroyContext");
    symbol(a.make_current, "OSMesaMakeCurrent");
    return a;
  }();
  return api;
}

// A GL info log on one line (error messages are one line).
std::string one_line(const char* log) {
  std::string s(log);
  for (char& ch : s)
    if (ch == '\n') ch = ' ';
  return s;
}
}  // namespace

Osmesa_context::Osmesa_context(int major, int minor, const char* who) {
  // Core 3.3 is requested because llvmpipe refuses 4.6 but upgrades any lower core request to
  // 4.5; the version actually obtained is checked below.
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            0,
                            OSMESA_STENCIL_BITS,
                            0,
                            OSMESA_ACCUM_BITS,
                            0,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            3,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            3,
                            0};
  const Osmesa_api& api = osmesa();
  if (!api.error.empty()) throw Error(std::string(who) + ": " + api.error);
  OSMesaContext c = api.create_context(attributes, nullptr);
  if (!c) throw Error(std::string(who) + ": OSMesa cannot create an OpenGL core context");
  context_ = c;
  try {
    make_current();
    if (!gl.load([](const char* name) { return osmesa().get_proc_address(name); }))
      throw Error(std::string(who) + ": OSMesa is missing OpenGL entry points");
    const char* version = reinterpret_cast<const char*>(gl.GetString(GL_VERSION));
    const char* renderer = reinterpret_cast<const char*>(gl.GetString(GL_RENDERER));
    GLint got_major = 0, got_minor = 0;
    gl.GetIntegerv(GL_MAJOR_VERSION, &got_major);
    gl.GetIntegerv(GL_MINOR_VERSION, &got_minor);
    if (!version || got_major * 10 + got_minor < major * 10 + minor)
      throw Error(std::string(who) + ": OpenGL " + std::to_string(major) + "." + std::to_string(minor) +
                  " or later is required, OSMesa offers " + (version ? version : "none"));
    description_ = std::string(renderer ? renderer : "?") + ", " + version;
  } catch (...) {
    api.destroy_context(c);
    context_ = nullptr;
    throw;
  }
}

Osmesa_context::~Osmesa_context() {
  if (context_) osmesa().destroy_context(static_cast<OSMesaContext>(context_));
}

void Osmesa_context::make_current() {
  if (!osmesa().make_current(static_cast<OSMesaContext>(context_), dummy_, GL_UNSIGNED_BYTE, 16, 16))
    throw Error("OSMesa: cannot make the OpenGL context current");
}

void Osmesa_context::check(const char* where) {
  const GLenum e = gl.GetError();
  if (e != GL_NO_ERROR) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "OpenGL error 0x%04x in %s", unsigned(e), where);
    throw Error(buf);
  }
}

GLuint Osmesa_context::compile(GLenum type, const char* source) {
  const GLuint s = gl.CreateShader(type);
  gl.ShaderSource(s, 1, &source, nullptr);
  gl.CompileShader(s);
  GLint ok = 0;
  gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetShaderInfoLog(s, sizeof log, nullptr, log);
    gl.DeleteShader(s);
    throw Error("OpenGL shader compilation failed: " + one_line(log));
  }
  return s;
}

GLuint Osmesa_context::program(const char* vertex_source, const char* fragment_source) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_source);
  } catch (...) {
    gl.DeleteShader(vs);
    throw;
  }
  const GLuint p = gl.CreateProgram();
  gl.AttachShader(p, vs);
  gl.AttachShader(p, fs);
  gl.LinkProgram(p);
  GLint ok = 0;
  gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
  gl.DeleteShader(vs);
  gl.DeleteShader(fs);
  if (!ok) {
    char log[2048] = {};
    gl.GetProgramInfoLog(p, sizeof log, nullptr, log);
    gl.DeleteProgram(p);
    throw Error("OpenGL program does not link: " + one_line(log));
  }
  return p;
}

}  // namespace internal
}  // namespace CMGeom
