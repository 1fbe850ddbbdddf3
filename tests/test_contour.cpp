// Dual contouring on LDC rays: accuracy on analytic shapes, closed output,
// chunked equals one piece, incremental re-meshing, material relaxation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>

#include <glm/gtc/matrix_transform.hpp>
#include <meshoptimizer.h>
#include <tbb/task_arena.h>

#include "contour/contour.h"
#include "ldc/build.h"
#include "ldc/terrain.h"
#include "test_util.h"

namespace ldc {
namespace {

// Distance from p to the surface of the axis-aligned box [-e, e] in local coordinates.
double box_distance(const glm::dvec3& local, const glm::dvec3& e) {
  glm::dvec3 d = glm::abs(local) - e;
  double outside = glm::length(glm::max(d, 0.0));
  return outside > 0.0 ? outside : -std::max(d.x, std::max(d.y, d.z));
}

struct BoxCase {
  glm::dmat4 transform;
  glm::dvec3 half;
};

// Every vertex within 0.05 h of the box, and a vertex within 0.05 h of each corner.
void expect_box_kept(const BoxCase& b, const ContourConfig& config, const char* name) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.half_extents = b.half;
  p.transform = b.transform;
  World w = build_from_primitive(p, {.cells = 40}).value();
  ContourMesh m = contour_world(w, config).value();
  const double h = w.lattice().cell_size;
  const glm::dmat4 inv = glm::inverse(b.transform);
  double worst = 0.0;
  for (const glm::dvec3& q : m.positions) {
    worst = std::max(worst, std::abs(box_distance(glm::dvec3(inv * glm::dvec4(q, 1.0)), b.half)));
  }
  EXPECT_LT(worst, 0.05 * h) << name;
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 corner((c & 1) ? b.half.x : -b.half.x, (c & 2) ? b.half.y : -b.half.y, (c & 4) ? b.half.z : -b.half.z);
    glm::dvec3 world_corner = glm::dvec3(b.transform * glm::dvec4(corner, 1.0));
    double nearest = 1e300;
    for (const glm::dvec3& q : m.positions) nearest = std::min(nearest, glm::length(q - world_corner));
    EXPECT_LT(nearest, 0.05 * h) << name << " corner " << c;
  }
  MeshQuality quality = mesh_quality(m);
  EXPECT_TRUE(quality.watertight()) << name;
  const double volume = 8.0 * b.half.x * b.half.y * b.half.z * std::abs(glm::determinant(glm::dmat3(b.transform)));
  EXPECT_NEAR(quality.volume, volume, 0.01 * volume) << name;
}

// Gently curved ground with two materials meeting along a diagonal line,
// which the lattice turns into a staircase.
class TwoMaterialGround final : public ImplicitSolid {
 public:
  double value(const glm::dvec3& p) const override {
    double ground = p.z - (1.0 + 0.3 * std::sin(p.x) * std::cos(p.y));
    double sides = std::max({-p.x, p.x - 4.0, -p.y, p.y - 4.0, -p.z});
    return std::max(ground, sides);
  }
  uint16_t material(const glm::dvec3& p) const override { return p.x + 0.37 * p.y > 2.2 ? 1 : 0; }
  WorldBox bounds() const override { return {{0, 0, 0}, {4, 4, 1.4}}; }
};

World build_terrain_for_tests(double h = 0.1) {
  TwoMaterialGround g;
  GridConfig grid;
  grid.cell_size = h;
  grid.chunk_size = 16;
  return build_from_implicit(g, grid).value();
}

// Vertices may leave their cell by one cell: where a box's edge or corner
// lies just across a cell border, its planes meet there (see cell_slack).
constexpr double kBoxSlack = 1.0;

TEST(DualContouring, AxisAlignedBoxKeepsFacesEdgesAndCorners) {
  BoxCase b{glm::translate(glm::dmat4(1.0), glm::dvec3(0.013, -0.021, 0.007)), {1.0, 0.7, 0.5}};
  expect_box_kept(b, {.cell_slack = kBoxSlack}, "iterative");
  expect_box_kept(b, {.placement = Placement::kQef, .cell_slack = kBoxSlack}, "qef");
}

