// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Overflow charts of the texture shared by every level of a chain (simplify_to_levels() with
// `shared_texture`). The input is mapped into the coarsest level's atlas by projecting each of its
// parts on the coarse face it became (map_by_history()). Where the input is steep against that
// face (the side of a ridge the coarse level flattened) the projection squashes it into a sliver
// of texels, and where two parts fold onto one place (a visor over a helmet) one of them loses its
// texels to the other; the finer levels, which still have those parts, show them smeared or in the
// other part's colours. Those faces of the input, the ones left with less than half of the atlas'
// density in some direction or that lost most of their texels (and those under a finer level's
// face that reads colours other than a bake's, Shown_colour_error), get charts of their own (grown and
// parameterised as rebuild_atlas() does, by LSCM), packed at the atlas' texel density into a strip
// added under the atlas, where they paint their own colours. A finer level's face that stands for
// them (most of the input's faces that ended on it have such a chart) addresses that chart: each of
// its corners takes the coordinates of its closest point on those input faces. The coarsest level
// never does: its faces are the surface the atlas above the strip was made for.
// Not part of the documented interface.
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_ATLAS_LAYERS_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_ATLAS_LAYERS_H

#include <CMGeom/Compact_model/internal/Vec3.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Textured_simplification/internal/atlas_charts.h>
#include <CMGeom/Textured_simplification/internal/collapse_history.h>
#include <CMGeom/Textured_simplification/rebuild_atlas.h>
#include <CMGeom/internal/huge_pages.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {
namespace internal {

/// The strip of overflow charts under an atlas of width x base_height texels: a texture
/// coordinate (u, v) of the atlas becomes base() of it; an input face with an overflow chart has
/// its own coordinates there.
struct Atlas_layers {
  int width = 0, base_height = 0, strip_height = 0;
  std::size_t charts = 0;
  /// Per input face: its overflow chart (-1: none) and, when it has one, its corners' coordinates
  /// (in the order of halfedges_around_face from halfedge(f)).
  std::vector<std::int32_t> chart_of_input_face;
  std::vector<std::array<Point_2, 3>> input_uv;
  /// The share of the input's area given overflow charts, and the share of the texels the input
  /// covers in the atlas that faces without one lost to another part of the input.
  double area_share = 0, hidden_share = 0;
  /// The texel densities (texels per length unit) of the atlas and of the strip.
  double base_texels_per_unit = 0, texels_per_unit = 0;

  double total_height() const { return double(base_height) + double(strip_height); }
  Point_2 base(const Point_2& p) const {
    return Point_2(p.x(), (p.y() * double(base_height) + double(strip_height)) / total_height());
  }
};

/// Gives every face corner of `mesh` its coordinates in the atlas with the strip (Atlas_layers::base()).
inline void move_to_layered_atlas(Textured_mesh& mesh, const Atlas_layers& layers) {
  if (layers.strip_height == 0) return;
  for (auto h : mesh.mesh().halfedges())
    if (!mesh.mesh().is_border(h)) mesh.set_uv(h, layers.base(mesh.uv(h)));
}

/// The corners of face f of m (in the order of corner_halfedge()) as Vec3.
inline std::array<CM::internal::Vec3, 3> corner_points(const Surface_mesh& m, Surface_mesh::Face_index f) {
  std::array<CM::internal::Vec3, 3> p;
  for (int k = 0; k < 3; ++k) {
    const Point_3& q = m.point(m.target(corner_halfedge(m, f, k)));
    p[std::size_t(k)] = CM::internal::Vec3(q.x(), q.y(), q.z());
  }
  return p;
}

/// The singular values {least, greatest} of the affine map that takes triangle p (length units)
/// to triangle t (texels): the texels per length unit in the direction it squashes most and in the
/// one it stretches most ({0, 0}: degenerate).
inline std::array<double, 2> texels_per_unit_range(const std::array<CM::internal::Vec3, 3>& p,
                                                   const std::array<UV2, 3>& t) {
  using CM::internal::dot;
  const auto e1 = p[1] - p[0], e2 = p[2] - p[0];
  const double l1 = std::sqrt(dot(e1, e1));
  if (!(l1 > 0)) return {{0, 0}};
  const double x2 = dot(e2, e1) / l1, y2 = std::sqrt((std::max)(0.0, dot(e2, e2) - x2 * x2));
  if (!(y2 > 0)) return {{0, 0}};
  // J = T X^-1 with X = [[l1, x2], [0, y2]] (the edges in the triangle's plane), T the texel edges
  const double a = t[1][0] - t[0][0], b = t[2][0] - t[0][0], c = t[1][1] - t[0][1], d = t[2][1] - t[0][1];
  const double j11 = a / l1, j12 = (b - a * x2 / l1) / y2, j21 = c / l1, j22 = (d - c * x2 / l1) / y2;
  const double f = j11 * j11 + j12 * j12 + j21 * j21 + j22 * j22, det = j11 * j22 - j12 * j21;
  const double g = std::sqrt((std::max)(0.0, f * f - 4 * det * det));
  return {{std::sqrt((std::max)(0.0, 0.5 * (f - g))), std::sqrt(0.5 * (f + g))}};
}

/// The smallest singular value of texels_per_unit_range().
inline double least_texels_per_unit(const std::array<CM::internal::Vec3, 3>& p, const std::array<UV2, 3>& t) {
  return texels_per_unit_range(p, t)[0];
}

/// Marks in `marked` (one entry per input face) the input faces whose centroid point
/// (`input_face_point`) ended (`on_level`) on a face of a level that `flagged` (one entry per face
/// of that level) flags.
inline void mark_input_under(const std::vector<char>& flagged, const std::vector<std::uint32_t>& input_face_point,
                             const std::vector<std::uint32_t>& on_level, std::vector<char>& marked) {
  for (std::size_t j = 0; j < input_face_point.size() && j < marked.size(); ++j) {
    const std::uint32_t q = input_face_point[j];
    if (q < on_level.size() && on_level[q] < flagged.size() && flagged[on_level[q]]) marked[j] = 1;
  }
}

/// Marks in `marked` (one entry per input face) the input faces whose centroid points
/// (`input_face_point`) ended (`on_level`) on a face of `level` that its texture coordinates in a
/// W x H atlas serve poorly: squashed (least stretch, least_texels_per_unit(), below half
/// `texels_per_unit`), stretched (greatest stretch above twice it: the face spans a chart's gutter
/// and what lies beyond) or with a corner on the texture's edge (clamped there by on_texture(): it
/// was mapped past the atlas). A finer level's face can be served so where none of the input faces
/// under it is (its corners, mapped through the history past a chart's border, fall on one line of
/// texels or beyond the chart), and it then shows a smear of that border or another chart's colours.
inline void mark_input_under_poorly_served(const Textured_mesh& level, int W, int H, double texels_per_unit,
                                           const std::vector<std::uint32_t>& input_face_point,
                                           const std::vector<std::uint32_t>& on_level, std::vector<char>& marked) {
  using Face = Surface_mesh::Face_index;
  const Surface_mesh& lm = level.mesh();
  const std::size_t nl = lm.number_of_faces();
  std::vector<char> poor(nl, 0);
  for (Face f : lm.faces()) {
    std::array<UV2, 3> t;
    bool on_edge = false;
    for (int k = 0; k < 3; ++k) {
      const Point_2 uv = level.uv(corner_halfedge(lm, f, k));
      t[std::size_t(k)] = {{uv.x() * W, uv.y() * H}};
      on_edge = on_edge || !(uv.x() > 0 && uv.x() < 1 && uv.y() > 0 && uv.y() < 1);
    }
    const std::array<double, 2> range = texels_per_unit_range(corner_points(lm, f), t);
    poor[std::size_t(f)] = on_edge || range[0] < 0.5 * texels_per_unit || range[1] > 2 * texels_per_unit;
  }
  mark_input_under(poor, input_face_point, on_level, marked);
}

/// How far the colours a face of a level shows from an atlas are from those a bake would give it:
/// the face is sampled at fixed barycentric points (its centroid and the midpoints between it and
/// its corners); each sample reads the atlas (bilinear, through the face's texture coordinates)
/// and is set against the input's colour at its closest point facing the same way
/// (Atlas_source::colour_near(), what rebuild_atlas() paints there).
class Shown_colour_error {
public:
  Shown_colour_error(const Image& atlas, const Atlas_source& source) : atlas_(atlas), source_(source) {
    channels_ = (std::min)(3, (std::min)(atlas.channels(), source.colour_channels()));
  }

