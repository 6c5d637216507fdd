// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// CMGeom configuration: version number, the kernel every package defaults to, and the one
// portability shim between CGAL 5.5 (boost::optional in policy signatures) and CGAL 6.x
// (std::optional). Every policy signature spells CMGeom::internal::optional<T>.
// CMGEOM_ALWAYS_INLINE marks the few small kernels that must be inlined into their hot loops even
// when they have several callers (GCC and Clang; plain `inline` elsewhere).
#ifndef CMGEOM_CONFIG_H
#define CMGEOM_CONFIG_H

#include <CGAL/version.h>

#if CGAL_VERSION_NR >= 1060000000
#include <optional>
#else
#include <boost/optional.hpp>
#endif

#define CMGEOM_VERSION_MAJOR 0
#define CMGEOM_VERSION_MINOR 1
#define CMGEOM_VERSION_PATCH 0
#define CMGEOM_VERSION_STR "0.1.0"
#define CMGEOM_VERSION_NR 100100000  // 1MMmmpp000 as CGAL does: 0.1.0

#if defined(__GNUC__) || defined(__clang__)
#define CMGEOM_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define CMGEOM_ALWAYS_INLINE inline
#endif

namespace CMGeom {
namespace internal {
#if CGAL_VERSION_NR >= 1060000000
template <class T>
using optional = std::optional<T>;
inline constexpr std::nullopt_t none = std::nullopt;
#else
template <class T>
using optional = boost::optional<T>;
inline const boost::none_t none = boost::none;
#endif
}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_CONFIG_H
