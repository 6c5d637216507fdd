// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// OSMesa implementation of CMGeom::Rendering::Renderer (see Renderer.h for the contract).
// Every picture goes to a multisampled sRGB FBO, whose resolved copy is read back (the context's
// own buffer is a dummy: src/GL_context/osmesa_context.h).
#include "GL_context/osmesa_context.h"  // first: defines GL_GLEXT_PROTOTYPES before any GL header

#include <CMGeom/Error.h>
#include <CMGeom/Rendering/Renderer.h>
#include <CMGeom/Rendering/colormap.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace CMGeom {
namespace Rendering {

namespace {

const char* const vertex_shader = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUV;
layout(location = 3) in float aScalar;
uniform mat4 uMVP;
uniform mat4 uMV;
out vec3 vPos;
out vec3 vNormal;
out vec2 vUV;
out float vScalar;
void main() {
  gl_Position = uMVP * vec4(aPos, 1.0);
  vPos = (uMV * vec4(aPos, 1.0)).xyz;
  vNormal = mat3(uMV) * aNormal;  // uMV is rigid: no inverse transpose needed
  vUV = aUV;
  vScalar = aScalar;
})";

// Modes: 0 smooth, 1 flat, 2 textured, 3 scalar field, 4 constant colour (lines).
// Colours arrive in linear space; the sRGB framebuffer encodes on write.
const char* const fragment_shader = R"(#version 330 core
uniform int uMode;
uniform int uLit;
uniform int uOrtho;
uniform vec3 uColor;
uniform sampler2D uTexture;
uniform sampler2D uColormap;
uniform vec2 uRange;  // (min, 1 / (max - min))
in vec3 vPos;
in vec3 vNormal;
in vec2 vUV;
in float vScalar;
layout(location = 0) out vec4 oColor;
void main() {
  if (uMode == 4) { oColor = vec4(uColor, 1.0); return; }
  vec3 base = uColor;
  if (uMode == 2) {
    base = texture(uTexture, vUV).rgb * uColor;
  } else if (uMode == 3) {
    if (isnan(vScalar)) base = vec3(0.22);
    else {
      float t = clamp((vScalar - uRange.x) * uRange.y, 0.0, 1.0);
      base = texture(uColormap, vec2((floor(t * 255.0 + 0.5) + 0.5) / 256.0, 0.5)).rgb;
    }
  }
  if (uLit == 0) { oColor = vec4(base, 1.0); return; }
  vec3 n;
  if (uMode == 1) {
    n = normalize(cross(dFdx(vPos), dFdy(vPos)));  // faces the viewer by construction
  } else {
    n = normalize(vNormal);
    if (!gl_FrontFacing) n = -n;
  }
  vec3 v = uOrtho == 1 ? vec3(0.0, 0.0, 1.0) : normalize(-vPos);
  vec3 l = normalize(vec3(0.35, 0.5, 1.0));  // key light above-left of the camera
  float diffuse = max(dot(n, l), 0.0);
  float ambient = uMode == 3 ? 0.45 : 0.22;
  float specular = uMode <= 1 ? 0.2 * pow(max(dot(n, normalize(l + v)), 0.0), 40.0) : 0.0;
  oColor = vec4(base * (ambient + (1.0 - ambient) * diffuse) + vec3(specular), 1.0);
})";

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// Column-major 4x4 matrices.
using Mat4 = std::array<float, 16>;

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 o{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      double s = 0.;
      for (int k = 0; k < 4; ++k) s += double(a[k * 4 + r]) * double(b[c * 4 + k]);
      o[c * 4 + r] = float(s);
    }
  return o;
}

struct Camera {
  Mat4 mv{}, mvp{};
  bool ortho = false;
};

