// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// OpenGL index-texture resampler (see Osmesa_index_texture_resampler.h for the contract).
//
// GL objects: the index texture (RG32F, attached to the framebuffer object drawn into), its copy
// (RG32F, same coordinates; only the regions read by the pending batch are copied), the chart map
// of the original layout (R32UI), three shader storage buffers holding the batch's plans, and one
// vertex buffer. Per batch: upload, copy the read regions, one draw.
//
// Plan layout in the storage buffers, per collapse (offsets travel as flat vertex attributes):
//   ints:    n, then per wedge w (0, 1): x0, y0, x1, y1, has_copy; then per old triangle j:
//            valid, wedge
//   doubles: per old triangle j: the six barycentric coefficients; per new triangle: PM_{t'}
//   floats:  per new triangle: six per old triangle j (the composed map, zeros when invalid)
#include "GL_context/osmesa_context.h"  // first: defines GL_GLEXT_PROTOTYPES before any GL header

#include <CMGeom/Error.h>
#include <CMGeom/Textured_simplification/Osmesa_index_texture_resampler.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

namespace {

// Positions arrive in texel units, already on the 1/256 grid; uScale = 2 / P with P the power of
// two >= the texture sides, so x * uScale - 1 and the viewport transform back are exact.
const char* const vertex_shader = R"(#version 430 core
layout(location = 0) in vec2 aTexel;
layout(location = 1) in ivec4 aPlan;
uniform float uScale;
flat out ivec4 vPlan;
void main() {
  precise vec2 ndc = aTexel * uScale - 1.0;
  gl_Position = vec4(ndc, 0.0, 1.0);
  vPlan = aPlan;
})";

// Mirrors Resampling_plan::select_old_triangle, Resampling_plan::map_to_old and
// Index_texture_resampler::sample (Index_texture.h) operation by operation.
const char* const fragment_shader = R"(#version 430 core
layout(std430, binding = 0) readonly buffer Plan_doubles { double D[]; };
layout(std430, binding = 1) readonly buffer Plan_floats { float F[]; };
layout(std430, binding = 2) readonly buffer Plan_ints { int I[]; };
layout(binding = 0) uniform sampler2D uCopy;    // old index values (texelFetch only)
layout(binding = 1) uniform usampler2D uChart;  // chart id + 1 of the original layout
flat in ivec4 vPlan;  // offsets: PM_{t'} (doubles), barycentrics (doubles), ints, maps (floats)
layout(location = 0) out vec2 oIndex;

uint chart_of(vec2 a, ivec2 size) {
  if (!(a.x >= 0.0) || !(a.y >= 0.0)) return 0u;
  ivec2 p = min(ivec2(a), size - 1);
  return texelFetch(uChart, p, 0).r;
}

