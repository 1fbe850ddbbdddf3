// Small scenes for the GI tests (CPU and Vulkan): unions of boxes on a
// lattice of h = 0.1 m with its origin at 0, so that 0.2 m voxels have
// their faces on multiples of 0.2 m; and a ball over the ground (implicit)
// for the path tracer's view-factor test.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "gi_bridge/gi.h"
#include "ldc/build.h"
#include "voxelize/voxelize.h"

namespace ldc::test {

struct GiBox {
  glm::dvec3 lo, hi;
  uint16_t material = 0;
};

inline void add_box(TriangleMesh& m, const GiBox& b) {
  const uint32_t base = uint32_t(m.positions.size());
  for (int i = 0; i < 8; ++i)
    m.positions.emplace_back(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z);
  const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.emplace_back(base + f[0], base + f[1], base + f[2]);
    m.triangles.emplace_back(base + f[0], base + f[2], base + f[3]);
    m.triangle_material.push_back(b.material);
    m.triangle_material.push_back(b.material);
  }
}

inline World build_boxes(const std::vector<GiBox>& boxes) {
  TriangleMesh mesh;
  for (const GiBox& b : boxes) add_box(mesh, b);
  GridConfig grid;
  grid.cell_size = 0.1;
  grid.use_origin = true;
  grid.origin = glm::dvec3(0.0);
  Result<World> w = build_from_mesh(mesh, grid);
  EXPECT_TRUE(w.ok()) << w.status().message();
  return std::move(w).value();
}

// Materials: 0 grey 0.7, 1 black, 2 white emitter (emission 4), 3 red 0.7, 4 green 0.7.
inline MaterialTable gi_test_materials() {
  MaterialTable t;
  t.materials = {{glm::vec3(0.7f), glm::vec3(0.0f)},
                 {glm::vec3(0.0f), glm::vec3(0.0f)},
                 {glm::vec3(0.7f), glm::vec3(4.0f)},
                 {glm::vec3(0.7f, 0.1f, 0.1f), glm::vec3(0.0f)},
                 {glm::vec3(0.1f, 0.7f, 0.1f), glm::vec3(0.0f)}};
  return t;
}

inline Cascades make_cascades(const World& world, const glm::dvec3& camera, int levels = 3, int resolution = 16) {
  CascadeConfig c;
  c.levels = levels;
  c.resolution = resolution;
  c.voxel_size = 0.2;
  c.materials = gi_test_materials();
  Result<Cascades> cas = Cascades::create(world.lattice(), c);
  EXPECT_TRUE(cas.ok()) << cas.status().message();
  Status s = cas.value().update_all(world, camera);
  EXPECT_TRUE(s.ok()) << s.message();
  return std::move(cas).value();
}

// A closed room: walls around the inside [-0.8, 0.8]^3 out to `outer`
// (1.6 m thick by default). Thick, because cones see a wall through coarse
// voxels once they are as wide as the room: with 0.4 m walls around a 2.4 m
// room the coarsest level (0.8 m voxels) holds them at half opacity (the
// talk's "cone tracing is only a rough estimate"). The sealed-pocket rule
// (gi_common.glsl's point_dark) keeps such a room black under the sky
// alone whatever its walls; a light inside still sees the leak.
inline std::vector<GiBox> closed_room(uint16_t wall_material = 0, double outer = 2.4) {
  const double a = 0.8, b = outer;
  return {{{-b, -b, -b}, {b, b, -a}, wall_material}, {{-b, -b, a}, {b, b, b}, wall_material},
          {{-b, -b, -b}, {-a, b, b}, wall_material}, {{a, -b, -b}, {b, b, b}, wall_material},
          {{-b, -b, -b}, {b, -a, b}, wall_material}, {{-b, a, -b}, {b, b, b}, wall_material}};
}

