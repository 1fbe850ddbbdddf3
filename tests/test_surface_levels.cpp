// surface_levels (contour/contour.h, issue 19): the coarsest level each chunk
// can be meshed at while its surface stays within the tolerance. Plain
// surfaces (flat faces, creases) go coarse; curvature, thin parts and small
// bumps keep their chunks at level 0; the levels mesh closed and, on a box,
// on its faces.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/build.h"
#include "test_util.h"

namespace ldc {
namespace {

constexpr double kH = 0.01;  // cell size of every world here

// A cube of side `side` centred at `centre`, turned about a tilted axis, so
// that no face lies along the lattice.
TriangleMesh turned_cube(const glm::dvec3& centre, double side) {
  TriangleMesh m = test::box_mesh(glm::dvec3(-0.5 * side), glm::dvec3(0.5 * side));
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1.0, 2.0, 3.0));
  const double a = 0.4, c = std::cos(a), s = std::sin(a);
  for (glm::dvec3& p : m.positions)  // Rodrigues' rotation
    p = centre + p * c + glm::cross(axis, p) * s + axis * glm::dot(axis, p) * (1.0 - c);
  return m;
}

World build(const TriangleMesh& mesh) {
  GridConfig g = test::lattice_at_origin(kH);
  g.chunk_size = 32;
  return build_from_mesh(mesh, g).value();
}

// A slab whose top is material 1 for x > 0.5 m and 0 elsewhere.
class TwoMaterialSlab final : public ImplicitSolid {
 public:
  double value(const glm::dvec3& p) const override {
    return std::max({0.05 - p.x, p.x - 0.9, 0.05 - p.y, p.y - 0.9, 0.05 - p.z, p.z - 0.3});
  }
  uint16_t material(const glm::dvec3& p) const override { return p.x > 0.5 ? 1 : 0; }
  WorldBox bounds() const override { return {{0.05, 0.05, 0.05}, {0.9, 0.9, 0.3}}; }
};

// The mean distance from a mesh's vertices to the cube's surface (cube
// turned as turned_cube; in its own frame the distance to a box).
double mean_distance_to_cube(const ContourMesh& mesh, const glm::dvec3& centre, double side) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1.0, 2.0, 3.0));
  const double a = -0.4, c = std::cos(a), s = std::sin(a);
  double sum = 0.0;
  for (const glm::dvec3& q : mesh.positions) {
    const glm::dvec3 p = q - centre;
    const glm::dvec3 r = p * c + glm::cross(axis, p) * s + axis * glm::dot(axis, p) * (1.0 - c);
    const glm::dvec3 d = glm::abs(r) - glm::dvec3(0.5 * side);
    const double outside = glm::length(glm::max(d, glm::dvec3(0.0)));
    const double inside = std::min(std::max({d.x, d.y, d.z}), 0.0);
    sum += std::abs(outside + inside);
  }
  return sum / double(std::max<size_t>(mesh.positions.size(), 1));
}

size_t surface_total(const ChunkLevels& l) { return l.surface_chunks(0) + l.surface_chunks(1) + l.surface_chunks(2); }

TEST(SurfaceLevels, ATurnedCubeGoesCoarseAndPaysOff) {
  const glm::dvec3 centre(0.5, 0.5, 0.5);
  const World w = build(turned_cube(centre, 0.7));
  const ChunkLevels l = surface_levels(w).value();
  ASSERT_GT(surface_total(l), 20u);
  // Faces and most creases and corners are explained by their coarse cells' planes.
  EXPECT_GE(l.surface_chunks(2), surface_total(l) * 3 / 4)
      << l.surface_chunks(0) << " / " << l.surface_chunks(1) << " / " << l.surface_chunks(2);
  EXPECT_TRUE(surface_levels_pay_off(l));
  // Meshed at those levels: closed, with fewer triangles, and on the cube's faces.
  const ContourMesh coarse = contour_levels(w, l).value();
  const MeshQuality q = mesh_quality(coarse);
  EXPECT_TRUE(q.closed()) << quality_failures(q);
  EXPECT_LT(coarse.triangle_count(), contour_world(w).value().triangle_count() / 4);
  EXPECT_LT(mean_distance_to_cube(coarse, centre, 0.7), 0.01 * kH);
}

