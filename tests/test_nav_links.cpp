// Navigation: query filters (per-material costs, include/exclude flags) and
// off-mesh links added and removed at run time.
#include <gtest/gtest.h>

#include "csg/csg.h"
#include "ldc/build.h"
#include "nav/nav.h"
#include "test_util.h"

namespace ldc {
namespace {

constexpr double kH = 0.2;
constexpr uint16_t kMud = 1;

// Mud (material 1) in its own area 1, so filters can tell it apart.
NavConfig mud_area() {
  NavConfig c;
  c.material_areas = {0, 1};
  return c;
}

struct Box {
  glm::dvec3 lo, hi;
  uint16_t material = 0;
};

World world_of(const std::vector<Box>& boxes) {
  TriangleMesh mesh;
  for (const Box& b : boxes) {
    TriangleMesh box = test::box_mesh(b.lo, b.hi);
    box.triangle_material.assign(box.triangles.size(), b.material);
    test::append_mesh(mesh, box);
  }
  GridConfig grid;
  grid.cell_size = kH;
  grid.use_origin = true;
  return build_from_mesh(mesh, grid).value();
}

NavPath path(const NavMesh& nav, const glm::dvec3& a, const glm::dvec3& b, const NavFilter& filter = {}) {
  NavQuery query(nav);
  PathQueryOptions options;
  options.filter = filter;
  Result<NavPath> p = query.find_path(a, b, options);
  EXPECT_TRUE(p.ok()) << p.status().to_string();
  return p.ok() ? p.value() : NavPath{};
}

double max_y(const NavPath& p) {
  double y = -1e9;
  for (const glm::dvec3& c : p.corners) y = std::max(y, c.y);
  return y;
}

// A floor 20 x 16 m with a wall across x = 10 that has a mud-paved gap in
// its middle (y 4.5 .. 7.5) and ends at y = 12, so there is a dry way round.
World mud_gap_world() {
  return world_of({
      {{0.05, 0.05, 0.25}, {19.95, 15.95, 1.0}},                // floor, top 1
      {{9.5, 0.05, 0.25}, {10.5, 4.5, 3.0}},                    // wall, south part
      {{9.5, 7.5, 0.25}, {10.5, 12.0, 3.0}},                    // wall, north part
      {{7.05, 4.5, 0.25}, {12.95, 7.5, 1.05}, kMud},            // mud, 5 cm above the floor
  });
}

TEST(NavFilter, DefaultFilterTakesTheMudShortcut) {
  const NavMesh nav = NavMesh::build(mud_gap_world(), mud_area()).value();
  const NavPath p = path(nav, {2, 6, 1}, {18, 6, 1});
  ASSERT_EQ(p.status, PathStatus::kComplete);
  EXPECT_LT(max_y(p), 8.0);
  EXPECT_LT(p.length, 17.0);
}

TEST(NavFilter, CostlyMudIsWalkedRound) {
  const NavMesh nav = NavMesh::build(mud_gap_world(), mud_area()).value();
  NavFilter filter;
  filter.area_cost = {1.0, 10.0};
  const NavPath p = path(nav, {2, 6, 1}, {18, 6, 1}, filter);
  ASSERT_EQ(p.status, PathStatus::kComplete);
  EXPECT_GT(max_y(p), 12.0) << "round the wall's north end";
  // Mud at cost 2 is still worth crossing (about 6 m of mud against a 7 m detour).
  filter.area_cost = {1.0, 2.0};
  EXPECT_LT(max_y(path(nav, {2, 6, 1}, {18, 6, 1}, filter)), 8.0);
  // Without an area of its own, mud is area 0 like the floor: the filter cannot see it.
  const NavMesh one_area = NavMesh::build(mud_gap_world(), {}).value();
  filter.area_cost = {1.0, 10.0};
  EXPECT_LT(max_y(path(one_area, {2, 6, 1}, {18, 6, 1}, filter)), 8.0);
  EXPECT_LT(one_area.stats().regions, nav.stats().regions) << "one area: fewer rectangles";
}

TEST(NavFilter, AreasBeyondSixtyThreeAreRefused) {
  NavConfig c;
  c.material_areas = {0, 64};
  const Result<NavMesh> nav = NavMesh::build(mud_gap_world(), c);
  ASSERT_FALSE(nav.ok());
  EXPECT_NE(nav.status().message().find("material_areas[1]"), std::string::npos);
}

TEST(NavFilter, ExcludedMudIsNeverEntered) {
  const NavMesh nav = NavMesh::build(mud_gap_world(), mud_area()).value();
  NavFilter filter;
  filter.area_flags = {1, 2};
  filter.exclude_flags = 2;
  const NavPath p = path(nav, {2, 6, 1}, {18, 6, 1}, filter);
  ASSERT_EQ(p.status, PathStatus::kComplete);
  EXPECT_GT(max_y(p), 12.0);
  // A goal on the mud snaps to the nearest dry floor.
  NavQuery query(nav);
  PathQueryOptions options;
  options.filter = filter;
  const Result<NavPath> onto = query.find_path({2, 6, 1}, {10, 6, 1.05}, options);
  ASSERT_TRUE(onto.ok());
  EXPECT_NEAR(onto->corners.back().z, 1.0, 0.05) << "not on the mud (z 1.05)";
  // Include flags work the same way round.
  NavFilter dry_only;
  dry_only.area_flags = {1, 2};
  dry_only.include_flags = 1;
  EXPECT_GT(max_y(path(nav, {2, 6, 1}, {18, 6, 1}, dry_only)), 12.0);
}

TEST(NavFilter, BadCostsAreRefusedByName) {
  const NavMesh nav = NavMesh::build(mud_gap_world(), mud_area()).value();
  NavQuery query(nav);
  PathQueryOptions options;
  options.filter.area_cost = {1.0, -1.0};
  const Result<NavPath> p = query.find_path({2, 6, 1}, {18, 6, 1}, options);
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.status().message().find("area_cost[1]"), std::string::npos);
}

// Two platforms with a 3 m gap and nothing below: separate islands.
World two_platforms() {
  return world_of({{{0.05, 0.05, 0.25}, {7.95, 7.95, 1.0}}, {{11.05, 0.05, 0.25}, {18.95, 7.95, 1.0}}});
}

TEST(NavLinks, ALinkJoinsTwoIslandsAndRemovingItSplitsThem) {
  NavMesh nav = NavMesh::build(two_platforms(), {}).value();
  const glm::dvec3 a(2, 4, 1), b(17, 4, 1);
  EXPECT_EQ(path(nav, a, b).status, PathStatus::kUnreachable);
  NavLink jump;
  jump.a = {7.0, 4.0, 1.0};
  jump.b = {12.0, 4.0, 1.0};
  const uint32_t id = nav.add_link(jump).value();
  EXPECT_TRUE(nav.link_attached(id));
  const NavPath p = path(nav, a, b);
  ASSERT_EQ(p.status, PathStatus::kComplete);
  ASSERT_EQ(p.links.size(), 1u);
  EXPECT_EQ(p.links[0].id, id);
  const size_t k = p.links[0].corner;
  ASSERT_LT(k + 1, p.corners.size());
  EXPECT_NEAR(p.corners[k].x, 7.0, 0.2);
  EXPECT_NEAR(p.corners[k + 1].x, 12.0, 0.2);
  EXPECT_NEAR(p.length, 15.0, 0.5);
  // Both ways by default.
  EXPECT_EQ(path(nav, b, a).status, PathStatus::kComplete);
  ASSERT_TRUE(nav.remove_link(id).ok());
  EXPECT_EQ(path(nav, a, b).status, PathStatus::kUnreachable);
  EXPECT_FALSE(nav.remove_link(id).ok()) << "already gone";
}

// An unreachable goal: the partial path ends at the point nearest the goal
// of the start's island, which a link makes two components: the far one's.
TEST(NavLinks, UnreachableGoalAimsAtTheNearestPointOfTheWholeLinkedIsland) {
  NavMesh nav = NavMesh::build(world_of({{{0.05, 0.05, 0.25}, {7.95, 7.95, 1.0}},
                                         {{11.05, 0.05, 0.25}, {18.95, 7.95, 1.0}},
                                         {{30.05, 0.05, 0.25}, {37.95, 7.95, 1.0}}}),
                               {})
                    .value();
  const glm::dvec3 a(2, 4, 1), goal(34, 4, 1);
  EXPECT_NEAR(path(nav, a, goal).corners.back().x, 7.3, 1e-6) << "no link: the start platform's east edge";
  NavLink jump;
  jump.a = {7.0, 4.0, 1.0};
  jump.b = {12.0, 4.0, 1.0};
  ASSERT_TRUE(nav.add_link(jump).ok());
  const NavPath p = path(nav, a, goal);
  EXPECT_EQ(p.status, PathStatus::kUnreachable);
  ASSERT_EQ(p.links.size(), 1u);
  EXPECT_NEAR(p.corners.back().x, 18.3, 1e-6) << "the middle platform's east edge, eroded 0.6 m";
  EXPECT_NEAR(p.corners.back().y, 4.0, 1e-6);
}

TEST(NavLinks, OneWayLinkIsTakenOnlyForwards) {
  NavMesh nav = NavMesh::build(two_platforms(), {}).value();
  NavLink drop;
  drop.a = {7.0, 4.0, 1.0};
  drop.b = {12.0, 4.0, 1.0};
  drop.bidirectional = false;
  ASSERT_TRUE(nav.add_link(drop).ok());
  EXPECT_EQ(path(nav, {2, 4, 1}, {17, 4, 1}).status, PathStatus::kComplete);
  EXPECT_EQ(path(nav, {17, 4, 1}, {2, 4, 1}).status, PathStatus::kUnreachable);
}

TEST(NavLinks, FilterFlagsAndCostsApplyToLinks) {
  NavMesh nav = NavMesh::build(two_platforms(), {}).value();
  NavLink ladder;
  ladder.a = {7.0, 4.0, 1.0};
  ladder.b = {12.0, 4.0, 1.0};
  ladder.flags = 4;
  ladder.cost = 50.0;
  ASSERT_TRUE(nav.add_link(ladder).ok());
  NavFilter no_ladders;
  no_ladders.exclude_flags = 4;
  EXPECT_EQ(path(nav, {2, 4, 1}, {17, 4, 1}, no_ladders).status, PathStatus::kUnreachable);
  // A second, cheap link 3 m further along is preferred over the costly one.
  NavLink plank;
  plank.a = {7.0, 7.0, 1.0};
  plank.b = {12.0, 7.0, 1.0};
  const uint32_t plank_id = nav.add_link(plank).value();
  const NavPath p = path(nav, {2, 4, 1}, {17, 4, 1});
  ASSERT_EQ(p.links.size(), 1u);
  EXPECT_EQ(p.links[0].id, plank_id);
}

TEST(NavLinks, LinksSurviveUpdatesAndFollowTheFloor) {
  const World world = two_platforms();
  NavMesh nav = NavMesh::build(world, {}).value();
  NavLink jump;
  jump.a = {7.0, 4.0, 1.0};
  jump.b = {12.0, 4.0, 1.0};
  const uint32_t id = nav.add_link(jump).value();
  WorldEditor editor(world);
  // Dig away the landing: the link has no floor at its end.
  ASSERT_TRUE(editor.apply(Brush::box({12.0, 4.0, 0.5}, {1.5, 1.5, 1.0}), EditOp::kSubtract).ok());
  ASSERT_TRUE(nav.update(editor.world(), editor.take_dirty()).ok());
  EXPECT_FALSE(nav.link_attached(id));
  EXPECT_EQ(path(nav, {2, 4, 1}, {17, 4, 1}).status, PathStatus::kUnreachable);
  // Build it back: attached again, with the same id.
  ASSERT_TRUE(editor.apply(Brush::box({12.0, 4.0, 0.625}, {1.5, 1.5, 0.375}), EditOp::kUnion).ok());
  ASSERT_TRUE(nav.update(editor.world(), editor.take_dirty()).ok());
  EXPECT_TRUE(nav.link_attached(id));
  EXPECT_EQ(path(nav, {2, 4, 1}, {17, 4, 1}).status, PathStatus::kComplete);
}

TEST(NavLinks, BadLinksAreRefusedByName) {
  NavMesh nav = NavMesh::build(two_platforms(), {}).value();
  NavLink bad;
  bad.a = {NAN, 0, 0};
  EXPECT_NE(nav.add_link(bad).status().message().find("finite"), std::string::npos);
  NavLink far;
  far.a = {7, 4, 1};
  far.b = {500, 500, 500};
  const uint32_t id = nav.add_link(far).value();
  EXPECT_FALSE(nav.link_attached(id)) << "an end off every floor is kept but unused";
  NavLink wide;
  wide.radius = 0.0;
  EXPECT_NE(nav.add_link(wide).status().message().find("radius"), std::string::npos);
}

}  // namespace
}  // namespace ldc
