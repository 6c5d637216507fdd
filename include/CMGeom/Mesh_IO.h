// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Convenience header of the Mesh_IO package: the textured-mesh data model, charts, readers and
// writers (link CMGeom::Mesh_IO; for images and textures also CMGeom::Image_IO and include
// <CMGeom/Mesh_IO/textured_mesh_io.h>).
#ifndef CMGEOM_MESH_IO_H
#define CMGEOM_MESH_IO_H

#include <CMGeom/Error.h>
#include <CMGeom/Mesh_IO/Atomic_output.h>
#include <CMGeom/Mesh_IO/Image.h>
#include <CMGeom/Mesh_IO/Polygon_soup.h>
#include <CMGeom/Mesh_IO/Textured_mesh.h>
#include <CMGeom/Mesh_IO/charts.h>
#include <CMGeom/Mesh_IO/mesh_io.h>

#endif