// The CPU engine's irradiance at five points on the inside walls of a
// glowing closed room (closed_room(2, ...): emission 4, albedo 0.7) over
// the exact furnace value 4 pi (1 + 0.7 + 0.49 ...), after 1, 2 and 3
// bounces: ratio[bounces - 1][point].
inline std::vector<std::vector<float>> furnace_ratios(const World& world) {
  const Cascades cas = make_cascades(world, glm::dvec3(0.0));
  auto gi = make_cpu_gi();
  EXPECT_TRUE(gi->load(cas, GiLights{}).ok());
  EXPECT_TRUE(gi->update_all(3).ok());
  const std::vector<glm::dvec3> p = {{0, 0, -0.8}, {0.3, -0.2, 0.8}, {0.8, 0.3, 0.2}, {-0.5, 0.8, -0.5}, {-0.6, -0.6, -0.8}};
  const std::vector<glm::vec3> n = {{0, 0, 1}, {0, 0, -1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}};
  std::vector<std::vector<float>> ratio;
  for (int b = 1; b <= 3; ++b) {
    std::vector<glm::vec3> e(p.size());
    EXPECT_TRUE(gi->irradiance(p, n, b, e).ok());
    const float exact = 4.0f * 3.14159265f * (b == 1 ? 1.0f : b == 2 ? 1.7f : 2.19f);
    ratio.emplace_back();
    for (const glm::vec3& v : e) ratio.back().push_back((v.r + v.g + v.b) / 3.0f / exact);
  }
  return ratio;
}

// Checks furnace_ratios: above low[bounces - 1] and under 1.02 at every point.
inline void expect_furnace_ratios(const std::vector<std::vector<float>>& ratio, const std::array<float, 3>& low) {
  for (int b = 1; b <= 3; ++b) {
    for (size_t i = 0; i < ratio[size_t(b - 1)].size(); ++i) {
      EXPECT_GT(ratio[size_t(b - 1)][i], low[size_t(b - 1)]) << "bounces " << b << ", point " << i;
      EXPECT_LT(ratio[size_t(b - 1)][i], 1.02f) << "bounces " << b << ", point " << i;
    }
  }
}

}  // namespace ldc::test

namespace ldc::test {

// A ball of radius r centred at `centre` above a slab whose top is z = 0
// (x, y in [-half, half], 0.3 m thick), both of one material: an implicit
// solid, so the ball's crossings are its exact roots.
class BallOverGround : public ImplicitSolid {
 public:
  BallOverGround(const glm::dvec3& centre, double r, double half, uint16_t material)
      : centre_(centre), r_(r), half_(half), material_(material) {}
  double value(const glm::dvec3& p) const override {
    const double slab = std::max({p.z, -0.3 - p.z, std::abs(p.x) - half_, std::abs(p.y) - half_});
    return std::min(slab, glm::length(p - centre_) - r_);
  }
  uint16_t material(const glm::dvec3&) const override { return material_; }
  WorldBox bounds() const override {
    return {glm::min(glm::dvec3(-half_, -half_, -0.3), centre_ - r_),
            glm::max(glm::dvec3(half_, half_, 0.0), centre_ + r_)};
  }

 private:
  glm::dvec3 centre_;
  double r_, half_;
  uint16_t material_;
};

// The ball over the ground built on a lattice of cell size h whose planes miss
// z = 0 (origin offset by a fraction of a cell), so that no node lies on the ground.
inline World build_ball_over_ground(const glm::dvec3& centre, double r, double half, double h, uint16_t material) {
  GridConfig grid;
  grid.cell_size = h;
  grid.use_origin = true;
  grid.origin = glm::dvec3(0.31, 0.17, 0.43) * h;
  Result<World> w = build_from_implicit(BallOverGround(centre, r, half, material), grid);
  EXPECT_TRUE(w.ok()) << w.status().message();
  return std::move(w).value();
}

// A full update's stage times: each measured, the cones and updates > 0,
// and together at most the device time (Vulkan: their timestamps tile it;
// CPU: the loop between the kernels is left out). `where` names the case.
inline void expect_stages_within_device_time(const GiTimings& t, const char* where) {
  const GiTimings::Stages& s = t.stage_device_seconds;
  EXPECT_GT(s.cones, 0.0) << where;
  EXPECT_GT(s.update, 0.0) << where;
  EXPECT_GE(s.copy, 0.0) << where;
  EXPECT_GE(s.precombine, 0.0) << where;
  EXPECT_LE(s.cones + s.update + s.copy + s.precombine, t.device_seconds * (1.0 + 1e-9)) << where;
}

}  // namespace ldc::test
