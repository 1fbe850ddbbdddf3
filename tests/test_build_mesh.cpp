// Building LDCs from triangle meshes: watertightness on degenerate input,
// winding-number unions, repair of open meshes, bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <tbb/global_control.h>

#include "ldc/build.h"
#include "meshio/meshio.h"
#include "test_util.h"

namespace ldc {
namespace {

using test::box_mesh;
using test::is_valid;
using test::sphere_mesh;

using test::lattice_at_origin;

// Number of points on every ray of every axis, summed.
size_t total_points(const World& w) { return w.stats().points; }

void expect_volumes(const World& w, double expected, double rel) {
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(w.volume(a), expected, rel * expected) << "axis " << a;
}

TEST(MeshBuild, CubeWithFacesOnLatticePlanes) {
  World w = build_from_mesh(box_mesh({0, 0, 0}, {1, 1, 1}), lattice_at_origin(0.125)).value();
  EXPECT_TRUE(is_valid(w));
  expect_volumes(w, 1.0, 1e-3);
  // Every ray through the cube's lattice footprint crosses it exactly twice.
  for (int a = 0; a < 3; ++a) {
    for (int u = 0; u < 8; ++u) {
      for (int v = 0; v < 8; ++v) {
        auto spans = w.ray_spans(a, {u, v});
        ASSERT_EQ(spans.size(), 1u) << "axis " << a << " ray " << u << "," << v;
        EXPECT_NEAR(spans[0].enter.depth, 0.0, 1e-3);
        EXPECT_NEAR(spans[0].exit.depth, 8.0, 1e-3);
      }
    }
  }
  // Nodes exactly on the faces follow the symbolic perturbation: consistent, not guessed.
  EXPECT_TRUE(w.inside_node({4, 4, 4}));
  EXPECT_FALSE(w.inside_node({9, 4, 4}));
}

TEST(MeshBuild, RaysThroughVerticesAndAlongEdges) {
  // An octahedron with every vertex on a lattice node: rays pass exactly
  // through its vertices and through its edges.
  TriangleMesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const unsigned f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                            {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& t : f) m.triangles.push_back({t[0], t[1], t[2]});
  GridConfig g = lattice_at_origin(0.25);
  g.origin = glm::dvec3(-2.0);  // lattice coordinate = (world + 2) * 4
  World w = build_from_mesh(m, g).value();
  EXPECT_TRUE(is_valid(w));
  // Through two vertices: x from -1 to 1 at y = z = 0.
  for (int a = 0; a < 3; ++a) {
    auto spans = w.ray_spans(a, {8, 8});
    ASSERT_EQ(spans.size(), 1u) << "axis " << a;
    EXPECT_NEAR(spans[0].enter.depth, 4.0, 1e-3);
    EXPECT_NEAR(spans[0].exit.depth, 12.0, 1e-3);
  }
  // Through two edges: at y = 0.5, z = 0 the ray meets the edges at x = -0.5 and 0.5.
  auto spans = w.ray_spans(0, {10, 8});
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_NEAR(spans[0].enter.depth, 6.0, 1e-3);
  EXPECT_NEAR(spans[0].exit.depth, 10.0, 1e-3);
  // Column sums at 8 cells across are coarse: within 4% of 4/3.
  expect_volumes(w, 4.0 / 3.0, 0.04);
}

TEST(MeshBuild, GridOfUnitCubesSharingFacesIsOneSolid) {
  TriangleMesh m;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      for (int z = 0; z < 3; ++z) test::append_mesh(m, box_mesh({x, y, z}, {x + 1, y + 1, z + 1}));
  for (double h : {0.25, 0.3}) {  // faces on lattice planes, and off them
    GridConfig g = lattice_at_origin(h);
    World w = build_from_mesh(m, g).value();
    EXPECT_TRUE(is_valid(w));
    expect_volumes(w, 27.0, 0.04);
    // No internal surfaces: a ray through the middle crosses the block once.
    auto spans = w.ray_spans(0, {int(1.5 / h), int(1.5 / h)});
    EXPECT_EQ(spans.size(), 1u) << "h " << h;
  }
}

TEST(MeshBuild, DuplicatedTrianglesChangeNothing) {
  TriangleMesh once = sphere_mesh({0.1, 0.2, 0.3}, 1.0, 3);
  TriangleMesh twice = once;
  test::append_mesh(twice, once);
  World a = build_from_mesh(once, {.cells = 48}).value();
  World b = build_from_mesh(twice, {.cells = 48}).value();
  EXPECT_TRUE(is_valid(b));
  EXPECT_EQ(total_points(a), total_points(b));
  for (int ax = 0; ax < 3; ++ax) EXPECT_DOUBLE_EQ(a.volume(ax), b.volume(ax));
}

TEST(MeshBuild, CoplanarTrianglesOfTouchingBoxesLeaveNoSliver) {
  TriangleMesh m = box_mesh({0, 0, 0}, {1, 1, 1});
  test::append_mesh(m, box_mesh({1, 0, 0}, {2, 1, 1}));  // shares the face x = 1
  test::append_mesh(m, box_mesh({0.25, 0.25, 1}, {0.75, 0.75, 1.5}));  // sits on top, coplanar
  World w = build_from_mesh(m, lattice_at_origin(0.125)).value();
  EXPECT_TRUE(is_valid(w));
  expect_volumes(w, 2.0 + 0.125, 0.01);
  EXPECT_EQ(w.ray_spans(0, {4, 4}).size(), 1u);  // through both boxes: one span
}

TEST(MeshBuild, OverlappingPartsUnion) {
  TriangleMesh m = box_mesh({0, 0, 0}, {2, 2, 2});
  test::append_mesh(m, box_mesh({1, 1, 1}, {3, 3, 3}));
  World w = build_from_mesh(m, {.cells = 60}).value();
  EXPECT_TRUE(is_valid(w));
  expect_volumes(w, 8.0 + 8.0 - 1.0, 0.03);
}

TEST(MeshBuild, NestedShellsMakeAHollowBall) {
  TriangleMesh outer = sphere_mesh({0, 0, 0}, 1.0, 4);
  TriangleMesh inner = sphere_mesh({0, 0, 0}, 0.5, 4);
  for (auto& t : inner.triangles) std::swap(t[1], t[2]);  // inward-facing
  test::append_mesh(outer, inner);
  World w = build_from_mesh(outer, {.cells = 80}).value();
  EXPECT_TRUE(is_valid(w));
  EXPECT_FALSE(w.inside({0, 0, 0}));
  EXPECT_TRUE(w.inside({0.75, 0, 0}));
  const double shell = 4.0 / 3.0 * M_PI * (1.0 - 0.125);
  expect_volumes(w, shell, 0.02);
}

TEST(MeshBuild, InsideOutMeshIsStillSolidWithOutwardNormals) {
  TriangleMesh m = sphere_mesh({0, 0, 0}, 1.0, 3);
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  BuildReport r;
  World w = build_from_mesh(m, {.cells = 40}, nullptr, &r).value();
  EXPECT_TRUE(is_valid(w));  // validate() checks normals point out of the solid
  EXPECT_TRUE(w.inside({0, 0, 0}));
  EXPECT_GT(r.normal_flips, 0u);
}

TEST(MeshBuild, ZeroAreaTrianglesAreSkippedAndCounted) {
  TriangleMesh m = box_mesh({0, 0, 0}, {1, 1, 1});
  m.positions.push_back({0.5, 0.5, 0.5});
  m.positions.push_back({0.6, 0.6, 0.6});
  m.positions.push_back({0.7, 0.7, 0.7});  // collinear
  m.triangles.push_back({8, 9, 10});
  m.triangles.push_back({8, 8, 9});  // repeated vertex
  BuildReport r;
  World w = build_from_mesh(m, {.cells = 16}, nullptr, &r).value();
  EXPECT_TRUE(is_valid(w));
  EXPECT_EQ(r.degenerate_triangles, 2u);
}

TEST(MeshBuild, HugeOffsetAndTinyScaleGiveTheSameShape) {
  TriangleMesh base = test::load_test_mesh("spot.obj");
  TriangleMesh far = base, tiny = base;
  for (auto& p : far.positions) p += glm::dvec3(1e5, -1e5, 1e5);
  for (auto& p : tiny.positions) p *= 1e-3;
  World a = build_from_mesh(base, {.cells = 64}).value();
  World b = build_from_mesh(far, {.cells = 64}).value();
  World c = build_from_mesh(tiny, {.cells = 64}).value();
  EXPECT_TRUE(is_valid(b));
  EXPECT_TRUE(is_valid(c));
  double va = a.volume(0);
  EXPECT_NEAR(b.volume(0), va, 1e-3 * va);
  EXPECT_NEAR(c.volume(0), va * 1e-9, 1e-3 * va * 1e-9);
}

TEST(MeshBuild, EverySharedMeshGivesAValidWorld) {
  for (const char* name : {"stanford-bunny.obj", "fandisk.obj", "rocker-arm.obj", "spot.obj",
                           "teapot.obj", "suzanne.obj", "nav_test.obj"}) {
    TriangleMesh m = test::load_test_mesh(name);
    for (int cells : {32, 64, 96}) {
      BuildReport r;
      Result<World> w = build_from_mesh(m, {.cells = cells, .chunk_size = cells == 96 ? 16 : 32}, nullptr, &r);
      ASSERT_TRUE(w.ok()) << name << ": " << w.status().to_string();
      EXPECT_TRUE(is_valid(w.value())) << name << " at " << cells;
    }
  }
}

TEST(MeshBuild, ClosedMeshesVolumeWithinHalfAPercentAt256Cells) {
  for (const char* name : {"spot.obj", "fandisk.obj", "rocker-arm.obj"}) {
    TriangleMesh m = test::load_test_mesh(name);
    World w = build_from_mesh(m, {.cells = 256}).value();
    const double v = mesh_signed_volume(m);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(w.volume(a), v, 0.005 * v) << name << " axis " << a;
    // Each axis samples flat faces parallel to it at different lattice lines,
    // so they differ by up to the sum of their errors.
    EXPECT_NEAR(w.volume(0), w.volume(1), 0.01 * v) << name;
    EXPECT_NEAR(w.volume(0), w.volume(2), 0.01 * v) << name;
  }
}

TEST(MeshBuild, OpenMeshesAreRepairedAndCounted) {
  for (const char* name : {"stanford-bunny.obj", "teapot.obj", "suzanne.obj"}) {
    BuildReport r;
    World w = build_from_mesh(test::load_test_mesh(name), {.cells = 64}, nullptr, &r).value();
    EXPECT_FALSE(r.input_closed) << name;
    EXPECT_GT(r.boundary_edges, 0u) << name;
    EXPECT_GT(r.repaired_rays, 0u) << name;
    EXPECT_TRUE(is_valid(w)) << name;
    EXPECT_EQ(w.metadata_value("build.repaired_rays"), std::to_string(r.repaired_rays));
  }
}

TEST(MeshBuild, AnOpenSheetHasNoVolume) {
  TriangleMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1}, {0, 1, 0.1}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  World w = build_from_mesh(m, {.cells = 32}).value();
  EXPECT_TRUE(is_valid(w));
  EXPECT_LT(w.volume(2), 1e-3);
}

TEST(MeshBuild, MaterialsFollowTheirTriangles) {
  TriangleMesh m = box_mesh({0, 0, 0}, {1, 1, 1});
  m.triangle_material.assign(m.triangles.size(), 0);
  m.triangle_material[2] = m.triangle_material[3] = 7;  // the +x face
  World w = build_from_mesh(m, lattice_at_origin(0.125)).value();
  auto pts = w.ray_points(0, {4, 4});
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[0].material, 0);
  EXPECT_EQ(pts[1].material, 7);
  EXPECT_GT(pts[1].normal.x, 0.99f);
  EXPECT_LT(pts[0].normal.x, -0.99f);
}

