// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// The combinatorial structure of a *Cages system (thesis §5.3.2, §5.3.4), built once by
// Cage_system from its description: the leaf cages, their vertices welded by identical rest
// position, the borders B_ij (faces two leaf cages share with opposite orientation), the incident
// cages of each welded vertex, the classes [u] of boundary vertices with their join cages, and
// the parents-first order of the hierarchy. No coordinates are made here: Cage_system builds
// those on the cages and join cages this structure describes. See "*Cages" in
// doc/Cage_deformation/README.md ("What is built" and the choices where the thesis leaves room).
//
// Complexity: O(Σ m_i log) for the welding and the borders, O(V · C) for the join classes.
#ifndef CMGEOM_CAGE_DEFORMATION_INTERNAL_CAGE_SYSTEM_TOPOLOGY_H
#define CMGEOM_CAGE_DEFORMATION_INTERNAL_CAGE_SYSTEM_TOPOLOGY_H

#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Cage_deformation/Triangle_cage.h>
#include <CMGeom/Error.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {
namespace internal {

/// The border B_ij seen from leaf cage i.
struct Cage_border {
  std::size_t other = 0, triangles = 0;
  std::vector<std::uint32_t> local;  ///< VB_ij, local indices in this cage
  double h = 0;                      ///< own h_ij, 0: none (h_i applies)
};

/// A class [u] of boundary vertices sharing their incident cages, and its join cage.
struct Join_class {
  std::vector<std::size_t> cages;       ///< incident cage set (sorted)
  std::vector<std::uint32_t> vertices;  ///< [u], global ids
  Triangle_cage cage;                   ///< join cage
  std::vector<std::uint32_t> global;    ///< join cage local -> global
  std::vector<std::uint32_t> local;     ///< vertices of [u] on the join cage (local ids)
  /// When no vertex of [u] lies on the join cage (a vertex surrounded by its cages): per cage
  /// outside the join cage sharing faces with it, the local ids of those faces' vertices.
  std::vector<std::vector<std::uint32_t>> bubble;
};

/// The structure of a cage system. Cage_system calls the steps in this order: find_leaves,
/// weld_leaves, build_borders, build_classes, topological_order. Each step reads the
/// description it is given (the same one every time) and throws Invalid_input on what it finds
/// wrong.
struct Cage_system_topology {
  static constexpr std::size_t npos = std::size_t(-1);

  std::vector<char> is_leaf;                          ///< per cage of the description
  std::vector<std::size_t> leaves;                    ///< leaf cages, in description order
  std::vector<std::size_t> order;                     ///< every cage, parents before children
  std::vector<Vec3> vertices;                         ///< welded leaf vertices (rest positions)
  std::vector<std::vector<std::uint32_t>> global_of;  ///< per leaf cage: local -> welded id
  std::vector<std::vector<char>> owned;               ///< per cage and local vertex: has a parent
  std::vector<std::vector<std::size_t>> incident;     ///< per welded vertex: its leaf cages
  std::vector<std::array<Vec3, 2>> box;               ///< per leaf cage: its bounding box, widened
  std::vector<std::vector<Cage_border>> borders;      ///< per cage: its borders (leaf cages only)
  std::vector<Join_class> classes;                    ///< the partition of boundary vertices
  std::vector<std::vector<std::size_t>> classes_of;   ///< per cage: the classes of ∂C_i

  /// The leaf cages: those no cage names as a parent. Checks every parent link first (a
  /// hand-made description has not been through the reader): the parent is another cage of the
  /// system and every owned vertex is a vertex of the child's rest cage.
  void find_leaves(const Cage_system_description& d) {
    const std::size_t C = d.cages.size();
    if (C == 0) throw Invalid_input("a cage system needs at least one cage");
    for (std::size_t c = 0; c < C; ++c)
      for (const auto& l : d.cages[c].parents) {
        if (l.cage >= C || l.cage == c)
          throw Invalid_input("cage " + std::to_string(c) + ": bad parent link to cage " + std::to_string(l.cage) +
                              " (" + std::to_string(C) + " cages)");
        for (std::uint32_t k : l.vertices)
          if (k >= d.cages[c].rest.vertices.size())
            throw Invalid_input("cage " + std::to_string(c) + ": parent link to cage " + std::to_string(l.cage) +
                                " owns vertex " + std::to_string(k) + " of a cage with " +
                                std::to_string(d.cages[c].rest.vertices.size()) + " vertices");
      }
    is_leaf.assign(C, 1);
    for (const auto& c : d.cages)
      for (const auto& l : c.parents) is_leaf[l.cage] = 0;
    for (std::size_t i = 0; i < C; ++i)
      if (is_leaf[i]) leaves.push_back(i);
  }

  bool in_box(std::size_t c, const Vec3& p) const {
    for (int a = 0; a < 3; ++a)
      if (p[a] < box[c][0][a] || p[a] > box[c][1][a]) return false;
    return true;
  }

