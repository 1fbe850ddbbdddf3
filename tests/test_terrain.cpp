// The procedural landscape: determinism, its contract as an implicit solid,
// and that it really has caves, overhangs, arches and its materials.
//
// The Terrain tests use the solid alone; the DefaultLandscape and
// TerrainBuild tests go through build_terrain().
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include "ldc/terrain.h"
#include "test_util.h"

namespace ldc {
namespace {

// Uniform in [lo, hi) from a generator whose output the standard fixes
// (std::uniform_real_distribution is implementation-defined).
double uniform(std::mt19937& rng, double lo, double hi) {
  return lo + (hi - lo) * (double(rng()) / 4294967296.0);
}

// Inside/outside changes along the vertical line at (x, y), sampled every dz
// from below the floor to above the top of the bounds.
int sign_changes_along_z(const ImplicitSolid& s, double x, double y, double dz = 0.05) {
  const WorldBox b = s.bounds();
  int changes = 0;
  bool inside = s.value({x, y, b.min.z - dz}) < 0.0;
  for (double z = b.min.z; z <= b.max.z + dz; z += dz) {
    const bool now = s.value({x, y, z}) < 0.0;
    changes += now != inside;
    inside = now;
  }
  return changes;
}

// Counts vertical lines on a grid of `step` metres with more than two changes:
// solid, air, solid again (a cave, an overhang or an arch over the ground).
int layered_lines(const ImplicitSolid& s, const TerrainConfig& c, double step) {
  int layered = 0;
  for (double x = 0.5 * step; x < c.size_x; x += step) {
    for (double y = 0.5 * step; y < c.size_y; y += step) layered += sign_changes_along_z(s, x, y) > 2;
  }
  return layered;
}

// The surface point between a (inside) and b (outside), by bisection.
glm::dvec3 surface_between(const ImplicitSolid& s, glm::dvec3 a, glm::dvec3 b) {
  for (int k = 0; k < 50; ++k) {
    const glm::dvec3 mid = 0.5 * (a + b);
    (s.value(mid) < 0.0 ? a : b) = mid;
  }
  return a;
}

// Surface points where vertical and horizontal lines through the block cross
// the surface: the top, cave walls, cliffs, arches.
std::vector<glm::dvec3> surface_points(const ImplicitSolid& s, int lines, uint32_t seed) {
  const WorldBox b = s.bounds();
  std::mt19937 rng(seed);
  std::vector<glm::dvec3> points;
  for (int i = 0; i < lines; ++i) {
    const int axis = i % 3;
    glm::dvec3 p(uniform(rng, b.min.x + 0.1, b.max.x - 0.1), uniform(rng, b.min.y + 0.1, b.max.y - 0.1),
                 uniform(rng, b.min.z + 0.1, b.max.z));
    const double step = 0.1;
    glm::dvec3 a = p;
    a[axis] = b.min[axis] + 0.05;
    bool inside = s.value(a) < 0.0;
    for (double t = a[axis] + step; t < b.max[axis]; t += step) {
      glm::dvec3 q = a;
      q[axis] = t;
      const bool now = s.value(q) < 0.0;
      if (now != inside) points.push_back(now ? surface_between(s, q, a) : surface_between(s, a, q));
      inside = now;
      a = q;
    }
  }
  return points;
}

// The topmost surface point above (x, y).
glm::dvec3 top_surface(const ImplicitSolid& s, double x, double y) {
  const WorldBox b = s.bounds();
  for (double z = b.max.z; z > b.min.z; z -= 0.05) {
    if (s.value({x, y, z}) < 0.0) return surface_between(s, {x, y, z}, {x, y, z + 0.05});
  }
  return {x, y, b.min.z};
}

TEST(Terrain, SameSeedGivesIdenticalValues) {
  TerrainConfig c;
  auto a = make_terrain_solid(c), b = make_terrain_solid(c);
  std::mt19937 rng(1);
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 p(uniform(rng, -2.0, 50.0), uniform(rng, -2.0, 50.0), uniform(rng, -1.0, 15.0));
    ASSERT_EQ(a->value(p), b->value(p));
    ASSERT_EQ(a->material(p), b->material(p));
  }
}

TEST(Terrain, DefaultSceneIsTheSameOnEveryMachine) {
  // FNV-1a over the bits of value() and material() at fixed points. The
  // landscape uses no libm calls and no fused multiply-adds, so this holds for
  // every compiler, optimisation level and target. Update the constant only
  // when the landscape is changed on purpose.
  auto s = make_terrain_solid(TerrainConfig{});
  uint64_t hash = 1469598103934665603ull;
  for (int i = 0; i < 200000; ++i) {
    const glm::dvec3 p(0.37 * (i % 131), 0.29 * ((i / 131) % 167), 0.11 * (i % 113));
    const double v = s->value(p);
    uint64_t bits;
    std::memcpy(&bits, &v, sizeof(bits));
    hash = (hash ^ bits) * 1099511628211ull;
    hash = (hash ^ s->material(p)) * 1099511628211ull;
  }
  EXPECT_EQ(hash, 0x4e8a5c216e7488b6ull);
}

TEST(Terrain, ValuesDoNotDependOnTheThread) {
  auto s = make_terrain_solid(TerrainConfig{});
  std::vector<glm::dvec3> points;
  std::mt19937 rng(2);
  for (int i = 0; i < 20000; ++i) {
    points.push_back({uniform(rng, 0.0, 48.0), uniform(rng, 0.0, 48.0), uniform(rng, 0.0, 12.0)});
  }
  std::vector<double> serial(points.size()), parallel(points.size());
  for (size_t i = 0; i < points.size(); ++i) serial[i] = s->value(points[i]);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (size_t i = t; i < points.size(); i += 4) parallel[i] = s->value(points[i]);
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(serial, parallel);
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
    for (double z : {0.5, 3.0, 6.0}) {
      EXPECT_GT(s->value({-0.01, t, z}), 0.0);
      EXPECT_GT(s->value({48.01, t, z}), 0.0);
      EXPECT_GT(s->value({t, -0.01, z}), 0.0);
      EXPECT_GT(s->value({t, 48.01, z}), 0.0);
    }
    EXPECT_GT(s->value({t, t, -0.01}), 0.0);
    EXPECT_GT(s->value({t, t, -50.0}), 0.0);
    EXPECT_GT(s->value({t, t, s->bounds().max.z + 0.01}), 0.0);
  }
  // Far away and non-finite coordinates are outside too (and do not crash).
  EXPECT_GT(s->value({1e300, 5.0, 5.0}), 0.0);
  EXPECT_GT(s->value({5.0, -1e300, 5.0}), 0.0);
}