// Placement alone: untangling moves the vertices around folds at the box's
// edges to their mass points, up to about 0.4 h inside (tests in
// test_manifold_contour.cpp).
TEST(DualContouring, RotatedBoxKeepsFacesEdgesAndCorners) {
  for (int i = 0; i < 3; ++i) {
    glm::dmat4 m = glm::rotate(glm::dmat4(1.0), 0.3 + 0.5 * i, glm::normalize(glm::dvec3(1.0, 2.0 - i, 0.5 + i)));
    BoxCase b{m, {1.0, 0.8, 0.6}};
    expect_box_kept(b, {.cell_slack = kBoxSlack, .untangle = false}, "iterative");
    expect_box_kept(b, {.placement = Placement::kQef, .cell_slack = kBoxSlack, .untangle = false}, "qef");
  }
}

TEST(DualContouring, WithoutSlackVerticesStayInTheirCellsAndNearTheSurface) {
  glm::dmat4 m = glm::rotate(glm::dmat4(1.0), 0.8, glm::normalize(glm::dvec3(1.0, 1.0, 1.5)));
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.half_extents = {1.0, 0.8, 0.6};
  p.transform = m;
  World w = build_from_primitive(p, {.cells = 40}).value();
  const double h = w.lattice().cell_size;
  ContourStats stats;
  ContourMesh mesh = contour_world(w, {}, nullptr, &stats).value();
  double worst = 0.0;
  for (const glm::dvec3& q : mesh.positions) {
    worst = std::max(worst, std::abs(box_distance(glm::dvec3(glm::inverse(m) * glm::dvec4(q, 1.0)), p.half_extents)));
  }
  EXPECT_GT(stats.clamped_vertices, 0u);
  EXPECT_LT(worst, 0.4 * h);  // measured 0.31 h: the cost of staying in the cell
  EXPECT_TRUE(mesh_quality(mesh).watertight());
}

TEST(DualContouring, SphereWithinOneHundredthOfACellOnAverage) {
  Primitive p;
  p.radius = 1.0;
  World w = build_from_primitive(p, {.cells = 64}).value();
  const double h = w.lattice().cell_size;
  for (Placement method : {Placement::kIterative, Placement::kQef, Placement::kMassPoint}) {
    ContourMesh m = contour_world(w, {.placement = method}).value();
    double sum = 0.0;
    for (const glm::dvec3& q : m.positions) sum += std::abs(glm::length(q) - 1.0);
    EXPECT_LT(sum / double(m.positions.size()), 0.01 * h) << placement_name(method);
    for (size_t i = 0; i < m.positions.size(); i += 97) {
      EXPECT_GT(glm::dot(glm::dvec3(m.normals[i]), glm::normalize(m.positions[i])), 0.99);
    }
  }
}

TEST(DualContouring, MassPointRoundsCornersThatThePlaneMethodsKeep) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.half_extents = glm::dvec3(1.0);
  p.transform = glm::rotate(glm::dmat4(1.0), 0.4, glm::normalize(glm::dvec3(1, 1, 0)));
  World w = build_from_primitive(p, {.cells = 32}).value();
  auto corner_error = [&](Placement method) {
    ContourMesh m = contour_world(w, {.placement = method}).value();
    glm::dvec3 corner = glm::dvec3(p.transform * glm::dvec4(1, 1, 1, 1));
    double nearest = 1e300;
    for (const glm::dvec3& q : m.positions) nearest = std::min(nearest, glm::length(q - corner));
    return nearest / w.lattice().cell_size;
  };
  EXPECT_GT(corner_error(Placement::kMassPoint), 0.1);
  EXPECT_LT(corner_error(Placement::kQef), 0.05);
  EXPECT_LT(corner_error(Placement::kIterative), 0.05);
}

