#pragma once
/// \file
/// Small procedural meshes for tests, examples and scenes.

#include "caliber/export.h"
#include "caliber/mesh.h"

namespace caliber {

/// UV sphere of the given radius, centered at the origin: `rings` latitude bands (>= 2) and
/// `segments` longitude slices (>= 3). Outward normals.
[[nodiscard]] CALIBER_EXPORT Mesh make_sphere(double radius, int rings, int segments);

/// Torus around the z axis: `major` radius of the tube's center line, `minor` radius of the tube.
[[nodiscard]] CALIBER_EXPORT Mesh make_torus(double major, double minor, int rings, int segments);

/// Axis-aligned box centered at the origin with half-extents (hx, hy, hz); each face is a
/// `divisions` x `divisions` grid of quads (two triangles each). Outward normals.
[[nodiscard]] CALIBER_EXPORT Mesh make_box(double hx, double hy, double hz, int divisions);

/// A thin plate (box of the given thickness) in the xy plane, `divisions` quads per side.
[[nodiscard]] CALIBER_EXPORT Mesh make_plate(double half_size, double thickness, int divisions);

}  // namespace caliber
