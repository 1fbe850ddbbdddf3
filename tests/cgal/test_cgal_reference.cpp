// Agreement with CGAL, the exact reference: inside/outside at lattice nodes
// (Side_of_triangle_mesh) and the volume of the open bunny against the same
// bunny with its holes filled by CGAL's triangulate_hole.
#include <gtest/gtest.h>

#include <random>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>

#include "ldc/build.h"
#include "cgal/cgal_mesh.h"
#include "test_util.h"

namespace ldc {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = test::CgalMesh;
namespace PMP = CGAL::Polygon_mesh_processing;
using test::to_cgal;

// At least 100,000 random lattice nodes inside the mesh's bounding box, leaving
// out those within 1e-6 of the diagonal from the surface.
void expect_nodes_agree_with_cgal(const char* name, int cells) {
  TriangleMesh m = test::load_test_mesh(name);
  Mesh cm = to_cgal(m);
  ASSERT_TRUE(CGAL::is_closed(cm)) << name;
  World w = build_from_mesh(m, {.cells = cells}).value();
  CGAL::Side_of_triangle_mesh<Mesh, Kernel> side(cm);
  using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
  CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>> tree(faces(cm).first, faces(cm).second, cm);
  tree.accelerate_distance_queries();
  MeshBounds b = mesh_bounds(m);
  const double near = 1e-6 * b.diagonal();
  glm::ivec3 lo = glm::ivec3(glm::floor(w.lattice().to_lattice(b.min)));
  glm::ivec3 hi = glm::ivec3(glm::ceil(w.lattice().to_lattice(b.max)));
  std::mt19937 rng(42);
  size_t checked = 0, agree = 0, inside = 0, skipped = 0;
  while (checked < 100000) {
    glm::ivec3 n(lo.x + int(rng() % (hi.x - lo.x + 1)), lo.y + int(rng() % (hi.y - lo.y + 1)),
                 lo.z + int(rng() % (hi.z - lo.z + 1)));
    glm::dvec3 p = w.lattice().node_position(n);
    Point q(p.x, p.y, p.z);
    if (tree.squared_distance(q) < near * near) {
      ++skipped;
      continue;
    }
    bool cgal_in = side(q) == CGAL::ON_BOUNDED_SIDE;
    bool ours = w.inside_node(n);
    ++checked;
    agree += cgal_in == ours;
    inside += cgal_in;
  }
  EXPECT_EQ(agree, checked) << name << ": " << checked - agree << " of " << checked
                            << " nodes disagree (" << inside << " inside, " << skipped << " skipped)";
  EXPECT_GT(inside, checked / 20) << name << ": too few inside samples to mean anything";
}

TEST(CgalReference, InsideAgreesWithSideOfTriangleMeshOnSpot) { expect_nodes_agree_with_cgal("spot.obj", 128); }
TEST(CgalReference, InsideAgreesWithSideOfTriangleMeshOnFandisk) { expect_nodes_agree_with_cgal("fandisk.obj", 128); }
TEST(CgalReference, InsideAgreesWithSideOfTriangleMeshOnRockerArm) { expect_nodes_agree_with_cgal("rocker-arm.obj", 128); }

TEST(CgalReference, OpenBunnyVolumeWithinTwoPercentOfTheHoleFilledBunny) {
  TriangleMesh m = test::load_test_mesh("stanford-bunny.obj");
  Mesh cm = to_cgal(m);
  int holes = 0;
  std::vector<Mesh::Halfedge_index> borders;
  for (auto h : halfedges(cm)) {
    if (cm.is_border(h)) borders.push_back(h);
  }
  std::set<Mesh::Halfedge_index> seen;
  for (auto h : borders) {
    if (seen.count(h) || !cm.is_border(h)) continue;
    for (auto g : CGAL::halfedges_around_face(h, cm)) seen.insert(g);
    std::vector<Mesh::Face_index> added;
    PMP::triangulate_hole(cm, h, std::back_inserter(added));
    ++holes;
  }
  ASSERT_TRUE(CGAL::is_closed(cm));
  EXPECT_EQ(holes, 5);
  const double reference = PMP::volume(cm);
  for (int cells : {128, 256}) {
    BuildReport r;
    World w = build_from_mesh(m, {.cells = cells}, nullptr, &r).value();
    EXPECT_TRUE(test::is_valid(w));
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(w.volume(a), reference, 0.02 * reference)
          << "axis " << a << " at " << cells << " cells (" << r.repaired_rays << " repaired rays)";
    }
    std::printf("bunny at %d cells: volume %.6g %.6g %.6g vs filled %.6g (%.2f%%), %zu repaired rays\n",
                cells, w.volume(0), w.volume(1), w.volume(2), reference,
                100.0 * (w.volume(0) - reference) / reference, r.repaired_rays);
  }
}

}  // namespace
}  // namespace ldc

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include "contour/contour.h"
#include "meshio/meshio.h"