Camera make_camera(const std::array<double, 6>& box, const Render_options& o) {
  const double pi = 3.14159265358979323846;
  const double c[3] = {(box[0] + box[3]) / 2, (box[1] + box[4]) / 2, (box[2] + box[5]) / 2};
  double R = 0.5 * std::sqrt((box[3] - box[0]) * (box[3] - box[0]) + (box[4] - box[1]) * (box[4] - box[1]) +
                             (box[5] - box[2]) * (box[5] - box[2]));
  if (!(R > 0.)) R = 1.;
  const double az = o.azimuth * pi / 180., el = o.elevation * pi / 180.;
  const double dir[3] = {std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
  double up[3] = {0., 1., 0.};
  if (std::abs(o.elevation) > 89.9) {  // looking straight down (up): +Z towards the bottom (top)
    up[1] = 0.;
    up[2] = o.elevation > 0 ? -1. : 1.;
  }
  const double aspect = double(o.width) / double(o.height);
  Camera cam;
  cam.ortho = o.projection == Projection::Orthographic;
  double dist, near_z, far_z;
  Mat4 P{};
  if (!cam.ortho) {
    const double half = 0.5 * o.field_of_view * pi / 180.;
    const double fit = aspect >= 1. ? half : std::atan(std::tan(half) * aspect);  // smaller side
    dist = R * o.margin / std::sin(fit);
    near_z = std::max(dist - 1.5 * R, 1e-3 * dist);
    far_z = dist + 1.5 * R;
    const double f = 1. / std::tan(half);
    P[0] = float(f / aspect);
    P[5] = float(f);
    P[10] = float((far_z + near_z) / (near_z - far_z));
    P[11] = -1.f;
    P[14] = float(2. * far_z * near_z / (near_z - far_z));
  } else {
    const double hh = o.ortho_half_height > 0. ? o.ortho_half_height : R * o.margin;
    const double top = aspect >= 1. ? hh : hh / aspect, right = aspect >= 1. ? hh * aspect : hh;
    const double extent = std::max(R, hh);
    dist = 3. * extent;
    near_z = dist - 2. * extent;
    far_z = dist + 2. * extent;
    P[0] = float(1. / right);
    P[5] = float(1. / top);
    P[10] = float(-2. / (far_z - near_z));
    P[14] = float(-(far_z + near_z) / (far_z - near_z));
    P[15] = 1.f;
  }
  // lookAt(eye = c + dist * dir, centre c, up)
  const double f[3] = {-dir[0], -dir[1], -dir[2]};
  double s[3] = {f[1] * up[2] - f[2] * up[1], f[2] * up[0] - f[0] * up[2], f[0] * up[1] - f[1] * up[0]};
  const double sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  for (double& x : s) x /= sl;
  const double u[3] = {s[1] * f[2] - s[2] * f[1], s[2] * f[0] - s[0] * f[2], s[0] * f[1] - s[1] * f[0]};
  const double eye[3] = {c[0] + dist * dir[0], c[1] + dist * dir[1], c[2] + dist * dir[2]};
  Mat4 V{};
  for (int k = 0; k < 3; ++k) {
    V[k * 4 + 0] = float(s[k]);
    V[k * 4 + 1] = float(u[k]);
    V[k * 4 + 2] = float(-f[k]);
  }
  V[12] = float(-(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]));
  V[13] = float(-(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]));
  V[14] = float(f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2]);
  V[15] = 1.f;
  cam.mv = V;
  cam.mvp = multiply(P, V);
  return cam;
}

}  // namespace

struct Renderer::Impl {
  CMGeom::internal::Osmesa_context context{3, 3, "renderer"};
  CMGeom::internal::GL_functions& gl = context.gl;
  GLuint program = 0, colormap = 0, white = 0;
  GLint u_mvp = -1, u_mv = -1, u_mode = -1, u_lit = -1, u_ortho = -1, u_color = -1, u_texture = -1, u_colormap = -1,
        u_range = -1;
  GLint max_samples = 0;
  // Framebuffers, recreated when the size or sample count changes.
  int fb_width = 0, fb_height = 0, fb_samples = -1;
  GLuint ms_fbo = 0, ms_color = 0, ms_depth = 0, resolve_fbo = 0, resolve_tex = 0;

  void make_current() { context.make_current(); }
  void check(const char* where) { context.check(where); }

  GLuint make_texture_rgba8(int w, int h, const std::uint8_t* rgba, bool mipmaps, GLint wrap) {
    GLuint t = 0;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8_ALPHA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
    if (mipmaps) gl.GenerateMipmap(GL_TEXTURE_2D);
    check("texture upload");
    return t;
  }

