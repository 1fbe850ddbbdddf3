// simplify_mesh: adaptive output within an error bound (issue 19 item 3).
// Cubes become 12 triangles with their corners kept, a sphere stays within
// the bound, topology, material borders and intersections never get worse,
// the result does not depend on the thread count, and options are checked.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <tbb/global_control.h>

#include "contour/contour.h"
#include "ldc/build.h"
#include "test_util.h"

namespace ldc {
namespace {

struct Cube {
  glm::dmat4 transform;
  glm::dvec3 half;
};

World cube_world(const Cube& c, int cells) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.half_extents = c.half;
  p.transform = c.transform;
  return build_from_primitive(p, {.cells = cells}).value();
}

// Slack 1: the contoured box keeps its corners (see test_contour.cpp).
// Untangling off: it moves the vertices around folds (which rotated boxes
// have at their corners) to their mass points, rounding the corners away.
ContourMesh contour_cube(const World& w) { return contour_world(w, {.cell_slack = 1.0, .untangle = false}).value(); }

// 12 triangles, 8 vertices, each at a corner (within 0.05 h, what contouring
// gives), with the bound `relative` times the cube's longest edge.
void expect_twelve_triangles_with_corners(const Cube& c, int cells, double relative, const char* name) {
  World w = cube_world(c, cells);
  const double h = w.lattice().cell_size;
  ContourMesh mesh = contour_cube(w);
  const size_t uniform = mesh.triangle_count();
  Result<SimplifyStats> stats = simplify_mesh(mesh, {.max_error = relative * 2.0 * c.half.x});
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();
  EXPECT_EQ(stats->triangles_before, uniform);
  EXPECT_EQ(mesh.triangle_count(), 12u) << name << " at " << cells << " cells (from " << uniform << ")";
  EXPECT_EQ(mesh.vertex_count(), 8u) << name;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 local((k & 1) ? c.half.x : -c.half.x, (k & 2) ? c.half.y : -c.half.y,
                           (k & 4) ? c.half.z : -c.half.z);
    const glm::dvec3 corner(c.transform * glm::dvec4(local, 1.0));
    double nearest = INFINITY;
    for (const glm::dvec3& q : mesh.positions) nearest = std::min(nearest, glm::length(q - corner));
    EXPECT_LT(nearest, 0.05 * h) << name << " corner " << k;
  }
  const MeshQuality q = mesh_quality(mesh);
  EXPECT_TRUE(q.closed()) << name << ": " << quality_failures(q);
  const double volume = 8.0 * c.half.x * c.half.y * c.half.z;
  EXPECT_NEAR(q.volume, volume, 0.01 * volume) << name;
}

TEST(Simplify, AxisAlignedCubeBecomesTwelveTrianglesAtAnyResolution) {
  const Cube c{glm::translate(glm::dmat4(1.0), glm::dvec3(0.013, -0.021, 0.007)), glm::dvec3(1.0)};
  for (int cells : {16, 40, 100}) expect_twelve_triangles_with_corners(c, cells, 1e-3, "axis-aligned");
}

// Rotated faces carry placement noise (vertices within about 0.001 h of the
// face, triangle normals off by about 0.1 degree); the bound sums the squared
// distances to every plane merged, so it needs more room than on an
// axis-aligned face, growing with the resolution (1% of the edge: 12
// triangles at 40 and 64 cells; 0.1% leaves 44-104 triangles).
TEST(Simplify, RotatedBoxesBecomeTwelveTriangles) {
  for (int i = 0; i < 3; ++i) {
    const glm::dmat4 m = glm::rotate(glm::dmat4(1.0), 0.3 + 0.5 * i, glm::normalize(glm::dvec3(1.0, 2.0 - i, 0.5 + i)));
    for (int cells : {40, 64}) expect_twelve_triangles_with_corners({m, {1.0, 0.8, 0.6}}, cells, 1e-2, "rotated");
  }
}

// Points on every triangle (a barycentric grid, corners and edges included).
template <class F>
void for_each_surface_sample(const ContourMesh& mesh, F&& f) {
  constexpr int kSteps = 6;
  for (const glm::uvec3& t : mesh.triangles)
    for (int i = 0; i <= kSteps; ++i)
      for (int j = 0; i + j <= kSteps; ++j) {
        const double a = double(i) / kSteps, b = double(j) / kSteps;
        f((1.0 - a - b) * mesh.positions[t.x] + a * mesh.positions[t.y] + b * mesh.positions[t.z]);
      }
}