// OBJ usemtl names become world metadata material.<id> = name (as the
// landscape's), in both readings, so tools can name materials.
TEST(MeshBuild, MaterialNamesAreRecordedAsMetadata) {
  const char* obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "usemtl stone\nf 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
      "usemtl moss\nf 5 6 7 8\n";
  const TriangleMesh m = parse_obj(obj, "cube.obj").value();
  ASSERT_EQ(m.material_names, (std::vector<std::string>{"stone", "moss"}));
  for (BuildMode mode : {BuildMode::kSolid, BuildMode::kAuto}) {
    BuildConfig config;
    config.mode = mode;
    const World w = build_from_mesh(m, lattice_at_origin(0.125), config).value();
    EXPECT_EQ(w.metadata_value("material.0"), "stone") << build_mode_name(mode);
    EXPECT_EQ(w.metadata_value("material.1"), "moss") << build_mode_name(mode);
    EXPECT_EQ(w.metadata_value("material.2"), "") << build_mode_name(mode);
    // The top face (+z) carries moss's id.
    const auto pts = w.ray_points(2, {4, 4});
    ASSERT_EQ(pts.size(), 2u) << build_mode_name(mode);
    EXPECT_EQ(pts[1].material, 1) << build_mode_name(mode);
  }
  // A mesh without names records none.
  const World plain = build_from_mesh(box_mesh({0, 0, 0}, {1, 1, 1}), lattice_at_origin(0.125)).value();
  for (const auto& [key, value] : plain.metadata()) EXPECT_NE(key.rfind("material.", 0), 0u) << key;
}

