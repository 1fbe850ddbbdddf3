// The procedural landscape: the built-in default scene.
//
// Rolling noise terrain with ridges, a network of caves below the surface,
// overhangs (the terrain is warped sideways with height, so cliffs lean out)
// and rock arches standing on the ground. Deterministic for a given seed on
// every machine and thread count.
//
// Thread safety: build_terrain is re-entrant; the solid returned by
// make_terrain_solid is immutable and safe to evaluate from many threads.
#pragma once

#include <cstdint>
#include <memory>

#include "ldc/build.h"

namespace ldc {

// Material ids the landscape uses.
enum TerrainMaterial : uint16_t {
  kMaterialRock = 0,
  kMaterialGrass = 1,
  kMaterialDirt = 2,
  kMaterialSand = 3,
};
const char* terrain_material_name(uint16_t id);

struct TerrainConfig {
  uint32_t seed = 1;           // any value; same seed, same landscape
  double size_x = 48.0;        // extent along x [Units: m] [Limit: > 0]
  double size_y = 48.0;        // extent along y [Units: m] [Limit: > 0]
  double floor_z = 0.0;        // bottom of the solid [Units: m]
  double base_height = 6.0;    // mean ground height above the floor [Units: m] [Limit: > 0]
  double relief = 5.0;         // peak-to-valley amplitude of the hills [Units: m] [Limit: >= 0]
  double overhang = 1.5;       // sideways warp that makes cliffs lean out [Units: m] [Limit: >= 0]
  double cave_radius = 1.1;    // radius of cave tunnels [Units: m] [Limit: >= 0; 0 = no caves]
  int arches = 3;              // rock arches on the ground [Limit: 0 .. 64]
};

Status check_terrain(const TerrainConfig& config);

// The landscape as an implicit solid (negative inside), z up.
std::unique_ptr<ImplicitSolid> make_terrain_solid(const TerrainConfig& config);

// Builds the landscape at cell size `cell_size` (0.2 m is the game default).
Result<World> build_terrain(const TerrainConfig& config, double cell_size = 0.2,
                            int chunk_size = 32, Context* ctx = nullptr,
                            BuildReport* report = nullptr);

}  // namespace ldc
