// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CPU picture composition used around the renderer: text (a built-in 5x7 pixel font, so that no
// font library is needed and pictures are bit-identical everywhere), the colour-bar legend of
// scalar-field pictures, captions, and side-by-side grids of pictures with captions (the layout
// of the thesis' comparison figures, e.g. Figures 3.3 and 5.2).
//
// Images are 8-bit RGB or RGBA, row 0 at the top. Text is upper case only (lower-case letters
// are drawn as capitals); characters without a glyph are drawn as '?'.
//
// Complexity: O(pixels written).
#ifndef CMGEOM_RENDERING_COMPOSE_H
#define CMGEOM_RENDERING_COMPOSE_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Image.h>
#include <CMGeom/Rendering/colormap.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace CMGeom {
namespace Rendering {

namespace internal {
/// 5x7 glyph of `c`: 7 rows, bit 4 = leftmost column.
inline const std::uint8_t* glyph(char c) {
  struct G {
    char c;
    std::uint8_t rows[7];
  };
  static const G font[] = {
      {' ', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}}, {'!', {0x04, 0x04, 0x04, 0x04, 0x04, 0x00, 0x04}},
      {'#', {0x0A, 0x0A, 0x1F, 0x0A, 0x1F, 0x0A, 0x0A}}, {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
      {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}}, {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
      {'*', {0x00, 0x04, 0x15, 0x0E, 0x15, 0x04, 0x00}}, {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
      {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
      {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
      {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
      {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
      {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
      {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
      {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
      {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {';', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x04, 0x08}},
      {'<', {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02}}, {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
      {'>', {0x08, 0x04, 0x02, 0x01, 0x02, 0x04, 0x08}}, {'?', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x00, 0x04}},
      {'A', {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}}, {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
      {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}}, {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
      {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
      {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}}, {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
      {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}}, {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
      {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}}, {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
      {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}}, {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
      {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
      {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}}, {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
      {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}}, {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
      {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}}, {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
      {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}}, {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
      {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}}, {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
      {'[', {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}}, {']', {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}},
      {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}}};
  if (c >= 'a' && c <= 'z') c = char(c - 'a' + 'A');
  for (const G& g : font)
    if (g.c == c) return g.rows;
  return glyph('?');
}
}  // namespace internal

/// Width in pixels of `text` drawn at `scale` (each glyph cell is 6 x 8 pixels at scale 1).
inline int text_width(const std::string& text, int scale = 1) { return int(text.size()) * 6 * scale; }
inline int text_height(int scale = 1) { return 8 * scale; }

/// Draws `text` with its top-left corner at (x, y); clipped to the image.
inline void draw_text(Image& img, int x, int y, const std::string& text, std::array<std::uint8_t, 3> color,
                      int scale = 1) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const std::uint8_t* rows = internal::glyph(text[i]);
    const int gx = x + int(i) * 6 * scale;
    for (int r = 0; r < 7; ++r)
      for (int c = 0; c < 5; ++c) {
        if (!(rows[r] & (0x10 >> c))) continue;
        for (int sy = 0; sy < scale; ++sy)
          for (int sx = 0; sx < scale; ++sx) {
            const int px = gx + c * scale + sx, py = y + r * scale + sy;
            if (px < 0 || py < 0 || px >= img.width() || py >= img.height()) continue;
            for (int k = 0; k < 3; ++k) img.bytes()[img.index(px, py, k)] = color[k];
            if (img.channels() == 4) img.bytes()[img.index(px, py, 3)] = 255;
          }
      }
  }
}

/// Fills the rectangle [x0, x1) x [y0, y1) (clipped).
inline void fill_rect(Image& img, int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> color) {
  for (int y = std::max(0, y0); y < std::min(img.height(), y1); ++y)
    for (int x = std::max(0, x0); x < std::min(img.width(), x1); ++x) {
      for (int k = 0; k < 3; ++k) img.bytes()[img.index(x, y, k)] = color[k];
      if (img.channels() == 4) img.bytes()[img.index(x, y, 3)] = 255;
    }
}

/// Shortest readable label of a value ("%.3g").
inline std::string format_value(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

/// Text scale that suits a picture of this size (1 up to 600 px, then larger).
inline int text_scale_for(const Image& img) { return std::max(1, std::min(img.width(), img.height()) / 500); }

/// Draws a vertical viridis colour bar near the right edge with min / mid / max labels and an
/// optional title: the legend of a Shading::Field picture.
inline void draw_legend(Image& img, double vmin, double vmax, const std::string& title = std::string()) {
  const int s = text_scale_for(img);
  const int bar_w = 14 * s, bar_h = std::max(40, img.height() * 2 / 5);
  const std::string labels[3] = {format_value(vmax), format_value(0.5 * (vmin + vmax)), format_value(vmin)};
  int label_w = 0;
  for (const auto& l : labels) label_w = std::max(label_w, text_width(l, s));
  const int x1 = img.width() - 8 * s - label_w - 4 * s;  // right end of the bar
  const int x0 = x1 - bar_w;
  const int y0 = (img.height() - bar_h) / 2, y1 = y0 + bar_h;
  const std::array<std::uint8_t, 3> ink{{20, 20, 20}};
  fill_rect(img, x0 - 1, y0 - 1, x1 + 1, y1 + 1, ink);
  for (int y = y0; y < y1; ++y) {
    const double t = 1. - double(y - y0) / double(std::max(1, bar_h - 1));
    fill_rect(img, x0, y, x1, y + 1, viridis(t));
  }
  const int th = text_height(s);
  draw_text(img, x1 + 4 * s, y0 - th / 2, labels[0], ink, s);
  draw_text(img, x1 + 4 * s, (y0 + y1) / 2 - th / 2, labels[1], ink, s);
  draw_text(img, x1 + 4 * s, y1 - th / 2, labels[2], ink, s);
  if (!title.empty()) draw_text(img, std::max(0, x1 - text_width(title, s)), y0 - th - 6 * s, title, ink, s);
}

/// Draws `caption` in the bottom-left corner.
inline void draw_caption(Image& img, const std::string& caption) {
  if (caption.empty()) return;
  const int s = text_scale_for(img);
  draw_text(img, 6 * s, img.height() - text_height(s) - 6 * s, caption, {{20, 20, 20}}, s);
}

/// An opaque RGB copy of an RGB or RGBA 8-bit image (alpha dropped: renders are already
/// composited over their background).
inline Image to_rgb(const Image& in) {
  if (in.format() != Image::Format::UInt8 || in.channels() < 3)
    throw Invalid_input("to_rgb: 8-bit RGB(A) image expected");
  Image out(in.width(), in.height(), 3);
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x)
      for (int k = 0; k < 3; ++k) out.bytes()[out.index(x, y, k)] = in.bytes()[in.index(x, y, k)];
  return out;
}

/// Side-by-side grid: cells (all of the same size) in rows of `columns`, each with its caption
/// in a strip below it, on a white background, 8-bit RGB.
inline Image make_grid(const std::vector<Image>& cells, const std::vector<std::string>& captions, int columns) {
  if (cells.empty()) throw Invalid_input("make_grid: no picture");
  const int w = cells[0].width(), h = cells[0].height();
  for (const Image& c : cells)
    if (c.width() != w || c.height() != h || c.channels() < 3 || c.format() != Image::Format::UInt8)
      throw Invalid_input("make_grid: pictures must be 8-bit RGB(A) of the same size");
  columns = std::max(1, std::min(columns, int(cells.size())));
  const int rows = (int(cells.size()) + columns - 1) / columns;
  const int s = std::max(1, std::min(w, h) / 300);
  const int strip = captions.empty() ? 0 : text_height(s) + 8 * s, gap = 4;
  Image out(columns * w + (columns + 1) * gap, rows * (h + strip) + (rows + 1) * gap, 3);
  fill_rect(out, 0, 0, out.width(), out.height(), {{255, 255, 255}});
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const int cx = gap + int(i % columns) * (w + gap), cy = gap + int(i / columns) * (h + strip + gap);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 3; ++k)
          out.bytes()[out.index(cx + x, cy + y, k)] = cells[i].bytes()[cells[i].index(x, y, k)];
    if (i < captions.size()) draw_text(out, cx + 2 * s, cy + h + 4 * s, captions[i], {{20, 20, 20}}, s);
  }
  return out;
}

}  // namespace Rendering
}  // namespace CMGeom

#endif  // CMGEOM_RENDERING_COMPOSE_H