TEST(Terrain, SidesOfTheBlockAreVerticalWalls) {
  // Just inside a side wall, below the ground, the value is the distance to
  // the wall: the solid is cut straight down.
  auto s = make_terrain_solid(TerrainConfig{});
  for (double t = 1.0; t < 47.0; t += 1.3) {
    EXPECT_DOUBLE_EQ(s->value({0.01, t, 0.6}), -0.01);
    EXPECT_NEAR(s->value({t, 47.99, 0.6}), -0.01, 1e-9);
  }
}

TEST(Terrain, BoundsAreTheBlockUpToTheHighestPoint) {
  TerrainConfig c;
  c.size_x = 40.0;
  c.size_y = 30.0;
  c.floor_z = -3.0;
  auto s = make_terrain_solid(c);
  const WorldBox b = s->bounds();
  EXPECT_EQ(b.min, glm::dvec3(0.0, 0.0, -3.0));
  EXPECT_EQ(b.max.x, 40.0);
  EXPECT_EQ(b.max.y, 30.0);
  // Ground up to base + relief / 2, arches above it.
  EXPECT_GE(b.max.z, c.floor_z + c.base_height + 0.5 * c.relief);
  EXPECT_LE(b.max.z, c.floor_z + c.base_height + 0.5 * c.relief + 8.0);
  for (double x = 0.25; x < 40.0; x += 0.5) {
    for (double y = 0.25; y < 30.0; y += 0.5) ASSERT_GT(s->value({x, y, b.max.z}), 0.0);
  }
}

