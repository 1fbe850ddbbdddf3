// The world container, point encoding and validate() catching broken invariants.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "ldc/build.h"
#include "ldc/internal/ray_math.h"
#include "test_util.h"

namespace ldc {
namespace {

TEST(PointCodec, NormalErrorStaysBelowTwoHundredthsOfADegree) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    glm::dvec3 n = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    glm::dvec3 d = glm::dvec3(decode_normal(encode_normal(n)));
    worst = std::max(worst, std::acos(std::min(1.0, glm::dot(n, d))) * 180.0 / M_PI);
  }
  EXPECT_LT(worst, 0.02);  // the design target is 0.1 degrees
}

TEST(PointCodec, AxisNormalsAreExact) {
  for (int a = 0; a < 3; ++a) {
    for (double s : {-1.0, 1.0}) {
      glm::dvec3 n(0.0);
      n[a] = s;
      glm::vec3 d = decode_normal(encode_normal(n));
      EXPECT_NEAR(d[a], s, 1e-6);
      EXPECT_NEAR(glm::length(d), 1.0, 1e-6);
    }
  }
}

TEST(PointCodec, DecodingCountsDepthStepsFromTheSegmentStart) {
  PackedPoint p;
  p.depth = 12345;
  SurfacePoint s = decode_point(p, 32, 64);
  EXPECT_DOUBLE_EQ(s.depth, 64.0 + 12345.0 / 2048.0);
}

// The round trip: a sphere's crossings, encoded by the builder and decoded
// by ray_points, against the exact intersections of the vertical rays.
TEST(PointCodec, EncodedDepthsAreWithinHalfAStepOfTheExactCrossings) {
  Primitive sphere;
  sphere.radius = 1.3;
  sphere.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.31, -0.2, 0.05));
  const World w = build_from_primitive(sphere, {.cells = 48, .chunk_size = 16}).value();
  const Lattice& l = w.lattice();
  const double step = 1.0 / depth_steps_per_cell(16);  // cells
  size_t checked = 0;
  for (int v = 0; v < 60; ++v)
    for (int u = 0; u < 60; ++u) {
      const glm::dvec3 at = l.to_world(glm::dvec3(u, v, 0.0));
      const double dx = at.x - 0.31, dy = at.y + 0.2, r2 = 1.3 * 1.3 - dx * dx - dy * dy;
      const std::vector<SurfacePoint> pts = w.ray_points(2, {u, v});
      if (r2 <= 0.0) {
        EXPECT_TRUE(pts.empty()) << u << " " << v;
        continue;
      }
      ASSERT_EQ(pts.size(), 2u) << u << " " << v;
      const double exact[2] = {(0.05 - std::sqrt(r2) - l.origin.z) / l.cell_size,
                               (0.05 + std::sqrt(r2) - l.origin.z) / l.cell_size};
      for (int k = 0; k < 2; ++k) {
        // Crossings within a step of a node are nudged off it (never stored on a node).
        if (std::abs(exact[k] - std::round(exact[k])) < step) continue;
        EXPECT_NEAR(pts[k].depth, exact[k], 0.5 * step + 1e-9) << u << " " << v;
        ++checked;
      }
    }
  EXPECT_GT(checked, 1000u);
}

TEST(BitTricks, TransposesMatchTheNaiveOnes) {
  std::mt19937_64 rng(3);
  for (int c : {8, 16, 32, 64}) {
    uint64_t m[64], t[64];
    for (int i = 0; i < 64; ++i) m[i] = i < c ? rng() & (c == 64 ? ~0ull : (1ull << c) - 1) : 0;
    std::copy(m, m + 64, t);
    detail::transpose_bits(t, c);
    for (int r = 0; r < c; ++r)
      for (int col = 0; col < c; ++col) ASSERT_EQ((t[r] >> col) & 1, (m[col] >> r) & 1) << c;
  }
}

TEST(BitTricks, NodeWordCountsPointsBeforeEachNode) {
  std::vector<PackedPoint> pts(2);
  pts[0].depth = 2048 * 3 + 5;   // between nodes 3 and 4
  pts[1].depth = 2048 * 7 + 100; // between nodes 7 and 8
  uint64_t w = detail::node_word(false, pts, 32);
  for (int n = 0; n < 32; ++n) EXPECT_EQ((w >> n) & 1, uint64_t(n >= 4 && n <= 7)) << n;
}