namespace ldc {
namespace {

// Self-intersecting triangle pairs of a contoured mesh, counted by CGAL.
size_t self_intersections(const ContourMesh& m) {
  TriangleMesh t = to_triangle_mesh(m);
  Mesh cm = to_cgal(t);
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  PMP::self_intersections(cm, std::back_inserter(pairs));
  return pairs.size();
}

TEST(CgalReference, SelfIntersectionsOfContouredMeshesAreCounted) {
  for (const char* name : {"spot.obj", "fandisk.obj", "rocker-arm.obj"}) {
    World w = build_from_mesh(test::load_test_mesh(name), {.cells = 64}).value();
    for (Placement method : {Placement::kIterative, Placement::kQef, Placement::kMassPoint}) {
      ContourMesh m = contour_world(w, {.placement = method}).value();
      size_t n = self_intersections(m);
      std::printf("%s %s: %zu self-intersecting pairs in %zu triangles\n", name, placement_name(method), n,
                  m.triangle_count());
      // Vertices stay in their cells, so intersections are rare and local:
      // none for the mass point, a few where sharp features fold triangles
      // (measured at 64 cells: 25 to 197 pairs with 256 iterative steps, 4 to
      // 158 qef: sharper features fold more triangles).
      if (method == Placement::kMassPoint) EXPECT_EQ(n, 0u) << name;
      else EXPECT_LE(n, m.triangle_count() / 100) << name << " " << placement_name(method);
    }
  }
}

}  // namespace
}  // namespace ldc

// --- The quality report's counts against CGAL's ---------------------------------

#include "cgal/cgal_quality.h"
#include "contour/detail/triangle_intersection.h"
#include "csg/csg.h"
#include "quality_meshes.h"

