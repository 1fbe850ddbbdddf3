// mesh_quality's honest report: self-intersecting pairs, non-manifold edges
// and vertices on hand-made meshes with counts worked out by hand
// (tests/quality_meshes.h), the exact triangle predicates, the grid against
// all pairs, the same count for any thread count, and what closed() and
// quality_failures() say.
#include <gtest/gtest.h>

#include <random>

#include <tbb/task_arena.h>

#include "contour/contour.h"
#include "contour/detail/triangle_intersection.h"
#include "ldc/build.h"
#include "quality_meshes.h"
#include "test_util.h"

namespace ldc {
namespace {

void expect_same_quality(const MeshQuality& a, const MeshQuality& b) {
  EXPECT_EQ(a.boundary_edges, b.boundary_edges);
  EXPECT_EQ(a.nonmanifold_edges, b.nonmanifold_edges);
  EXPECT_EQ(a.unpaired_edges, b.unpaired_edges);
  EXPECT_EQ(a.nonmanifold_vertices, b.nonmanifold_vertices);
  EXPECT_EQ(a.self_intersecting_pairs, b.self_intersecting_pairs);
  EXPECT_EQ(a.degenerate_triangles, b.degenerate_triangles);
}

TEST(Quality, HandMadeMeshesHaveTheirHandCountedFlaws) {
  for (const test::QualityCase& c : test::quality_cases()) {
    const MeshQuality q = mesh_quality(c.mesh);
    EXPECT_EQ(q.boundary_edges, c.boundary_edges) << c.name;
    EXPECT_EQ(q.nonmanifold_edges, c.nonmanifold_edges) << c.name;
    EXPECT_EQ(q.nonmanifold_vertices, c.nonmanifold_vertices) << c.name;
    EXPECT_EQ(q.self_intersecting_pairs, c.self_intersecting_pairs) << c.name;
    const bool flawless = c.boundary_edges + c.nonmanifold_edges + c.nonmanifold_vertices + c.self_intersecting_pairs +
                              q.degenerate_triangles ==
                          0;
    EXPECT_EQ(q.closed(), flawless) << c.name;
    EXPECT_EQ(quality_failures(q).empty(), flawless) << c.name << ": " << quality_failures(q);
  }
}

TEST(Quality, InterpenetratingCubesAreWatertightButNotClosed) {
  const MeshQuality q = mesh_quality(test::box_pair({0.9, 0.1, 0.6}, {1.1, 0.3, 0.8}));
  EXPECT_TRUE(q.watertight());
  EXPECT_FALSE(q.closed());
  EXPECT_EQ(quality_failures(q), "8 self-intersecting triangle pairs");
}

TEST(Quality, FailuresNameEveryFlaw) {
  MeshQuality q;
  EXPECT_EQ(quality_failures(q), "");
  q.boundary_edges = 12;
  q.unpaired_edges = 15;
  q.nonmanifold_edges = 1;
  q.nonmanifold_vertices = 3;
  q.self_intersecting_pairs = 40;
  EXPECT_EQ(quality_failures(q),
            "12 boundary edges, 3 edges not used once in each direction, 1 non-manifold edge, "
            "3 non-manifold vertices, 40 self-intersecting triangle pairs");
  EXPECT_FALSE(q.watertight());
  EXPECT_FALSE(q.closed());
}

TEST(Quality, AZeroAreaTriangleIsNamed) {
  const MeshQuality q = mesh_quality(test::cube_with_flat_triangle());  // see quality_meshes.h
  EXPECT_TRUE(q.watertight());
  EXPECT_EQ(q.nonmanifold_vertices, 0u);
  EXPECT_EQ(q.self_intersecting_pairs, 2u);
  EXPECT_EQ(q.degenerate_triangles, 1u);
  EXPECT_FALSE(q.closed());
  EXPECT_EQ(quality_failures(q), "2 self-intersecting triangle pairs, 1 degenerate triangle");
}

// Area and volume at scales where an edge length to the fourth overflows
// (1e100 m) or underflows (1e-100 m): the right figures, the same angles
// and counts as the unit cube; past a double's range (1e200 m: area 6e400)
// inf, never NaN.
TEST(Quality, AreaAndVolumeHoldAtExtremeScales) {
  for (const double side : {1e100, 1e-100, 1e150}) {
    ContourMesh m;
    test::add_box(m, glm::dvec3(side), glm::dvec3(2.0 * side));
    const MeshQuality q = mesh_quality(m);
    EXPECT_NEAR(q.area / (6.0 * side * side), 1.0, 1e-12) << side;
    if (side < 1e150) {
      EXPECT_NEAR(q.volume / (side * side * side), 1.0, 1e-12) << side;
    }
    EXPECT_EQ(q.degenerate_triangles, 0u) << side;
    EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-9) << side;
    EXPECT_TRUE(q.closed()) << side << ": " << quality_failures(q);
  }
  ContourMesh huge;
  test::add_box(huge, glm::dvec3(1e200), glm::dvec3(2e200));
  const MeshQuality q = mesh_quality(huge);
  EXPECT_TRUE(std::isinf(q.area));
  EXPECT_TRUE(std::isinf(q.volume));
  EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-9);
  EXPECT_EQ(q.degenerate_triangles, 0u);
}