TEST(Terrain, ClassifyNeverContradictsValue) {
  TerrainConfig c;
  auto s = make_terrain_solid(c);
  std::mt19937 rng(9);
  int inside = 0, outside = 0;
  for (int i = 0; i < 4000; ++i) {
    // Mostly boxes anywhere; every fourth one low down, where kInside is possible.
    const bool low = i % 4 == 0;
    const glm::dvec3 lo(uniform(rng, -3.0, 51.0), uniform(rng, -3.0, 51.0),
                        low ? uniform(rng, -0.5, 1.5) : uniform(rng, -2.0, 17.0));
    const double scale = low ? 1.0 : 8.0;
    const glm::dvec3 size(uniform(rng, 0.1, scale), uniform(rng, 0.1, scale), uniform(rng, 0.05, scale));
    const WorldBox box{lo, lo + size};
    const ImplicitSolid::BoxClass cls = s->classify(box);
    if (cls == ImplicitSolid::BoxClass::kUnknown) continue;
    (cls == ImplicitSolid::BoxClass::kInside ? inside : outside) += 1;
    for (int k = 0; k < 125; ++k) {  // a 5^3 grid including corners and faces
      const glm::dvec3 f((k % 5) / 4.0, ((k / 5) % 5) / 4.0, (k / 25) / 4.0);
      const double v = s->value(box.min + f * (box.max - box.min));
      if (cls == ImplicitSolid::BoxClass::kOutside) {
        ASSERT_GE(v, 0.0) << "box " << i;
      } else {
        ASSERT_LT(v, 0.0) << "box " << i;
      }
    }
  }
  EXPECT_GT(outside, 300);  // the classifier is worth having
  EXPECT_GT(inside, 50);
}

TEST(Terrain, NormalsPointOutward) {
  auto s = make_terrain_solid(TerrainConfig{});
  const std::vector<glm::dvec3> points = surface_points(*s, 300, 4);
  ASSERT_GT(points.size(), 300u);
  for (const glm::dvec3& p : points) {
    const glm::dvec3 n = s->normal(p, 2e-4);
    EXPECT_NEAR(glm::length(n), 1.0, 1e-9);
    EXPECT_GT(s->value(p + 0.01 * n), s->value(p - 0.01 * n)) << p.x << " " << p.y << " " << p.z;
  }
}

TEST(Terrain, ValueIsDistanceLikeNearTheSurface) {
  // |grad value| about 1 at the surface, so root finding converges fast.
  auto s = make_terrain_solid(TerrainConfig{});
  std::vector<double> slopes;
  for (const glm::dvec3& p : surface_points(*s, 300, 5)) {
    const double h = 1e-4;
    const glm::dvec3 g(s->value(p + glm::dvec3(h, 0, 0)) - s->value(p - glm::dvec3(h, 0, 0)),
                       s->value(p + glm::dvec3(0, h, 0)) - s->value(p - glm::dvec3(0, h, 0)),
                       s->value(p + glm::dvec3(0, 0, h)) - s->value(p - glm::dvec3(0, 0, h)));
    slopes.push_back(glm::length(g) / (2.0 * h));
  }
  std::sort(slopes.begin(), slopes.end());
  ASSERT_FALSE(slopes.empty());
  EXPECT_GT(slopes[slopes.size() / 2], 0.8);
  EXPECT_LT(slopes[slopes.size() / 2], 1.25);
  EXPECT_GT(slopes[slopes.size() / 10], 0.4);
  EXPECT_LT(slopes[slopes.size() * 9 / 10], 2.5);
}