void main() {
  const int pm = vPlan.x, bary = vPlan.y, ints = vPlan.z, maps = vPlan.w;
  const int n = I[ints];
  // the old triangle whose projection contains the texel centre's image in the tangent plane
  precise double cx = double(gl_FragCoord.x);
  precise double cy = double(gl_FragCoord.y);
  precise double qx = (D[pm] * cx + D[pm + 1] * cy) + D[pm + 2];
  precise double qy = (D[pm + 3] * cx + D[pm + 4] * cy) + D[pm + 5];
  int best = n;
  double best_score = -1.0e300LF;
  for (int j = 0; j < n; ++j) {
    if (I[ints + 11 + 2 * j] == 0) continue;
    const int o = bary + 6 * j;
    precise double l1 = (D[o] * qx + D[o + 1] * qy) + D[o + 2];
    precise double l2 = (D[o + 3] * qx + D[o + 4] * qy) + D[o + 5];
    precise double l0 = (1.0LF - l1) - l2;
    double s = l1 < l0 ? l1 : l0;
    s = l2 < s ? l2 : s;
    if (s > best_score) {
      best_score = s;
      best = j;
      if (s >= 0.0LF) break;
    }
  }
  if (best == n) discard;
  const int r = ints + 1 + 5 * I[ints + 12 + 2 * best];
  if (I[r + 4] == 0) discard;
  const ivec2 lo = ivec2(I[r], I[r + 1]), hi = ivec2(I[r + 2], I[r + 3]);
  // its map, in float at the texel centre
  const int m = maps + 6 * best;
  precise float t0 = F[m] * gl_FragCoord.x;
  precise float t1 = F[m + 1] * gl_FragCoord.y;
  precise float t2 = F[m + 3] * gl_FragCoord.x;
  precise float t3 = F[m + 4] * gl_FragCoord.y;
  precise float sx = (t0 + t1) + F[m + 2];
  precise float sy = (t2 + t3) + F[m + 5];
  // chart-aware bilinear lookup inside the copied region
  const float lox = float(lo.x), loy = float(lo.y);
  precise float hix = float(hi.x) + 1.0;
  precise float hiy = float(hi.y) + 1.0;
  sx = sx < lox ? lox : sx;
  sx = hix < sx ? hix : sx;
  sy = sy < loy ? loy : sy;
  sy = hiy < sy ? hiy : sy;
  const ivec2 size = textureSize(uChart, 0);
  const vec2 an = texelFetch(uCopy, clamp(ivec2(floor(sx), floor(sy)), lo, hi), 0).rg;
  const uint cn = chart_of(an, size);
  precise float px = sx - 0.5;
  precise float py = sy - 0.5;
  const float flx = floor(px), fly = floor(py);
  precise float fx = px - flx;
  precise float fy = py - fly;
  const ivec2 i0 = ivec2(int(flx), int(fly));
  precise float a0 = 0.0;
  precise float a1 = 0.0;
  precise float ws = 0.0;
  if (cn != 0u) {
    for (int k = 0; k < 4; ++k) {
      const int ox = k & 1, oy = k >> 1;
      const vec2 q = texelFetch(uCopy, clamp(i0 + ivec2(ox, oy), lo, hi), 0).rg;
      precise float wx = ox == 1 ? fx : 1.0 - fx;
      precise float wy = oy == 1 ? fy : 1.0 - fy;
      precise float wt = wx * wy;
      if (chart_of(q, size) == cn) {
        precise float b0 = wt * q.x;
        precise float b1 = wt * q.y;
        a0 = a0 + b0;
        a1 = a1 + b1;
        ws = ws + wt;
      }
    }
  }
  if (ws > 0.0) {
    precise float o0 = a0 / ws;
    precise float o1 = a1 / ws;
    oIndex = vec2(o0, o1);
  } else {
    oIndex = an;
  }
})";

struct Vertex {
  float x, y;
  std::int32_t plan[4];
};

// Pending-write marks: tiles of this many texels a side.
constexpr int tile = 4;

}  // namespace

struct Osmesa_index_texture_resampler::Impl {
  Impl(Index_texture& texture, const Osmesa_resampler_options& o)
      : it(&texture), options(o), context(4, 3, "OSMesa index-texture resampler") {}

  Index_texture* it;
  Osmesa_resampler_options options;
  CMGeom::internal::Osmesa_context context;
  GLuint program = 0, index_tex = 0, copy_tex = 0, chart_tex = 0, fbo = 0, vao = 0, vbo = 0;
  GLuint storage[3] = {0, 0, 0};
  GLint u_scale = -1;
  int W = 0, H = 0, P = 1;
  internal::Resampling_plan plan;
  // the pending batch
  std::vector<double> doubles;
  std::vector<float> floats;
  std::vector<std::int32_t> ints;
  std::vector<Vertex> vertices;
  std::vector<internal::Resampling_plan::Rect> reads;
  std::size_t batch_collapses = 0;
  std::vector<std::uint32_t> written;  // per tile: the batch number that writes it
  std::uint32_t batch = 1;
  int tiles_x = 0, tiles_y = 0;
  std::size_t n_collapses = 0, n_draws = 0;

