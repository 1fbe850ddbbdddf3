// The one material palette: the colour every output gives a material id.
//
// glTF's baseColorFactor, `ldc render` and `ldc gi` images, and the voxel
// G-buffer's default albedo (voxelize/voxelize.h, default_material_table)
// all read it, so rock looks like rock everywhere. Ids 0 .. 3 are the
// landscape's (ldc/terrain.h: rock, grass, dirt, sand); the next twelve are
// colours far apart from each other; ids past the palette repeat it.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace ldc {

inline constexpr int kPaletteSize = 16;

// Linear (not gamma-encoded) albedo of a material id, each channel in [0, 1]:
// what a renderer multiplies light by and what glTF's baseColorFactor holds.
glm::vec3 material_albedo(uint16_t id);

// The same colour for display: sRGB-encoded, each channel in [0, 1].
glm::vec3 material_display_colour(uint16_t id);

}  // namespace ldc