  // Image rows are top-first and v = 1 is the top; GL's texture row 0 is t = 0: flip.
  GLuint upload_image(const Image& img) {
    if (img.empty()) throw Invalid_input("cannot render with an empty texture image");
    const int w = img.width(), h = img.height(), nc = img.channels();
    std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        std::uint8_t* d = &rgba[(std::size_t(h - 1 - y) * w + x) * 4];
        for (int k = 0; k < 4; ++k) {
          int src = k;
          if (nc <= 2) src = k < 3 ? 0 : 1;  // grey (+ alpha)
          if (k == 3 && (nc == 1 || nc == 3)) {
            d[k] = 255;
            continue;
          }
          d[k] = img.format() == Image::Format::UInt8
                     ? img.bytes()[img.index(x, y, src)]
                     : std::uint8_t(std::lround(std::min(1.f, std::max(0.f, img.value(x, y, src))) * 255.f));
        }
      }
    return make_texture_rgba8(w, h, rgba.data(), true, GL_REPEAT);
  }

  void ensure_framebuffer(int w, int h, int samples) {
    samples = std::max(0, std::min(samples <= 1 ? 0 : samples, int(max_samples)));
    if (w == fb_width && h == fb_height && samples == fb_samples) return;
    release_framebuffer();
    gl.GenRenderbuffers(1, &ms_color);
    gl.BindRenderbuffer(GL_RENDERBUFFER, ms_color);
    gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_SRGB8_ALPHA8, w, h);
    gl.GenRenderbuffers(1, &ms_depth);
    gl.BindRenderbuffer(GL_RENDERBUFFER, ms_depth);
    gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
    gl.GenFramebuffers(1, &ms_fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, ms_fbo);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, ms_color);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, ms_depth);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("OpenGL: incomplete multisampled framebuffer");
    gl.GenTextures(1, &resolve_tex);
    gl.BindTexture(GL_TEXTURE_2D, resolve_tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8_ALPHA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.GenFramebuffers(1, &resolve_fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, resolve_tex, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("OpenGL: incomplete resolve framebuffer");
    check("framebuffer creation");
    fb_width = w;
    fb_height = h;
    fb_samples = samples;
  }

  void release_framebuffer() {
    if (ms_fbo) gl.DeleteFramebuffers(1, &ms_fbo);
    if (resolve_fbo) gl.DeleteFramebuffers(1, &resolve_fbo);
    if (ms_color) gl.DeleteRenderbuffers(1, &ms_color);
    if (ms_depth) gl.DeleteRenderbuffers(1, &ms_depth);
    if (resolve_tex) gl.DeleteTextures(1, &resolve_tex);
    ms_fbo = resolve_fbo = ms_color = ms_depth = resolve_tex = 0;
    fb_width = fb_height = 0;
    fb_samples = -1;
  }
};

Renderer::Renderer() : impl_(new Impl) {
  Impl& I = *impl_;
  I.gl.GetIntegerv(GL_MAX_SAMPLES, &I.max_samples);
  I.program = I.context.program(vertex_shader, fragment_shader);
  I.u_mvp = I.gl.GetUniformLocation(I.program, "uMVP");
  I.u_mv = I.gl.GetUniformLocation(I.program, "uMV");
  I.u_mode = I.gl.GetUniformLocation(I.program, "uMode");
  I.u_lit = I.gl.GetUniformLocation(I.program, "uLit");
  I.u_ortho = I.gl.GetUniformLocation(I.program, "uOrtho");
  I.u_color = I.gl.GetUniformLocation(I.program, "uColor");
  I.u_texture = I.gl.GetUniformLocation(I.program, "uTexture");
  I.u_colormap = I.gl.GetUniformLocation(I.program, "uColormap");
  I.u_range = I.gl.GetUniformLocation(I.program, "uRange");

  const auto table = viridis_table();
  I.colormap = I.make_texture_rgba8(256, 1, table.data(), false, GL_CLAMP_TO_EDGE);
  I.gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  I.gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  const std::uint8_t white[4] = {255, 255, 255, 255};
  I.white = I.make_texture_rgba8(1, 1, white, false, GL_REPEAT);
  I.check("renderer set-up");
}

Renderer::~Renderer() {
  if (!impl_) return;
  Impl& I = *impl_;
  try {
    I.make_current();
    I.release_framebuffer();
    if (I.program) I.gl.DeleteProgram(I.program);
    if (I.colormap) I.gl.DeleteTextures(1, &I.colormap);
    if (I.white) I.gl.DeleteTextures(1, &I.white);
  } catch (const Error&) {
    // the context is destroyed with its objects anyway
  }
}

std::string Renderer::description() const { return impl_->context.description(); }

Image Renderer::render(const Render_mesh& mesh, const Render_options& options) {
  return render_views(mesh, {options}).front();
}

