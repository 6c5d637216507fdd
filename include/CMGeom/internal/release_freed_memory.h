// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// release_freed_memory(): hands the memory that the C library keeps for reuse back to the system.
// glibc keeps freed blocks in its arenas: blocks a worker thread allocated stay in that thread's
// arena, and once a large block has been freed, glibc raises its mmap threshold so that later
// blocks of that size come from the heap and stay there after they are freed as well. A stage
// that frees a lot and is followed by one that allocates a lot then peaks at the sum of both.
// Called between such stages (after the parallel parse of a file, after the parts of a simplification
// are built, before the final fit of a simplification); with another C library it does nothing.
#ifndef CMGEOM_INTERNAL_RELEASE_FREED_MEMORY_H
#define CMGEOM_INTERNAL_RELEASE_FREED_MEMORY_H

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace CMGeom {
namespace internal {

inline void release_freed_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace internal
}  // namespace CMGeom

#endif  // CMGEOM_INTERNAL_RELEASE_FREED_MEMORY_H