  /// The sums of the squared colour differences (values in [0, 1]) of the samples of the level's
  /// face with corners `p`, under each texture coordinates of `t`; `count` the number of values
  /// in each sum. `hint`: a face of the input likely near the face (Atlas_source::colour_near()).
  template <std::size_t N>
  std::array<double, N> squared_errors(const std::array<CM::internal::Vec3, 3>& p,
                                       const std::array<std::array<Point_2, 3>, N>& t, std::size_t& count,
                                       std::size_t hint = std::size_t(-1)) const {
    const CM::internal::Vec3 nv = CM::internal::cross(p[1] - p[0], p[2] - p[0]);
    const Vector_3 n(nv.x, nv.y, nv.z);
    return sum_errors(t, count, [&](const double* b, float* own) {
      const CM::internal::Vec3 x = b[0] * p[0] + b[1] * p[1] + b[2] * p[2];
      source_.colour_near(Point_3(x.x, x.y, x.z), n, own, hint);
    });
  }

  /// The same for the input's own face `face` (face order of the original the source was made
  /// from, corners in corner_halfedge() order): its colours are read there, with no search.
  template <std::size_t N>
  std::array<double, N> squared_errors_on_input_face(std::size_t face, const std::array<std::array<Point_2, 3>, N>& t,
                                                     std::size_t& count) const {
    return sum_errors(t, count, [&](const double* b, float* own) { source_.colour_at(face, b[0], b[1], b[2], own); });
  }

private:
  // the four samples (the centroid and the midpoints between it and the corners), each compared
  // under every texture coordinates of `t`; own_colour(b, out) gives the colour to match at
  // barycentric coordinates b
  template <std::size_t N, class Own>
  std::array<double, N> sum_errors(const std::array<std::array<Point_2, 3>, N>& t, std::size_t& count,
                                   const Own& own_colour) const {
    std::array<double, N> sum{};
    count = 0;
    const int W = atlas_.width(), H = atlas_.height(), C = channels_;
    if (W <= 0 || H <= 0 || C <= 0) return sum;
    for (int s = 0; s < 4; ++s) {
      double b[3] = {1. / 3, 1. / 3, 1. / 3};
      if (s > 0) {
        for (int k = 0; k < 3; ++k) b[k] = 1. / 6;
        b[s - 1] = 2. / 3;
      }
      float own[4];
      own_colour(b, own);
      for (std::size_t i = 0; i < N; ++i) {
        const double u = (std::min)((std::max)(b[0] * t[i][0].x() + b[1] * t[i][1].x() + b[2] * t[i][2].x(), 0.0), 1.0);
        const double v = (std::min)((std::max)(b[0] * t[i][0].y() + b[1] * t[i][1].y() + b[2] * t[i][2].y(), 0.0), 1.0);
        const double fx = u * W - 0.5, fy = (1 - v) * H - 0.5;  // image rows run down
        const int x0 = (std::max)(0, (std::min)(W - 1, int(std::floor(fx))));
        const int y0 = (std::max)(0, (std::min)(H - 1, int(std::floor(fy))));
        const int x1 = (std::min)(W - 1, x0 + 1), y1 = (std::min)(H - 1, y0 + 1);
        const float ax = float((std::min)(1.0, (std::max)(0.0, fx - x0)));
        const float ay = float((std::min)(1.0, (std::max)(0.0, fy - y0)));
        for (int c = 0; c < C; ++c) {
          const float shown = (1 - ax) * (1 - ay) * atlas_.value(x0, y0, c) + ax * (1 - ay) * atlas_.value(x1, y0, c) +
                              (1 - ax) * ay * atlas_.value(x0, y1, c) + ax * ay * atlas_.value(x1, y1, c);
          sum[i] += double(shown - own[c]) * double(shown - own[c]);
        }
      }
      count += std::size_t(C);
    }
    return sum;
  }

