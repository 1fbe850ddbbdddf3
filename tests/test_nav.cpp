// Navigation: walkable floors, regions, A*, string pulling, updates after edits.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "csg/csg.h"
#include "ldc/build.h"
#include "nav/nav.h"
#include "test_util.h"

namespace ldc {
namespace {

constexpr double kH = 0.2;

struct Box {
  glm::dvec3 lo, hi;
};

// A world of boxes (their union) at h = 0.2 on a lattice anchored at the origin.
World boxes_world(const std::vector<Box>& boxes) {
  TriangleMesh mesh;
  for (const Box& b : boxes) test::append_mesh(mesh, test::box_mesh(b.lo, b.hi));
  GridConfig grid;
  grid.cell_size = kH;
  grid.use_origin = true;
  Result<World> w = build_from_mesh(mesh, grid);
  EXPECT_TRUE(w.ok()) << w.status().to_string();
  return std::move(w.value());
}

NavMesh nav_of(const World& world, NavConfig config = {}) {
  Result<NavMesh> nav = NavMesh::build(world, config);
  EXPECT_TRUE(nav.ok()) << nav.status().to_string();
  return std::move(nav.value());
}

NavPath path_of(const NavMesh& nav, const glm::dvec3& from, const glm::dvec3& to) {
  NavQuery query(nav);
  Result<NavPath> p = query.find_path(from, to);
  EXPECT_TRUE(p.ok()) << p.status().to_string();
  return p.ok() ? p.value() : NavPath{};
}

// A floor slab whose top is at z = 1, columns' squares inside it.
Box floor_slab(double x0, double y0, double x1, double y1, double top = 1.0) {
  return {{x0 + 0.05, y0 + 0.05, 0.25}, {x1 - 0.05, y1 - 0.05, top}};
}

// Every point along the path (every h/4) has a walkable floor under it.
void expect_on_walkable_ground(const NavMesh& nav, const NavPath& path) {
  NavQuery query(nav);
  for (size_t i = 1; i < path.corners.size(); ++i) {
    const glm::dvec3 a = path.corners[i - 1], b = path.corners[i];
    const int steps = std::max(1, int(glm::length(b - a) / (kH / 4)));
    for (int s = 0; s <= steps; ++s) {
      const glm::dvec3 p = glm::mix(a, b, double(s) / steps);
      // Within the square of a kept floor column, at most a step away vertically.
      Result<NavPoint> at = query.nearest_walkable(p, {kH * 0.51, kH * 0.51, 1.0});
      ASSERT_TRUE(at.ok()) << "segment " << i << " leaves walkable ground at " << p.x << ","
                           << p.y << "," << p.z;
    }
  }
}

TEST(Nav, StraightCorridorPathIsTheStraightLine) {
  const World world = boxes_world({floor_slab(0, 0, 20, 4)});
  const NavMesh nav = nav_of(world);
  const NavPath path = path_of(nav, {2, 2, 1}, {18, 2, 1});
  EXPECT_EQ(path.status, PathStatus::kComplete);
  ASSERT_EQ(path.corners.size(), 2u);
  EXPECT_NEAR(path.corners.front().x, 2.0, 1e-9);
  EXPECT_NEAR(path.corners.back().x, 18.0, 1e-9);
  EXPECT_NEAR(path.length, 16.0, 1e-6);
  EXPECT_NEAR(path.corners.front().z, 1.0, 0.01);
}

TEST(Nav, ErosionKeepsTheAgentRadiusFromTheEdges) {
  const World world = boxes_world({floor_slab(0, 0, 20, 4)});
  const NavMesh nav = nav_of(world);  // radius 0.6: 3 cells
  NavQuery query(nav);
  // The slab's columns run from y = 0.2 to 3.8; 3 cells are eroded from each side.
  Result<NavPoint> p = query.nearest_walkable({10, 0.0, 1}, {2, 2, 2});
  ASSERT_TRUE(p.ok());
  EXPECT_NEAR(p->position.y, 0.8 - 0.1, 1e-9);  // first kept column 0.8, its square from 0.7
  NavConfig thin;
  thin.agent_radius = 0.0;
  const NavMesh nav0 = nav_of(world, thin);
  NavQuery query0(nav0);
  Result<NavPoint> q = query0.nearest_walkable({10, 0.0, 1}, {2, 2, 2});
  ASSERT_TRUE(q.ok());
  EXPECT_NEAR(q->position.y, 0.1, 1e-9);
}

// Floor 10 x 10 with a wall across most of it: the path goes round the wall's
// end. With radius 0 the walkable area is the floor minus the wall exactly,
// so the shortest path touches the wall's two end corners.
TEST(Nav, MazeShortestLengthIsKnown) {
  const World world = boxes_world({floor_slab(0, 0, 10, 10), {{4.9, 0.0, 0.5}, {5.1, 6.9, 3.0}}});
  NavConfig config;
  config.agent_radius = 0.0;
  const NavMesh nav = nav_of(world, config);
  const glm::dvec3 a(2, 2, 1), b(8, 2, 1);
  const NavPath path = path_of(nav, a, b);
  ASSERT_EQ(path.status, PathStatus::kComplete);
  const glm::dvec3 c1(4.9, 6.9, 1), c2(5.1, 6.9, 1);
  const double exact = glm::length(c1 - a) + 0.2 + glm::length(b - c2);
  EXPECT_NEAR(path.length, exact, 1e-3);
  ASSERT_EQ(path.corners.size(), 4u);
  EXPECT_NEAR(path.corners[1].x, 4.9, 1e-6);
  EXPECT_NEAR(path.corners[1].y, 6.9, 1e-6);
  expect_on_walkable_ground(nav, path);
  // The grid baseline is longer (8 directions: up to 8% per straight stretch)
  // but never shorter.
  NavQuery query(nav, 1 << 20);
  Result<NavPath> grid = query.find_grid_path(a, b);
  ASSERT_TRUE(grid.ok());
  EXPECT_EQ(grid->status, PathStatus::kComplete);
  EXPECT_GE(grid->length, exact - 0.3);
  EXPECT_LE(grid->length, exact * 1.12);
}

// A start snapped to the far edge of a column's square (which rounds to the
// next column) still starts the grid search on that column.
TEST(Nav, GridBaselineStartsOnTheSnappedColumn) {
  const World world = boxes_world({floor_slab(0, 0, 8, 4)});
  NavConfig config;
  config.agent_radius = 0.0;
  const NavMesh nav = nav_of(world, config);
  NavQuery query(nav, 1 << 16);
  Result<NavPath> path = query.find_grid_path({9, 2, 1}, {4, 2, 1});
  ASSERT_TRUE(path.ok()) << path.status().to_string();
  EXPECT_EQ(path->status, PathStatus::kComplete);
  EXPECT_NEAR(path->corners.front().x, 7.8, 1e-6);
  EXPECT_NEAR(path->length, 3.8, 1e-6);
}

// The same wall with the default radius: the path keeps about 0.6 m from it;
// its length is that of the path round the wall grown by a disc of 0.6 m.
TEST(Nav, MazeWithAgentRadiusKeepsClear) {
  const World world = boxes_world({floor_slab(0, 0, 10, 10), {{4.9, 0.0, 0.5}, {5.1, 6.9, 3.0}}});
  const NavMesh nav = nav_of(world);
  const glm::dvec3 a(2, 2, 1), b(8, 2, 1);
  const NavPath path = path_of(nav, a, b);
  ASSERT_EQ(path.status, PathStatus::kComplete);
  // Tangent from a to the disc (r) round (4.9, 6.9), arc, straight 0.2, arc, tangent to b.
  const double r = 0.6;
  auto tangent_and_angle = [&](const glm::dvec2& from, const glm::dvec2& centre) {
    const glm::dvec2 d = centre - from;
    const double dist = glm::length(d);
    return std::pair{std::sqrt(dist * dist - r * r), std::atan2(d.y, d.x) + std::asin(r / dist)};
  };
  auto [ta, angle_a] = tangent_and_angle({2, 2}, {4.9, 6.9});
  // Arc from the tangent point to the top of the disc (direction +y of the
  // centre): the tangent direction turns from angle_a to 0 (heading +x).
  const double arc = r * angle_a;
  const double exact = 2 * (ta + arc) + 0.2;
  EXPECT_GT(path.length, exact - 0.25);
  EXPECT_LT(path.length, exact * 1.03);
  for (const glm::dvec3& c : path.corners) {
    if (c.y < 6.9) {  // beside the wall: at least the radius less half a cell away
      EXPECT_GE(std::abs(c.x - 5.0) - 0.1, r - 0.11) << c.x << "," << c.y;
    }
  }
  expect_on_walkable_ground(nav, path);
}

// Lower floor, upper platform 2.4 m higher, reachable only by stairs.
World stairs_world(double rise) {
  std::vector<Box> boxes{floor_slab(0, 0, 8, 4), floor_slab(8, 0, 16, 4, 1.0 + 4 * rise)};
  // The platform sits on a block; the stairs are 4 steps of 1 m.
  for (int s = 1; s <= 3; ++s) {
    boxes.push_back({{4.0 + s + 0.05, 0.05, 0.25}, {8.05, 3.95, 1.0 + s * rise}});
  }
  return boxes_world(boxes);
}

TEST(Nav, StairsWithinMaxClimbAreWalked) {
  const World world = stairs_world(0.5);
  const NavMesh nav = nav_of(world);
  const NavPath path = path_of(nav, {2, 2, 1}, {14, 2, 3});
  EXPECT_EQ(path.status, PathStatus::kComplete);
  EXPECT_NEAR(path.corners.back().z, 3.0, 0.05);
}

TEST(Nav, StairsBeyondMaxClimbBlock) {
  const World world = stairs_world(1.2);
  const NavMesh nav = nav_of(world);
  const NavPath path = path_of(nav, {2, 2, 1}, {14, 2, 1 + 4 * 1.2});
  EXPECT_EQ(path.status, PathStatus::kUnreachable);
  EXPECT_LT(path.corners.back().x, 5.2);  // stops on the step it can reach
}

// A ramp rising at `degrees` from a floor to a platform.
World ramp_world(double degrees) {
  const double rise = 2.0, run = rise / std::tan(degrees * M_PI / 180.0);
  TriangleMesh mesh = test::box_mesh({0.05, 0.05, 0.25}, {6, 3.95, 1});
  test::append_mesh(mesh, test::box_mesh({6 + run, 0.05, 0.25}, {12 + run, 3.95, 1 + rise}));
  // Wedge: from (6, z=1) up to (6 + run, z=1+rise), across y in [0.05, 3.95].
  TriangleMesh wedge;
  const double y0 = 0.05, y1 = 3.95, x0 = 5.9, x1 = 6 + run + 0.1, z0 = 0.25;
  const double zt0 = 1.0 - 0.1 * std::tan(degrees * M_PI / 180.0);
  const double zt1 = 1.0 + rise + 0.1 * std::tan(degrees * M_PI / 180.0);
  wedge.positions = {{x0, y0, z0}, {x1, y0, z0}, {x1, y0, zt1}, {x0, y0, zt0},
                     {x0, y1, z0}, {x1, y1, z0}, {x1, y1, zt1}, {x0, y1, zt0}};
  wedge.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                     {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  test::append_mesh(mesh, wedge);
  GridConfig grid;
  grid.cell_size = kH;
  grid.use_origin = true;
  Result<World> w = build_from_mesh(mesh, grid);
  EXPECT_TRUE(w.ok());
  return std::move(w.value());
}

TEST(Nav, SlopeWithinMaxSlopeIsWalked) {
  const World world = ramp_world(40.0);
  const NavMesh nav = nav_of(world);
  const double run = 2.0 / std::tan(40.0 * M_PI / 180.0);
  const NavPath path = path_of(nav, {2, 2, 1}, {9 + run, 2, 3});
  EXPECT_EQ(path.status, PathStatus::kComplete);
}

TEST(Nav, SlopeBeyondMaxSlopeBlocks) {
  const World world = ramp_world(50.0);
  const NavMesh nav = nav_of(world);
  const double run = 2.0 / std::tan(50.0 * M_PI / 180.0);
  const NavPath path = path_of(nav, {2, 2, 1}, {9 + run, 2, 3});
  EXPECT_EQ(path.status, PathStatus::kUnreachable);
}

// A corridor under a slab: passable when the slab is high enough.
TEST(Nav, LowCeilingBlocksAndHighCeilingPasses) {
  for (double ceiling : {1.0 + 1.5, 1.0 + 2.5}) {
    // Walls either side of the corridor so nothing goes round.
    const World world = boxes_world({floor_slab(0, 0, 20, 4), {{8.05, 0.05, ceiling}, {12.05, 3.95, ceiling + 0.5}}});
    const NavMesh nav = nav_of(world);
    const NavPath path = path_of(nav, {2, 2, 1}, {18, 2, 1});
    EXPECT_EQ(path.status, ceiling < 3.0 ? PathStatus::kUnreachable : PathStatus::kComplete)
        << "ceiling " << ceiling;
  }
}

TEST(Nav, LowHeightFilterOffLetsTheAgentUnderALowCeiling) {
  const World world = boxes_world({floor_slab(0, 0, 20, 4), {{8.05, 0.05, 2.5}, {12.05, 3.95, 3.0}}});
  NavConfig crouch;
  crouch.filter_low_height_spans = false;
  EXPECT_EQ(path_of(nav_of(world), {2, 2, 1}, {18, 2, 1}).status, PathStatus::kUnreachable);
  EXPECT_EQ(path_of(nav_of(world, crouch), {2, 2, 1}, {18, 2, 1}).status, PathStatus::kComplete);
}

// A platform 1.5 m above the ground (more than max_climb): with no agent
// radius, only the ledge filter takes its rim columns out, as Recast's
// rcFilterLedgeSpans does; the ground's outer rim has no drop (nothing lies
// beyond it) and stays.
TEST(Nav, LedgeFilterRemovesThePlatformRim) {
  const World world = boxes_world({floor_slab(0, 0, 10, 10, 0.5), {{3.05, 3.05, 0.5}, {6.95, 6.95, 2.0}}});
  NavConfig no_radius;
  no_radius.agent_radius = 0.0;
  NavConfig no_filter = no_radius;
  no_filter.filter_ledge_spans = false;
  const size_t with = nav_of(world, no_radius).stats().walkable;
  const size_t without = nav_of(world, no_filter).stats().walkable;
  // The platform covers columns 16 .. 34 (x and y = 3.2 .. 6.8 m): 19 x 19, rim 4 * 18.
  EXPECT_EQ(without - with, size_t(4 * 18));
}

// A wedge whose top is steeper than max_slope, at most max_climb above the
// ground it stands on and linked to no flat floor: walkable only through
// Recast's low-hanging-obstacle rule.
TEST(Nav, LowHangingFilterLiftsASteepFloorJustAboveAWalkableOne) {
  TriangleMesh mesh = test::box_mesh({0.05, 0.05, 0.2}, {9.95, 9.95, 0.5});  // ground, top 0.5
  // Wedge along y in [2, 8]: x from 3.0 to 3.8, top rising 60 degrees from z = 0.6.
  const double rise = 0.8 * std::tan(60.0 * M_PI / 180.0);
  TriangleMesh wedge;
  wedge.positions = {{3.0, 2, 0.6}, {3.8, 2, 0.6}, {3.8, 2, 0.6 + rise},
                     {3.0, 8, 0.6}, {3.8, 8, 0.6}, {3.8, 8, 0.6 + rise}};
  wedge.triangles = {{0, 2, 1}, {3, 4, 5}, {0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}, {0, 3, 5}, {0, 5, 2}};
  test::append_mesh(mesh, wedge);
  GridConfig grid;
  grid.cell_size = kH;
  grid.use_origin = true;
  const World world = build_from_mesh(mesh, grid).value();
  ASSERT_GT(world.volume(2), 10 * 10 * 0.3) << "the wedge is solid (outward winding)";
  NavConfig config;
  config.agent_radius = 0.0;
  config.filter_ledge_spans = false;
  NavConfig no_lift = config;
  no_lift.filter_low_hanging_obstacles = false;
  const size_t with = nav_of(world, config).stats().walkable;
  const size_t without = nav_of(world, no_lift).stats().walkable;
  // Lifted: the wedge's columns x = 3.0 (on its vertical face, 0.1 m up),
  // 3.2 and 3.4 (0.45 and 0.79 m up), not 3.6 (1.14 m: beyond max_climb);
  // on 30 rows (y = 2.0 .. 8.0, the end faces counted once by the symbolic
  // perturbation). A 60 degree floor is no riser: nothing else lifts it.
  EXPECT_EQ(with - without, size_t(3 * 30));
}

TEST(Nav, ALevelWithNoWalkableFloorSaysSo) {
  // A thin wall alone: its top is eroded away by the agent radius.
  const World world = boxes_world({{{1.05, 1.05, 0.05}, {1.45, 5.95, 3.0}}});
  const NavMesh nav = nav_of(world);
  EXPECT_EQ(nav.stats().walkable, 0u);
  NavQuery query(nav);
  const Result<NavPath> path = query.find_path({1.2, 2, 3}, {1.2, 5, 3});
  ASSERT_FALSE(path.ok());
  EXPECT_NE(path.status().message().find("the level has no walkable floor for this agent at all"),
            std::string::npos) << path.status().message();
  // With floors elsewhere the message stays about the point asked for.
  const World with_floor = boxes_world({{{1.05, 1.05, 0.05}, {1.45, 5.95, 3.0}}, floor_slab(10, 0, 16, 6)});
  const NavMesh nav2 = nav_of(with_floor);
  NavQuery query2(nav2);
  const Result<NavPath> far = query2.find_path({1.2, 2, 3}, {12, 3, 1});
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.status().message().find("at all"), std::string::npos) << far.status().message();
}

// A bridge at z = 4 over a lower floor: two levels in the same columns.
TEST(Nav, TwoLevelsWithABridge) {
  const World world = boxes_world({
      floor_slab(0, 0, 20, 20),                      // lower floor, top z = 1
      {{2.05, 8.05, 0.25}, {6.05, 11.95, 4.0}},      // west tower, top z = 4
      {{14.05, 8.05, 0.25}, {18.05, 11.95, 4.0}},    // east tower
      {{6.0, 8.05, 3.6}, {14.1, 11.95, 4.0}},        // bridge deck between them
  });
  const NavMesh nav = nav_of(world);
  // Across the bridge: stays at z = 4.
  const NavPath over = path_of(nav, {4, 10, 4}, {16, 10, 4});
  ASSERT_EQ(over.status, PathStatus::kComplete);
  EXPECT_NEAR(over.length, 12.0, 1e-3);
  for (const glm::dvec3& c : over.corners) EXPECT_NEAR(c.z, 4.0, 0.01);
  // Underneath: the lower floor, from south to north under the deck (2.6 m free).
  const NavPath under = path_of(nav, {10, 2, 1}, {10, 18, 1});
  ASSERT_EQ(under.status, PathStatus::kComplete);
  EXPECT_NEAR(under.length, 16.0, 1e-3);
  for (const glm::dvec3& c : under.corners) EXPECT_NEAR(c.z, 1.0, 0.01);
  // The towers are islands (their sides are cliffs).
  const NavPath down = path_of(nav, {4, 10, 4}, {10, 2, 1});
  EXPECT_EQ(down.status, PathStatus::kUnreachable);
  EXPECT_GE(nav.stats().components, 2u);
}

// A floor with a diagonal staircase edge (x + y <= 13 in 1 m steps): the
// rectangles along the edge are strips, chained into far fewer search nodes,
// and a path along the edge is still the straight line, both ways (of two
// entries into a chain the search keeps the one on the better way on, not
// the cheaper to reach).
TEST(Nav, StaircaseEdgeStripsAreChainedAndPathsStayStraight) {
  std::vector<Box> boxes;
  for (int k = 0; k <= 10; ++k) boxes.push_back({{0.05, 0.05, 0.25}, {1.05 + k, 12.05 - k, 1.0}});
  const NavMesh nav = nav_of(boxes_world(boxes));
  const NavStats stats = nav.stats();
  EXPECT_GE(stats.regions, 10u);
  EXPECT_LT(stats.chains * 2, stats.regions);
  // Along x + y = 9, 2 m inside the edge: in sight of each other.
  for (const auto& [from, to] : {std::pair{glm::dvec3(1, 8, 1), glm::dvec3(8, 1, 1)},
                                 std::pair{glm::dvec3(8, 1, 1), glm::dvec3(1, 8, 1)}}) {
    const NavPath path = path_of(nav, from, to);
    ASSERT_EQ(path.status, PathStatus::kComplete);
    EXPECT_NEAR(path.length, 7.0 * std::sqrt(2.0), 1e-6) << "the straight line";
    EXPECT_GT(path.regions, path.nodes_searched / 4) << "the corridor counts rectangles, the search chains";
    expect_on_walkable_ground(nav, path);
  }
}

// A wall across the floor whose end is reached through chained strips (a
// diagonal edge beside it): the path bends round the wall's end, on the
// ground, no longer than the grid baseline.
TEST(Nav, ChainedStripsDoNotLetThePathCutThroughAWall) {
  std::vector<Box> boxes;
  for (int k = 0; k <= 10; ++k) boxes.push_back({{0.05, 0.05, 0.25}, {1.05 + k, 12.05 - k, 1.0}});
  boxes.push_back({{4.9, 0.0, 0.5}, {5.1, 4.0, 3.0}});  // wall from the south edge up to y = 4
  const NavMesh nav = nav_of(boxes_world(boxes));
  const glm::dvec3 a(2, 2, 1), b(8, 2, 1);
  const NavPath path = path_of(nav, a, b);
  ASSERT_EQ(path.status, PathStatus::kComplete);
  EXPECT_GE(path.corners.size(), 3u);
  expect_on_walkable_ground(nav, path);
  NavQuery grid(nav, 1 << 20);
  Result<NavPath> baseline = grid.find_grid_path(a, b);
  ASSERT_TRUE(baseline.ok());
  ASSERT_EQ(baseline->status, PathStatus::kComplete);
  EXPECT_LE(path.length, baseline->length + 1e-6);
}

TEST(Nav, UnreachableGoalGivesThePartialPathToTheNearestPoint) {
  const World world = boxes_world({floor_slab(0, 0, 8, 4), floor_slab(10, 0, 18, 4)});
  const NavMesh nav = nav_of(world);
  const NavPath path = path_of(nav, {2, 2, 1}, {16, 2, 1});
  EXPECT_EQ(path.status, PathStatus::kUnreachable);
  ASSERT_GE(path.corners.size(), 2u);
  // The start island's walkable area ends 0.6 m (3 cells) before x = 8.
  EXPECT_NEAR(path.corners.back().x, 7.3, 1e-6);
  EXPECT_NEAR(path.corners.back().y, 2.0, 1e-6);
  // A goal with no floor near it at all: the same partial answer.
  const NavPath air = path_of(nav, {2, 2, 1}, {16, 2, 30});
  EXPECT_EQ(air.status, PathStatus::kUnreachable);
}

TEST(Nav, NodeBudgetGivesAPartialPathAndSlicesAgree) {
  // A long zig-zag: many regions between start and goal.
  std::vector<Box> boxes{floor_slab(0, 0, 40, 40)};
  for (int k = 0; k < 6; ++k) {
    const double x = 5.0 + 5.0 * k;
    const bool from_south = k % 2 == 0;
    boxes.push_back({{x - 0.1, from_south ? 0.0 : 6.0, 0.5}, {x + 0.1, from_south ? 34.0 : 40.0, 3.0}});
  }
  const World world = boxes_world(boxes);
  const NavMesh nav = nav_of(world);
  const glm::dvec3 a(2, 2, 1), b(38, 38, 1);
  NavQuery big(nav, 1 << 16);
  Result<NavPath> full = big.find_path(a, b);
  ASSERT_TRUE(full.ok());
  ASSERT_EQ(full->status, PathStatus::kComplete);
  NavQuery small(nav, 16);
  Result<NavPath> cut = small.find_path(a, b);
  ASSERT_TRUE(cut.ok());
  EXPECT_EQ(cut->status, PathStatus::kOutOfNodes);
  EXPECT_LE(cut->nodes_searched, 16u);
  EXPECT_GE(cut->corners.size(), 2u);
  // Sliced, 3 expansions per call, equals the one-shot search.
  NavQuery sliced(nav, 1 << 16);
  ASSERT_TRUE(sliced.begin_path(a, b).ok());
  int calls = 0;
  while (true) {
    Result<SliceStatus> s = sliced.step(3);
    ASSERT_TRUE(s.ok());
    ++calls;
    if (s.value() == SliceStatus::kDone) break;
  }
  EXPECT_GT(calls, 2);
  Result<NavPath> done = sliced.finish_path();
  ASSERT_TRUE(done.ok());
  EXPECT_EQ(done->status, PathStatus::kComplete);
  EXPECT_DOUBLE_EQ(done->length, full->length);
  EXPECT_EQ(done->corners.size(), full->corners.size());
}

TEST(Nav, DigOpensAShortcutAndFillClosesIt) {
  const World world = boxes_world({floor_slab(0, 0, 10, 10), {{4.9, 0.0, 0.5}, {5.1, 6.9, 3.0}}});
  NavMesh nav = nav_of(world);
  const glm::dvec3 a(2, 2, 1), b(8, 2, 1);
  const double around = path_of(nav, a, b).length;
  WorldEditor editor(world);
  // Dig a 2 m wide gap in the wall down to the floor.
  Result<EditReceipt> dig = editor.apply(Brush::box({5.0, 2.0, 2.25}, {0.5, 1.0, 1.25}), EditOp::kSubtract);
  ASSERT_TRUE(dig.ok()) << dig.status().to_string();
  std::vector<DirtyChunk> dirty = editor.take_dirty();
  Result<NavUpdateStats> up = nav.update(editor.world(), dirty);
  ASSERT_TRUE(up.ok());
  EXPECT_FALSE(up->full_rebuild);
  const NavPath through = path_of(nav, a, b);
  EXPECT_EQ(through.status, PathStatus::kComplete);
  EXPECT_NEAR(through.length, 6.0, 1e-3);
  EXPECT_LT(through.length, around - 4.0);
  // Fill it again (a build brush) and the shortcut is gone.
  ASSERT_TRUE(editor.apply(Brush::box({5.0, 2.0, 1.75}, {0.1, 1.5, 1.25}), EditOp::kUnion).ok());
  ASSERT_TRUE(nav.update(editor.world(), editor.take_dirty()).ok());
  EXPECT_NEAR(path_of(nav, a, b).length, around, 1e-6);
}

// A build beyond the world's box grows the world: the update rebuilds all and
// the new ground is walkable and linked.
TEST(Nav, UpdateFollowsAWorldThatGrew) {
  const World world = boxes_world({floor_slab(0, 0, 8, 4)});
  NavMesh nav = nav_of(world);
  WorldEditor editor(world);
  // A slab continuing the floor eastwards, well past the box.
  ASSERT_TRUE(editor.apply(Brush::box({14.0, 2.0, 0.625}, {6.1, 1.95, 0.375}), EditOp::kUnion).ok());
  ASSERT_GT(editor.world().chunk_dims().x, world.chunk_dims().x);
  Result<NavUpdateStats> up = nav.update(editor.world(), editor.take_dirty());
  ASSERT_TRUE(up.ok());
  EXPECT_TRUE(up->full_rebuild);
  const NavPath path = path_of(nav, {2, 2, 1}, {18, 2, 1});
  EXPECT_EQ(path.status, PathStatus::kComplete);
  EXPECT_NEAR(path.length, 16.0, 1e-3);
}

// After random digs and builds, the updated mesh equals one built from scratch.
TEST(Nav, UpdateEqualsRebuildAfterRandomEdits) {
  const World world = boxes_world({floor_slab(0, 0, 16, 16), {{6.9, 2.0, 0.5}, {7.1, 14.0, 3.0}}});
  NavMesh nav = nav_of(world);
  WorldEditor editor(world);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(0.0, 16.0), z(0.5, 2.0), r(0.4, 1.6);
  for (int i = 0; i < 10; ++i) {
    const EditOp op = i % 3 == 2 ? EditOp::kUnion : EditOp::kSubtract;
    ASSERT_TRUE(editor.apply(Brush::sphere({x(rng), x(rng), z(rng)}, r(rng)), op).ok());
    ASSERT_TRUE(nav.update(editor.world(), editor.take_dirty()).ok());
    const NavMesh fresh = nav_of(editor.world());
    const NavStats a = nav.stats(), b = fresh.stats();
    EXPECT_EQ(a.floors, b.floors) << "edit " << i;
    EXPECT_EQ(a.walkable, b.walkable) << "edit " << i;
    EXPECT_EQ(a.regions, b.regions) << "edit " << i;
    EXPECT_EQ(a.chains, b.chains) << "edit " << i;
    EXPECT_EQ(a.portals, b.portals) << "edit " << i;
    EXPECT_EQ(a.components, b.components) << "edit " << i;
    NavQuery qa(nav), qb(fresh);
    for (int k = 0; k < 20; ++k) {
      const glm::dvec3 p(x(rng), x(rng), 1.0), q(x(rng), x(rng), 1.0);
      Result<NavPath> pa = qa.find_path(p, q), pb = qb.find_path(p, q);
      ASSERT_EQ(pa.ok(), pb.ok());
      if (!pa.ok()) continue;
      EXPECT_EQ(pa->status, pb->status);
      EXPECT_NEAR(pa->length, pb->length, 1e-9);
    }
  }
}

// The same world gives the same navigation whatever the thread count.
TEST(Nav, BuildIsDeterministicAcrossThreadCounts) {
  std::vector<Box> boxes{floor_slab(0, 0, 30, 30)};
  for (int k = 0; k < 5; ++k) boxes.push_back({{3.0 + 5 * k, 2.0 + k, 0.5}, {4.0 + 5 * k, 20.0 + k, 2.5}});
  const World world = boxes_world(boxes);
  auto build_with = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    return nav_of(world);
  };
  const NavMesh one = build_with(1), two = build_with(2);
  EXPECT_EQ(one.stats().regions, two.stats().regions);
  EXPECT_EQ(one.stats().portals, two.stats().portals);
  NavQuery qa(one), qb(two);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(0.5, 29.5);
  for (int k = 0; k < 30; ++k) {
    const glm::dvec3 p(x(rng), x(rng), 1.0), q(x(rng), x(rng), 1.0);
    Result<NavPath> a = qa.find_path(p, q), b = qb.find_path(p, q);
    ASSERT_EQ(a.ok(), b.ok());
    if (!a.ok()) continue;
    ASSERT_EQ(a->corners.size(), b->corners.size());
    for (size_t i = 0; i < a->corners.size(); ++i) EXPECT_EQ(a->corners[i], b->corners[i]);
  }
}

TEST(Nav, BadConfigAndInputAreRefusedByName) {
  const World world = boxes_world({floor_slab(0, 0, 8, 4)});
  NavConfig c;
  c.agent_height = -1;
  Result<NavMesh> bad = NavMesh::build(world, c);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("agent_height"), std::string::npos);
  c = {};
  c.max_slope_degrees = std::nan("");
  EXPECT_FALSE(NavMesh::build(world, c).ok());
  c = {};
  c.up_axis = 3;
  EXPECT_FALSE(NavMesh::build(world, c).ok());
  c = {};
  c.agent_radius = 100;
  EXPECT_FALSE(NavMesh::build(world, c).ok());
  const NavMesh nav = nav_of(world);
  NavQuery q(nav);
  Result<NavPath> nan_start = q.find_path({std::nan(""), 0, 0}, {1, 1, 1});
  ASSERT_FALSE(nan_start.ok());
  EXPECT_NE(nan_start.status().message().find("start"), std::string::npos);
  Result<NavPath> nowhere = q.find_path({50, 50, 50}, {1, 1, 1});
  ASSERT_FALSE(nowhere.ok());
  EXPECT_NE(nowhere.status().message().find("no walkable floor"), std::string::npos);
  EXPECT_FALSE(q.step(1).ok());  // nothing begun
  EXPECT_FALSE(q.nearest_walkable({1, 1, 1}, {0, 1, 1}).ok());
}

