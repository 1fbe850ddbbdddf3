// What `ldc remesh` and `ldc boolean` write, checked by CGAL (issue 19):
// every output a valid, closed polygon mesh without self-intersections
// (CGAL::is_valid_polygon_mesh, is_closed, !does_self_intersect), for the
// shared meshes and boolean results at 64, 128 and 256 cells, adaptive (the
// tools' default bound) and uniform. The pipeline is the tool's: contour
// (without the local untangling round; adaptive: at the levels the surface
// allows where they pay off), simplify within the bound, untangle_mesh.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>

#include "cgal/cgal_validity.h"
#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/build.h"
#include "test_util.h"

namespace ldc {
namespace {

constexpr double kToolMaxErrorCells = 0.2;  // ldc remesh / boolean --max-error default (tools/mesh_output.h)

// Contours `w` as the tool does (adaptive: at the levels the surface
// allows, contour_at_surface_levels) and checks the result with CGAL.
void expect_valid_output(const World& w, double max_error_cells, const std::string& name) {
  ContourMesh m = max_error_cells > 0.0
                      ? contour_at_surface_levels(w, surface_level_tolerance(max_error_cells), {.untangle = false}).value()
                      : contour_world(w, {.untangle = false}).value();
  const size_t uniform = m.triangle_count();
  if (max_error_cells > 0.0) {
    ASSERT_TRUE(simplify_mesh(m, {.max_error = max_error_cells * w.lattice().cell_size}).ok()) << name;
  }
  const UntangleMeshStats untangled = untangle_mesh(m).value();
  EXPECT_EQ(untangled.pairs_after, 0u) << name;
  const cgal_validity::Verdict v = cgal_validity::check(m.positions, m.triangles);
  EXPECT_TRUE(v.ok()) << name << ": " << v.text();
  EXPECT_TRUE(mesh_quality(m).closed()) << name << ": " << quality_failures(mesh_quality(m));
  std::printf("%s: %zu -> %zu triangles, %zu pairs untangled, CGAL: %s\n", name.c_str(), uniform,
              m.triangle_count(), untangled.pairs_before, v.ok() ? "valid, closed, no self-intersection" : v.text().c_str());
}

void expect_valid_remeshes(const char* file) {
  const TriangleMesh input = test::load_test_mesh(file);
  for (int cells : {64, 128, 256}) {
    const World w = build_from_mesh(input, {.cells = cells}).value();
    for (double bound : {kToolMaxErrorCells, 0.0})
      expect_valid_output(w, bound, std::string(file) + " at " + std::to_string(cells) +
                                        (bound > 0.0 ? " cells, adaptive" : " cells, uniform"));
  }
}

TEST(CgalValidity, RemeshedSpotIsValidClosedAndFreeOfSelfIntersections) { expect_valid_remeshes("spot.obj"); }
TEST(CgalValidity, RemeshedFandiskIsValidClosedAndFreeOfSelfIntersections) { expect_valid_remeshes("fandisk.obj"); }
TEST(CgalValidity, RemeshedRockerArmIsValidClosedAndFreeOfSelfIntersections) {
  expect_valid_remeshes("rocker-arm.obj");
}
TEST(CgalValidity, RemeshedBunnyIsValidClosedAndFreeOfSelfIntersections) {
  expect_valid_remeshes("stanford-bunny.obj");
}

void expect_valid_booleans(const TriangleMesh& a, const TriangleMesh& b, const std::string& name) {
  const std::pair<BooleanOp, const char*> ops[] = {
      {BooleanOp::kUnion, "union"}, {BooleanOp::kSubtract, "subtract"}, {BooleanOp::kIntersect, "intersect"}};
  for (const auto& [op, op_name] : ops) {
    for (int cells : {64, 128, 256}) {
      const World w = mesh_boolean(a, b, op, {.cells = cells}).value();
      for (double bound : {kToolMaxErrorCells, 0.0})
        expect_valid_output(w, bound, name + " " + op_name + " at " + std::to_string(cells) +
                                          (bound > 0.0 ? " cells, adaptive" : " cells, uniform"));
    }
  }
}

TEST(CgalValidity, BooleansOfSpotAndTeapotAreValidClosedAndFreeOfSelfIntersections) {
  expect_valid_booleans(test::load_test_mesh("spot.obj"), test::load_test_mesh("teapot.obj"), "spot, teapot");
}

TEST(CgalValidity, BooleansOfFandiskAndASphereAreValidClosedAndFreeOfSelfIntersections) {
  const TriangleMesh fandisk = test::load_test_mesh("fandisk.obj");
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::dvec3& p : fandisk.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  // A sphere over one corner of the part: sharp rims where it cuts the faces.
  const TriangleMesh ball = test::sphere_mesh(lo + 0.3 * (hi - lo), 0.3 * glm::length(hi - lo), 4);
  expect_valid_booleans(fandisk, ball, "fandisk, sphere");
}

// Two turned boxes: sharp CSG solids whose seams between surface levels
// contour_levels left non-manifold (contour_at_surface_levels falls back).
TEST(CgalValidity, BooleansOfTwoTurnedBoxesAreValidClosedAndFreeOfSelfIntersections) {
  expect_valid_booleans(test::load_test_mesh("turned_box_a.obj"), test::load_test_mesh("turned_box_b.obj"),
                        "turned boxes");
}

}  // namespace
}  // namespace ldc
