// The surface reading of mesh builds (BuildConfig in ldc/build.h): one-sided
// floors, single-quad walls, inside-out and double-sided parts read as thin
// shells under their triangles; closed outward parts stay solids.
#include <gtest/gtest.h>

#include <cmath>

#include "ldc/build.h"
#include "nav/nav.h"
#include "test_util.h"

namespace ldc {
namespace {

using test::append_mesh;
using test::box_mesh;
using test::is_valid;

constexpr double kH = 0.25;  // cell size of every test here
constexpr double kDepth = kH / 1000;  // stored depths are quantized finer than this

// Lattice planes at multiples of kH.
GridConfig grid_at_origin() { return test::lattice_at_origin(kH); }

BuildConfig reading(BuildMode mode, double thickness = 0.0) {
  BuildConfig c;
  c.mode = mode;
  c.shell_thickness = thickness;
  c.up_axis = 2;
  return c;
}

// A quad a-b-c-d (counter-clockwise seen from the side it faces) as two triangles.
TriangleMesh quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
  TriangleMesh m;
  m.positions = {a, b, c, d};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TriangleMesh flipped(TriangleMesh m) {
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

// The floor quad at z = 1.1 over [0.1, 3.9]^2, facing up.
TriangleMesh floor_quad() { return quad({0.1, 0.1, 1.1}, {3.9, 0.1, 1.1}, {3.9, 3.9, 1.1}, {0.1, 3.9, 1.1}); }

// The spans of the vertical ray through world (x, y) on the lattice at the origin.
std::vector<Span> column(const World& w, double x, double y) {
  // Axis 2's rays are indexed (u, v) = (x, y) in lattice nodes.
  return w.ray_spans(2, {int(std::lround(x / kH)), int(std::lround(y / kH))});
}

Result<World> build(const TriangleMesh& m, const BuildConfig& c, BuildReport* report = nullptr) {
  return build_from_mesh(m, grid_at_origin(), c, nullptr, report);
}

TEST(SurfaceBuild, OneSidedFloorHasItsTopExactlyAtTheTriangle) {
  BuildReport report;
  World w = build(floor_quad(), reading(BuildMode::kAuto), &report).value();
  EXPECT_TRUE(is_valid(w));
  EXPECT_EQ(report.surface_components, 1u);
  EXPECT_EQ(report.solid_components, 0u);
  EXPECT_EQ(report.shell_triangles, 2u);
  EXPECT_FALSE(report.input_closed);
  EXPECT_EQ(report.repaired_rays, 0u) << "shells are closed: nothing to repair";
  for (double x : {0.5, 2.0, 3.5}) {
    const auto spans = column(w, x, 2.0);
    ASSERT_EQ(spans.size(), 1u) << "x " << x;
    EXPECT_NEAR(spans[0].exit.depth * kH, 1.1, kDepth);
    EXPECT_NEAR(spans[0].exit.normal.z, 1.0, 1e-4);
    // The default shell reaches a little over one cell below.
    EXPECT_NEAR((spans[0].exit.depth - spans[0].enter.depth), 65.0 / 64.0, 1e-3);
  }
  EXPECT_TRUE(column(w, 4.5, 2.0).empty()) << "nothing outside the quad";
}

TEST(SurfaceBuild, FloorWoundFacingDownStillHasItsTopAtTheTriangle) {
  World w = build(flipped(floor_quad()), reading(BuildMode::kAuto)).value();
  EXPECT_TRUE(is_valid(w));
  const auto spans = column(w, 2.0, 2.0);
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_NEAR(spans[0].exit.depth * kH, 1.1, kDepth);
  EXPECT_NEAR(spans[0].exit.normal.z, 1.0, 1e-4) << "the top faces up whichever way it was wound";
}

TEST(SurfaceBuild, ShellThicknessIsHonoured) {
  World w = build(floor_quad(), reading(BuildMode::kSurface, 0.6)).value();
  const auto spans = column(w, 2.0, 2.0);
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_NEAR(spans[0].enter.depth * kH, 0.5, kDepth);
  EXPECT_NEAR(spans[0].enter.normal.z, -1.0, 1e-4);
}

TEST(SurfaceBuild, SolidReadingOfTheSameSheetHasNoFloor) {
  // What the solid reading (the default) does with a sheet: it bounds no volume.
  World w = build_from_mesh(floor_quad(), grid_at_origin()).value();
  EXPECT_TRUE(column(w, 2.0, 2.0).empty());
}

// A single-quad wall x = x0 across the floor: every lattice row along y must
// see it in some column, or a walker would cross it between columns.
TEST(SurfaceBuild, SingleQuadWallIsSeenInEveryRowItCrosses) {
  for (double x0 : {1.0, 1.07, 1.13, 1.2499}) {
    TriangleMesh m = floor_quad();
    append_mesh(m, quad({x0, 0.1, 1.0}, {x0, 3.9, 1.0}, {x0, 3.9, 3.0}, {x0, 0.1, 3.0}));
    World w = build(m, reading(BuildMode::kAuto)).value();
    ASSERT_TRUE(is_valid(w));
    for (int row = 1; row < 15; ++row) {
      bool seen = false;
      for (int col = 0; col <= 16 && !seen; ++col) {
        for (const Span& s : column(w, col * kH, row * kH)) seen |= s.exit.depth * kH > 2.9;
      }
      EXPECT_TRUE(seen) << "wall at x = " << x0 << " missed in row " << row;
    }
  }
}

TEST(SurfaceBuild, DiagonalWallBlocksEveryFourConnectedStep) {
  // A wall along the diagonal x = y: the columns whose top reaches the wall's
  // top must split the floor's columns into two sides with no 4-neighbour
  // pair across (nav links 4-neighbours).
  TriangleMesh m = floor_quad();
  append_mesh(m, quad({0.2, 0.2, 1.0}, {3.8, 3.8, 1.0}, {3.8, 3.8, 3.0}, {0.2, 0.2, 3.0}));
  World w = build(m, reading(BuildMode::kAuto)).value();
  ASSERT_TRUE(is_valid(w));
  auto wall = [&](int i, int j) {
    for (const Span& s : column(w, i * kH, j * kH))
      if (s.exit.depth * kH > 2.9) return true;
    return false;
  };
  int steps = 0, wall_columns = 0;
  for (int i = 2; i < 14; ++i) {
    for (int j = 2; j < 14; ++j) {
      wall_columns += wall(i, j);
      if (wall(i, j)) continue;
      for (auto [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const int a = i + di, b = j + dj;
        if (wall(a, b)) continue;
        ++steps;
        EXPECT_EQ(j - i > 0, b - a > 0) << "step " << i << "," << j << " -> " << a << "," << b
                                          << " crosses the wall";
      }
    }
  }
  EXPECT_GT(steps, 150) << "the floor around the wall was checked";
  EXPECT_LT(wall_columns, 30) << "the wall is one or two columns wide";
}

TEST(SurfaceBuild, ClosedOutwardBoxStaysSolidInsideOutBoxBecomesARoom) {
  const TriangleMesh box = box_mesh({0.1, 0.1, 0.1}, {3.9, 3.9, 3.1});
  BuildReport report;
  World solid = build(box, reading(BuildMode::kAuto), &report).value();
  EXPECT_EQ(report.solid_components, 1u);
  EXPECT_EQ(report.surface_components, 0u);
  EXPECT_TRUE(report.input_closed);
  ASSERT_EQ(column(solid, 2.0, 2.0).size(), 1u);
  EXPECT_NEAR(column(solid, 2.0, 2.0)[0].length() * kH, 3.0, kDepth);

  // Inside out, a closed box is a room seen from inside: a floor and a roof.
  World room = build(flipped(box), reading(BuildMode::kAuto), &report).value();
  EXPECT_TRUE(is_valid(room));
  EXPECT_EQ(report.solid_components, 0u);
  EXPECT_EQ(report.surface_components, 1u);
  const auto spans = column(room, 2.0, 2.0);
  ASSERT_EQ(spans.size(), 2u);
  EXPECT_NEAR(spans[0].exit.depth * kH, 0.1, kDepth) << "the room's floor";
  EXPECT_NEAR(spans[0].exit.normal.z, 1.0, 1e-4);
  EXPECT_NEAR(spans[1].enter.depth * kH, 3.1 - kH * 65 / 64, kDepth) << "the roof hangs below its triangles";

  // Surface mode reads even the outward box as shells: hollow.
  World hollow = build(box, reading(BuildMode::kSurface), &report).value();
  EXPECT_EQ(report.surface_components, 1u);
  EXPECT_EQ(column(hollow, 2.0, 2.0).size(), 2u);
}

TEST(SurfaceBuild, DoubleSidedQuadIsAFloorNotNothing) {
  // Two coincident quads, opposite windings: closed by edge balance, no volume.
  TriangleMesh m = floor_quad();
  append_mesh(m, flipped(floor_quad()));
  BuildReport report;
  World w = build(m, reading(BuildMode::kAuto), &report).value();
  EXPECT_TRUE(report.input_closed);
  EXPECT_EQ(report.surface_components, 1u);
  const auto spans = column(w, 2.0, 2.0);
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_NEAR(spans[0].exit.depth * kH, 1.1, kDepth);
}

TEST(SurfaceBuild, PropOnAFloorIsOneSolidWithIt) {
  TriangleMesh m = floor_quad();
  append_mesh(m, box_mesh({1.0, 1.0, 1.1}, {2.0, 2.0, 2.1}));  // a crate standing on the floor
  BuildReport report;
  World w = build(m, reading(BuildMode::kAuto), &report).value();
  EXPECT_TRUE(is_valid(w));
  EXPECT_EQ(report.solid_components, 1u);
  EXPECT_EQ(report.surface_components, 1u);
  const auto on_crate = column(w, 1.5, 1.5);
  ASSERT_EQ(on_crate.size(), 1u) << "crate and floor shell merge into one span";
  EXPECT_NEAR(on_crate[0].exit.depth * kH, 2.1, kDepth);
}

TEST(SurfaceBuild, MaterialsFollowTheirTriangles) {
  TriangleMesh m = floor_quad();
  m.triangle_material = {3, 3};
  m.material_names = {"a", "b", "c", "grass"};
  World w = build(m, reading(BuildMode::kSurface)).value();
  const auto spans = column(w, 2.0, 2.0);
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_EQ(spans[0].exit.material, 3);
}

TEST(SurfaceBuild, SolidModeIsTheDefaultAndUnchanged) {
  const TriangleMesh sphere = test::sphere_mesh({2, 2, 2}, 1.5, 3);
  World a = build_from_mesh(sphere, grid_at_origin()).value();
  World b = build(sphere, BuildConfig{}).value();
  World c = build(sphere, reading(BuildMode::kAuto)).value();
  EXPECT_EQ(a.stats().points, b.stats().points);
  EXPECT_DOUBLE_EQ(a.volume(2), c.volume(2)) << "a closed outward sphere reads the same under auto";
}

TEST(SurfaceBuild, BadConfigIsRefusedNamingTheField) {
  auto message = [&](BuildConfig c) {
    Result<World> r = build(floor_quad(), c);
    return r.ok() ? std::string("ok") : r.status().message();
  };
  EXPECT_NE(message(reading(BuildMode::kAuto, -1.0)).find("shell_thickness"), std::string::npos);
  EXPECT_NE(message(reading(BuildMode::kAuto, NAN)).find("shell_thickness"), std::string::npos);
  EXPECT_NE(message(reading(BuildMode::kAuto, 100.0)).find("between h/16 and 16 h"), std::string::npos);
  BuildConfig bad_up = reading(BuildMode::kAuto);
  bad_up.up_axis = 3;
  EXPECT_NE(message(bad_up).find("up_axis"), std::string::npos);
  BuildConfig bad_mode = reading(BuildMode::kAuto);
  bad_mode.mode = BuildMode(7);
  EXPECT_NE(message(bad_mode).find("mode"), std::string::npos);
}

// A level the way artists make them: a one-sided floor (wound facing down by
// mistake), an open-topped room of single-quad walls with a door gap, y up. A
// path from outside to the room's middle must go through the door.
TEST(SurfaceBuild, PathIntoAnOpenRoomGoesThroughTheDoor) {
  TriangleMesh m = quad({0, 0, 0}, {0, 0, -20}, {20, 0, -20}, {20, 0, 0});
  auto wall = [&](glm::dvec3 a, glm::dvec3 b) {  // vertical quad from a to b, 3 m high, one-sided
    append_mesh(m, quad(a, b, b + glm::dvec3(0, 3, 0), a + glm::dvec3(0, 3, 0)));
  };
  // Room [6, 14] x [-14, -6] (x, z); the door: a 2 m gap in the wall z = -6 at x in [9, 11].
  wall({6, 0, -6}, {9, 0, -6});
  wall({11, 0, -6}, {14, 0, -6});
  wall({14, 0, -6}, {14, 0, -14});
  wall({14, 0, -14}, {6, 0, -14});
  wall({6, 0, -14}, {6, 0, -6});
  GridConfig grid;
  grid.cell_size = 0.3;
  BuildConfig c;
  c.mode = BuildMode::kAuto;
  c.up_axis = 1;
  World w = build_from_mesh(m, grid, c).value();
  ASSERT_TRUE(is_valid(w));
  NavConfig agent;
  agent.up_axis = 1;
  NavMesh nav = NavMesh::build(w, agent).value();
  NavQuery query(nav);
  NavPath path = query.find_path({10, 0, -2}, {10, 0, -10}).value();
  EXPECT_EQ(path.status, PathStatus::kComplete);
  EXPECT_NEAR(path.corners.back().y, 0.0, 1e-3) << "on the floor";
  // Straight through the door: about 8 m.
  EXPECT_LT(path.length, 8.5);
  for (const glm::dvec3& p : path.corners) EXPECT_LT(p.y, 0.5) << "never on a wall top";
  // From the far side the path must come round to the door: a straight 8 m
  // would go through the wall.
  NavPath around = query.find_path({10, 0, -18}, {10, 0, -10}).value();
  EXPECT_EQ(around.status, PathStatus::kComplete);
  EXPECT_GT(around.length, 8.0 + 2 * 4.0);
}

}  // namespace
}  // namespace ldc