TEST(SurfaceLevels, ASmallSphereStaysAtLevelZero) {
  // Radius 20 cells: over a level-1 cell the sag (about d^2 / 2R) is far above 0.02 cells.
  const World w = build(test::sphere_mesh(glm::dvec3(0.3), 20 * kH, 5));
  const ChunkLevels l = surface_levels(w).value();
  ASSERT_GT(surface_total(l), 0u);
  EXPECT_EQ(l.surface_chunks(0), surface_total(l));
  EXPECT_FALSE(surface_levels_pay_off(l));
  // A loose enough tolerance lets the same sphere go coarse: the test does measure the sag.
  const ChunkLevels loose = surface_levels(w, {.tolerance = 2.0}).value();
  EXPECT_GT(loose.surface_chunks(1) + loose.surface_chunks(2), 0u);
}

TEST(SurfaceLevels, APlateThinnerThanACoarseCellStaysAtLevelZero) {
  // 1.2 cells thick, from z = 10.3 h: a level-1 edge from node 10 to 12 holds both faces.
  const World w = build(test::box_mesh({0.05, 0.05, 10.3 * kH}, {0.55, 0.55, 11.5 * kH}));
  const ChunkLevels l = surface_levels(w).value();
  ASSERT_GT(surface_total(l), 0u);
  EXPECT_EQ(l.surface_chunks(0), surface_total(l));
}

TEST(SurfaceLevels, ABumpSmallerThanACoarseCellKeepsItsChunkFine) {
  // A flat slab (its faces between lattice planes) with a bump of 1.5 x 1.5 x 1.25
  // cells on top, in one chunk: level-0 rays at x = 50 h and y = 50 h see it.
  TriangleMesh m = test::box_mesh({0.053, 0.053, 0.053}, {0.907, 0.907, 0.2005});
  test::append_mesh(m, test::box_mesh({0.493, 0.493, 0.2}, {0.508, 0.508, 0.213}));
  const World w = build(m);
  const ChunkLevels l = surface_levels(w).value();
  const ChunkLevels slab = surface_levels(build(test::box_mesh({0.053, 0.053, 0.053}, {0.907, 0.907, 0.2005}))).value();
  EXPECT_EQ(slab.surface_chunks(0), 0u);  // the slab alone: all coarse
  EXPECT_GE(l.surface_chunks(0), 1u);     // the bump's chunk stays at level 0
  EXPECT_EQ(l(glm::ivec3(glm::floor(glm::dvec3(0.5, 0.5, 0.205) / (32 * kH)))), 0);
}

TEST(SurfaceLevels, TheSameLevelsForAnyThreadCount) {
  const World w = build_from_mesh(test::load_test_mesh("fandisk.obj"), {.cells = 160, .chunk_size = 32}).value();
  const ChunkLevels two = surface_levels(w).value();
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  const ChunkLevels single = surface_levels(w).value();
  EXPECT_EQ(two.level, single.level);
  EXPECT_EQ(two.surface, single.surface);
  EXPECT_GT(two.surface_chunks(1) + two.surface_chunks(2), 0u);  // fandisk's flat faces
  const MeshQuality q = mesh_quality(contour_levels(w, two).value());
  EXPECT_TRUE(q.closed()) << quality_failures(q);
}

// contour_levels leaves material borders unrelaxed, so callers need to know.
TEST(SurfaceLevels, SaysWhenTheSurfaceHoldsSeveralMaterials) {
  GridConfig g = test::lattice_at_origin(kH);
  g.chunk_size = 32;
  EXPECT_TRUE(surface_levels(build_from_implicit(TwoMaterialSlab(), g).value()).value().several_materials);
  EXPECT_FALSE(surface_levels(build(turned_cube(glm::dvec3(0.5), 0.7))).value().several_materials);
}

