// The contoured volume against the input mesh's own volume (an outside
// answer: the divergence theorem over the input's triangles), on the closed
// shared meshes, at resolutions where the bound must shrink.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "contour/contour.h"
#include "ldc/build.h"
#include "test_util.h"

namespace ldc {
namespace {

// Signed volume by the divergence theorem: the sum of the tetrahedra from the
// origin to each triangle, (a . (b x c)) / 6, with the centroid subtracted
// first to keep the sums small.
template <class Positions, class Triangles>
double divergence_volume(const Positions& positions, const Triangles& triangles) {
  glm::dvec3 o(0.0);
  for (const auto& p : positions) o += glm::dvec3(p) / double(positions.size());
  double v = 0.0;
  for (const auto& t : triangles) {
    const glm::dvec3 a = glm::dvec3(positions[t[0]]) - o, b = glm::dvec3(positions[t[1]]) - o,
                     c = glm::dvec3(positions[t[2]]) - o;
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

// The default pipeline (build_from_mesh, contour_world with ContourConfig{}) at
// `cells` along the longest axis: relative volume error against the input.
double contoured_volume_error(const TriangleMesh& input, int cells) {
  Result<World> w = build_from_mesh(input, {.cells = cells});
  EXPECT_TRUE(w.ok()) << w.status().message();
  if (!w.ok()) return 1.0;
  Result<ContourMesh> m = contour_world(w.value());
  EXPECT_TRUE(m.ok()) << m.status().message();
  if (!m.ok()) return 1.0;
  const double v_in = divergence_volume(input.positions, input.triangles);
  return (divergence_volume(m.value().positions, m.value().triangles) - v_in) / v_in;
}

// Measured on the default pipeline (tests/data as committed): errors of
// +0.27, -0.22, +0.22% at 32 cells; +0.028, -0.087, +0.091% at 64; +0.0047,
// -0.017, +0.029% at 128 (spot, fandisk, rocker-arm), falling about as h^2.
// The bounds are about twice the largest error at each resolution, and
// shrink with it.
TEST(ReferenceVolume, ContouredVolumeApproachesTheInputMeshVolume) {
  const int resolutions[3] = {32, 64, 128};
  const double bounds[3] = {0.006, 0.002, 0.0006};
  for (const char* name : {"spot.obj", "fandisk.obj", "rocker-arm.obj"}) {
    const TriangleMesh input = test::load_test_mesh(name);
    const double v_in = divergence_volume(input.positions, input.triangles);
    ASSERT_NEAR(mesh_signed_volume(input), v_in, 1e-9 * std::abs(v_in)) << name;
    for (int k = 0; k < 3; ++k) {
      const double error = contoured_volume_error(input, resolutions[k]);
      std::printf("%s at %d cells: volume error %+.5f%% (bound %.2f%%)\n", name, resolutions[k], 100.0 * error,
                  100.0 * bounds[k]);
      EXPECT_LE(std::abs(error), bounds[k]) << name << " at " << resolutions[k] << " cells";
    }
  }
}

}  // namespace
}  // namespace ldc
