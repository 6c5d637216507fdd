// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// simplify_textured_mesh(): the texture-preserving simplification of thesis chapter 3 on a
// Textured_mesh. By default a new atlas is baked from the input after the collapses
// (rebuild_atlas.h), so any face count is reached: the input's vertices and faces are followed
// down the collapses and paint the new atlas with their own colours, and only the texels no input
// face reaches are looked up on the input (internal/collapse_history.h). With `keep_charts` it is
// the thesis' method: weighted quadric collapses (§3.4) under the chart constraints of §3.5, the index texture of §3.3
// rewritten at every collapse through the bijective mappings of §3.6 (by `Resampler`, the CPU
// Index_texture_resampler or the bit-identical Osmesa_index_texture_resampler), and the output
// textures generated through it. A mesh without a decoded texture keeps its UVs under the same
// constraints. Normal maps are resampled like colours (exact for object-space maps only).
//
// Manual: doc/Textured_simplification/README.md, "Texture part".
#ifndef CMGEOM_TEXTURED_SIMPLIFICATION_SIMPLIFY_TEXTURED_MESH_H
#define CMGEOM_TEXTURED_SIMPLIFICATION_SIMPLIFY_TEXTURED_MESH_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Textured_simplification/Area_weighted_quadric_policies.h>
#include <CMGeom/Textured_simplification/Chart_constraints.h>
#include <CMGeom/Textured_simplification/Endpoint_placement.h>
#include <CMGeom/Textured_simplification/Hausdorff_bound.h>
#include <CMGeom/Textured_simplification/Index_texture.h>
#include <CMGeom/Textured_simplification/Stop_predicates.h>
#include <CMGeom/Textured_simplification/edge_collapse.h>
#include <CMGeom/Textured_simplification/internal/collapse_history.h>
#include <CMGeom/Textured_simplification/rebuild_atlas.h>
#include <CMGeom/Textured_simplification/simplify_mesh.h>
#include <CMGeom/Textured_simplification/Surface_memory.h>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace CMGeom {
namespace Textured_simplification {

struct Textured_simplification_options {
  std::size_t target_faces = 0;
  /// A guaranteed bound on the Hausdorff distance between output and input geometry, as a fraction
  /// of the input's bounding-box diagonal (simplify_mesh()'s `max_error`, Hausdorff_bound.h),
  /// whichever of it and `target_faces` comes first. With keep_charts the bound is tested after
  /// the chart constraints, at the placement they give, and the run also ends where no collapse
  /// keeps the charts (Stop_reason::max_error when the bound refused a collapse the charts
  /// allowed, chart_limit otherwise): near the chart limit the collapses the charts still allow
  /// are often far from the surface (Duck: Hausdorff 6.6 % at the limit, 712 faces; manual).
  std::optional<double> max_error;
  /// The bound's limits (cuts, work per test), as simplify_mesh()'s `error_bound`.
  Hausdorff_bound_options error_bound;
  /// true: the thesis' method (§3.5): collapses never change the input's charts, the index
  /// texture is rewritten at every collapse; the simplification stops where no collapse keeps
  /// the charts (Stop_reason::chart_limit), which can be far above the target on models with
  /// many charts. false (default): the collapses ignore the charts, any target is reached, and
  /// a new atlas is baked from the input (rebuild_atlas.h). Without a decoded texture there is
  /// nothing to bake and the charts are kept whatever this says.
  bool keep_charts = false;
  /// Edge flips after each collapse (§3.5.1) when the charts are not kept (the new atlas is made
  /// after the collapses, so flips need no UV rules); refused with keep_charts (Invalid_input).
  bool flips = false;
  /// The new atlas when the charts are not kept (texture size 0: options' `texture_size`, else
  /// the input's texel density, see Atlas_options).
  Atlas_options atlas;
  /// New atlas: paint it from the input followed down the collapses (internal/collapse_history.h)
  /// and look up on the input only the texels left; false: look up every texel (the closest input
  /// point facing the same way). Painting was measured as fast or faster (DamagedHelmet at 1 %:
  /// 0.5 s of baking instead of 1.3 s) with equal or lower image error (manual, "Painting the new
  /// atlas"). Not used when the run is split into parts (Mesh_simplification_options'
  /// `parts_min_faces`): the history follows one whole mesh.
  bool paint_from_history = true;
  /// Cost and placement: plain Garland-Heckbert quadrics by default (measured on the textured
  /// models: lower image, Hausdorff and RMS error than the weighted quadrics of §3.4.2; manual,
  /// Textured_simplification, "Which policy"); `quadric.weighted = true` for the thesis' weighting.
  Quadric_options quadric = Quadric_options{false};
  /// The memoryful cost of Surface_memory.h (the input's vertices stay attached to the faces
  /// and price the collapses that move them away) when the charts are not kept; `memory` its
  /// options, with the fit of the vertices to those points after the collapses (`memory.fit`, as
  /// simplify_mesh() runs it: not with max_error).
  bool surface_memory = true;
  Surface_memory_options memory;
  Chart_constraint_options constraints;
  /// Remove whole connected components when cheaper than the next collapse (simplify_mesh()'s
  /// `prune_components`); new-atlas path only, with a face target, not with max_error (Invalid_input).
  bool prune_components = false;
  /// Rewrite the index texture and generate output textures (when the input has a texture).
  bool resample_textures = true;
  /// Texels per unit of UV for the index and output textures (0: the input texture's size).
  int texture_size = 0;
  /// Largest index/output texture side (bigger domains, e.g. tiled UVs, are scaled down).
  int max_texture_side = 8192;
  /// A chart may grow across a concave corner of its boundary by a sliver whose texels all lie
  /// within this many texels of the chart's original texels (and in no other chart's): 0 = charts
  /// only shrink. Texel size: the index texture's, or 1/1024 of UV when there is no texture.
  int chart_growth_texels = 2;
  /// Keep every vertex on an input vertex (Endpoint_placement: the cheaper endpoint of each
  /// collapsed edge) instead of the quadric's optimal placement; Compact Model bases need it.
  bool endpoint_placement = false;
  /// Worker threads of the texture work (index texture set-up, resampling of large collapses,
  /// output texture generation); 0 lets TBB choose (all cores). The result does not depend on it.
  int threads = 0;
};

struct Textured_simplification_result {
  Stop_reason stopped_by = Stop_reason::target;
  bool charts_kept = true;  ///< false when a new atlas was baked (`atlas` then says how)
  Atlas_result atlas;
  std::size_t faces_in = 0, faces_out = 0, charts_in = 0, charts_out = 0;
  int texture_width = 0, texture_height = 0;
  double seconds_collapse = 0;  ///< the collapses, including the per-collapse index-texture resampling
  double seconds_texture = 0;   ///< index texture set-up, output texture generation and dilation
                                ///< (new-atlas path: the input's extraction overlaps the collapses)
  Chart_constraint_statistics statistics;
  /// With max_error: the bound kept, as a fraction of the input's diagonal (see simplify_mesh()).
  double error_bound = 0;
};

namespace internal {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// UV triangles (in face order) and chart ids of every face of `tm`.
inline std::size_t uv_layout(const Textured_mesh& tm, std::vector<std::array<UV2, 3>>& tris,
                             std::vector<int>& chart_ids) {
  const auto& m = tm.mesh();
  auto tmp = const_cast<Surface_mesh&>(m).add_property_map<Surface_mesh::Face_index, int>("f:cmgeom_chart", -1).first;
  const std::size_t n = compute_chart_ids(m, tm.uv_map(), tmp);
  tris.clear();
  chart_ids.clear();
  for (auto f : faces(m)) {
    std::array<UV2, 3> t;
    int c = 0;
    for (auto h : CGAL::halfedges_around_face(halfedge(f, m), m)) {
      const Point_2 p = tm.uv(h);
      if (c < 3) t[c] = {{p.x(), p.y()}};
      ++c;
    }
    tris.push_back(t);
    chart_ids.push_back(tmp[f]);
  }
  const_cast<Surface_mesh&>(m).remove_property_map(tmp);
  return n;
}

}  // namespace internal

/// Simplifies `tm` to `options.target_faces` faces (see the file comment); `visitor` receives
/// the engine's visitor calls too (e.g. progress). `Resampler` models IndexTextureResampler
/// (constructible from Index_texture&, called with each Collapse_record, synchronize() brings the
/// Index_texture up to date); it is created only when there is a texture to resample.
template <class Resampler = Index_texture_resampler, class Visitor = Edge_collapse_visitor_base>
Textured_simplification_result simplify_textured_mesh(Textured_mesh& tm, const Textured_simplification_options& options,
                                                      Visitor visitor = Visitor());

namespace internal {

/// The default path: collapses free of the charts, then a new atlas baked from the input (an
/// Atlas_source taken before the collapses).
template <class Visitor>
Textured_simplification_result rebuild_path(Textured_mesh& tm, const Textured_simplification_options& options,
                                            Visitor visitor) {
  using Mesh = Surface_mesh;
  Mesh& mesh = tm.mesh();
  Textured_simplification_result res;
  res.charts_kept = false;
  res.faces_in = mesh.number_of_faces();
  Atlas_options ao = options.atlas;
  if (ao.texture_width <= 0 && options.texture_size > 0) ao.texture_width = ao.texture_height = options.texture_size;
  // the atlas source (what the baking needs from the input) is taken on another core while the
  // first collapses run (simplify_mesh changes the input only after its parts are simplified, and
  // waits for the source there); its tree and chart map are then built beside the collapses
  const bool collapses = options.target_faces < res.faces_in;
  std::optional<Atlas_source> source;
  tbb::task_group take, prepare;
  take.run([&] {
    const auto t_source = std::chrono::steady_clock::now();
    source.emplace(tm, ao);
    res.seconds_texture = internal::seconds_since(t_source);
    prepare.run([&source] { source->prepare(); });
  });
  // the input's vertices and faces followed down the collapses paint the atlas (when the run is
  // one piece: the history follows one mesh)
  Mesh_simplification_options so;
  so.quadric = options.quadric;
  so.surface_memory = options.surface_memory;
  so.memory = options.memory;
  so.flips = options.flips;
  so.endpoint_placement = options.endpoint_placement;
  if (options.target_faces > 0 || !options.max_error) so.target_faces = options.target_faces;
  so.max_error = options.max_error;
  so.error_bound = options.error_bound;
  so.prune_components = options.prune_components;
  so.before_changing_input = [&take] { take.wait(); };
  const bool paint = collapses && options.paint_from_history && !mesh.has_garbage() &&
                     internal::run_part_levels(res.faces_in, so) == 0;
  std::optional<internal::Collapse_history> history;
  std::optional<Mesh> input_copy;
  internal::Level_snapshot input_points;
  std::vector<typename Mesh::Face_index> on_before;  // per point: the face it ended on, before compaction
  const auto t0 = std::chrono::steady_clock::now();
  try {
    if (paint) {
      input_copy.emplace(mesh);
      history.emplace(mesh);
      history->follow_levels(false);
      input_points = history->add_input(mesh);
    }
    if (collapses) {
      if (paint) {
        const Mesh_simplification_result r =
            simplify_mesh(mesh, so, internal::Following_visitor<Visitor>(visitor, &*history, &on_before));
        res.stopped_by = r.stopped_by;
        res.error_bound = r.error_bound;
      } else {
        const Mesh_simplification_result r = simplify_mesh(mesh, so, visitor);
        res.stopped_by = r.stopped_by;
        res.error_bound = r.error_bound;
      }
    }
    take.wait();
  } catch (...) {
    take.wait();     // (a second wait returns at once; an exception of the source was thrown already)
    prepare.wait();  // `source` must outlive the tasks
    throw;
  }
  res.charts_in = source->charts();
  mesh.collect_garbage();  // (a no-op after simplify_mesh(), which compacts)
  // per point: the face of the output it ended on
  const std::vector<std::uint32_t> on_output =
      paint ? internal::renumbered_faces(mesh, on_before) : std::vector<std::uint32_t>();
  res.seconds_collapse = internal::seconds_since(t0);
  res.faces_out = mesh.number_of_faces();
  if (res.faces_out <= options.target_faces) res.stopped_by = Stop_reason::target;
  const auto t1 = std::chrono::steady_clock::now();
  prepare.wait();
  if (paint) {
    const internal::Atlas_painter painter = [&](const Textured_mesh& simplified, internal::Atlas_paint& out) {
      Textured_mesh mapped(std::move(*input_copy));
      internal::paint_input_onto(*source, input_points, simplified, mapped, on_output,
                                 internal::default_max_extrapolation, ao.gutter_texels, out);
    };
    res.atlas = rebuild_atlas(*source, tm, ao, &painter);
  } else {
    res.atlas = rebuild_atlas(*source, tm, ao);
  }
  res.seconds_texture += internal::seconds_since(t1);
  res.texture_width = res.atlas.texture_width;
  res.texture_height = res.atlas.texture_height;
  res.charts_out = res.atlas.charts;
  return res;
}

template <class Resampler, class Visitor>
Textured_simplification_result simplify_textured_mesh_impl(Textured_mesh& tm,
                                                           const Textured_simplification_options& options,
                                                           Visitor visitor) {
  using Mesh = Surface_mesh;
  Mesh& mesh = tm.mesh();
  if (!tm.has_uvs()) throw Invalid_input("simplify_textured_mesh: the mesh has no texture coordinates");
  if (!CGAL::is_triangle_mesh(mesh)) throw Invalid_input("simplify_textured_mesh: not a triangle mesh");
  if (options.flips && options.keep_charts)
    throw Invalid_input(
        "simplify_textured_mesh: edge flips need a new atlas (keep_charts = false): a flip across a "
        "chart would need UV rules the chart constraints do not have");
  internal::check_max_error(options.max_error, options.error_bound, "simplify_textured_mesh");
  if (options.prune_components && (options.max_error || options.target_faces == 0))
    throw Invalid_input(
        "simplify_textured_mesh: prune_components needs a face target and cannot be combined with max_error");
  Textured_simplification_result res;
  res.faces_in = mesh.number_of_faces();

  // the texture(s) in use: one atlas at most
  const Material* textured = nullptr;
  std::vector<char> used(tm.materials().size(), 0);
  for (auto f : faces(mesh)) {
    const int m = tm.material(f);
    if (m >= 0 && std::size_t(m) < used.size()) used[std::size_t(m)] = 1;
  }
  for (std::size_t i = 0; i < used.size(); ++i) {
    const Material& m = tm.materials()[i];
    if (!used[i] || (m.diffuse_image.empty() && m.normal_image.empty())) continue;
    if (options.keep_charts && textured &&
        (textured->diffuse_texture != m.diffuse_texture || textured->diffuse_image.width() != m.diffuse_image.width()))
      throw Invalid_input("textured simplification supports a single texture atlas; '" + tm.source() +
                          "' uses several textures");
    if (!textured) textured = &m;
  }
  const bool resample = options.resample_textures && textured != nullptr;
  if (!options.keep_charts && resample) return rebuild_path(tm, options, visitor);
  if (options.flips)  // the chart-keeping path below has no flips: never drop them silently
    throw Invalid_input(
        "simplify_textured_mesh: edge flips need a new atlas, which needs a decoded texture and "
        "resample_textures");
  if (options.prune_components)  // nor component pruning
    throw Invalid_input(
        "simplify_textured_mesh: prune_components needs a new atlas (keep_charts = false), which needs a "
        "decoded texture and resample_textures");

  std::vector<std::array<UV2, 3>> tris;
  std::vector<int> chart_ids;
  res.charts_in = internal::uv_layout(tm, tris, chart_ids);

  Index_texture it;
  const auto t_set_up = std::chrono::steady_clock::now();
  int su = options.texture_size > 0 ? options.texture_size : 1024, sv = su;
  if (resample) {
    const Image& ref = !textured->diffuse_image.empty() ? textured->diffuse_image : textured->normal_image;
    if (options.texture_size <= 0) {
      su = ref.width();
      sv = ref.height();
    }
    it = Index_texture(make_texture_domain(tris, su, sv, options.max_texture_side), tris, chart_ids);
  }
  // region map for the growth test: original chart ids grown by chart_growth_texels
  Chart_map region;
  auto face_chart = get(CGAL::dynamic_face_property_t<int>(), mesh);
  if (options.chart_growth_texels > 0) {
    // texels where the input's charts overlap (themselves or each other) are nobody's to grow into
    region = Chart_map(make_texture_domain(tris, su, sv, options.max_texture_side), tris, chart_ids,
                       options.chart_growth_texels, true);
    std::size_t i = 0;
    for (auto f : faces(mesh)) put(face_chart, f, chart_ids[i++]);
  }
  res.seconds_texture += internal::seconds_since(t_set_up);

  using VPM = typename boost::property_map<Mesh, CGAL::vertex_point_t>::type;
  using UVMap = Textured_mesh::UV_map;
  using CC = Chart_constraints<Mesh, VPM, UVMap>;
  CC cc(mesh, get(CGAL::vertex_point, mesh), tm.uv_map(), options.constraints);
  if (options.chart_growth_texels > 0) {
    cc.set_growth_test([&](const std::array<UV2, 3>& sliver, Surface_mesh::Face_index f) {
      const std::uint32_t own = std::uint32_t(get(face_chart, f) + 1);
      std::array<UV2, 3> t;
      for (int c = 0; c < 3; ++c) {
        t[c] = region.domain().to_texel(sliver[c]);
        if (region.chart_of(float(t[c][0]), float(t[c][1])) != own) return false;
      }
      bool inside = true;
      rasterize_triangle(t, region.width(), region.height(),
                         [&](int x, int y) { inside &= region.chart(x, y) == own; });
      return inside;
    });
  }
  // the error bound: tested at the placement the chart constraints give (a half-edge collapse onto
  // a chart boundary keeps that vertex where it is), after them
  const double diagonal = internal::max_error_diagonal(mesh, options.max_error, "simplify_textured_mesh");
  using Bound = Hausdorff_bound<Mesh, VPM>;
  std::optional<Bound> bound;
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<Resampler> resampler;
  if (resample) resampler.emplace(it);
  if (options.target_faces < res.faces_in) {
    Area_weighted_quadric_policies<Mesh> policy(mesh, options.quadric);
    Face_count_stop_predicate<Mesh> stop(mesh, options.target_faces);
    Chart_constraint_visitor<CC, Resampler, Visitor> vis(cc, resampler ? &*resampler : nullptr, visitor);
    if (options.max_error)
      bound.emplace(mesh, get(CGAL::vertex_point, mesh), *options.max_error * diagonal, options.error_bound);
    Bound* b = bound ? &*bound : nullptr;
    internal::collapse_with_placement(policy, options.endpoint_placement, [&](const auto& placement) {
      edge_collapse(
          mesh, stop,
          CGAL::parameters::get_cost(policy)
              .get_placement(placement)
              .filter(Hausdorff_bound_filter<Bound, Chart_constraint_filter<CC>>{b, Chart_constraint_filter<CC>(cc)})
              .visitor(Hausdorff_bound_visitor<Bound, decltype(vis)>(b, vis)));
    });
  }
  if (resampler) resampler->synchronize();
  resampler.reset();
  const double total = internal::seconds_since(t0);
  internal::remove_isolated_vertices(mesh);
  mesh.collect_garbage();
  res.statistics = cc.statistics();
  res.faces_out = mesh.number_of_faces();

  if (resample) {
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<std::array<UV2, 3>> final_tris;
    std::vector<int> ids;
    internal::uv_layout(tm, final_tris, ids);
    for (std::size_t i = 0; i < used.size(); ++i) {
      Material& m = tm.materials()[i];
      if (!used[i]) continue;
      if (!m.diffuse_image.empty()) m.diffuse_image = generate_texture(it, m.diffuse_image, final_tris);
      if (!m.normal_image.empty()) m.normal_image = generate_texture(it, m.normal_image, final_tris);
      m.diffuse_texture_blob.clear();
    }
    // output UVs: the domain normalised to [0,1]²
    for (auto h : halfedges(mesh)) {
      if (is_border(h, mesh)) continue;
      const Point_2 p = tm.uv(h);
      const UV2 q = it.domain().to_output_uv({{p.x(), p.y()}});
      tm.set_uv(h, Point_2(q[0], q[1]));
    }
    res.texture_width = it.width();
    res.texture_height = it.height();
    res.seconds_texture += internal::seconds_since(t1);
  }
  res.charts_out = internal::uv_layout(tm, tris, chart_ids);
  res.seconds_collapse = total;
  // above the target: the bound's end when it refused a collapse the charts allowed, else the charts'
  if (res.faces_out > options.target_faces)
    res.stopped_by = bound && bound->refused() > 0 ? Stop_reason::max_error : Stop_reason::chart_limit;
  if (bound) res.error_bound = bound->bound() / diagonal;
  return res;
}

}  // namespace internal

template <class Resampler, class Visitor>
Textured_simplification_result simplify_textured_mesh(Textured_mesh& tm, const Textured_simplification_options& options,
                                                      Visitor visitor) {
  if (options.threads <= 0) return internal::simplify_textured_mesh_impl<Resampler>(tm, options, visitor);
  Textured_simplification_result res;
  tbb::task_arena arena(options.threads);
  arena.execute([&] { res = internal::simplify_textured_mesh_impl<Resampler>(tm, options, visitor); });
  return res;
}

#ifdef CMGEOM_TEXTURED_SIMPLIFICATION_PRECOMPILED
// Compiled once into CMGeom::Textured_simplification with the default resampler, and the
// default visitor or Removed_faces_visitor.
extern template Textured_simplification_result
simplify_textured_mesh<Index_texture_resampler, Edge_collapse_visitor_base>(Textured_mesh&,
                                                                            const Textured_simplification_options&,
                                                                            Edge_collapse_visitor_base);
extern template Textured_simplification_result simplify_textured_mesh<Index_texture_resampler, Removed_faces_visitor>(
    Textured_mesh&, const Textured_simplification_options&, Removed_faces_visitor);
#endif

}  // namespace Textured_simplification
}  // namespace CMGeom

#endif  // CMGEOM_TEXTURED_SIMPLIFICATION_SIMPLIFY_TEXTURED_MESH_H