// What the tools run before simplifying: levels where they pay off, and
// always a mesh with no non-manifold edge or vertex.
TEST(SurfaceLevels, ContourAtSurfaceLevelsUsesThemWhereTheyPayOff) {
  ContourConfig raw;
  raw.untangle = false;
  SurfaceLevelChoice cube;
  const World turned = build(turned_cube(glm::dvec3(0.5), 0.7));
  const ContourMesh m = contour_at_surface_levels(turned, 0.02, raw, nullptr, nullptr, &cube).value();
  EXPECT_TRUE(cube.used);
  EXPECT_FALSE(cube.fell_back);
  EXPECT_EQ(m.triangle_count(), contour_levels(turned, cube.levels, raw).value().triangle_count());
  SurfaceLevelChoice sphere;
  const World round = build(test::sphere_mesh(glm::dvec3(0.3), 20 * kH, 5));
  const ContourMesh s = contour_at_surface_levels(round, 0.02, raw, nullptr, nullptr, &sphere).value();
  EXPECT_FALSE(sphere.used);
  EXPECT_EQ(s.triangle_count(), contour_world(round, raw).value().triangle_count());
  // Two materials: kept on one level while borders are to be relaxed, not when relaxation is off.
  GridConfig g = test::lattice_at_origin(kH);
  g.chunk_size = 32;
  const World slab = build_from_implicit(TwoMaterialSlab(), g).value();
  SurfaceLevelChoice relaxed, plain;
  ASSERT_TRUE(contour_at_surface_levels(slab, 0.02, raw, nullptr, nullptr, &relaxed).ok());
  EXPECT_FALSE(relaxed.used);
  EXPECT_TRUE(relaxed.borders_relaxed);
  ContourConfig no_relax = raw;
  no_relax.relax_iterations = 0;
  ASSERT_TRUE(contour_at_surface_levels(slab, 0.02, no_relax, nullptr, nullptr, &plain).ok());
  EXPECT_TRUE(plain.used);
  EXPECT_FALSE(plain.borders_relaxed);
}

// Two turned boxes (tests/data/turned_box_*.obj) whose union contour_levels
// once meshed with a non-manifold seam between levels (the guard fell back
// to one level): the levels are used now, and the result is manifold.
TEST(SurfaceLevels, ContourAtSurfaceLevelsNeverReturnsANonManifoldMesh) {
  const World w = build_from_mesh(test::load_test_mesh("turned_box_a.obj"), {.cells = 256}).value();
  const World both = mesh_boolean(test::load_test_mesh("turned_box_a.obj"), test::load_test_mesh("turned_box_b.obj"),
                                  BooleanOp::kUnion, {.cells = 256})
                         .value();
  ContourConfig raw;
  raw.untangle = false;
  for (const World* world : {&w, &both}) {
    SurfaceLevelChoice choice;
    const ContourMesh m = contour_at_surface_levels(*world, 0.02, raw, nullptr, nullptr, &choice).value();
    const MeshQuality q = mesh_quality(m);
    EXPECT_EQ(q.nonmanifold_edges, 0u);
    EXPECT_EQ(q.nonmanifold_vertices, 0u);
    EXPECT_TRUE(q.watertight());
    EXPECT_FALSE(choice.fell_back);
    EXPECT_TRUE(choice.used || !surface_levels_pay_off(choice.levels));
  }
}

TEST(SurfaceLevels, ChunksWithoutSurfaceTakeTheTopLevel) {
  const World w = build(test::box_mesh({0.1, 0.1, 0.1}, {0.2, 0.2, 0.2}));
  const ChunkLevels l = surface_levels(w, {.max_level = 1}).value();
  ASSERT_EQ(l.level.size(), l.surface.size());
  for (size_t i = 0; i < l.level.size(); ++i)
    if (!l.surface[i]) {
      EXPECT_EQ(l.level[i], 1);
    }
  EXPECT_EQ(l.surface_chunks(2), 0u);  // max_level caps every chunk
}

TEST(SurfaceLevels, BadOptionsAreRefusedByName) {
  const World w = build(test::box_mesh({0.1, 0.1, 0.1}, {0.2, 0.2, 0.2}));
  for (double t : {-1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const Result<ChunkLevels> r = surface_levels(w, {.tolerance = t});
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find("tolerance"), std::string::npos) << r.status().message();
  }
  const Result<ChunkLevels> r = surface_levels(w, {.max_level = -1});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("max_level"), std::string::npos) << r.status().message();
}

TEST(SurfaceLevels, CancelledThroughTheContext) {
  const World w = build(test::box_mesh({0.1, 0.1, 0.1}, {0.9, 0.9, 0.9}));
  Context ctx;
  ctx.cancel();
  const Result<ChunkLevels> r = surface_levels(w, {}, &ctx);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kCancelled);
}

}  // namespace
}  // namespace ldc