  GLuint make_texture(GLenum internal_format, GLenum format, GLenum type, const void* data) {
    auto& gl = context.gl;
    GLuint t = 0;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GLint(internal_format), W, H, 0, format, type, data);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    return t;
  }

  bool reads_pending_writes(const internal::Resampling_plan::Rect& r) const {
    for (int ty = r.y0 / tile; ty <= r.y1 / tile; ++ty)
      for (int tx = r.x0 / tile; tx <= r.x1 / tile; ++tx)
        if (written[std::size_t(ty) * std::size_t(tiles_x) + std::size_t(tx)] == batch) return true;
    return false;
  }

  void mark_written(int x0, int y0, int x1, int y1) {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    x1 = std::min(x1, W - 1);
    y1 = std::min(y1, H - 1);
    for (int ty = y0 / tile; ty <= y1 / tile; ++ty)
      for (int tx = x0 / tile; tx <= x1 / tile; ++tx)
        written[std::size_t(ty) * std::size_t(tiles_x) + std::size_t(tx)] = batch;
  }

  void add(const Collapse_record& rec) {
    plan.build(rec, it->domain(), W, H);
    ++n_collapses;
    if (plan.added.empty()) return;
    for (const auto& r : plan.rects)
      if (!r.empty() && reads_pending_writes(r)) {
        flush();
        break;
      }
    const std::size_t n = plan.old.size();
    const auto ints_base = std::int32_t(ints.size()), bary_base = std::int32_t(doubles.size());
    ints.push_back(std::int32_t(n));
    for (const auto& r : plan.rects) {
      ints.insert(ints.end(), {r.x0, r.y0, r.x1, r.y1, r.empty() ? 0 : 1});
      if (!r.empty()) reads.push_back(r);
    }
    for (const auto& o : plan.old) {
      ints.push_back(o.valid ? 1 : 0);
      ints.push_back(o.wedge);
      doubles.insert(doubles.end(), o.bary.begin(), o.bary.end());
    }
    double xmin = W, ymin = H, xmax = 0, ymax = 0;
    for (std::size_t k = 0; k < plan.added.size(); ++k) {
      const auto& t = plan.added[k];
      const auto pm_base = std::int32_t(doubles.size()), map_base = std::int32_t(floats.size());
      for (int r = 0; r < 2; ++r) doubles.insert(doubles.end(), t.pm[r], t.pm[r] + 3);
      for (std::size_t j = 0; j < n; ++j) floats.insert(floats.end(), plan.map(k, j).begin(), plan.map(k, j).end());
      if (!rasterizable(t.dst)) continue;  // the CPU rasteriser skips such triangles too
      for (const auto& c : t.dst) {
        // the rasteriser's own snapping, exact in float below 2^15 texels
        constexpr float steps = float(rasterizer_subtexel_steps);
        const float x = float(snap_to_subtexel(c[0])) / steps, y = float(snap_to_subtexel(c[1])) / steps;
        vertices.push_back(Vertex{x, y, {pm_base, bary_base, ints_base, map_base}});
        xmin = std::min(xmin, c[0]);
        ymin = std::min(ymin, c[1]);
        xmax = std::max(xmax, c[0]);
        ymax = std::max(ymax, c[1]);
      }
    }
    if (xmin <= xmax)
      mark_written(int(std::floor(xmin)) - 1, int(std::floor(ymin)) - 1, int(std::ceil(xmax)) + 1,
                   int(std::ceil(ymax)) + 1);
    if (++batch_collapses >= options.max_batch) flush();
  }

  template <class T>
  void upload_storage(int binding, const std::vector<T>& data) {
    auto& gl = context.gl;
    gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, storage[binding]);
    const T zero{};
    gl.BufferData(GL_SHADER_STORAGE_BUFFER, GLsizeiptr(std::max<std::size_t>(data.size(), 1) * sizeof(T)),
                  data.empty() ? &zero : data.data(), GL_STREAM_DRAW);
    gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, GLuint(binding), storage[binding]);
  }

  void flush() {
    if (!vertices.empty()) {
      context.make_current();
      auto& gl = context.gl;
      for (const auto& r : reads)
        gl.CopyImageSubData(index_tex, GL_TEXTURE_2D, 0, r.x0, r.y0, 0, copy_tex, GL_TEXTURE_2D, 0, r.x0, r.y0, 0,
                            r.x1 - r.x0 + 1, r.y1 - r.y0 + 1, 1);
      upload_storage(0, doubles);
      upload_storage(1, floats);
      upload_storage(2, ints);
      gl.BindVertexArray(vao);
      gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
      gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(), GL_STREAM_DRAW);
      gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
      gl.UseProgram(program);
      gl.ActiveTexture(GL_TEXTURE0);
      gl.BindTexture(GL_TEXTURE_2D, copy_tex);
      gl.ActiveTexture(GL_TEXTURE1);
      gl.BindTexture(GL_TEXTURE_2D, chart_tex);
      gl.DrawArrays(GL_TRIANGLES, 0, GLsizei(vertices.size()));
      context.check("index-texture resampling");
      ++n_draws;
    }
    doubles.clear();
    floats.clear();
    ints.clear();
    vertices.clear();
    reads.clear();
    batch_collapses = 0;
    if (++batch == 0) {  // wrapped: forget every mark
      std::fill(written.begin(), written.end(), 0u);
      batch = 1;
    }
  }

  void release() {
    auto& gl = context.gl;
    if (program) gl.DeleteProgram(program);
    if (fbo) gl.DeleteFramebuffers(1, &fbo);
    if (vao) gl.DeleteVertexArrays(1, &vao);
    if (vbo) gl.DeleteBuffers(1, &vbo);
    if (storage[0]) gl.DeleteBuffers(3, storage);
    const GLuint textures[3] = {index_tex, copy_tex, chart_tex};
    gl.DeleteTextures(3, textures);
  }
};