  const Image& atlas_;
  const Atlas_source& source_;
  int channels_ = 0;
};

/// The faces of `tm` whose colours through its texture coordinates are off by more than `tolerance`
/// (root mean square, colour values in [0, 1]): `squared_errors(face index, corners' coordinates,
/// count)` gives a face's sum of squared differences (Shown_colour_error) and its number of values.
/// One flag per face; faces on all cores.
template <class SquaredErrors>
std::vector<char> faces_shown_wrong(const Textured_mesh& tm, double tolerance, const SquaredErrors& squared_errors) {
  using Face = Surface_mesh::Face_index;
  const Surface_mesh& m = tm.mesh();
  std::vector<char> wrong(m.number_of_faces(), 0);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, wrong.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t f = r.begin(); f != r.end(); ++f) {
          std::array<std::array<Point_2, 3>, 1> t;
          for (int k = 0; k < 3; ++k)
            t[0][std::size_t(k)] = tm.uv(corner_halfedge(m, Face(static_cast<Surface_mesh::size_type>(f)), k));
          std::size_t n = 0;
          const double sum = squared_errors(f, t, n);
          wrong[f] = n > 0 && sum > tolerance * tolerance * double(n);
        }
      });
  return wrong;
}

/// Marks in `marked` (one entry per input face) the input faces under the faces of `level`, mapped
/// into the atlas `colours` (as map_by_history() leaves it), that show colours other than a bake's
/// (Shown_colour_error): those whose root mean square difference exceeds `tolerance` (colour
/// values in [0, 1]). The input faces under a level's face are those whose centroid point
/// (`input_face_point`) ended on it (`on_level`). It sees what the geometric tests of
/// mark_input_under_poorly_served() miss: a finer level's face laid over a chart of the coarsest
/// level whose map does not follow it.
inline void mark_input_under_shown_wrong(const Textured_mesh& level, const Image& colours, const Atlas_source& source,
                                         const std::vector<std::uint32_t>& input_face_point,
                                         const std::vector<std::uint32_t>& on_level, double tolerance,
                                         std::vector<char>& marked) {
  using Face = Surface_mesh::Face_index;
  const Surface_mesh& lm = level.mesh();
  const std::size_t nl = lm.number_of_faces();
  const Shown_colour_error error(colours, source);
  // per face of the level, an input face under it (the first whose centroid point ended there):
  // the closest-point searches start from it
  std::vector<std::size_t> under(nl, std::size_t(-1));
  for (std::size_t j = 0; j < input_face_point.size(); ++j) {
    const std::uint32_t q = input_face_point[j];
    if (q < on_level.size() && on_level[q] < nl && under[on_level[q]] == std::size_t(-1)) under[on_level[q]] = j;
  }
  const std::vector<char> wrong =
      faces_shown_wrong(level, tolerance, [&](std::size_t f, const auto& t, std::size_t& n) {
        return error.squared_errors(corner_points(lm, Face(static_cast<Surface_mesh::size_type>(f))), t, n,
                                    under[f])[0];
      });
  mark_input_under(wrong, input_face_point, on_level, marked);
}

/// Marks in `marked` (one entry per input face) the faces of `mapped`, the input with its texture
/// coordinates in the atlas `colours` (as paint_input_onto() leaves them), that show colours other
/// than their own (Shown_colour_error::squared_errors_on_input_face(): the input's texture read on
/// the face itself): those whose root mean square difference exceeds `tolerance`. `mapped` has the
/// faces, in the same order and with the same corners, of the original `source` was made from
/// (otherwise nothing is marked). It sees what the won-texel count of add_overflow_charts() misses
/// on the input level itself: a face that kept most of its texels but shows another part's colours
/// on the rest, or whose texels a neighbour's map smeared.
inline void mark_input_shown_wrong(const Textured_mesh& mapped, const Image& colours, const Atlas_source& source,
                                   double tolerance, std::vector<char>& marked) {
  const std::size_t nf = mapped.mesh().number_of_faces();
  if (nf != source.number_of_faces() || nf > marked.size()) return;  // (not the original's faces)
  const Shown_colour_error error(colours, source);
  const std::vector<char> wrong = faces_shown_wrong(
      mapped, tolerance,
      [&](std::size_t f, const auto& t, std::size_t& n) { return error.squared_errors_on_input_face(f, t, n)[0]; });
  for (std::size_t f = 0; f < nf; ++f)
    if (wrong[f]) marked[f] = 1;
}