std::vector<Image> Renderer::render_views(const Render_mesh& mesh, const std::vector<Render_options>& views) {
  Impl& I = *impl_;
  auto& gl = I.gl;
  for (const Render_options& o : views) {
    if (o.width < 1 || o.height < 1 || o.width > 16384 || o.height > 16384)
      throw Invalid_input("picture size must be between 1x1 and 16384x16384");
    if (o.shading == Shading::Field && !mesh.has_scalars())
      throw Invalid_input("scalar-field shading needs a field (one value per vertex)");
  }
  if (mesh.positions.empty()) throw Invalid_input("cannot render a mesh without faces");
  I.make_current();

  // ---- upload the mesh once
  GLuint vao = 0, buffers[5] = {0, 0, 0, 0, 0}, line_vao = 0;
  gl.GenVertexArrays(1, &vao);
  gl.BindVertexArray(vao);
  gl.GenBuffers(5, buffers);
  auto attribute = [&](GLuint index, GLuint buffer, const std::vector<float>& data, int size) {
    gl.BindBuffer(GL_ARRAY_BUFFER, buffer);
    gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
    gl.VertexAttribPointer(index, size, GL_FLOAT, GL_FALSE, 0, nullptr);
    gl.EnableVertexAttribArray(index);
  };
  attribute(0, buffers[0], mesh.positions, 3);
  attribute(1, buffers[1], mesh.normals, 3);
  if (mesh.has_uvs())
    attribute(2, buffers[2], mesh.uvs, 2);
  else
    gl.DisableVertexAttribArray(2);
  if (mesh.has_scalars())
    attribute(3, buffers[3], mesh.scalars, 1);
  else
    gl.DisableVertexAttribArray(3);
  gl.VertexAttrib2f(2, 0.f, 0.f);
  gl.VertexAttrib1f(3, 0.f);
  // Lines: the wireframe, then the chart boundaries, in one buffer.
  std::vector<float> lines(mesh.wire_lines);
  lines.insert(lines.end(), mesh.chart_lines.begin(), mesh.chart_lines.end());
  const GLsizei wire_vertices = GLsizei(mesh.wire_lines.size() / 3),
                chart_vertices = GLsizei(mesh.chart_lines.size() / 3);
  gl.GenVertexArrays(1, &line_vao);
  gl.BindVertexArray(line_vao);
  if (!lines.empty()) attribute(0, buffers[4], lines, 3);
  std::map<const Image*, GLuint> textures;
  for (const auto& r : mesh.ranges)
    if (r.texture && !textures.count(r.texture)) textures[r.texture] = I.upload_image(*r.texture);
  I.check("mesh upload");

  std::vector<Image> out;
  try {
    for (const Render_options& o : views) {
      const int W = o.width, H = o.height;
      I.ensure_framebuffer(W, H, o.samples);
      const Camera cam = make_camera(o.has_fit_box ? o.fit_box : mesh.bbox, o);
      gl.BindFramebuffer(GL_FRAMEBUFFER, I.ms_fbo);
      gl.Viewport(0, 0, W, H);
      gl.Enable(GL_FRAMEBUFFER_SRGB);
      gl.Enable(GL_MULTISAMPLE);
      gl.ClearColor(float(srgb_to_linear(o.background[0])), float(srgb_to_linear(o.background[1])),
                    float(srgb_to_linear(o.background[2])), 0.f);
      gl.ClearDepth(1.0);
      gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      gl.Enable(GL_DEPTH_TEST);
      gl.DepthFunc(GL_LEQUAL);
      gl.UseProgram(I.program);
      gl.UniformMatrix4fv(I.u_mvp, 1, GL_FALSE, cam.mvp.data());
      gl.UniformMatrix4fv(I.u_mv, 1, GL_FALSE, cam.mv.data());
      gl.Uniform1i(I.u_lit, o.lighting ? 1 : 0);
      gl.Uniform1i(I.u_ortho, cam.ortho ? 1 : 0);
      gl.Uniform1i(I.u_texture, 0);
      gl.Uniform1i(I.u_colormap, 1);
      double lo = std::isnan(o.field_min) ? mesh.scalar_min : o.field_min;
      double hi = std::isnan(o.field_max) ? mesh.scalar_max : o.field_max;
      gl.Uniform2f(I.u_range, float(lo), float(hi > lo ? 1. / (hi - lo) : 0.));
      gl.ActiveTexture(GL_TEXTURE1);
      gl.BindTexture(GL_TEXTURE_2D, I.colormap);
      gl.ActiveTexture(GL_TEXTURE0);
      const bool any_lines = (o.wireframe && wire_vertices) || (o.charts && chart_vertices);
      if (any_lines) {
        // Push the faces back a little so that their own edges win the depth test.
        gl.Enable(GL_POLYGON_OFFSET_FILL);
        gl.PolygonOffset(1.f, 1.f);
      }
      gl.BindVertexArray(vao);
      const std::array<double, 3> base = o.base_color;
      for (const auto& r : mesh.ranges) {
        int mode = 0;
        std::array<double, 3> color = base;
        switch (o.shading) {
          case Shading::Smooth:
            mode = 0;
            break;
          case Shading::Flat:
            mode = 1;
            break;
          case Shading::Field:
            mode = 3;
            break;
          case Shading::Textured:
            mode = mesh.has_uvs() ? 2 : 0;
            if (mode == 2 && r.texture) color = {{1., 1., 1.}};
            break;
        }
        gl.Uniform1i(I.u_mode, mode);
        gl.Uniform3f(I.u_color, float(srgb_to_linear(color[0])), float(srgb_to_linear(color[1])),
                     float(srgb_to_linear(color[2])));
        gl.BindTexture(GL_TEXTURE_2D, r.texture && mode == 2 ? textures[r.texture] : I.white);
        gl.DrawArrays(GL_TRIANGLES, GLint(r.first * 3), GLsizei(r.count * 3));
      }
      gl.Disable(GL_POLYGON_OFFSET_FILL);
      gl.BindVertexArray(line_vao);
      auto draw_lines = [&](GLint first, GLsizei count, const std::array<double, 3>& color, float width) {
        gl.Uniform1i(I.u_mode, 4);
        gl.Uniform3f(I.u_color, float(srgb_to_linear(color[0])), float(srgb_to_linear(color[1])),
                     float(srgb_to_linear(color[2])));
        gl.LineWidth(width);
        if (gl.GetError() != GL_NO_ERROR) gl.LineWidth(1.f);  // wide lines unsupported: thin ones
        gl.DrawArrays(GL_LINES, first, count);
      };
      if (o.wireframe && wire_vertices) draw_lines(0, wire_vertices, o.wire_color, o.wire_width);
      if (o.charts && chart_vertices) draw_lines(wire_vertices, chart_vertices, o.chart_color, o.chart_width);
      // Resolve the samples, read back (bottom row first), flip to top row first.
      gl.BindFramebuffer(GL_READ_FRAMEBUFFER, I.ms_fbo);
      gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, I.resolve_fbo);
      gl.BlitFramebuffer(0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
      gl.BindFramebuffer(GL_READ_FRAMEBUFFER, I.resolve_fbo);
      std::vector<std::uint8_t> pixels(std::size_t(W) * H * 4);
      gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
      gl.ReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
      I.check("rendering");
      Image img(W, H, 4);
      for (int y = 0; y < H; ++y)
        std::memcpy(img.bytes() + std::size_t(y) * W * 4, pixels.data() + std::size_t(H - 1 - y) * W * 4,
                    std::size_t(W) * 4);
      out.push_back(std::move(img));
    }
  } catch (...) {
    gl.GetError();
    gl.DeleteVertexArrays(1, &vao);
    gl.DeleteVertexArrays(1, &line_vao);
    gl.DeleteBuffers(5, buffers);
    for (auto& t : textures) gl.DeleteTextures(1, &t.second);
    throw;
  }
  gl.DeleteVertexArrays(1, &vao);
  gl.DeleteVertexArrays(1, &line_vao);
  gl.DeleteBuffers(5, buffers);
  for (auto& t : textures) gl.DeleteTextures(1, &t.second);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  return out;
}