TEST(Terrain, HasCavesBelowTheSurface) {
  // Caves alone (no arches, no overhangs): some vertical lines go solid, air,
  // solid, air.
  TerrainConfig c;
  c.arches = 0;
  c.overhang = 0.0;
  auto s = make_terrain_solid(c);
  EXPECT_GT(layered_lines(*s, c, 1.0), 20);
}

TEST(Terrain, SomeCaveOpensToTheSurface) {
  // A cave mouth: the topmost surface over some columns is a cave wall (dirt).
  auto s = make_terrain_solid(TerrainConfig{});
  int mouths = 0;
  for (double x = 0.25; x < 48.0; x += 0.5) {
    for (double y = 0.25; y < 48.0; y += 0.5) {
      mouths += s->material(top_surface(*s, x, y)) == kMaterialDirt;
    }
  }
  EXPECT_GT(mouths, 10);
}

TEST(Terrain, CliffsLeanOutIntoOverhangs) {
  // Without caves and arches, a vertical line can only cross the surface more
  // than twice where a cliff leans out over the ground below it ...
  TerrainConfig c;
  c.cave_radius = 0.0;
  c.arches = 0;
  auto s = make_terrain_solid(c);
  EXPECT_GT(layered_lines(*s, c, 0.5), 20);
  // ... and the sideways warp is what makes them.
  c.overhang = 0.0;
  auto flat = make_terrain_solid(c);
  EXPECT_EQ(layered_lines(*flat, c, 0.5), 0);
}

TEST(Terrain, ArchesStandOverOpenGround) {
  TerrainConfig c;
  c.cave_radius = 0.0;
  c.overhang = 0.0;
  auto s = make_terrain_solid(c);
  EXPECT_GT(layered_lines(*s, c, 0.5), 20);
  c.arches = 0;
  auto none = make_terrain_solid(c);
  EXPECT_EQ(layered_lines(*none, c, 0.5), 0);
  EXPECT_LT(none->bounds().max.z, s->bounds().max.z);
}

TEST(Terrain, MaterialsIncludeGrassRockAndDirt) {
  auto s = make_terrain_solid(TerrainConfig{});
  std::set<uint16_t> seen;
  for (const glm::dvec3& p : surface_points(*s, 600, 6)) {
    const uint16_t m = s->material(p);
    seen.insert(m);
    ASSERT_LE(m, kMaterialSand);
    // Sand only low down, in the valleys.
    if (m == kMaterialSand) {
      EXPECT_LT(p.z, 6.0);
    }
  }
  EXPECT_TRUE(seen.count(kMaterialGrass));
  EXPECT_TRUE(seen.count(kMaterialRock));
  EXPECT_TRUE(seen.count(kMaterialDirt));
  EXPECT_TRUE(seen.count(kMaterialSand));
}

TEST(Terrain, SmallBlockStillWorks) {
  // Too small for any arch; still a valid, bounded solid.
  TerrainConfig c;
  c.size_x = 3.0;
  c.size_y = 2.0;
  auto s = make_terrain_solid(c);
  EXPECT_DOUBLE_EQ(s->bounds().max.z, c.floor_z + c.base_height + 0.5 * c.relief);
  EXPECT_LT(s->value({1.5, 1.0, 0.3}), 0.0);
  EXPECT_GT(s->value({1.5, 1.0, 12.0}), 0.0);
}

TEST(Terrain, MaterialNames) {
  EXPECT_STREQ(terrain_material_name(kMaterialRock), "rock");
  EXPECT_STREQ(terrain_material_name(kMaterialGrass), "grass");
  EXPECT_STREQ(terrain_material_name(kMaterialDirt), "dirt");
  EXPECT_STREQ(terrain_material_name(kMaterialSand), "sand");
  EXPECT_STREQ(terrain_material_name(77), "unknown");
}