double worst_sphere_distance(const ContourMesh& mesh) {
  double worst = 0.0;
  for_each_surface_sample(mesh, [&](const glm::dvec3& p) { worst = std::max(worst, std::abs(glm::length(p) - 1.0)); });
  return worst;
}

TEST(Simplify, SphereStaysWithinTheBound) {
  Primitive p;
  p.radius = 1.0;
  World w = build_from_primitive(p, {.cells = 64}).value();
  const double h = w.lattice().cell_size;
  ContourMesh mesh = contour_world(w).value();
  const double contour_error = worst_sphere_distance(mesh);
  // A curved surface simplifies far less than a flat one: the fewer
  // triangles the bound allows (measured 1.6x and 7x fewer).
  for (auto [bound, fewer] : {std::pair{0.02 * h, 1.4}, std::pair{0.25 * h, 5.0}}) {
    ContourMesh simple = mesh;
    SimplifyStats stats = simplify_mesh(simple, {.max_error = bound}).value();
    EXPECT_LE(stats.max_error_reached, bound);
    EXPECT_LT(double(simple.triangle_count()) * fewer, double(mesh.triangle_count())) << "bound " << bound / h << " h";
    EXPECT_LE(worst_sphere_distance(simple), bound + contour_error) << "bound " << bound / h << " h";
    const MeshQuality q = mesh_quality(simple);
    EXPECT_TRUE(q.closed()) << quality_failures(q);
  }
}

TEST(Simplify, ZeroErrorLeavesTheMeshUnchanged) {
  Primitive p;
  World w = build_from_primitive(p, {.cells = 24}).value();
  const ContourMesh mesh = contour_world(w).value();
  ContourMesh same = mesh;
  SimplifyStats stats = simplify_mesh(same, {.max_error = 0.0, .target_triangles = 10}).value();
  EXPECT_EQ(stats.collapses, 0u);
  EXPECT_EQ(stats.triangles_after, mesh.triangle_count());
  EXPECT_EQ(same.positions, mesh.positions);
  EXPECT_EQ(same.triangles, mesh.triangles);
  EXPECT_EQ(same.normals, mesh.normals);
  EXPECT_EQ(same.triangle_material, mesh.triangle_material);
}

// Remeshed shared meshes: every defect count of mesh_quality stays or drops.
TEST(Simplify, NeverAddsNonManifoldSpotsHolesOrIntersections) {
  for (const char* name : {"spot.obj", "fandisk.obj", "rocker-arm.obj", "stanford-bunny.obj"}) {
    World w = build_from_mesh(test::load_test_mesh(name), {.cells = 64}).value();
    ContourMesh mesh = contour_world(w).value();
    const MeshQuality before = mesh_quality(mesh);
    SimplifyStats stats = simplify_mesh(mesh, {.max_error = 0.25 * w.lattice().cell_size}).value();
    const MeshQuality after = mesh_quality(mesh);
    EXPECT_LT(after.triangles, before.triangles / 2) << name;
    EXPECT_EQ(after.boundary_edges, before.boundary_edges) << name;
    EXPECT_EQ(after.unpaired_edges, before.unpaired_edges) << name;
    EXPECT_LE(after.nonmanifold_edges, before.nonmanifold_edges) << name;
    EXPECT_LE(after.nonmanifold_vertices, before.nonmanifold_vertices) << name;
    EXPECT_LE(after.self_intersecting_pairs, before.self_intersecting_pairs) << name;
    EXPECT_LE(after.degenerate_triangles, before.degenerate_triangles) << name;
    EXPECT_EQ(after.unused_vertices, 0u) << name;
    EXPECT_NEAR(after.volume, before.volume, 0.01 * before.volume) << name;
    EXPECT_GT(stats.collapses, 0u);
  }
}

// Ground whose two materials meet along a slanted line (as in test_contour.cpp).
class TwoMaterialGround final : public ImplicitSolid {
 public:
  double value(const glm::dvec3& p) const override {
    const double ground = p.z - (1.0 + 0.3 * std::sin(p.x) * std::cos(p.y));
    return std::max(ground, std::max({-p.x, p.x - 4.0, -p.y, p.y - 4.0, -p.z}));
  }
  uint16_t material(const glm::dvec3& p) const override { return p.x + 0.37 * p.y > 2.2 ? 1 : 0; }
  WorldBox bounds() const override { return {{0, 0, 0}, {4, 4, 1.4}}; }
};