Image Renderer::render_uv_atlas(const Render_mesh& mesh, int size, std::array<double, 3> line_color) {
  if (!mesh.has_uvs()) throw Invalid_input("the mesh has no texture coordinates: no UV atlas to draw");
  // A unit square carrying the texture, seen from +Z with an orthographic camera that frames
  // exactly [0,1]^2; the UV edges are drawn as its wireframe.
  Render_mesh quad;
  quad.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 1, 0, 0, 1, 0};
  quad.normals.assign(18, 0.f);
  for (int i = 0; i < 6; ++i) quad.normals[3 * i + 2] = 1.f;
  quad.uvs = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
  quad.ranges.push_back({0, 2, mesh.texture()});
  quad.wire_lines.reserve(mesh.uv_lines.size() / 2 * 3);
  for (std::size_t i = 0; i + 1 < mesh.uv_lines.size(); i += 2)
    quad.wire_lines.insert(quad.wire_lines.end(), {mesh.uv_lines[i], mesh.uv_lines[i + 1], 0.f});
  quad.bbox = {{0, 0, 0, 1, 1, 0}};
  Render_options o;
  o.width = o.height = size;
  o.shading = Shading::Textured;
  o.base_color = {{0.85, 0.85, 0.85}};
  o.lighting = false;
  o.wireframe = true;
  o.wire_color = line_color;
  o.projection = Projection::Orthographic;
  o.ortho_half_height = 0.5;
  o.azimuth = 0.;
  o.elevation = 0.;
  return render(quad, o);
}

}  // namespace Rendering
}  // namespace CMGeom
