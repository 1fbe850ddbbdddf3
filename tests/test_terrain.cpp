// The procedural landscape: determinism, its contract as an implicit solid,
// and that it really has caves, overhangs, arches and its materials.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "ldc/terrain.h"
#include "test_util.h"

namespace ldc {
namespace {

TEST(Terrain, SameSeedGivesIdenticalValues) {
  TerrainConfig c;
  auto a = make_terrain_solid(c), b = make_terrain_solid(c);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-2.0, 50.0);
  for (int i = 0; i < 20000; ++i) {
    glm::dvec3 p(u(rng), u(rng), u(rng) * 0.3);
    ASSERT_EQ(a->value(p), b->value(p));
    ASSERT_EQ(a->material(p), b->material(p));
  }
}

TEST(Terrain, DifferentSeedsGiveDifferentLandscapes) {
  TerrainConfig c1, c2;
  c2.seed = 2;
  auto a = make_terrain_solid(c1), b = make_terrain_solid(c2);
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    glm::dvec3 p(1.0 + i * 0.046, 30.0 - i * 0.02, 6.0);
    differ += a->value(p) != b->value(p);
  }
  EXPECT_GT(differ, 900);
}

TEST(Terrain, OutsideTheBlockAndBelowTheFloorIsOutside) {
  TerrainConfig c;
  auto s = make_terrain_solid(c);
  for (double t = 0.0; t <= 48.0; t += 0.7) {
    EXPECT_GT(s->value({-0.01, t, 3.0}), 0.0);
    EXPECT_GT(s->value({48.01, t, 3.0}), 0.0);
    EXPECT_GT(s->value({t, -0.01, 3.0}), 0.0);
    EXPECT_GT(s->value({t, 48.01, 3.0}), 0.0);
    EXPECT_GT(s->value({t, t, -0.01}), 0.0);
    EXPECT_GT(s->value({t, t, s->bounds().max.z + 0.01}), 0.0);
  }
}

TEST(Terrain, ClassifyNeverContradictsValue) {
  TerrainConfig c;
  auto s = make_terrain_solid(c);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-3.0, 51.0), size(0.2, 8.0);
  int decided = 0;
  for (int i = 0; i < 3000; ++i) {
    glm::dvec3 lo(u(rng), u(rng), u(rng) * 0.35 - 2.0);
    WorldBox box{lo, lo + glm::dvec3(size(rng), size(rng), size(rng))};
    ImplicitSolid::BoxClass cls = s->classify(box);
    if (cls == ImplicitSolid::BoxClass::kUnknown) continue;
    ++decided;
    for (int k = 0; k < 64; ++k) {
      glm::dvec3 f((k & 3) / 3.0, ((k >> 2) & 3) / 3.0, ((k >> 4) & 3) / 3.0);
      double v = s->value(box.min + f * (box.max - box.min));
      if (cls == ImplicitSolid::BoxClass::kOutside) ASSERT_GE(v, 0.0);
      else ASSERT_LT(v, 0.0);
    }
  }
  EXPECT_GT(decided, 300);  // the classifier is worth having
}

TEST(Terrain, NormalsPointOutward) {
  TerrainConfig c;
  auto s = make_terrain_solid(c);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(1.0, 47.0);
  int checked = 0;
  for (int i = 0; i < 4000 && checked < 500; ++i) {
    // Find a surface point on a vertical segment, then test the normal there.
    double x = u(rng), y = u(rng);
    double lo = 0.2, hi = s->bounds().max.z;
    if (!(s->value({x, y, lo}) < 0.0) || !(s->value({x, y, hi}) > 0.0)) continue;
    for (int k = 0; k < 50; ++k) {
      double mid = 0.5 * (lo + hi);
      (s->value({x, y, mid}) < 0.0 ? lo : hi) = mid;
    }
    glm::dvec3 p(x, y, lo), n = s->normal(p, 1e-4);
    EXPECT_NEAR(glm::length(n), 1.0, 1e-6);
    EXPECT_GT(s->value(p + 0.01 * n), s->value(p - 0.01 * n));
    ++checked;
  }
  EXPECT_GT(checked, 100);
}

TEST(Terrain, BadConfigsNameTheirField) {
  TerrainConfig c;
  c.size_x = -1.0;
  Result<World> w = build_terrain(c, 0.4);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("size_x"), std::string::npos);
  c = TerrainConfig{};
  c.arches = 1000;
  EXPECT_FALSE(build_terrain(c, 0.4).ok());
  EXPECT_FALSE(build_terrain(TerrainConfig{}, -0.2).ok());
}

// The default scene at the game's cell size: what every user sees first.
class DefaultLandscape : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { world_ = new World(build_terrain(TerrainConfig{}, 0.2).value()); }
  static void TearDownTestSuite() { delete world_; }
  static World* world_;
};
World* DefaultLandscape::world_ = nullptr;

TEST_F(DefaultLandscape, IsValid) { EXPECT_TRUE(test::is_valid(*world_)); }

TEST_F(DefaultLandscape, HasColumnsWithSeveralSolidLayers) {
  // Caves, overhangs and arches all show up as vertical rays with more than one span.
  const World& w = *world_;
  int columns = 0, layered = 0, three_or_more = 0;
  for (int i = 5; i < 240; i += 2) {
    for (int j = 5; j < 240; j += 2) {
      size_t spans = w.ray_spans(2, {i, j}).size();
      ++columns;
      layered += spans >= 2;
      three_or_more += spans >= 3;
    }
  }
  EXPECT_GT(layered, columns / 100) << layered << " of " << columns;
  EXPECT_GT(three_or_more, 0);
}

TEST_F(DefaultLandscape, HasAirEnclosedBelowTheSurface) {
  // A cave: an air node with solid straight above it and solid straight below it.
  const World& w = *world_;
  int cave_nodes = 0;
  for (int i = 3; i < 240; i += 3) {
    for (int j = 3; j < 240; j += 3) {
      auto spans = w.ray_spans(2, {i, j});
      for (size_t k = 0; k + 1 < spans.size(); ++k) cave_nodes += spans[k + 1].enter.depth - spans[k].exit.depth > 3.0;
    }
  }
  EXPECT_GT(cave_nodes, 10);
}

TEST_F(DefaultLandscape, UsesGrassRockAndDirt) {
  std::set<uint16_t> seen;
  world_->for_each_chunk([&](const glm::ivec3&, ChunkKind, const Chunk* d) {
    if (!d) return;
    for (const RayFamily& f : d->axis)
      for (const PackedPoint& p : f.all_points()) seen.insert(p.material);
  });
  EXPECT_TRUE(seen.count(kMaterialGrass));
  EXPECT_TRUE(seen.count(kMaterialRock));
  EXPECT_TRUE(seen.count(kMaterialDirt));
  EXPECT_EQ(world_->metadata_value("material.1"), "grass");
}

}  // namespace
}  // namespace ldc