TEST(Quality, BowTieIsWatertightButNotClosed) {
  // Two closed cubes sharing one corner: every edge paired, one vertex with two fans.
  ContourMesh m;
  test::add_box(m, glm::dvec3(0.0), glm::dvec3(1.0));
  test::add_box(m, glm::dvec3(1.0), glm::dvec3(2.0));
  for (glm::uvec3& t : m.triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] == 8) t[k] = 7;  // weld the second cube's corner 0 to the first's corner 7
  const MeshQuality q = mesh_quality(m);
  EXPECT_TRUE(q.watertight());
  EXPECT_EQ(q.nonmanifold_vertices, 1u);
  // The cubes touch only at the shared corner: no intersection beyond it.
  EXPECT_EQ(q.self_intersecting_pairs, 0u);
  EXPECT_FALSE(q.closed());
  EXPECT_EQ(quality_failures(q), "1 non-manifold vertex");
}

TEST(Quality, CubesTouchingAtACornerWithoutSharingItIntersect) {
  // Not welded, the same two cubes touch at (1, 1, 1). Each face's split
  // diagonal ends at that corner, so it is a corner of all 6 triangles of
  // each cube's three faces there: 6 x 6 pairs that meet at one point.
  const MeshQuality q = mesh_quality(test::box_pair(glm::dvec3(1.0), glm::dvec3(2.0)));
  EXPECT_EQ(q.nonmanifold_vertices, 0u);
  EXPECT_EQ(q.self_intersecting_pairs, 36u);
}

// --- The exact predicates ------------------------------------------------------

TEST(Quality, OrientationIsExactWhereDoublesRound) {
  // Integer points of the plane z = 3x - 7y + 5 near 1e9: the determinant's
  // products (about 1e27) round in doubles; the sign must still be 0, and
  // one unit off the plane must still be seen.
  auto on_plane = [](double x, double y) { return glm::dvec3(x, y, 3.0 * x - 7.0 * y + 5.0); };
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> off(-100000, 100000);
  for (int i = 0; i < 200; ++i) {
    glm::dvec3 p[4];
    for (glm::dvec3& q : p) q = on_plane(1e9 + off(rng), 2e9 + off(rng));
    EXPECT_EQ(detail::orient3d(p[0], p[1], p[2], p[3]), 0);
    const int up = detail::orient3d(p[0], p[1], p[2], p[3] + glm::dvec3(0, 0, 1));
    EXPECT_NE(up, 0);
    EXPECT_EQ(detail::orient3d(p[0], p[1], p[2], p[3] - glm::dvec3(0, 0, 1)), -up);
  }
  // Collinear integer points far apart (products near 1e26).
  const glm::dvec3 p(1e9 + 1, 2e9 + 3, 5), d(3, -7, 11);
  EXPECT_TRUE(detail::collinear(p, p + 1e11 * d, p + 7e11 * d));
  EXPECT_FALSE(detail::collinear(p, p + 1e11 * d, p + 7e11 * d + glm::dvec3(0, 0, 1)));
  EXPECT_EQ(detail::orient2d(p, p + 1e11 * d, p + 7e11 * d, 0, 1), 0);
  EXPECT_EQ(detail::orient2d(p, p + 1e11 * d, p + 7e11 * d + glm::dvec3(1, 0, 0), 0, 1), 1);  // det = 7e11
}