TEST(DualContouring, QefRanksAreRecorded) {
  Primitive p;
  p.shape = Primitive::Shape::kBox;
  p.transform = glm::rotate(glm::dmat4(1.0), 0.3, glm::dvec3(0, 0, 1));
  World w = build_from_primitive(p, {.cells = 24}).value();
  ContourStats stats;
  ContourMesh m = contour_world(w, {.placement = Placement::kQef}, nullptr, &stats).value();
  EXPECT_EQ(stats.qef_rank[0] + stats.qef_rank[1] + stats.qef_rank[2] + stats.qef_rank[3], stats.cells);
  EXPECT_GT(stats.qef_rank[1], 0u);  // faces
  EXPECT_GT(stats.qef_rank[2], 0u);  // edges
  EXPECT_GT(stats.qef_rank[3], 0u);  // corners
}

// A slab thinner than a cell: what happens depends on whether a lattice node
// lies inside it. With one, the node layer is solid and comes out as a thin
// closed sheet; with none, the slab is lost (the LDC's implicit builder keeps
// no feature between nodes; the mesh builder keeps the crossings, but dual
// contouring ignores edges whose ends agree, counted as thin edges).
TEST(DualContouring, SlabThinnerThanACellIsKeptOnlyAroundANodeLayer) {
  GridConfig g;
  g.cell_size = 0.1;
  g.use_origin = true;
  g.origin = glm::dvec3(0.0);
  TriangleMesh around_node = test::box_mesh({-1, -1, 0.47}, {1, 1, 0.52});  // holds the node plane z = 0.5
  TriangleMesh between = test::box_mesh({-1, -1, 0.52}, {1, 1, 0.57});      // no node plane inside
  ContourStats s1, s2;
  ContourMesh kept = contour_world(build_from_mesh(around_node, g).value(), {}, nullptr, &s1).value();
  ContourMesh lost = contour_world(build_from_mesh(between, g).value(), {}, nullptr, &s2).value();
  EXPECT_GT(kept.triangle_count(), 0u);
  EXPECT_TRUE(mesh_quality(kept).watertight());
  EXPECT_EQ(lost.triangle_count(), 0u);
  EXPECT_GT(s2.thin_edges, 0u);
}

TEST(DualContouring, ClosedMeshesGiveClosedOutput) {
  for (const char* name : {"spot.obj", "fandisk.obj", "rocker-arm.obj", "stanford-bunny.obj"}) {
    World w = build_from_mesh(test::load_test_mesh(name), {.cells = 64}).value();
    ContourMesh m = contour_world(w).value();
    MeshQuality q = mesh_quality(m);
    EXPECT_EQ(q.boundary_edges, 0u) << name;
    // DC pairs every edge except on faces with four sign changes, where four
    // quads share an edge (the documented non-manifold case): counted, not hidden.
    EXPECT_EQ(q.unpaired_edges, 0u) << name;
    EXPECT_LE(q.nonmanifold_edges, q.triangles / 1000) << name;
    EXPECT_GT(q.volume, 0.0) << name;
    EXPECT_NEAR(q.volume, w.volume(0), 0.02 * w.volume(0)) << name;
  }
}

