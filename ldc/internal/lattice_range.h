// The lattices whose arithmetic doubles can carry (issue 24): one check for
// the builders (plan_grid) and for every World made or grown (the loader's
// World::create included), so a world that one refuses the other never makes.
#pragma once

#include <string_view>

#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc::detail {

// Smallest cell size: the square and cube of a length (areas, volumes,
// distances squared) stay normal doubles. [Units: m]
inline constexpr double kMinLatticeCellSize = 1e-100;
// Largest coordinate magnitude of a world's box: squares and cubes stay
// finite. [Units: m]
inline constexpr double kMaxLatticeCoordinate = 1e100;
// A cell must span this many units in the last place of the largest
// coordinate: points snap to h / 65536 within a cell, and a cell only a few
// ulp wide makes most triangles degenerate (a cube at 1e15 with h = 0.031,
// where doubles are 0.125 apart).
inline constexpr double kMinCellUlps = 1e3;

// The smallest cell size allowed for a box whose largest coordinate
// magnitude is `magnitude` (kMinCellUlps ulp of it, at least kMinLatticeCellSize).
double min_cell_size_at(double magnitude);

// Refuses a finite-looking lattice that doubles cannot carry: a cell size
// below min_cell_size_at the box's largest coordinate, and a box (origin to
// the far corner of its chunks) that is not finite or reaches past
// kMaxLatticeCoordinate. The message starts "<what>: " and names the value
// and the limit.
Status check_lattice_range(const WorldConfig& config, std::string_view what);

}  // namespace ldc::detail