TEST(Quality, TouchingTrianglesMeetAndSeparatedOnesDoNot) {
  const glm::dvec3 t[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  auto tri = [](glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    return std::array<glm::dvec3, 3>{a, b, c};
  };
  auto meets = [&](const std::array<glm::dvec3, 3>& u) {
    const glm::dvec3 uu[3] = {u[0], u[1], u[2]};
    return detail::triangles_meet(t, uu) && detail::triangles_meet(uu, t);
  };
  EXPECT_TRUE(meets(tri({0.5, 0.5, 0}, {0.5, 0.5, 1}, {1, 1, 1})));     // a corner on t's long edge
  EXPECT_FALSE(meets(tri({0.5, 0.5001, 0}, {0.5, 0.5, 1}, {1, 1, 1})));  // that corner just outside
  EXPECT_TRUE(meets(tri({0.2, 0.2, -1}, {0.2, 0.2, 1}, {3, 3, 0})));    // pierces t
  EXPECT_TRUE(meets(tri({1, 0, 0}, {2, 0, 0}, {1, -1, 0})));            // coplanar, one shared point
  EXPECT_FALSE(meets(tri({1.01, 0, 0}, {2, 0, 0}, {1, -1, 0})));        // coplanar, apart
  EXPECT_TRUE(meets(tri({0.1, 0.1, 0}, {0.2, 0.1, 0}, {0.1, 0.2, 0})));  // coplanar, inside
  EXPECT_FALSE(meets(tri({0, 0, 1e-300}, {1, 0, 1e-300}, {0, 1, 1e-300})));  // parallel, just above
}

// All pairs with overlapping boxes, one by one: what the grid must find.
size_t brute_force_pairs(const ContourMesh& m) {
  size_t count = 0;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> box;
  std::vector<bool> ok;
  for (const glm::uvec3& t : m.triangles) {
    const glm::dvec3 &a = m.positions[t.x], &b = m.positions[t.y], &c = m.positions[t.z];
    box.push_back({glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))});
    ok.push_back(t.x != t.y && t.y != t.z && t.x != t.z && !detail::collinear(a, b, c));
  }
  for (size_t i = 0; i < m.triangle_count(); ++i)
    for (size_t j = i + 1; j < m.triangle_count(); ++j) {
      if (!ok[i] || !ok[j]) continue;
      if (glm::any(glm::greaterThan(box[i].first, box[j].second)) ||
          glm::any(glm::greaterThan(box[j].first, box[i].second)))
        continue;
      count += detail::triangle_pair_intersects(m.positions.data(), m.triangles[i], m.triangles[j]) ? 1 : 0;
    }
  return count;
}

// A contoured mesh with every vertex moved by up to `amount` cells in each
// axis: folds near and far, among triangles of every size and slant.
ContourMesh jittered_contour(const char* name, int cells, double amount) {
  World w = build_from_mesh(test::load_test_mesh(name), {.cells = cells}).value();
  ContourMesh m = contour_world(w, {.untangle = false}).value();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-amount, amount);
  for (glm::dvec3& p : m.positions) p += w.lattice().cell_size * glm::dvec3(u(rng), u(rng), u(rng));
  return m;
}

TEST(Quality, GridFindsEveryPairThatAllPairsFind) {
  for (const char* name : {"fandisk.obj", "spot.obj"}) {
    const ContourMesh m = jittered_contour(name, 40, 0.3);
    const size_t brute = brute_force_pairs(m);
    EXPECT_EQ(mesh_quality(m).self_intersecting_pairs, brute) << name;
    EXPECT_GT(brute, 0u) << name;
  }
  // Big and small triangles together (the grid grows its cells for the big ones).
  ContourMesh m = test::box_pair({0.9, 0.1, 0.6}, {1.1, 0.3, 0.8});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 300; ++i) {
    const glm::dvec3 p(u(rng) * 1.2, u(rng), u(rng));
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.push_back(p);
    m.positions.push_back(p + 0.05 * glm::dvec3(u(rng), u(rng), u(rng)));
    m.positions.push_back(p + 0.05 * glm::dvec3(u(rng), u(rng), u(rng)));
    m.triangles.push_back({base, base + 1, base + 2});
  }
  EXPECT_EQ(mesh_quality(m).self_intersecting_pairs, brute_force_pairs(m));
}

TEST(Quality, SameCountsForAnyThreadCount) {
  const ContourMesh m = jittered_contour("rocker-arm.obj", 96, 0.3);
  const MeshQuality many = mesh_quality(m);
  MeshQuality one;
  tbb::task_arena(1).execute([&] { one = mesh_quality(m); });
  expect_same_quality(one, many);
  EXPECT_GT(many.self_intersecting_pairs, 0u);
}

// Dual contouring's output: watertight; closed() exactly when nothing is named.
TEST(Quality, ContouredMeshesAreWatertightAndClosedOnlyWhenNothingFails) {
  World w = build_from_mesh(test::load_test_mesh("spot.obj"), {.cells = 64}).value();
  const MeshQuality q = mesh_quality(contour_world(w).value());
  EXPECT_TRUE(q.watertight());
  EXPECT_EQ(q.closed(), quality_failures(q).empty()) << quality_failures(q);
}

}  // namespace
}  // namespace ldc
