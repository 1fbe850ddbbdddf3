#include "ldc/materials.h"

#include <array>
#include <cmath>

namespace ldc {

namespace {

// Linear albedos. The landscape's four are measured-looking values (rock
// and sand from common albedo tables); the rest are distinct hues of
// similar lightness.
constexpr std::array<glm::vec3, kPaletteSize> kPalette = {{
    {0.42f, 0.40f, 0.38f},  // 0 rock
    {0.22f, 0.45f, 0.14f},  // 1 grass
    {0.40f, 0.28f, 0.17f},  // 2 dirt
    {0.76f, 0.69f, 0.50f},  // 3 sand
    {0.08f, 0.21f, 0.69f},  // 4 blue
    {0.69f, 0.08f, 0.06f},  // 5 red
    {0.34f, 0.15f, 0.60f},  // 6 violet
    {0.05f, 0.45f, 0.45f},  // 7 teal
    {0.83f, 0.30f, 0.03f},  // 8 orange
    {0.52f, 0.52f, 0.07f},  // 9 olive
    {0.69f, 0.21f, 0.38f},  // 10 pink
    {0.17f, 0.17f, 0.21f},  // 11 slate
    {0.26f, 0.60f, 0.17f},  // 12 light green
    {0.13f, 0.07f, 0.04f},  // 13 umber
    {0.60f, 0.60f, 0.64f},  // 14 white
    {0.03f, 0.10f, 0.26f},  // 15 navy
}};

float srgb_encode(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

glm::vec3 material_albedo(uint16_t id) { return kPalette[id % kPaletteSize]; }

glm::vec3 material_display_colour(uint16_t id) {
  const glm::vec3 a = material_albedo(id);
  return {srgb_encode(a.x), srgb_encode(a.y), srgb_encode(a.z)};
}

}  // namespace ldc