// Triangles as sorted position triples, each rotated to start at its smallest corner.
std::vector<std::array<std::tuple<double, double, double>, 3>> canonical(const ContourMesh& m) {
  std::vector<std::array<std::tuple<double, double, double>, 3>> out;
  for (const glm::uvec3& t : m.triangles) {
    std::array<std::tuple<double, double, double>, 3> c;
    for (int i = 0; i < 3; ++i) c[i] = {m.positions[t[i]].x, m.positions[t[i]].y, m.positions[t[i]].z};
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    out.push_back(c);
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(DualContouring, ChunkedEqualsOnePiece) {
  TriangleMesh mesh = test::load_test_mesh("rocker-arm.obj");
  for (int chunk : {8, 16, 32}) {
    World w = build_from_mesh(mesh, {.cells = 72, .chunk_size = chunk}).value();
    ContourConfig chunked, one_piece;
    one_piece.chunked = false;
    ContourMesh a = contour_world(w, chunked).value();
    ContourMesh b = contour_world(w, one_piece).value();
    EXPECT_EQ(a.vertex_count(), b.vertex_count()) << chunk;
    EXPECT_EQ(canonical(a), canonical(b)) << "chunk size " << chunk;
    EXPECT_EQ(mesh_quality(a).unused_vertices, 0u);
  }
}

TEST(DualContouring, ChunkedEqualsOnePieceWithMaterialsAndRelaxation) {
  World w = build_terrain_for_tests();
  ContourConfig chunked, one_piece;
  one_piece.chunked = false;
  ContourMesh a = contour_world(w, chunked).value();
  ContourMesh b = contour_world(w, one_piece).value();
  EXPECT_EQ(canonical(a), canonical(b));
}

TEST(DualContouring, EmptyAndSolidWorldsGiveNoTriangles) {
  World empty = World::create({.chunk_dims = {2, 2, 2}}).value();
  ContourStats stats;
  EXPECT_EQ(contour_world(empty, {}, nullptr, &stats).value().triangle_count(), 0u);
  EXPECT_EQ(stats.chunks_meshed, 0u);  // skipped without reading a ray
  // Every chunk solid: no crossing anywhere, so no surface (the box faces
  // are not a surface of the stored solid).
  World solid = World::create({.chunk_dims = {2, 2, 2}}).value();
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) solid.set_uniform_chunk(solid.chunk_origin() + glm::ivec3(x, y, z), true);
  ASSERT_EQ(solid.chunk_kind(solid.chunk_origin()), ChunkKind::kSolid);
  EXPECT_EQ(contour_world(solid).value().triangle_count(), 0u);
}

TEST(DualContouring, BadConfigsNameTheirField) {
  World w;
  Result<ContourMesh> m = contour_world(w, {.step = 3.0});
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("step"), std::string::npos);
  EXPECT_FALSE(contour_world(w, {.relax_iterations = -1}).ok());
}

// Total length of the mesh edges between triangles of different materials, and
// the summed turning angle along them: a staircase is long and turns a lot.
struct BorderShape {
  double length = 0.0;
  double turning = 0.0;
};

BorderShape material_border(const ContourMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<size_t>> edge_tris;
  for (size_t t = 0; t < m.triangles.size(); ++t)
    for (int e = 0; e < 3; ++e) {
      uint32_t a = m.triangles[t][e], b = m.triangles[t][(e + 1) % 3];
      edge_tris[{std::min(a, b), std::max(a, b)}].push_back(t);
    }
  BorderShape s;
  std::map<uint32_t, std::vector<uint32_t>> next;  // border graph
  for (const auto& [edge, tris] : edge_tris) {
    if (tris.size() != 2 || m.triangle_material[tris[0]] == m.triangle_material[tris[1]]) continue;
    s.length += glm::length(m.positions[edge.first] - m.positions[edge.second]);
    next[edge.first].push_back(edge.second);
    next[edge.second].push_back(edge.first);
  }
  for (const auto& [v, nbrs] : next) {
    if (nbrs.size() != 2) continue;
    glm::dvec3 a = m.positions[v] - m.positions[nbrs[0]], b = m.positions[nbrs[1]] - m.positions[v];
    s.turning += std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0));
  }
  return s;
}

TEST(MaterialRelaxation, ShortensAndSmoothsTheBorder) {
  World w = build_terrain_for_tests();
  ContourStats stats;
  // Without untangling, which would move a few border vertices off the ground.
  ContourMesh raw = contour_world(w, {.relax_iterations = 0, .untangle = false}).value();
  ContourMesh relaxed = contour_world(w, {.untangle = false}, nullptr, &stats).value();
  BorderShape before = material_border(raw), after = material_border(relaxed);
  EXPECT_GT(stats.relaxed_vertices, 0u);
  EXPECT_GT(before.length, 3.0);  // the border crosses the 4 m patch
  EXPECT_LT(after.length, 0.95 * before.length);
  EXPECT_LT(after.turning, 0.8 * before.turning);
  // Relaxed vertices stay on the ground (their planes) and in their cells.
  TwoMaterialGround g;
  for (const glm::dvec3& q : relaxed.positions) EXPECT_LT(std::abs(g.value(q)), 0.1 * w.lattice().cell_size);
}