// Vertices of edges whose two triangles differ in material.
std::set<std::pair<uint32_t, uint32_t>> border_edges(const ContourMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint16_t>> sides;
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3];
      sides[{std::min(a, b), std::max(a, b)}].push_back(m.triangle_material[t]);
    }
  std::set<std::pair<uint32_t, uint32_t>> out;
  for (const auto& [edge, materials] : sides)
    if (materials.size() == 2 && materials[0] != materials[1]) out.insert(edge);
  return out;
}

std::set<std::tuple<double, double, double>> border_points(const ContourMesh& m) {
  std::set<std::tuple<double, double, double>> out;
  for (const auto& [a, b] : border_edges(m))
    for (uint32_t v : {a, b}) out.insert({m.positions[v].x, m.positions[v].y, m.positions[v].z});
  return out;
}

double material_area(const ContourMesh& m, uint16_t material) {
  double area = 0.0;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    if (m.triangle_material[t] != material) continue;
    const glm::dvec3 &a = m.positions[m.triangles[t].x], &b = m.positions[m.triangles[t].y],
                     &c = m.positions[m.triangles[t].z];
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

TEST(Simplify, MaterialBordersStayOnTheirVerticesAndNormalsAndMaterialsFollowTheirVertices) {
  TwoMaterialGround ground;
  World w = build_from_implicit(ground, {.cell_size = 0.05, .chunk_size = 16}).value();
  const ContourMesh mesh = contour_world(w).value();
  ContourMesh simple = mesh;
  simplify_mesh(simple, {.max_error = 0.2 * w.lattice().cell_size}).value();
  ASSERT_LT(simple.triangle_count(), mesh.triangle_count() / 2);
  // The border runs through original border vertices only, and stays one line
  // (each border vertex on two border edges, except where it meets the sides).
  const auto before = border_points(mesh);
  const auto after = border_points(simple);
  EXPECT_FALSE(after.empty());
  for (const auto& p : after) EXPECT_TRUE(before.count(p)) << "a border vertex that was not on the border";
  EXPECT_LT(after.size(), before.size());  // the border was simplified too
  for (uint16_t m : {uint16_t(0), uint16_t(1)})
    EXPECT_NEAR(material_area(simple, m), material_area(mesh, m), 0.01 * material_area(mesh, m)) << "material " << m;
  // Surviving vertices keep their normal and material.
  std::map<std::tuple<double, double, double>, size_t> original;
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    original[{mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z}] = v;
  for (size_t v = 0; v < simple.vertex_count(); ++v) {
    auto it = original.find({simple.positions[v].x, simple.positions[v].y, simple.positions[v].z});
    ASSERT_NE(it, original.end()) << "a position that was not a contour vertex";
    EXPECT_EQ(simple.normals[v], mesh.normals[it->second]);
    EXPECT_EQ(simple.vertex_material[v], mesh.vertex_material[it->second]);
  }
  const MeshQuality q0 = mesh_quality(mesh), q1 = mesh_quality(simple);
  EXPECT_LE(q1.self_intersecting_pairs, q0.self_intersecting_pairs);
  EXPECT_EQ(q1.boundary_edges, q0.boundary_edges);
}

// A spherical shell one cell thick, simplified within 8 cells: flattening
// either sphere would push it through the other, so many collapses are
// refused as intersections (through the pair filters: stars known from
// earlier collapses, separating axes), and the two sheets never meet.
class ThinShell final : public ImplicitSolid {
 public:
  double value(const glm::dvec3& p) const override {
    const double r = glm::length(p - glm::dvec3(1.0));
    return std::max(r - 0.8, 0.78 - r);
  }
  WorldBox bounds() const override { return {{0.1, 0.1, 0.1}, {1.9, 1.9, 1.9}}; }
};

TEST(Simplify, ThinShellSheetsNeverMeet) {
  ThinShell shell;
  World w = build_from_implicit(shell, {.cell_size = 0.02, .chunk_size = 16}).value();
  ContourMesh mesh = contour_world(w).value();
  const MeshQuality before = mesh_quality(mesh);
  SimplifyStats stats = simplify_mesh(mesh, {.max_error = 8.0 * w.lattice().cell_size}).value();
  const MeshQuality after = mesh_quality(mesh);
  EXPECT_LT(after.triangles, before.triangles / 4);
  EXPECT_GT(stats.rejected_intersection, 0u);
  EXPECT_LE(after.self_intersecting_pairs, before.self_intersecting_pairs);
  EXPECT_EQ(after.boundary_edges, before.boundary_edges);
  EXPECT_LE(after.nonmanifold_edges, before.nonmanifold_edges);
  EXPECT_LE(after.degenerate_triangles, before.degenerate_triangles);
}

TEST(Simplify, SameResultForAnyThreadCount) {
  World w = build_from_mesh(test::load_test_mesh("spot.obj"), {.cells = 96}).value();
  const ContourMesh mesh = contour_world(w).value();
  // Small blocks: many blocks per thread and many seams.
  const SimplifyOptions options{.max_error = 0.2 * w.lattice().cell_size, .block_size = 8 * w.lattice().cell_size};
  ContourMesh one = mesh, two = mesh;
  SimplifyStats s1, s2;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    s1 = simplify_mesh(one, options).value();
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    s2 = simplify_mesh(two, options).value();
  }
  EXPECT_GT(s1.blocks, 8u);
  EXPECT_EQ(one.triangles, two.triangles);
  EXPECT_EQ(one.positions, two.positions);
  EXPECT_EQ(s1.collapses, s2.collapses);
  EXPECT_EQ(s1.rejected_intersection, s2.rejected_intersection);
}