namespace ldc {
namespace {

// mesh_quality's self-intersecting pairs and non-manifold edges and vertices
// equal CGAL's (see cgal/cgal_quality.h for how CGAL counts them).
void expect_quality_equals_cgal(const ContourMesh& m, const std::string& name) {
  const MeshQuality q = mesh_quality(m);
  const cgal_quality::Counts c = cgal_quality::counts(m);
  EXPECT_EQ(q.self_intersecting_pairs, c.pairs) << name;
  if (c.whole_mesh_pairs) {
    EXPECT_EQ(q.self_intersecting_pairs, *c.whole_mesh_pairs) << name << " (whole mesh)";
  }
  EXPECT_EQ(q.nonmanifold_edges, c.nonmanifold_edges) << name;
  EXPECT_EQ(q.nonmanifold_vertices, c.nonmanifold_vertices) << name;
  EXPECT_EQ(c.degenerate, q.degenerate_triangles) << name;  // CGAL's pairs (f, f): collinear triangles
  std::printf("%s: %zu triangles, %zu boundary edges, non-manifold edges %zu (CGAL %zu), vertices %zu (CGAL %zu), "
              "self-intersecting pairs %zu (CGAL %zu%s)\n",
              name.c_str(), q.triangles, q.boundary_edges, q.nonmanifold_edges, c.nonmanifold_edges,
              q.nonmanifold_vertices, c.nonmanifold_vertices, q.self_intersecting_pairs, c.pairs,
              c.whole_mesh_pairs ? ", whole mesh too" : "");
}

TEST(CgalReference, QualityCountsEqualCgalsOnHandMadeMeshes) {
  for (const test::QualityCase& c : test::quality_cases()) {
    expect_quality_equals_cgal(c.mesh, c.name);
    EXPECT_EQ(cgal_quality::counts(c.mesh).pairs, c.self_intersecting_pairs) << c.name << ": the hand count";
  }
  // Unwelded cubes touching along a face, an edge and a corner: coplanar and touching pairs.
  expect_quality_equals_cgal(test::box_pair({1, 0, 0}, {2, 1, 1}), "cubes sharing a face, unwelded");
  expect_quality_equals_cgal(test::box_pair({1, 1, 0}, {2, 2, 1}), "cubes sharing an edge, unwelded");
  expect_quality_equals_cgal(test::box_pair({1, 1, 1}, {2, 2, 2}), "cubes sharing a corner, unwelded");
  expect_quality_equals_cgal(test::box_pair({0.25, 0.25, 0.25}, {0.75, 0.75, 1.0}), "cube inside touching the top");
}

// Random pairs of triangles on a 3 x 3 x 3 grid of points, sharing vertices
// by chance: coplanar, touching, folded and crossing pairs in bulk.
TEST(CgalReference, TrianglePairTestAgreesWithCgalOnGridTriangles) {
  std::vector<glm::dvec3> grid;
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 3; ++x) grid.push_back(glm::dvec3(x, y, z) * 0.1 + glm::dvec3(0.3, -0.7, 1.9));
  const std::vector<cgal_quality::Point> p = cgal_quality::points(test::triangles(grid, {}));
  std::mt19937 rng(11);
  size_t tested = 0, intersecting = 0, shared_edge = 0, shared_vertex = 0;
  while (tested < 20000) {
    glm::uvec3 t(rng() % 27, rng() % 27, rng() % 27), u(rng() % 27, rng() % 27, rng() % 27);
    if (detail::collinear(grid[t[0]], grid[t[1]], grid[t[2]]) || detail::collinear(grid[u[0]], grid[u[1]], grid[u[2]]))
      continue;  // repeated indices are collinear too
    int shared = 0;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) shared += t[k] == u[l];
    const bool ours = detail::triangle_pair_intersects(grid.data(), t, u);
    ASSERT_EQ(ours, cgal_quality::pair_intersects(p, t, u))
        << "t = " << t.x << " " << t.y << " " << t.z << ", u = " << u.x << " " << u.y << " " << u.z;
    ++tested;
    intersecting += ours;
    shared_edge += shared == 2;
    shared_vertex += shared == 1;
  }
  std::printf("%zu pairs (%zu sharing an edge, %zu a vertex): %zu intersect\n", tested, shared_edge, shared_vertex,
              intersecting);
  EXPECT_GT(intersecting, tested / 10);
  EXPECT_GT(shared_edge, 100u);
  EXPECT_GT(shared_vertex, 1000u);
}

// What `ldc remesh --cells 64` writes for each shared mesh (iterative, the
// default, and qef, which folds more).
TEST(CgalReference, QualityCountsEqualCgalsOnRemeshedSharedMeshes) {
  for (const char* name : {"spot.obj", "fandisk.obj", "stanford-bunny.obj", "rocker-arm.obj"}) {
    World w = build_from_mesh(test::load_test_mesh(name), {.cells = 64}).value();
    for (Placement method : {Placement::kIterative, Placement::kQef}) {
      ContourMesh m = contour_world(w, {.placement = method}).value();
      expect_quality_equals_cgal(m, std::string(name) + " " + placement_name(method) + " at 64 cells");
    }
  }
}

// What `ldc boolean` writes: two meshes on one lattice, combined, contoured.
TEST(CgalReference, QualityCountsEqualCgalsOnBooleanResults) {
  const TriangleMesh spot = test::load_test_mesh("spot.obj");
  const TriangleMesh teapot = test::load_test_mesh("teapot.obj");
  World united = mesh_boolean(spot, teapot, BooleanOp::kUnion, {.cells = 64}).value();
  expect_quality_equals_cgal(contour_world(united).value(), "spot union teapot at 64 cells");
  TriangleMesh moved = spot;
  for (glm::dvec3& v : moved.positions) v += glm::dvec3(0.25, 0.1, 0.05);
  World cut = mesh_boolean(spot, moved, BooleanOp::kSubtract, {.cells = 64}).value();
  expect_quality_equals_cgal(contour_world(cut).value(), "spot subtract moved spot at 64 cells");
}

}  // namespace
}  // namespace ldc