// The shared navigation test level (Y up, built at Recast's 0.3 m cell).
TEST(Nav, NavTestLevelHasPathsWhereConnected) {
  TriangleMesh mesh = test::load_test_mesh("nav_test.obj");
  GridConfig grid;
  grid.cell_size = 0.3;
  Result<World> world = build_from_mesh(mesh, grid);
  ASSERT_TRUE(world.ok()) << world.status().to_string();
  NavConfig config;
  config.up_axis = 1;
  const NavMesh nav = nav_of(world.value(), config);
  const NavStats stats = nav.stats();
  EXPECT_GT(stats.walkable, 10000u);
  NavQuery query(nav);
  // Random walkable points: paths within an island complete and stay on the ground.
  std::mt19937 rng(3);
  const WorldBox box = world->box();
  std::uniform_real_distribution<double> ux(box.min.x, box.max.x), uz(box.min.z, box.max.z);
  int complete = 0, tried = 0;
  PathQueryOptions options;
  options.search_half_extents = {2.0, 4.0, 2.0};
  for (int i = 0; i < 400 && tried < 60; ++i) {
    Result<NavPoint> a = query.nearest_walkable({ux(rng), 0, uz(rng)}, {1, 20, 1});
    Result<NavPoint> b = query.nearest_walkable({ux(rng), 0, uz(rng)}, {1, 20, 1});
    if (!a.ok() || !b.ok()) continue;
    ++tried;
    Result<NavPath> p = query.find_path(a->position, b->position, options);
    ASSERT_TRUE(p.ok()) << p.status().to_string();
    const bool same_island = a->region == b->region || p->status == PathStatus::kComplete;
    if (p->status == PathStatus::kComplete) {
      ++complete;
      EXPECT_NEAR(glm::length(p->corners.back() - b->position), 0.0, 1e-6);
    }
    (void)same_island;
  }
  EXPECT_GE(tried, 50);
  EXPECT_GE(complete, 5);
}

}  // namespace
}  // namespace ldc