TEST(WorldConfig, BadValuesAreRefusedWithTheirName) {
  WorldConfig c;
  c.chunk_size = 12;
  Result<World> w = World::create(c);
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("chunk_size = 12"), std::string::npos);
  c.chunk_size = 32;
  c.lattice.cell_size = std::nan("");
  EXPECT_FALSE(World::create(c).ok());
  c.lattice.cell_size = 0.2;
  c.chunk_dims = {4096, 4096, 4096};
  w = World::create(c);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), ErrorCode::kTooLarge);
}

// Issue 24, item 4: the range every World keeps, whoever makes it (builders,
// the loader, an edit growing the box). Each message names value and limit.
std::string create_error(const WorldConfig& c) {
  Result<World> w = World::create(c);
  return w.ok() ? "created" : w.status().message();
}

TEST(WorldConfig, LatticesDoublesCannotCarryAreRefused) {
  WorldConfig c;  // h = 0.2, one chunk of 32 cells at the origin
  EXPECT_EQ(create_error(c), "created");
  c.lattice.cell_size = 5e-324;
  EXPECT_NE(create_error(c).find("world: cell size 4.94066e-324 m is below the limit of 1e-100 m"), std::string::npos)
      << create_error(c);
  c.lattice.cell_size = 1.7e308;
  EXPECT_NE(create_error(c).find("world: the lattice's box (0, 0, 0) .. (inf, inf, inf) is not finite"),
            std::string::npos)
      << create_error(c);
  c.lattice.cell_size = 0.2;
  c.lattice.origin = glm::dvec3(1.7e308, 0.0, 0.0);
  EXPECT_NE(create_error(c).find("reaches 1.7e+308 m, past the limit of 1e+100 m"), std::string::npos)
      << create_error(c);
  c.lattice.origin = glm::dvec3(0.0, 0.0, 1e15);
  EXPECT_NE(create_error(c).find("world: cell size 0.2 m is below the limit of 125 m for coordinates up to 1e+15 m"),
            std::string::npos)
      << create_error(c);
  c.lattice.cell_size = 125.0;
  EXPECT_EQ(create_error(c), "created");
}

TEST(World, GrowingPastTheCoordinateLimitIsRefused) {
  World w = World::create({.lattice = {.origin = glm::dvec3(0.0), .cell_size = 1e97}}).value();
  Status s = w.grow_to_include({0, 0, 0}, {1000, 1, 1});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("past the limit of 1e+100 m"), std::string::npos) << s.message();
  EXPECT_EQ(w.chunk_dims(), glm::ivec3(1));  // unchanged
}

TEST(World, EmptyWorldIsValidAndOutsideEverywhere) {
  World w = World::create({.chunk_dims = {2, 3, 1}}).value();
  EXPECT_TRUE(test::is_valid(w));
  EXPECT_FALSE(w.inside_node({5, 5, 5}));
  EXPECT_FALSE(w.inside({1.0, 1.0, 1.0}));
  EXPECT_EQ(w.volume(0), 0.0);
  EXPECT_FALSE(w.solid_bounds().has_value());
}

TEST(World, CopiesShareChunksAndStayIndependent) {
  Primitive p;
  p.radius = 1.0;
  World a = build_from_primitive(p, {.cells = 32}).value();
  World b = a;
  glm::ivec3 some_chunk = a.chunk_origin();
  b.set_uniform_chunk(some_chunk, true);
  EXPECT_NE(a.chunk_kind(some_chunk), b.chunk_kind(some_chunk));
  EXPECT_TRUE(test::is_valid(a));
}

// --- validate() must catch each kind of damage --------------------------------

World small_sphere_world() {
  Primitive p;
  p.radius = 1.0;
  return build_from_primitive(p, {.cells = 40, .chunk_size = 16}).value();
}

// Replaces one family of the first mixed chunk by the result of `edit` on its rays.
void damage_first_mixed(World& w, int axis,
                        const std::function<void(int ray, bool& start, std::vector<PackedPoint>&)>& edit) {
  glm::ivec3 target(0);
  const Chunk* data = nullptr;
  w.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* d) {
    if (!data && kind == ChunkKind::kMixed && !d->axis[axis].is_uniform() && d->axis[axis].point_count()) {
      data = d;
      target = ch;
    }
  });
  ASSERT_NE(data, nullptr);
  auto copy = std::make_shared<Chunk>(*data);
  const int c = w.chunk_size();
  RayFamilyWriter wr(c);
  bool edited = false;
  for (int r = 0; r < c * c; ++r) {
    bool start = data->axis[axis].starts_inside(r);
    auto span = data->axis[axis].points(r);
    std::vector<PackedPoint> pts(span.begin(), span.end());
    if (!edited && !pts.empty()) {
      edit(r, start, pts);
      edited = true;
    }
    wr.begin_ray(start);
    for (const PackedPoint& p : pts) wr.add_point(p);
  }
  copy->axis[axis] = wr.finish();
  w.set_chunk(target, copy);
}