TEST(MaterialRelaxation, QuadsCarryTheirEdgeMaterial) {
  World w = build_terrain_for_tests();
  ContourMesh m = contour_world(w).value();
  size_t ones = 0;
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    glm::dvec3 c = (m.positions[m.triangles[t].x] + m.positions[m.triangles[t].y] + m.positions[m.triangles[t].z]) / 3.0;
    if (m.triangle_material[t] == 1) ++ones;
    // Away from the border line the material is unambiguous.
    double side = c.x + 0.37 * c.y - 2.2;
    if (std::abs(side) > 0.3 && c.z > 0.5) {
      EXPECT_EQ(m.triangle_material[t], side > 0 ? 1 : 0);
    }
  }
  EXPECT_GT(ones, 0u);
  EXPECT_EQ(m.vertex_material.size(), m.positions.size());
}

TEST(ChunkedMesh, UpdateRemeshesOnlyAroundTheChangeAndMatchesAFreshBuild) {
  // Two worlds on one lattice: a sphere, and the same sphere with a bump. A
  // marker cube at the far corner gives both the same bounds.
  TriangleMesh a = test::sphere_mesh({0, 0, 0}, 1.0, 4);
  test::append_mesh(a, test::box_mesh({1.5, 1.5, 1.5}, {1.7, 1.7, 1.7}));
  TriangleMesh b = a;
  test::append_mesh(b, test::box_mesh({0.9, -0.1, -0.1}, {1.2, 0.1, 0.1}));
  GridConfig g{.cells = 96, .chunk_size = 16};
  World wa = build_from_mesh(a, g).value(), wb = build_from_mesh(b, g).value();
  ASSERT_EQ(wa.chunk_dims(), wb.chunk_dims());
  std::vector<glm::ivec3> changed;
  wa.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* d) {
    const Chunk* e = wb.chunk(ch);
    bool same = kind == wb.chunk_kind(ch) && (!d || (d->point_count() == e->point_count() &&
                std::equal(d->axis[0].all_points().begin(), d->axis[0].all_points().end(), e->axis[0].all_points().begin(),
                           [](auto& x, auto& y) { return x.depth == y.depth && x.normal == y.normal; })));
    if (!same) changed.push_back(ch);
  });
  ASSERT_FALSE(changed.empty());
  ChunkedMesh incremental, fresh;
  ASSERT_TRUE(incremental.build(wa).ok());
  ASSERT_TRUE(fresh.build(wb).ok());
  Result<MeshUpdate> remeshed = incremental.update(wb, changed);
  ASSERT_TRUE(remeshed.ok());
  EXPECT_LE(remeshed->chunks_remeshed, changed.size() * 27);
  size_t chunks = size_t(wa.chunk_dims().x) * wa.chunk_dims().y * wa.chunk_dims().z;
  EXPECT_LT(remeshed->chunks_remeshed, chunks);  // not everything
  EXPECT_EQ(canonical(incremental.assemble()), canonical(fresh.assemble()));
}

TEST(ChunkedMesh, ChunkMeshesRenderAloneWithoutCracks) {
  World w = build_from_mesh(test::load_test_mesh("spot.obj"), {.cells = 64, .chunk_size = 16}).value();
  ChunkedMesh cm;
  ASSERT_TRUE(cm.build(w).ok());
  ASSERT_GT(cm.chunks().size(), 4u);
  // Copies of neighbours' vertices sit exactly where their owners put them.
  std::map<std::tuple<int, int, int>, glm::dvec3> owned;
  for (const ChunkMesh& c : cm.chunks())
    for (size_t v = 0; v < c.own_vertices; ++v)
      owned[{c.vertex_cell[v].x, c.vertex_cell[v].y, c.vertex_cell[v].z}] = c.mesh.positions[v];
  size_t copies = 0;
  for (const ChunkMesh& c : cm.chunks())
    for (size_t v = c.own_vertices; v < c.mesh.positions.size(); ++v, ++copies) {
      auto it = owned.find({c.vertex_cell[v].x, c.vertex_cell[v].y, c.vertex_cell[v].z});
      ASSERT_NE(it, owned.end());
      EXPECT_EQ(it->second, c.mesh.positions[v]);
    }
  EXPECT_GT(copies, 0u);
  EXPECT_TRUE(mesh_quality(cm.assemble()).watertight());
}