TEST(MeshBuild, BadInputIsRefusedWithAMessageAndNoWorld) {
  TriangleMesh nan_mesh = box_mesh({0, 0, 0}, {1, 1, 1});
  nan_mesh.positions[3].y = std::numeric_limits<double>::quiet_NaN();
  Result<World> w = build_from_mesh(nan_mesh, {});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("3"), std::string::npos) << w.status().message();

  TriangleMesh bad_index = box_mesh({0, 0, 0}, {1, 1, 1});
  bad_index.triangles[5][1] = 99;
  EXPECT_FALSE(build_from_mesh(bad_index, {}).ok());

  EXPECT_FALSE(build_from_mesh(TriangleMesh{}, {}).ok());

  Result<World> huge = build_from_mesh(box_mesh({0, 0, 0}, {1, 1, 1}), {.cells = 65536});
  ASSERT_FALSE(huge.ok());
  EXPECT_EQ(huge.status().code(), ErrorCode::kTooLarge);
  EXPECT_NE(huge.status().message().find("fewer cells"), std::string::npos);

  Result<World> zero = build_from_mesh(box_mesh({0, 0, 0}, {1, 1, 1}), {.cells = 0});
  ASSERT_FALSE(zero.ok());
  EXPECT_NE(zero.status().message().find("cells = 0"), std::string::npos);
}