// validate() fails and names this kind of damage (issue 26: one mutation
// test per invariant, each asserting its own message).
void expect_caught(const ValidationReport& r, const std::string& message) {
  EXPECT_FALSE(r.ok);
  EXPECT_GT(r.errors, 0u);
  bool named = false;
  for (const std::string& m : r.messages) named = named || m.find(message) != std::string::npos;
  std::string all;
  for (const std::string& m : r.messages) all += "\n  " + m;
  EXPECT_TRUE(named) << "\"" << message << "\" not in: " << r.summary() << all;
}

TEST(Validate, AnUndamagedWorldPasses) {
  const ValidationReport r = validate(small_sphere_world());
  EXPECT_TRUE(r.ok) << r.summary();
  EXPECT_EQ(r.errors, 0u);
}

TEST(Validate, CatchesUnsortedPoints) {
  World w = small_sphere_world();
  damage_first_mixed(w, 0, [](int, bool&, std::vector<PackedPoint>& p) {
    std::swap(p.front(), p.back());  // out of order, same count
    if (p.size() < 2) p.push_back(p.front());
  });
  expect_caught(validate(w), "not after");
}

TEST(Validate, CatchesAPointOnANode) {
  World w = small_sphere_world();
  damage_first_mixed(w, 1, [](int, bool&, std::vector<PackedPoint>& p) {
    int node = std::max(1, p.front().depth / 4096);  // chunk size 16: 4096 steps per cell
    p.front().depth = uint16_t(node * 4096);
  });
  expect_caught(validate(w), "lies on a node");
}

TEST(Validate, CatchesTheReservedBit) {
  World w = small_sphere_world();
  damage_first_mixed(w, 2, [](int, bool&, std::vector<PackedPoint>& p) { p.front().normal |= kPointReservedBit; });
  expect_caught(validate(w), "reserved bit set");
}

TEST(Validate, CatchesAFlippedSense) {
  World w = small_sphere_world();
  damage_first_mixed(w, 2, [](int, bool&, std::vector<PackedPoint>& p) { p.front().normal ^= kPointExitBit; });
  expect_caught(validate(w), "where an");  // "exit where an enter was due" (or the reverse)
}

TEST(Validate, CatchesANormalPointingIntoTheSolid) {
  World w = small_sphere_world();
  damage_first_mixed(w, 0, [](int, bool&, std::vector<PackedPoint>& p) {
    glm::dvec3 n(decode_normal(p.front().normal));
    uint32_t sense = p.front().normal & kPointExitBit;
    p.front().normal = encode_normal(-n) | sense;
  });
  expect_caught(validate(w), "normal points into the solid");
}

TEST(Validate, CatchesAxesThatDisagreeAtANode) {
  World w = small_sphere_world();
  // Move one crossing a whole cell along its ray: its own ray stays consistent,
  // but the node it jumped over now disagrees with the other two axes.
  damage_first_mixed(w, 0, [](int, bool&, std::vector<PackedPoint>& p) {
    // Grow the ray's first or last span by one cell, whichever stays in the chunk.
    if (p.front().depth > 4096) p.front().depth = uint16_t(p.front().depth - 4096);
    else p.back().depth = uint16_t(p.back().depth + 4096);
  });
  expect_caught(validate(w), "axes disagree");
}

TEST(Validate, CatchesARayThatStartsInsideAtTheWorldBox) {
  World w = small_sphere_world();
  damage_first_mixed(w, 1, [](int, bool& start, std::vector<PackedPoint>& p) {
    start = !start;  // flip the start state and drop a point: alternation holds, the box face does not
    p.erase(p.begin());
  });
  expect_caught(validate(w), "inside at the world box face");
}

TEST(Validate, CatchesAStateBreakBetweenChunks) {
  World w = small_sphere_world();
  // A layer of empty chunks above the sphere; one of them made solid: rays
  // enter it from an empty chunk below without crossing a surface.
  const glm::ivec3 top = w.chunk_origin() + w.chunk_dims() - glm::ivec3(1);
  ASSERT_TRUE(w.grow_to_include(top, top + glm::ivec3(1, 1, 2)).ok());
  const glm::ivec3 target = top + glm::ivec3(0, 0, 1);
  ASSERT_EQ(w.chunk_kind(target), ChunkKind::kEmpty);
  w.set_uniform_chunk(target, true);
  expect_caught(validate(w), "state breaks at the boundary to the next chunk");
}

}  // namespace
}  // namespace ldc