TEST(Terrain, CheckNamesTheBadFieldAndValue) {
  EXPECT_TRUE(check_terrain(TerrainConfig{}).ok());
  TerrainConfig c;
  c.size_x = -1.0;
  Status s = check_terrain(c);
  EXPECT_EQ(s.code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "terrain: size_x = -1 must be > 0");
  c = TerrainConfig{};
  c.relief = std::nan("");
  EXPECT_NE(check_terrain(c).message().find("relief"), std::string::npos);
  c = TerrainConfig{};
  c.base_height = 0.0;
  EXPECT_NE(check_terrain(c).message().find("base_height = 0"), std::string::npos);
  c = TerrainConfig{};
  c.floor_z = INFINITY;
  EXPECT_NE(check_terrain(c).message().find("floor_z"), std::string::npos);
  c = TerrainConfig{};
  c.arches = 65;
  EXPECT_EQ(check_terrain(c).message(), "terrain: arches = 65 must be in 0 .. 64");
  c = TerrainConfig{};
  c.cave_radius = -0.5;
  EXPECT_EQ(check_terrain(c).message(), "terrain: cave_radius = -0.5 must be >= 0");
}

// --- Through the builder -------------------------------------------------------

TEST(TerrainBuild, BadConfigsNameTheirField) {
  TerrainConfig c;
  c.size_x = -1.0;
  Result<World> w = build_terrain(c, 0.4);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(w.status().message().find("size_x"), std::string::npos);
  c = TerrainConfig{};
  c.arches = 1000;
  EXPECT_FALSE(build_terrain(c, 0.4).ok());
  Result<World> bad_cell = build_terrain(TerrainConfig{}, -0.2);
  ASSERT_FALSE(bad_cell.ok());
  EXPECT_NE(bad_cell.status().message().find("cell_size"), std::string::npos);
}

TEST(TerrainBuild, BuildsAtACoarseCellSize) {
  BuildReport report;
  Result<World> w = build_terrain(TerrainConfig{}, 0.4, 32, nullptr, &report);
  ASSERT_TRUE(w.ok()) << w.status().to_string();
  const World& world = w.value();
  EXPECT_GT(world.stats().chunks_mixed, 0u);
  EXPECT_DOUBLE_EQ(world.lattice().cell_size, 0.4);
  EXPECT_EQ(world.chunk_size(), 32);
  EXPECT_EQ(world.metadata_value("source"), "terrain");
  EXPECT_EQ(world.metadata_value("terrain.seed"), "1");
  EXPECT_EQ(world.metadata_value("material.0"), "rock");
  EXPECT_EQ(world.metadata_value("material.3"), "sand");
  EXPECT_TRUE(test::is_valid(world));
}

TEST(TerrainBuild, SameSeedGivesTheSameWorld) {
  Result<World> a = build_terrain(TerrainConfig{}, 0.8, 16);
  Result<World> b = build_terrain(TerrainConfig{}, 0.8, 16);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.value().stats().points, b.value().stats().points);
  EXPECT_EQ(a.value().volume(2), b.value().volume(2));
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
  // A cave: an air gap of more than 3 cells between two solid spans of a vertical ray.
  const World& w = *world_;
  int cave_gaps = 0;
  for (int i = 3; i < 240; i += 3) {
    for (int j = 3; j < 240; j += 3) {
      auto spans = w.ray_spans(2, {i, j});
      for (size_t k = 0; k + 1 < spans.size(); ++k) {
        cave_gaps += spans[k + 1].enter.depth - spans[k].exit.depth > 3.0;
      }
    }
  }
  EXPECT_GT(cave_gaps, 10);
}

TEST_F(DefaultLandscape, UsesGrassRockAndDirt) {
  std::set<uint16_t> seen;
  world_->for_each_chunk([&](const glm::ivec3&, ChunkKind, const Chunk* d) {
    if (!d) return;
    for (const RayFamily& f : d->axis) {
      for (const PackedPoint& p : f.all_points()) seen.insert(p.material);
    }
  });
  EXPECT_TRUE(seen.count(kMaterialGrass));
  EXPECT_TRUE(seen.count(kMaterialRock));
  EXPECT_TRUE(seen.count(kMaterialDirt));
  EXPECT_EQ(world_->metadata_value("material.1"), "grass");
}

}  // namespace
}  // namespace ldc
