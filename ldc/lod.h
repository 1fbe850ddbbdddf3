// Levels of detail: a world seen through every 2^level-th ray.
//
// A coarser LDC is a subset of the same rays (issue 21): level k keeps, in
// each family, the rays whose lattice coordinates are multiples of s = 2^k,
// with their points as they are, on a lattice of cell size s * h and chunks
// of C / s cells. Nothing is resampled: every node of the coarse lattice is a
// node of the fine one with the same inside/outside state, every coarse point
// is a fine point, so the coarse world is a valid LDC (validate() holds) and
// any contouring of it (contour_world, ChunkedMesh, marching_cubes) is a
// closed mesh of about 4^-k the triangles, with features thinner than s cells
// gone. Edits and booleans stay on level 0; coarsen again after them.
//
// Chunks keep their coordinates, so the level-k mesh of chunk c is the mesh
// of chunk c of the coarse world. Chunks of one level meet without cracks;
// chunks of different levels do not (the seam between levels is not built).
// lod_level() picks a chunk's level by its distance to the camera.
//
// Thread safety: coarsen only reads `world`; the result shares no chunk
// data with it.
#pragma once

#include <vector>

#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

// The highest level a chunk size allows: coarse chunks keep at least 8 cells
// (C = 8: 0, 16: 1, 32: 2, 64: 3).
int max_lod_level(int chunk_size);

// The world through every 2^level-th ray (level 0: a copy). kInvalidArgument
// for a level below 0 or above max_lod_level(world.chunk_size()).
Result<World> coarsen(const World& world, int level);

// --- Choosing a chunk's level by distance, with hysteresis --------------------

// Level k is meant from distance start[k - 1] on (start[0] begins level 1),
// so start.size() + 1 levels. A chunk changes level only once it is
// `hysteresis` past a band's edge, so one moving along an edge does not
// flip between two levels every frame.
struct LodBands {
  std::vector<double> start;  // [Units: m] [Limit: finite, > 0, increasing]
  double hysteresis = 2.0;    // [Units: m] [Limit: finite, >= 0, below half of each band's width]
};
// kInvalidArgument naming the first bad value.
Status check_lod_bands(const LodBands& bands);

// The level of a chunk now at `level` (clamped to the bands' levels), at
// `distance` from the camera: it moves up to level k + 1 only at start[k] +
// hysteresis or farther, and down from level k only below start[k - 1] -
// hysteresis. Bands that fail check_lod_bands give `level` unchanged.
int lod_level(const LodBands& bands, double distance, int level);

// Distance from `point` to the nearest point of a chunk's box (0 inside) [Units: m].
double chunk_distance(const Lattice& lattice, int chunk_size, const glm::ivec3& chunk, const glm::dvec3& point);

}  // namespace ldc