  /// Welds the leaf vertices by rest position; throws when two free copies of a vertex get
  /// different deformed positions.
  void weld_leaves(const Cage_system_description& d) {
    std::map<Vec3, std::uint32_t> id;
    const std::size_t C = d.cages.size();
    global_of.assign(C, {});
    box.assign(C, {});
    owned.assign(C, {});
    double L = 0;
    for (std::size_t c : leaves) L = std::max(L, d.cages[c].rest.bbox_diagonal());
    for (std::size_t c = 0; c < C; ++c) {
      const auto& cd = d.cages[c];
      owned[c].assign(cd.rest.vertices.size(), 0);
      for (const auto& l : cd.parents)
        for (std::uint32_t k : l.vertices) owned[c][k] = 1;
    }
    std::vector<std::pair<std::size_t, std::size_t>> first;  // global -> (cage, local)
    for (std::size_t c : leaves) {
      const auto& cd = d.cages[c];
      Vec3 lo = cd.rest.vertices[0], hi = lo;
      for (std::size_t k = 0; k < cd.rest.vertices.size(); ++k) {
        const Vec3& p = cd.rest.vertices[k];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
        auto [it, fresh] = id.emplace(p, std::uint32_t(vertices.size()));
        if (fresh) {
          vertices.push_back(p);
          incident.emplace_back();
          first.push_back({c, k});
        } else if (!owned[c][k] && !owned[first[it->second].first][first[it->second].second]) {
          const auto [c0, k0] = first[it->second];
          if (norm(sub(d.cages[c0].deformed[k0], cd.deformed[k])) > 1e-9 * L)
            throw Invalid_input("cages " + std::to_string(c0) + " and " + std::to_string(c) + " share rest vertex " +
                                std::to_string(it->second) + " but give it different deformed positions");
        }
        global_of[c].push_back(it->second);
        if (incident[it->second].empty() || incident[it->second].back() != c) incident[it->second].push_back(c);
      }
      const double eps = 1e-9 * std::max(L, 1e-300);
      for (int a = 0; a < 3; ++a) {
        lo[a] -= eps;
        hi[a] += eps;
      }
      box[c] = {lo, hi};
    }
  }

  static std::array<std::uint32_t, 3> sorted(std::array<std::uint32_t, 3> t) {
    std::sort(t.begin(), t.end());
    return t;
  }
  // +1 / -1: orientation of t relative to its sorted order.
  static int parity(const std::array<std::uint32_t, 3>& t) {
    const auto s = sorted(t);
    for (int r = 0; r < 3; ++r)
      if (t[r] == s[0] && t[(r + 1) % 3] == s[1]) return 1;
    return -1;
  }

  /// The borders B_ij and their own h values; throws on overlapping cages and on bad border h.
  void build_borders(const Cage_system_description& d) {
    const std::size_t C = d.cages.size();
    borders.assign(C, {});
    std::map<std::array<std::uint32_t, 3>, std::vector<std::pair<std::size_t, int>>> faces;
    for (std::size_t c : leaves)
      for (const auto& t : d.cages[c].rest.triangles) {
        const std::array<std::uint32_t, 3> g{global_of[c][t[0]], global_of[c][t[1]], global_of[c][t[2]]};
        faces[sorted(g)].push_back({c, parity(g)});
      }
    std::map<std::pair<std::size_t, std::size_t>, std::set<std::uint32_t>> vb;
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> count;
    for (const auto& [key, users] : faces) {
      if (users.size() == 1) continue;
      if (users.size() > 2 || users[0].second == users[1].second || users[0].first == users[1].first)
        throw Invalid_input("leaf cages " + std::to_string(users[0].first) + " and " + std::to_string(users[1].first) +
                            " overlap (a face is used twice with the same orientation or by more "
                            "than two cages)");
      for (int s = 0; s < 2; ++s) {
        const auto pr = std::make_pair(users[s].first, users[1 - s].first);
        vb[pr].insert(key.begin(), key.end());
        ++count[pr];
      }
    }
    for (const auto& [pr, verts] : vb) {
      Cage_border b;
      b.other = pr.second;
      b.triangles = count[pr];
      for (std::uint32_t v : verts) {
        const auto& gl = global_of[pr.first];
        b.local.push_back(std::uint32_t(std::find(gl.begin(), gl.end(), v) - gl.begin()));
      }
      borders[pr.first].push_back(std::move(b));
    }
    for (std::size_t c = 0; c < d.cages.size(); ++c)
      for (const Cage_border_h& bh : d.cages[c].border_h) {
        const std::string who = "cage " + std::to_string(c) + ": border h for cage " + std::to_string(bh.cage);
        if (!(bh.h > 0 && bh.h <= 1)) throw Invalid_input(who + ": h must be in (0, 1]");
        if (!is_leaf[c]) throw Invalid_input(who + ": only leaf cages have borders");
        auto it = std::find_if(borders[c].begin(), borders[c].end(),
                               [&](const Cage_border& b) { return b.other == bh.cage; });
        if (it == borders[c].end()) throw Invalid_input(who + ", which shares no face with it");
        if (it->h > 0) throw Invalid_input(who + " is given twice");
        it->h = bh.h;
      }
  }