// Issue 24, item 4: a lattice whose cells are a few ulp wide made 94% of a
// remeshed cube's triangles degenerate (at 1e15 doubles are 0.125 apart).
TEST(MeshBuild, CellsBelowTheSpacingOfDoublesFarFromTheOriginAreRefused) {
  const glm::dvec3 far(1e15, 0.0, 0.0);
  Result<World> w = build_from_mesh(box_mesh(far, far + glm::dvec3(1.0)), {.cell_size = 0.031});
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(w.status().message().find("mesh: cell size 0.031 m is below the limit of 125 m for coordinates up to 1e+15 m"),
            std::string::npos)
      << w.status().message();
  // A cell of 1000 ulp there is fine.
  EXPECT_TRUE(build_from_mesh(box_mesh(far, far + glm::dvec3(1000.0)), {.cell_size = 125.0}).ok());
}

TEST(MeshBuild, ALatticeReachingPastTheCoordinateLimitIsRefused) {
  Result<World> w = build_from_mesh(box_mesh(glm::dvec3(-1e150), glm::dvec3(1e150)), {});
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.status().message().find("past the limit of 1e+100 m"), std::string::npos) << w.status().message();
}

// Issue 24, item 4: one unused vertex far away failed the build, naming a
// 0-based index no face uses. Unused positions neither size nor fail it.
TEST(MeshBuild, AnUnusedFarVertexNeitherSizesNorFailsTheBuild) {
  const TriangleMesh cube = box_mesh({0, 0, 0}, {1, 1, 1});
  TriangleMesh stray = cube;
  stray.positions.push_back(glm::dvec3(1e12, -1e12, 1e12));
  Result<World> w = build_from_mesh(stray, {.cells = 16});
  ASSERT_TRUE(w.ok()) << w.status().message();
  const World plain = build_from_mesh(cube, {.cells = 16}).value();
  EXPECT_EQ(w.value().lattice().cell_size, plain.lattice().cell_size);
  EXPECT_EQ(w.value().lattice().origin, plain.lattice().origin);
  EXPECT_EQ(w.value().stats().points, plain.stats().points);
  EXPECT_TRUE(is_valid(w.value()));
}

TEST(MeshBuild, CancelledBuildReturnsCancelled) {
  Context ctx;
  ctx.cancel();
  Result<World> w = build_from_mesh(sphere_mesh({0, 0, 0}, 1.0, 3), {.cells = 64}, &ctx);
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.status().code(), ErrorCode::kCancelled);
}

TEST(MeshBuild, SameInputSameWorldWhateverTheThreadCount) {
  TriangleMesh m = test::load_test_mesh("stanford-bunny.obj");
  World a = build_from_mesh(m, {.cells = 96}).value();
  World b = [&] {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    return build_from_mesh(m, {.cells = 96}).value();
  }();
  ASSERT_EQ(a.stats().points, b.stats().points);
  bool same = true;
  a.for_each_chunk([&](const glm::ivec3& ch, ChunkKind kind, const Chunk* d) {
    if (kind != b.chunk_kind(ch)) same = false;
    if (!d) return;
    const Chunk* e = b.chunk(ch);
    for (int ax = 0; ax < 3; ++ax) {
      auto pa = d->axis[ax].all_points(), pb = e->axis[ax].all_points();
      if (pa.size() != pb.size() || !std::equal(pa.begin(), pa.end(), pb.begin(), [](auto& x, auto& y) {
            return x.depth == y.depth && x.normal == y.normal && x.material == y.material;
          })) {
        same = false;
      }
    }
  });
  EXPECT_TRUE(same);
}

}  // namespace
}  // namespace ldc