/// The point of texel triangle `t` (twice its signed area `twice_area`, not 0) nearest to
/// (x, y): its barycentric coordinates in `t`, and its squared distance to (x, y).
inline std::pair<std::array<double, 3>, double> nearest_on_texel_triangle(const std::array<UV2, 3>& t,
                                                                          double twice_area, double x, double y) {
  using CM::internal::Vec3;
  const Vec3 p(x, y, 0);
  const Vec3 q = CM::internal::closest_on_triangle(p, Vec3(t[0][0], t[0][1], 0), Vec3(t[1][0], t[1][1], 0),
                                                   Vec3(t[2][0], t[2][1], 0));
  const UV2 r{{q.x, q.y}};
  const double b1 = signed_area_2(t[0], r, t[2]) / twice_area, b2 = signed_area_2(t[0], t[1], r) / twice_area;
  return {{{1 - b1 - b2, b1, b2}}, CM::internal::squared_length(q - p)};
}

/// The overflow charts of the shared atlas of `coarse` (its UVs and its one material's images, as
/// rebuild_atlas() with the painter left them; `texels_per_unit` its density), painted from
/// `source`. `mapped`: the input with its texture coordinates in that atlas, `texels` as
/// paint_input_onto() gave them. A face of the input needs its own chart when its map into the
/// atlas squashes it (its least stretch, least_texels_per_unit(), below half the atlas' density)
/// or when it won fewer than half of the texels it covers, or when `also_poor` marks it (the faces
/// under a finer level's poorly served face, mark_input_under_poorly_served()); such faces joined by edges form groups,
/// and a group gets charts when its area is at least 64 texels at that density (below, the gutters around its charts
/// would take more texels than it shows). The charts are packed at the atlas' density or more into a strip as wide as
/// the atlas and as short as that allows, at most half as tall as the atlas (then at a lower density: on DamagedHelmet
/// and texturedknot a strip as tall as the atlas gave the same image error at every level). On return `coarse`'s UVs
/// and images are those of the layered atlas; `mapped` is left as it is (see move_to_layered_atlas(),
/// Atlas_layers::input_uv).
inline Atlas_layers add_overflow_charts(const Atlas_source& source, Textured_mesh& coarse, const Textured_mesh& mapped,
                                        const Face_texels& texels, double texels_per_unit, const Atlas_options& options,
                                        const std::vector<char>& also_poor = {}) {
  using Face = Surface_mesh::Face_index;
  Atlas_layers L;
  if (coarse.materials().size() != 1) return L;
  Material& material = coarse.materials()[0];
  const Image& old_colours = material.diffuse_image;
  const int W = old_colours.width(), H = old_colours.height();
  L.width = W;
  L.base_height = H;
  const Surface_mesh& im = mapped.mesh();
  const std::size_t nf = im.number_of_faces();
  L.chart_of_input_face.assign(nf, -1);
  if (W <= 0 || H <= 0 || texels.covered.size() != nf || !(texels_per_unit > 0)) return L;
  const double rho2 = texels_per_unit * texels_per_unit;
  L.base_texels_per_unit = texels_per_unit;

  // the input faces the projection serves poorly
  std::vector<Vector_3> normal(nf);
  std::vector<double> area(nf);
  std::vector<char> poor(nf, 0);
  double total_area = 0;
  for (Face f : im.faces()) {
    const std::size_t i = std::size_t(f);
    std::array<Point_3, 3> p;
    std::array<Point_2, 3> t;
    for (int k = 0; k < 3; ++k) {
      const auto h = corner_halfedge(im, f, k);
      p[std::size_t(k)] = im.point(im.target(h));
      t[std::size_t(k)] = mapped.uv(h);
    }
    const Vector_3 c = CGAL::cross_product(p[1] - p[0], p[2] - p[0]);
    area[i] = 0.5 * std::sqrt(c.squared_length());
    normal[i] = unit_or_zero(c);
    total_area += area[i];
    std::array<UV2, 3> texels_of;
    for (int k = 0; k < 3; ++k) texels_of[std::size_t(k)] = {{t[std::size_t(k)].x() * W, t[std::size_t(k)].y() * H}};
    const bool squashed = least_texels_per_unit(corner_points(im, f), texels_of) < 0.5 * texels_per_unit;
    const bool hidden = texels.covered[i] > 0 && 2 * texels.won[i] < texels.covered[i];
    const bool under_poor_level_face = i < also_poor.size() && also_poor[i];
    poor[i] = area[i] > 0 && (squashed || hidden || under_poor_level_face);
  }
  std::vector<std::uint32_t> parent(nf);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (auto e : im.edges()) {
    const auto h = im.halfedge(e);
    if (im.is_border(h) || im.is_border(im.opposite(h))) continue;
    const std::size_t f = std::size_t(im.face(h)), g = std::size_t(im.face(im.opposite(h)));
    if (poor[f] && poor[g]) {
      const std::uint32_t a = find(std::uint32_t(f)), b = find(std::uint32_t(g));
      if (a != b) parent[(std::max)(a, b)] = (std::min)(a, b);
    }
  }
  std::vector<double> group_area(nf, 0);
  for (std::size_t i = 0; i < nf; ++i)
    if (poor[i]) group_area[find(std::uint32_t(i))] += area[i];
  std::vector<std::uint32_t> subset;
  double moved_area = 0;
  for (std::size_t i = 0; i < nf; ++i)
    if (poor[i] && group_area[find(std::uint32_t(i))] * rho2 >= 64) {
      subset.push_back(std::uint32_t(i));
      moved_area += area[i];
    }
  if (subset.empty()) return L;

  // their charts, packed into the shortest strip that keeps the atlas' density (bisection)
  std::vector<Atlas_chart> charts = make_charts(im, normal, area, options.chart_cone_degrees, subset);
  auto density = [&](int strip) {
    std::vector<Atlas_chart> trial = charts;
    return pack_charts(trial, W, strip, options.gutter_texels);
  };
  int lo = 0, hi = H / 2;
  if (density(hi) >= texels_per_unit) {
    while (hi - lo > 4) {
      const int mid = (lo + hi) / 2;
      if (density(mid) >= texels_per_unit)
        hi = mid;
      else
        lo = mid;
    }
  }
  const int S = (hi + 3) / 4 * 4;
  L.texels_per_unit = pack_charts(charts, W, S, options.gutter_texels);
  L.strip_height = S;
  L.charts = charts.size();
  L.area_share = total_area > 0 ? moved_area / total_area : 0;
  L.input_uv.assign(nf, {});
  std::vector<std::array<Atlas_uv, 3>> strip_uv(nf);  // the same in the strip's own [0, 1]²
  const double HT = double(H) + double(S);
  for (std::size_t c = 0; c < charts.size(); ++c)
    for (std::size_t j = 0; j < charts[c].faces.size(); ++j) {
      const std::uint32_t f = charts[c].faces[j];
      L.chart_of_input_face[f] = std::int32_t(c);
      strip_uv[f] = charts[c].uvs[j];
      for (int k = 0; k < 3; ++k) {
        const Atlas_uv& t = strip_uv[f][std::size_t(k)];
        L.input_uv[f][std::size_t(k)] = Point_2(t[0], t[1] * double(S) / HT);
      }
    }
  std::size_t covered = 0, still_hidden = 0;
  for (std::size_t i = 0; i < nf; ++i) {
    covered += texels.covered[i];
    if (L.chart_of_input_face[i] < 0) still_hidden += texels.covered[i] - texels.won[i];
  }
  L.hidden_share = covered > 0 ? double(still_hidden) / double(covered) : 0.0;

  // the layered images: the atlas on top (image rows run down), the strip under it
  const int HTi = H + S, C = old_colours.channels();
  const Image& old_normals = material.normal_image;
  const bool with_normals = !old_normals.empty() && source.has_normal_maps();
  auto stacked = [&](const Image& old) {
    Image out(W, HTi, old.channels(), old.format());
    const std::size_t values = std::size_t(W) * std::size_t(H) * std::size_t(old.channels());
    if (old.format() == Image::Format::UInt8)
      std::memcpy(out.bytes(), old.bytes(), values);
    else
      std::memcpy(out.floats(), old.floats(), values * sizeof(float));
    return out;
  };
  Image colours = stacked(old_colours);
  Image normals = with_normals ? stacked(old_normals) : Image();
  // each chart's faces paint their texels of the strip (charts do not share texels: the packing
  // leaves gutters between them), then the painted texels grow over the gutters
  std::vector<char> painted = CMGeom::internal::filled_on_huge_pages(std::size_t(W) * std::size_t(S), char(0));
  std::vector<std::int32_t> owner(painted.size(), -1);  // the chart of each texel, then the nearest
  // strip texel (x, y) (y up) painted by input face i at barycentric coordinates b, its normal in
  // `frame` (the frame of its texel triangle)
  auto paint_texel = [&](std::uint32_t i, const std::array<Vector_3, 3>& frame, int x, int y,
                         const std::array<double, 3>& b) {
    float col[4];
    const int Y = HTi - 1 - y;
    source.colour_at(i, b[0], b[1], b[2], col);
    for (int q = 0; q < C; ++q) colours.set_value(x, Y, q, col[q]);
    if (with_normals) {
      const Vector_3 n = source.normal_at(i, b[0], b[1], b[2]);
      for (int q = 0; q < 3; ++q) normals.set_value(x, Y, q, float(0.5 * (n * frame[std::size_t(q)]) + 0.5));
    }
  };
  auto frame_of = [&](std::uint32_t i, const std::array<UV2, 3>& t) {
    std::array<Vector_3, 3> frame;
    if (with_normals) {
      std::array<Point_3, 3> p;
      std::array<Atlas_uv, 3> uv;
      for (int k = 0; k < 3; ++k) {
        p[std::size_t(k)] = im.point(im.target(corner_halfedge(im, Face(i), k)));
        uv[std::size_t(k)] = {{t[std::size_t(k)][0], t[std::size_t(k)][1]}};
      }
      frame = tangent_frame(p, uv);
    }
    return frame;
  };
  auto strip_triangle = [&](std::uint32_t f) {  // input face f's corners in strip texels
    std::array<UV2, 3> t;
    for (int k = 0; k < 3; ++k)
      t[std::size_t(k)] = {{strip_uv[f][std::size_t(k)][0] * W, strip_uv[f][std::size_t(k)][1] * S}};
    return t;
  };
  // input face i rasterised at texel triangle t of the strip (corners in the order of
  // halfedges_around_face from halfedge(i)): its colours, and its normals in the frame of t, at the
  // texels `take(at)` accepts
  auto paint_face = [&](std::uint32_t i, const std::array<UV2, 3>& t, const auto& take) {
    const double det = signed_area_2(t[0], t[1], t[2]);
    if (det == 0 || !std::isfinite(det)) return;
    const std::array<Vector_3, 3> frame = frame_of(i, t);
    rasterize_triangle(t, W, S, [&](int x, int y) {
      if (!take(std::size_t(y) * std::size_t(W) + std::size_t(x))) return;
      paint_texel(i, frame, x, y, texel_centre_barycentric(t, det, x, y));
    });
  };
  std::vector<char> chart_painted(charts.size(), 0);  // (each written by its chart's task only)
  tbb::parallel_for(std::size_t(0), charts.size(), [&](std::size_t c) {
    for (std::size_t j = 0; j < charts[c].faces.size(); ++j) {
      const std::uint32_t f = charts[c].faces[j];
      paint_face(f, strip_triangle(f), [&](std::size_t at) {
        painted[at] = 1;
        owner[at] = std::int32_t(c);
        chart_painted[c] = 1;
        return true;
      });
    }
  });
  // the faces around each chart, unfolded about the chart's face they touch (its map extended),
  // paint the texels of its gutter (the texels nearer to it than to another chart): a finer
  // level's face that crosses the chart's border reads their colours there
  {
    grow_rings(
        W, S, options.gutter_texels + 1, [&](std::size_t at) { return owner[at] != -1; },
        [&](std::size_t at) { return owner[at] == -1; },
        [&](const Grid_texel& to, const Grid_texel& from) {
          owner[to.at] = owner[from.at];
          return true;
        });
    std::vector<char> ring_painted(painted.size(), 0);
    tbb::parallel_for(std::size_t(0), charts.size(), [&](std::size_t c) {  // (texels owned by c only)
      std::vector<std::uint32_t> ring;
      for (std::uint32_t f : charts[c].faces)
        for (auto v : CGAL::vertices_around_face(im.halfedge(Face(f)), im))
          for (Face g : CGAL::faces_around_target(im.halfedge(v), im))
            if (g != Surface_mesh::null_face() && L.chart_of_input_face[std::size_t(g)] != std::int32_t(c))
              ring.push_back(std::uint32_t(g));
      std::sort(ring.begin(), ring.end());
      ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
      for (std::uint32_t g : ring) {
        // the chart's face sharing the most corners with g, and g's corners under its map
        const std::array<CM::internal::Vec3, 3> gp = corner_points(im, Face(g));
        std::uint32_t best = 0;
        int shared = 0;
        for (auto v : CGAL::vertices_around_face(im.halfedge(Face(g)), im))
          for (Face f : CGAL::faces_around_target(im.halfedge(v), im))
            if (f != Surface_mesh::null_face() && L.chart_of_input_face[std::size_t(f)] == std::int32_t(c)) {
              int n = 0;
              for (auto a : CGAL::vertices_around_face(im.halfedge(f), im))
                for (auto b : CGAL::vertices_around_face(im.halfedge(Face(g)), im)) n += a == b;
              if (n > shared) {
                shared = n;
                best = std::uint32_t(f);
              }
            }
        if (shared == 0) continue;
        const std::array<CM::internal::Vec3, 3> fp = corner_points(im, Face(best));
        std::array<Point_2, 3> fuv;
        for (int k = 0; k < 3; ++k)
          fuv[std::size_t(k)] = Point_2(strip_uv[best][std::size_t(k)][0], strip_uv[best][std::size_t(k)][1]);
        std::array<UV2, 3> t;
        for (int k = 0; k < 3; ++k) {
          const Point_2 q = extended_uv(fp, fuv, gp[std::size_t(k)], 1e300);
          t[std::size_t(k)] = {{q.x() * W, q.y() * S}};
        }
        if (!(signed_area_2(t[0], t[1], t[2]) > 0)) continue;  // folded over the chart
        paint_face(g, t, [&](std::size_t at) {
          // (the owner first: the task of the chart that owns the texel may be writing ring_painted there)
          if (owner[at] != std::int32_t(c) || painted[at] || ring_painted[at]) return false;
          ring_painted[at] = 1;
          return true;
        });
      }
    });
    for (std::size_t at = 0; at < painted.size(); ++at) painted[at] = char(painted[at] | ring_painted[at]);
  }
  // A face thinner than a texel may cover no texel centre, and a chart made of such faces only (a
  // band of slivers, e.g. a thin rim) then paints nothing: its faces would read the colours the
  // gutter growth below brings from other charts (a chart that paints some texels grows its own
  // into the rest). Such a chart's faces paint the texels whose centres lie within half a texel's
  // diagonal of them, with the colour of their nearest point. Those texels lie inside the chart's
  // cell of the packing (its faces start a gutter and half a texel into it), where no other chart
  // paints; within the chart the first face in its order takes a texel.
  const double reach = 0.5 * std::sqrt(2.0);  // (the squared bound below: 0.5)
  tbb::parallel_for(std::size_t(0), charts.size(), [&](std::size_t c) {
    if (chart_painted[c]) return;
    for (std::uint32_t f : charts[c].faces) {
      const std::array<UV2, 3> t = strip_triangle(f);
      const double det = signed_area_2(t[0], t[1], t[2]);
      if (det == 0 || !std::isfinite(det)) continue;
      const std::array<Vector_3, 3> frame = frame_of(f, t);
      const int x0 = (std::max)(0, int(std::floor((std::min)({t[0][0], t[1][0], t[2][0]}) - reach)));
      const int x1 = (std::min)(W - 1, int(std::floor((std::max)({t[0][0], t[1][0], t[2][0]}) + reach)));
      const int y0 = (std::max)(0, int(std::floor((std::min)({t[0][1], t[1][1], t[2][1]}) - reach)));
      const int y1 = (std::min)(S - 1, int(std::floor((std::max)({t[0][1], t[1][1], t[2][1]}) + reach)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const std::size_t at = std::size_t(y) * std::size_t(W) + std::size_t(x);
          if (painted[at]) continue;
          const auto [b, d2] = nearest_on_texel_triangle(t, det, x + 0.5, y + 0.5);
          if (!(d2 <= 0.5)) continue;
          paint_texel(f, frame, x, y, b);
          painted[at] = 1;
        }
    }
  });
  auto copy_texel = [&](int tx, int ty, int fx, int fy) {  // strip texel coordinates (y up)
    colours.copy_pixel(tx, HTi - 1 - ty, fx, HTi - 1 - fy, C);
    if (with_normals) normals.copy_pixel(tx, HTi - 1 - ty, fx, HTi - 1 - fy, 3);
  };
  grow_rings(
      W, S, options.gutter_texels, [&](std::size_t at) { return painted[at] != 0; },
      [&](std::size_t at) { return !painted[at]; },
      [&](const Grid_texel& to, const Grid_texel& from) {
        copy_texel(to.x, to.y, from.x, from.y);
        painted[to.at] = 1;
        return true;
      });
  // the texels farther from every chart (read only by coarse mipmap levels) take the colour of the
  // nearest painted texel of their row, rows without one that of the row below (or above)
  std::vector<char> row_painted(std::size_t(S), 0);
  tbb::parallel_for(0, S, [&](int y) {
    const std::size_t row = std::size_t(y) * std::size_t(W);
    int last = -1;
    std::vector<int> left(std::size_t(W), -1);
    for (int x = 0; x < W; ++x) {
      if (painted[row + std::size_t(x)]) last = x;
      left[std::size_t(x)] = last;
    }
    if (last < 0) return;
    row_painted[std::size_t(y)] = 1;
    int next = -1;
    for (int x = W - 1; x >= 0; --x) {
      if (painted[row + std::size_t(x)]) {
        next = x;
        continue;
      }
      const int l = left[std::size_t(x)];
      const int from = l < 0 ? next : (next < 0 || x - l <= next - x ? l : next);
      copy_texel(x, y, from, y);
    }
  });
  for (int y = 1; y < S; ++y)  // rows without a painted texel, from below
    if (!row_painted[std::size_t(y)] && row_painted[std::size_t(y - 1)]) {
      for (int x = 0; x < W; ++x) copy_texel(x, y, x, y - 1);
      row_painted[std::size_t(y)] = 1;
    }
  for (int y = S - 2; y >= 0; --y)  // and from above
    if (!row_painted[std::size_t(y)] && row_painted[std::size_t(y + 1)]) {
      for (int x = 0; x < W; ++x) copy_texel(x, y, x, y + 1);
      row_painted[std::size_t(y)] = 1;
    }
  material.diffuse_image = std::move(colours);
  if (with_normals) material.normal_image = std::move(normals);
  move_to_layered_atlas(coarse, L);
  return L;
}

/// Gives the faces of the input (`input`, in the layered atlas) that have overflow charts their
/// coordinates there.
inline void input_into_overflow(Textured_mesh& input, const Atlas_layers& layers) {
  const Surface_mesh& m = input.mesh();
  for (auto f : m.faces()) {
    const std::size_t i = std::size_t(f);
    if (i >= layers.chart_of_input_face.size() || layers.chart_of_input_face[i] < 0) continue;
    for (int k = 0; k < 3; ++k) input.set_uv(corner_halfedge(m, f, k), layers.input_uv[i][std::size_t(k)]);
  }
}

/// Moves the faces of a level (`level`, mapped into the layered atlas) that stand for input faces
/// with overflow charts into those charts. A face's candidate is the chart most of the input's
/// faces that ended on it (`on_level` of their points `input_face_point`) have; each of its corners
/// takes the coordinates of its nearest point on the input's faces of that chart that ended on the
/// faces around it (the chart's map of the nearest face, extended past it by at most
/// `max_extrapolation`). The move is kept when the face keeps its orientation and each edge its
/// length in texels within a factor of 2 (a face the atlas squashes: no edge longer than twice,
/// and squashed less in the chart), and either more of its input faces have the chart than have
/// none or the chart stretches the face less (least_texels_per_unit()) than the atlas does; and,
/// given `colour_error` (on the layered atlas), when the face shows colours nearer to a bake's in
/// the chart than where it is.
inline void level_into_overflow(Textured_mesh& level, const Atlas_layers& layers, const Surface_mesh& input,
                                const std::vector<std::uint32_t>& input_face_point,
                                const std::vector<std::uint32_t>& on_level, double max_extrapolation,
                                const Shown_colour_error* colour_error = nullptr) {
  using Face = Surface_mesh::Face_index;
  using V3 = CM::internal::Vec3;
  if (layers.charts == 0) return;
  const Surface_mesh& lm = level.mesh();
  const std::size_t nl = lm.number_of_faces();
  // the input faces on each level face (CSR)
  std::vector<std::uint32_t> start(nl + 1, 0), on(input.number_of_faces(), Collapse_history::nil);
  for (std::size_t j = 0; j < input_face_point.size() && j < on.size(); ++j) {
    const std::uint32_t p = input_face_point[j];
    if (p < on_level.size() && on_level[p] < nl) {
      on[j] = on_level[p];
      ++start[on[j] + 1];
    }
  }
  for (std::size_t f = 0; f < nl; ++f) start[f + 1] += start[f];
  std::vector<std::uint32_t> list(start[nl]), fill(start.begin(), start.end() - 1);
  for (std::size_t j = 0; j < on.size(); ++j)
    if (on[j] != Collapse_history::nil) list[fill[on[j]]++] = std::uint32_t(j);
  // each level face's chart: the most common of its input faces' charts; taken when more of them
  // have it than have none, or else when it stretches the face less than the atlas does
  // a triangle of texture coordinates in texels of the layered atlas
  auto in_texels = [&](const std::array<Point_2, 3>& t) {
    std::array<UV2, 3> x;
    for (int k = 0; k < 3; ++k)
      x[std::size_t(k)] = {{t[std::size_t(k)].x() * layers.width, t[std::size_t(k)].y() * layers.total_height()}};
    return x;
  };
  // the least stretch of a level face under texture coordinates t (texels per length unit)
  auto stretch = [&](std::size_t f, const std::array<Point_2, 3>& t) {
    return least_texels_per_unit(corner_points(lm, Face(static_cast<Surface_mesh::size_type>(f))), in_texels(t));
  };
  auto uvs_of = [&](std::size_t f) {
    std::array<Point_2, 3> t;
    const Face lf = Face(static_cast<Surface_mesh::size_type>(f));
    for (int k = 0; k < 3; ++k) t[std::size_t(k)] = level.uv(corner_halfedge(lm, lf, k));
    return t;
  };
  std::vector<std::int32_t> chart(nl, -1);
  std::vector<char> majority(nl, 0);
  std::vector<std::int32_t> c;
  for (std::size_t f = 0; f < nl; ++f) {
    c.clear();
    for (std::uint32_t k = start[f]; k < start[f + 1]; ++k) c.push_back(layers.chart_of_input_face[list[k]]);
    std::sort(c.begin(), c.end());
    std::size_t none = 0, best = 0;
    for (std::size_t a = 0; a < c.size();) {
      std::size_t b = a;
      while (b < c.size() && c[b] == c[a]) ++b;
      if (c[a] < 0)
        none = b - a;
      else if (b - a > best) {
        best = b - a;
        chart[f] = c[a];
      }
      a = b;
    }
    majority[f] = best > none;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nl), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<std::uint32_t> near;
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      const std::int32_t c = chart[f];
      if (c < 0) continue;
      const Face lf = Face(static_cast<Surface_mesh::size_type>(f));
      near.clear();
      for (auto v : CGAL::vertices_around_face(lm.halfedge(lf), lm))
        for (Face g : CGAL::faces_around_target(lm.halfedge(v), lm))
          if (g != Surface_mesh::null_face())
            for (std::uint32_t k = start[std::size_t(g)]; k < start[std::size_t(g) + 1]; ++k)
              if (layers.chart_of_input_face[list[k]] == c) near.push_back(list[k]);
      std::sort(near.begin(), near.end());
      near.erase(std::unique(near.begin(), near.end()), near.end());
      if (near.empty()) continue;
      std::array<Point_2, 3> moved;
      const std::array<V3, 3> corner = corner_points(lm, lf);
      for (int k = 0; k < 3; ++k) {
        const auto h = corner_halfedge(lm, lf, k);
        const V3& p = corner[std::size_t(k)];
        double best = std::numeric_limits<double>::infinity();
        Point_2 uv = level.uv(h);
        for (std::uint32_t j : near) {
          const std::array<V3, 3> t = corner_points(input, Face(j));
          const V3 x = CM::internal::closest_on_triangle(p, t[0], t[1], t[2]);
          const double d = CM::internal::squared_length(p - x);
          if (!(d < best)) continue;
          best = d;
          // the chart's map of the nearest face, extended past its border (a corner beyond the
          // chart's border lands in its gutter, which the faces around the chart painted)
          uv = on_texture(extended_uv(t, layers.input_uv[j], p, max_extrapolation));
        }
        moved[std::size_t(k)] = uv;
      }
      // kept when the face keeps its orientation and each of its edges keeps its length in texels
      // within a factor of 2 (corners whose closest points lie on different sheets of a chart
      // would stretch it over the gutters); else the face keeps its place in the atlas
      const std::array<UV2, 3> m = in_texels(moved);
      if (!(signed_area_2(m[0], m[1], m[2]) > 0)) continue;
      bool shape_kept = true, longest_ok = true;
      for (int k = 0; k < 3; ++k) {
        const UV2& a = m[std::size_t(k)];
        const UV2& b = m[std::size_t((k + 1) % 3)];
        const double texels = std::hypot(b[0] - a[0], b[1] - a[1]);
        const double share =
            CM::internal::length(corner[std::size_t((k + 1) % 3)] - corner[std::size_t(k)]) * layers.texels_per_unit;
        shape_kept = shape_kept && texels >= 0.5 * share && texels <= 2 * share;
        longest_ok = longest_ok && texels <= 2 * share;
      }
      // (a face the atlas squashes, as add_overflow_charts() tells the input's, may shrink in the
      // chart, as long as it is squashed less there)
      const double now = stretch(f, uvs_of(f));
      const bool better = stretch(f, moved) > now;
      const bool squashed = now < 0.5 * layers.base_texels_per_unit;
      if (!shape_kept && !(longest_ok && better && squashed)) continue;
      if (!majority[f] && !better) continue;
      // and when the colours are checked, only where it shows colours nearer to a bake's
      // (the searches start from the first input face on it: f has one, as its chart is set)
      if (colour_error) {
        std::size_t n = 0;
        const auto e = colour_error->squared_errors(corner, std::array<std::array<Point_2, 3>, 2>{{uvs_of(f), moved}},
                                                    n, list[start[f]]);
        if (!(e[1] < e[0])) continue;
      }
      for (int k = 0; k < 3; ++k) level.set_uv(corner_halfedge(lm, lf, k), moved[std::size_t(k)]);
    }
  });
}

}  // namespace internal
}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_INTERNAL_ATLAS_LAYERS_H