  /// Union of the given leaf cages, faces shared by two of them removed; `global` gets local ->
  /// global ids.
  Triangle_cage merged_cage(const Cage_system_description& d, const std::vector<std::size_t>& cages,
                            std::vector<std::uint32_t>& global) const {
    std::map<std::array<std::uint32_t, 3>, std::vector<std::array<std::uint32_t, 3>>> faces;
    for (std::size_t c : cages)
      for (const auto& t : d.cages[c].rest.triangles) {
        const std::array<std::uint32_t, 3> g{global_of[c][t[0]], global_of[c][t[1]], global_of[c][t[2]]};
        faces[sorted(g)].push_back(g);
      }
    std::map<std::uint32_t, std::uint32_t> local;
    Triangle_cage out;
    global.clear();
    for (const auto& [key, ts] : faces) {
      if (ts.size() != 1) continue;
      std::array<std::uint32_t, 3> t;
      for (int k = 0; k < 3; ++k) {
        auto [it, fresh] = local.emplace(ts[0][k], std::uint32_t(global.size()));
        if (fresh) {
          global.push_back(ts[0][k]);
          out.vertices.push_back(vertices[ts[0][k]]);
        }
        t[k] = it->second;
      }
      out.triangles.push_back(t);
    }
    return out;
  }

  /// The partition of the boundary vertices by incident-cage set (§5.3.2) and each class's join
  /// cage.
  void build_classes(const Cage_system_description& d) {
    const std::size_t C = d.cages.size();
    classes_of.assign(C, {});
    std::map<std::vector<std::size_t>, std::size_t> by_set;
    std::vector<char> boundary(vertices.size(), 0);
    for (std::size_t c : leaves)
      for (const auto& b : borders[c])
        for (std::uint32_t l : b.local) boundary[global_of[c][l]] = 1;
    for (std::uint32_t v = 0; v < vertices.size(); ++v) {
      if (!boundary[v]) continue;
      auto [it, fresh] = by_set.emplace(incident[v], classes.size());
      if (fresh) {
        classes.emplace_back();
        classes.back().cages = incident[v];
      }
      classes[it->second].vertices.push_back(v);
    }
    for (std::size_t k = 0; k < classes.size(); ++k) {
      Join_class& cl = classes[k];
      cl.cage = merged_cage(d, cl.cages, cl.global);
      for (std::uint32_t v : cl.vertices) {
        auto it = std::find(cl.global.begin(), cl.global.end(), v);
        if (it != cl.global.end()) cl.local.push_back(std::uint32_t(it - cl.global.begin()));
      }
      if (cl.local.empty()) {
        std::set<std::array<std::uint32_t, 3>> surface;
        for (const auto& t : cl.cage.triangles)
          surface.insert(sorted({cl.global[t[0]], cl.global[t[1]], cl.global[t[2]]}));
        for (std::size_t j : leaves) {
          if (std::binary_search(cl.cages.begin(), cl.cages.end(), j)) continue;
          std::set<std::uint32_t> group;
          for (const auto& t : d.cages[j].rest.triangles) {
            const auto key = sorted({global_of[j][t[0]], global_of[j][t[1]], global_of[j][t[2]]});
            if (!surface.count(key)) continue;
            for (std::uint32_t g : key)
              group.insert(std::uint32_t(std::find(cl.global.begin(), cl.global.end(), g) - cl.global.begin()));
          }
          if (!group.empty()) cl.bubble.emplace_back(group.begin(), group.end());
        }
      }
      for (std::size_t c : cl.cages) classes_of[c].push_back(k);
    }
  }

  /// Parents before children (the links were checked acyclic by the reader; checked again here
  /// for hand-made descriptions).
  void topological_order(const Cage_system_description& d) {
    const std::size_t C = d.cages.size();
    std::vector<int> indeg(C, 0);
    std::vector<std::vector<std::size_t>> children(C);
    for (std::size_t c = 0; c < C; ++c)
      for (const auto& l : d.cages[c].parents) {
        if (l.cage >= C || l.cage == c) throw Invalid_input("cage " + std::to_string(c) + ": bad parent link");
        children[l.cage].push_back(c);
        ++indeg[c];
      }
    std::vector<std::size_t> q;
    for (std::size_t c = 0; c < C; ++c)
      if (!indeg[c]) q.push_back(c);
    for (std::size_t i = 0; i < q.size(); ++i)
      for (std::size_t ch : children[q[i]])
        if (--indeg[ch] == 0) q.push_back(ch);
    if (q.size() != C) throw Invalid_input("the parent links of the cage system form a cycle");
    order = q;
  }
};

}  // namespace internal
}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_INTERNAL_CAGE_SYSTEM_TOPOLOGY_H