Osmesa_index_texture_resampler::Osmesa_index_texture_resampler(Index_texture& it,
                                                               const Osmesa_resampler_options& options)
    : impl_(new Impl(it, options)) {
  Impl& I = *impl_;
  I.W = it.width();
  I.H = it.height();
  if (I.W < 1 || I.H < 1) throw Invalid_input("OSMesa index-texture resampler: the index texture is empty");
  GLint max_size = 0;
  auto& gl = I.context.gl;
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (I.W > max_size || I.H > max_size)
    throw Invalid_input("OSMesa index-texture resampler: " + std::to_string(I.W) + "x" + std::to_string(I.H) +
                        " texels exceed the OpenGL limit of " + std::to_string(max_size));
  while (I.P < std::max(I.W, I.H)) I.P *= 2;
  try {
    I.program = I.context.program(vertex_shader, fragment_shader);
    I.u_scale = gl.GetUniformLocation(I.program, "uScale");
    I.index_tex = I.make_texture(GL_RG32F, GL_RG, GL_FLOAT, it.data().data());
    I.copy_tex = I.make_texture(GL_RG32F, GL_RG, GL_FLOAT, it.data().data());
    std::vector<std::uint32_t> charts(std::size_t(I.W) * std::size_t(I.H));
    for (int y = 0; y < I.H; ++y)
      for (int x = 0; x < I.W; ++x) charts[std::size_t(y) * std::size_t(I.W) + std::size_t(x)] = it.chart(x, y);
    I.chart_tex = I.make_texture(GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, charts.data());
    gl.GenFramebuffers(1, &I.fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, I.fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, I.index_tex, 0);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error("OSMesa index-texture resampler: the RG32F framebuffer is incomplete");
    gl.GenBuffers(3, I.storage);
    gl.GenVertexArrays(1, &I.vao);
    gl.BindVertexArray(I.vao);
    gl.GenBuffers(1, &I.vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, I.vbo);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, x)));
    gl.VertexAttribIPointer(1, 4, GL_INT, sizeof(Vertex), reinterpret_cast<void*>(offsetof(Vertex, plan)));
    gl.EnableVertexAttribArray(0);
    gl.EnableVertexAttribArray(1);
    gl.UseProgram(I.program);
    gl.Uniform1f(I.u_scale, 2.f / float(I.P));
    gl.Viewport(0, 0, I.P, I.P);
    gl.Scissor(0, 0, I.W, I.H);
    gl.Enable(GL_SCISSOR_TEST);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_CULL_FACE);
    I.context.check("OSMesa index-texture resampler set-up");
  } catch (...) {
    I.release();
    throw;
  }
  I.tiles_x = (I.W + tile - 1) / tile;
  I.tiles_y = (I.H + tile - 1) / tile;
  I.written.assign(std::size_t(I.tiles_x) * std::size_t(I.tiles_y), 0u);
}

Osmesa_index_texture_resampler::~Osmesa_index_texture_resampler() {
  if (!impl_) return;
  try {
    impl_->context.make_current();
    impl_->release();
  } catch (const Error&) {
    // the context is destroyed with its objects anyway
  }
}

void Osmesa_index_texture_resampler::operator()(const Collapse_record& record) { impl_->add(record); }

void Osmesa_index_texture_resampler::synchronize() {
  Impl& I = *impl_;
  I.flush();
  I.context.make_current();
  auto& gl = I.context.gl;
  gl.BindTexture(GL_TEXTURE_2D, I.index_tex);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
  gl.GetTexImage(GL_TEXTURE_2D, 0, GL_RG, GL_FLOAT, I.it->data().data());
  I.context.check("index-texture read-back");
}

std::string Osmesa_index_texture_resampler::description() const { return impl_->context.description(); }
std::size_t Osmesa_index_texture_resampler::collapses() const { return impl_->n_collapses; }
std::size_t Osmesa_index_texture_resampler::draws() const { return impl_->n_draws; }

}  // namespace Textured_simplification
}  // namespace CMGeom