TEST(ChunkedMesh, TrianglesAreOrderedForTheVertexCache) {
  World w = build_from_mesh(test::load_test_mesh("spot.obj"), {.cells = 96}).value();
  ChunkedMesh cm;
  ASSERT_TRUE(cm.build(w).ok());
  double misses = 0.0;
  size_t triangles = 0;
  for (const ChunkMesh& c : cm.chunks()) {
    std::vector<unsigned> idx;
    for (const glm::uvec3& t : c.mesh.triangles) idx.insert(idx.end(), {t.x, t.y, t.z});
    meshopt_VertexCacheStatistics s = meshopt_analyzeVertexCache(idx.data(), idx.size(), c.mesh.positions.size(), 16, 0, 0);
    misses += s.acmr * double(c.mesh.triangles.size());
    triangles += c.mesh.triangles.size();
  }
  EXPECT_LT(misses / double(triangles), 0.8);  // quad order gives 1.2 to 1.5
}

TEST(MarchingCubes, VerticesAreTheExactCrossings) {
  Primitive p;
  p.radius = 1.0;
  World w = build_from_primitive(p, {.cells = 48}).value();
  ContourMesh m = marching_cubes(w).value();
  ASSERT_GT(m.triangle_count(), 1000u);
  const double h = w.lattice().cell_size;
  for (const glm::dvec3& q : m.positions) EXPECT_NEAR(glm::length(q), 1.0, h / 1000.0);
  double area = mesh_quality(m).area;
  EXPECT_NEAR(area, 4.0 * M_PI, 0.02 * 4.0 * M_PI);
  EXPECT_GT(mesh_quality(m).volume, 0.0);  // oriented outward
}

// Every crossing is one vertex, whichever chunk's cube made it: no cracks at
// chunk seams, and the same mesh for any thread count.
void expect_welded_and_deterministic(const World& w, const char* name) {
  ContourMesh m = marching_cubes(w).value();
  ASSERT_GT(m.triangle_count(), 1000u) << name;
  const MeshQuality q = mesh_quality(m);
  EXPECT_EQ(q.boundary_edges, 0u) << name;
  EXPECT_TRUE(q.watertight()) << name << ": " << quality_failures(q);
  EXPECT_EQ(q.unused_vertices, 0u) << name;
  ContourMesh one;
  tbb::task_arena(1).execute([&] { one = marching_cubes(w).value(); });
  EXPECT_EQ(one.positions, m.positions) << name;
  EXPECT_EQ(one.triangles, m.triangles) << name;
  EXPECT_EQ(one.normals, m.normals) << name;
  EXPECT_EQ(one.triangle_material, m.triangle_material) << name;
}

TEST(MarchingCubes, SphereIsWeldedAcrossChunkSeams) {
  Primitive p;
  p.radius = 1.0;
  World w = build_from_primitive(p, {.cells = 48, .chunk_size = 8}).value();
  ASSERT_GT(w.chunk_dims().x, 4);
  expect_welded_and_deterministic(w, "sphere");
}

TEST(MarchingCubes, LandscapeIsWeldedAcrossChunkSeams) {
  TerrainConfig t;  // the default landscape, a 16 m x 16 m piece of it
  t.size_x = 16.0;
  t.size_y = 16.0;
  World w = build_terrain(t, 0.25, 16).value();
  expect_welded_and_deterministic(w, "landscape");
}

}  // namespace
}  // namespace ldc