TEST(Simplify, TargetTrianglesStopsThereWhileTheBoundAllows) {
  Primitive p;
  World w = build_from_primitive(p, {.cells = 48}).value();
  const double h = w.lattice().cell_size;
  const ContourMesh mesh = contour_world(w).value();
  // A loose bound: the target stops it.
  ContourMesh targeted = mesh;
  SimplifyStats stats = simplify_mesh(targeted, {.max_error = 2.0 * h, .target_triangles = 1000}).value();
  EXPECT_LE(targeted.triangle_count(), 1000u);
  EXPECT_GE(targeted.triangle_count(), 999u);
  EXPECT_LE(stats.max_error_reached, 2.0 * h);
  // A tight bound: the bound stops it above the target, as without a target.
  ContourMesh tight = mesh, free = mesh;
  simplify_mesh(tight, {.max_error = 0.01 * h, .target_triangles = 1000}).value();
  simplify_mesh(free, {.max_error = 0.01 * h}).value();
  EXPECT_GT(tight.triangle_count(), 1000u);
  EXPECT_LE(worst_sphere_distance(tight), worst_sphere_distance(mesh) + 0.01 * h + 1e-12);
  EXPECT_TRUE(mesh_quality(targeted).closed());
}

TEST(Simplify, BadOptionsAndMeshesAreRefusedByName) {
  ContourMesh mesh;
  auto refused = [&](SimplifyOptions o, const char* field) {
    Result<SimplifyStats> r = simplify_mesh(mesh, o);
    ASSERT_FALSE(r.ok()) << field;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find(field), std::string::npos) << r.status().message();
    EXPECT_EQ(check_simplify_options(o).code(), ErrorCode::kInvalidArgument);
  };
  refused({.max_error = -1.0}, "max_error");
  refused({.max_error = NAN}, "max_error");
  refused({.max_error = INFINITY}, "max_error");
  refused({.max_error = 1.0, .max_normal_change_deg = 0.0}, "max_normal_change_deg");
  refused({.max_error = 1.0, .min_angle_deg = 45.0}, "min_angle_deg");
  refused({.max_error = 1.0, .block_size = -2.0}, "block_size");
  EXPECT_TRUE(check_simplify_options({.max_error = 0.5}).ok());
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  mesh.normals.assign(3, glm::vec3(0, 0, 1));
  mesh.vertex_material.assign(3, 0);
  mesh.triangles = {{0, 1, 7}};
  mesh.triangle_material = {0};
  Result<SimplifyStats> r = simplify_mesh(mesh, {.max_error = 1.0});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("out of range"), std::string::npos) << r.status().message();
}

}  // namespace
}  // namespace ldc
