// Levels of detail (ldc/lod.h, issue 21): the world through every 2^k-th ray
// is a valid LDC whose nodes are the fine world's, and its mesh is closed
// with about 4^-k of the triangles.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/build.h"
#include "ldc/lod.h"
#include "ldc/store.h"
#include "ldc/terrain.h"
#include "test_util.h"

namespace ldc {
namespace {

World spot_world(int cells) {
  return build_from_mesh(test::load_test_mesh("spot.obj"), {.cells = cells, .chunk_size = 32}).value();
}

TEST(Lod, MaxLevelKeepsChunksOfAtLeastEightCells) {
  EXPECT_EQ(max_lod_level(8), 0);
  EXPECT_EQ(max_lod_level(16), 1);
  EXPECT_EQ(max_lod_level(32), 2);
  EXPECT_EQ(max_lod_level(64), 3);
}

TEST(Lod, LevelsTheChunkSizeDoesNotAllowAreRefused) {
  const World w = spot_world(32);
  for (int level : {-1, 3}) {
    Result<World> r = coarsen(w, level);
    ASSERT_FALSE(r.ok()) << level;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(r.status().message().find("level " + std::to_string(level) + " is outside 0 .. 2 for chunks of 32"),
              std::string::npos)
        << r.status().message();
  }
}

TEST(Lod, LevelZeroIsACopy) {
  const World w = spot_world(48);
  const World same = coarsen(w, 0).value();
  EXPECT_EQ(same.chunk_size(), w.chunk_size());
  EXPECT_EQ(same.lattice().cell_size, w.lattice().cell_size);
  EXPECT_EQ(same.stats().points, w.stats().points);
  EXPECT_EQ(same.stats().chunks_mixed, w.stats().chunks_mixed);
}

TEST(Lod, CoarseWorldIsValidAndEveryCoarseNodeKeepsItsState) {
  const World w = spot_world(64);
  for (int level : {1, 2}) {
    const int s = 1 << level;
    const World coarse = coarsen(w, level).value();
    EXPECT_EQ(coarse.chunk_size(), 32 / s);
    EXPECT_DOUBLE_EQ(coarse.lattice().cell_size, w.lattice().cell_size * s);
    EXPECT_EQ(coarse.lattice().origin, w.lattice().origin);
    EXPECT_EQ(coarse.chunk_dims(), w.chunk_dims());
    const ValidationReport v = validate(coarse);
    EXPECT_TRUE(v.ok) << v.summary();
    EXPECT_LT(coarse.stats().points, w.stats().points);
    size_t inside = 0, checked = 0;
    for (int z = coarse.node_min().z; z < coarse.node_end().z; ++z)
      for (int y = coarse.node_min().y; y < coarse.node_end().y; ++y)
        for (int x = coarse.node_min().x; x < coarse.node_end().x; ++x) {
          const glm::ivec3 n(x, y, z);
          ASSERT_EQ(coarse.inside_node(n), w.inside_node(n * s)) << "level " << level << " node " << x << "," << y
                                                                   << "," << z;
          inside += coarse.inside_node(n);
          ++checked;
        }
    EXPECT_GT(inside, 0u);
    EXPECT_LT(inside, checked);
  }
}

TEST(Lod, EachLevelMeshesClosedWithAQuarterOfTheTriangles) {
  const World w = spot_world(128);
  ContourMesh fine = contour_world(w).value();
  ASSERT_TRUE(untangle_mesh(fine).ok());
  const MeshQuality q0 = mesh_quality(fine);
  ASSERT_TRUE(q0.closed()) << quality_failures(q0);
  for (int level : {1, 2}) {
    ContourMesh m = contour_world(coarsen(w, level).value()).value();
    ASSERT_TRUE(untangle_mesh(m).ok());
    const MeshQuality q = mesh_quality(m);
    EXPECT_TRUE(q.closed()) << "level " << level << ": " << quality_failures(q);
    // About 4^-k of level 0's triangles (measured: 0.247 and 0.062).
    const double ratio = double(q.triangles) / double(q0.triangles), expected = 1.0 / double(1 << (2 * level));
    EXPECT_GT(ratio, 0.8 * expected) << "level " << level;
    EXPECT_LT(ratio, 1.2 * expected) << "level " << level;
    // The volume stays within 0.5% (level 1) and 2% (level 2) of level 0's.
    EXPECT_NEAR(q.volume, q0.volume, (level == 1 ? 0.005 : 0.02) * q0.volume) << "level " << level;
  }
}

// Chunk by chunk (the bake's way): every chunk mesh of a coarse landscape
// indexes its own vertices only.
TEST(Lod, EveryChunkMeshOfACoarseLandscapeIsWellFormed) {
  TerrainConfig t;
  t.size_x = t.size_y = 64.0;
  const World w = build_terrain(t, 0.5, 32).value();
  for (int level : {1, 2}) {
    const World coarse = coarsen(w, level).value();
    coarse.for_each_chunk([&](const glm::ivec3& c, ChunkKind, const Chunk*) {
      Result<ChunkMesh> m = contour_chunk(coarse, c);
      ASSERT_TRUE(m.ok()) << m.status().message();
      for (const glm::uvec3& tri : m.value().mesh.triangles)
        for (int j = 0; j < 3; ++j)
          ASSERT_LT(tri[j], m.value().mesh.positions.size()) << "level " << level << " chunk " << c.x << "," << c.y << "," << c.z;
    });
  }
}

// The bake's way: a window of a column and enough chunks around it (one,
// two where coarse chunks have 8 cells), paged from the procedural source,
// coarsened, then the column's chunks one by one. A chunk whose reach meets
// the window's faces (cut through the ground) is refused, naming the face:
// it crashed the mesher (an index past the vertices).
TEST(Lod, ChunkMeshesOfACoarseWindowAreWellFormedAndItsFacesAreRefused) {
  TerrainConfig t;
  t.size_x = t.size_y = 64.0;
  auto source = make_terrain_source(t, 0.5, 32).value();
  PagedWorld paged(source);
  const SourceLayout layout = paged.layout();
  const int z0 = layout.box.chunk_origin.z, z1 = z0 + layout.box.chunk_dims.z;
  for (int level : {0, 1, 2}) {
    const int margin = (32 >> level) >= 16 ? 1 : 2;
    for (const glm::ivec2 column : {glm::ivec2(1, 1), glm::ivec2(2, 0), glm::ivec2(3, 2)}) {
      const glm::ivec3 lo(column.x - margin, column.y - margin, z0), hi(column.x + margin + 1, column.y + margin + 1, z1);
      const World coarse = coarsen(paged.window(lo, hi).value(), level).value();
      for (int z = z0; z < z1; ++z) {
        Result<ChunkMesh> m = contour_chunk(coarse, glm::ivec3(column, z));
        ASSERT_TRUE(m.ok()) << "level " << level << ": " << m.status().message();
        for (const glm::uvec3& tri : m.value().mesh.triangles)
          for (int j = 0; j < 3; ++j) ASSERT_LT(tri[j], m.value().mesh.positions.size()) << "level " << level;
      }
    }
    // A window of chunks 1 and 2 along x and y: both faces cut the ground.
    const World cut = coarsen(paged.window(glm::ivec3(1, 1, z0), glm::ivec3(3, 3, z1)).value(), level).value();
    Result<ChunkMesh> face = contour_chunk(cut, glm::ivec3(1, 1, 0));
    ASSERT_FALSE(face.ok()) << "level " << level;
    EXPECT_EQ(face.status().code(), ErrorCode::kInvalidArgument);
    EXPECT_NE(face.status().message().find("inside at the world box face"), std::string::npos) << face.status().message();
  }
}
// --- The level by distance -------------------------------------------------

TEST(Lod, LevelFollowsDistanceWithHysteresis) {
  const LodBands bands{.start = {50.0, 100.0}, .hysteresis = 5.0};
  ASSERT_TRUE(check_lod_bands(bands).ok());
  EXPECT_EQ(lod_level(bands, 10.0, 0), 0);
  EXPECT_EQ(lod_level(bands, 54.0, 0), 0);   // inside the dead band: stays
  EXPECT_EQ(lod_level(bands, 55.0, 0), 1);
  EXPECT_EQ(lod_level(bands, 46.0, 1), 1);   // coming back: stays until 45
  EXPECT_EQ(lod_level(bands, 44.9, 1), 0);
  EXPECT_EQ(lod_level(bands, 300.0, 0), 2);  // several levels at once
  EXPECT_EQ(lod_level(bands, 0.0, 2), 0);
  EXPECT_EQ(lod_level(bands, 70.0, 7), 1);   // a level past the bands is clamped first
}

TEST(Lod, ACameraSwayingOnABandEdgeDoesNotFlipTheLevel) {
  const LodBands bands{.start = {50.0}, .hysteresis = 2.0};
  int level = lod_level(bands, 60.0, 0), flips = 0;
  for (int frame = 0; frame < 200; ++frame) {
    const int next = lod_level(bands, 50.0 + 1.5 * std::sin(0.3 * frame), level);  // +-1.5 m around the edge
    flips += next != level;
    level = next;
  }
  EXPECT_EQ(flips, 0);
  EXPECT_EQ(level, 1);
}

TEST(Lod, BadBandsAreRefusedByName) {
  EXPECT_NE(check_lod_bands({.start = {50.0, 40.0}}).message().find("start[1] = 40"), std::string::npos);
  EXPECT_NE(check_lod_bands({.start = {std::nan("")}}).message().find("start[0]"), std::string::npos);
  EXPECT_NE(check_lod_bands({.start = {50.0}, .hysteresis = -1.0}).message().find("hysteresis"), std::string::npos);
  EXPECT_NE(check_lod_bands({.start = {3.0}, .hysteresis = 2.0}).message().find("twice the hysteresis"),
            std::string::npos);
  EXPECT_EQ(lod_level({.start = {50.0, 40.0}}, 1000.0, 1), 1);  // bad bands change nothing
}

TEST(Lod, ChunkDistanceIsToTheNearestPointOfItsBox) {
  const Lattice lattice{.origin = {1.0, 2.0, 3.0}, .cell_size = 0.5};  // chunks of 8 cells: 4 m
  EXPECT_DOUBLE_EQ(chunk_distance(lattice, 8, {0, 0, 0}, {2.0, 3.0, 4.0}), 0.0);  // inside
  EXPECT_DOUBLE_EQ(chunk_distance(lattice, 8, {1, 0, 0}, {2.0, 3.0, 4.0}), 3.0);  // box x from 5 m
  EXPECT_DOUBLE_EQ(chunk_distance(lattice, 8, {0, 0, 0}, {8.0, 10.0, 4.0}), 5.0);  // (3, 4, 0) away
}

// --- Chunks at different levels (contour_levels) ---------------------------------

namespace levels_test {

ContourConfig plain_config() {
  ContourConfig c;
  c.relax_iterations = 0;  // contour_levels does not relax material borders
  c.untangle = false;
  return c;
}

std::vector<glm::dvec3> sorted_positions(const ContourMesh& m) {
  std::vector<glm::dvec3> p = m.positions;
  std::sort(p.begin(), p.end(), [](const glm::dvec3& a, const glm::dvec3& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  });
  return p;
}

// The largest distance from a vertex of `a` to the nearest vertex of `b`
// (searched among those within `tolerance` in x; infinity when none is).
double farthest_match(const ContourMesh& a, const ContourMesh& b, double tolerance) {
  const std::vector<glm::dvec3> sorted = sorted_positions(b);
  double worst = 0.0;
  for (const glm::dvec3& p : a.positions) {
    auto it = std::lower_bound(sorted.begin(), sorted.end(), p.x - tolerance,
                               [](const glm::dvec3& q, double x) { return q.x < x; });
    double best = std::numeric_limits<double>::infinity();
    for (; it != sorted.end() && it->x <= p.x + tolerance; ++it) best = std::min(best, glm::length(*it - p));
    worst = std::max(worst, best);
  }
  return worst;
}

// A level per chunk from a hash of its coordinates: every pairing of levels
// across faces, edges and corners somewhere.
int scrambled_level(const glm::ivec3& c, int levels, unsigned seed) {
  unsigned h = unsigned(c.x) * 73856093u ^ unsigned(c.y) * 19349663u ^ unsigned(c.z) * 83492791u ^ seed * 2654435761u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return int(h % unsigned(levels));
}

}  // namespace levels_test

// One level everywhere: the same mesh as contour_world on the coarse world
// (positions to rounding: the planes are summed in another order).
TEST(LodLevels, OneLevelEverywhereIsTheCoarseWorldsMesh) {
  const World w = spot_world(96);
  for (int level : {0, 1, 2}) {
    ContourStats stats;
    const ContourMesh mixed =
        contour_levels(w, [&](const glm::ivec3&) { return level; }, levels_test::plain_config(), nullptr, &stats).value();
    const ContourMesh uniform = contour_world(coarsen(w, level).value(), levels_test::plain_config()).value();
    ASSERT_EQ(mixed.vertex_count(), uniform.vertex_count()) << "level " << level;
    ASSERT_EQ(mixed.triangle_count(), uniform.triangle_count()) << "level " << level;
    EXPECT_LT(levels_test::farthest_match(mixed, uniform, 1e-9 * w.lattice().cell_size), 1e-9 * w.lattice().cell_size)
        << "level " << level;
    EXPECT_GT(stats.cells, 0u);
    EXPECT_LE(stats.cells, mixed.vertex_count());
    EXPECT_GT(stats.quads, 0u);
    EXPECT_NEAR(mesh_quality(mixed).volume, mesh_quality(uniform).volume, 1e-9 * mesh_quality(uniform).volume);
  }
}

// Levels 0, 1 and 2 scattered over the chunks: the seams close. Without
// untangling the mesh is a closed 2-manifold (no boundary, no non-manifold
// edge or vertex); with it, also free of self-intersections.
TEST(LodLevels, ScatteredLevelsMeshClosedAcrossEverySeam) {
  const World w = spot_world(160);
  for (unsigned seed : {1u, 2u, 3u}) {
    auto level_of = [&](const glm::ivec3& c) { return levels_test::scrambled_level(c, 3, seed); };
    const ContourMesh raw = contour_levels(w, level_of, levels_test::plain_config()).value();
    const MeshQuality q = mesh_quality(raw);
    EXPECT_TRUE(q.watertight()) << "seed " << seed << ": " << quality_failures(q);
    EXPECT_EQ(q.nonmanifold_edges, 0u) << "seed " << seed;
    EXPECT_EQ(q.nonmanifold_vertices, 0u) << "seed " << seed;
    ContourMesh m = contour_levels(w, level_of).value();  // defaults: untangled
    const MeshQuality qm = mesh_quality(m);
    EXPECT_TRUE(qm.closed()) << "seed " << seed << ": " << quality_failures(qm);
  }
}

// Two turned boxes' union (sharp CSG) at the levels surface_levels gives: a
// coarse line beside a finer chunk is cut into two crossing edges whose quads
// have the same two diagonal cells as opposite corners. Both quads were split
// along that diagonal, an edge of four triangles; now the mesh is a closed
// 2-manifold without untangling.
TEST(LodLevels, CoarseCellsMeetingAlongACutLineKeepAManifoldSeam) {
  const World w = mesh_boolean(test::load_test_mesh("turned_box_a.obj"), test::load_test_mesh("turned_box_b.obj"),
                               BooleanOp::kUnion, {.cells = 200})
                      .value();
  const ChunkLevels levels = surface_levels(w, {.tolerance = 0.02}).value();
  ASSERT_GT(levels.surface_chunks(0), 0u);  // a seam between levels exists
  ASSERT_GT(levels.surface_chunks(2), 0u);
  const ContourMesh raw = contour_levels(w, levels, levels_test::plain_config()).value();
  const MeshQuality q = mesh_quality(raw, {.known_self_intersecting_pairs = 0});
  EXPECT_EQ(q.nonmanifold_edges, 0u);
  EXPECT_EQ(q.nonmanifold_vertices, 0u);
  EXPECT_TRUE(q.watertight()) << quality_failures(q);
}

// A ring of levels by distance from a point, as a camera would choose them,
// on a landscape with caves and overhangs: closed, and between level 2's and
// level 0's triangle counts.
TEST(LodLevels, LevelsByDistanceOnALandscapeMeshClosed) {
  TerrainConfig t;
  t.size_x = t.size_y = 64.0;
  const World w = build_terrain(t, 0.25, 32).value();
  const LodBands bands{.start = {10.0, 24.0}, .hysteresis = 1.0};
  const glm::dvec3 camera(20.0, 24.0, 8.0);
  auto level_of = [&](const glm::ivec3& c) {
    return lod_level(bands, chunk_distance(w.lattice(), w.chunk_size(), c, camera), 0);
  };
  ContourStats stats;
  const ContourMesh m = contour_levels(w, level_of, {}, nullptr, &stats).value();
  const MeshQuality q = mesh_quality(m);
  EXPECT_TRUE(q.closed()) << quality_failures(q);
  const size_t fine = contour_world(w).value().triangle_count();
  const size_t coarse = contour_world(coarsen(w, 2).value()).value().triangle_count();
  EXPECT_LT(q.triangles, fine / 2);
  EXPECT_GT(q.triangles, coarse);
  EXPECT_GT(stats.chunks_meshed, 0u);
}


// Chunk by chunk (an engine's way): the chunk meshes together are the whole
// mesh, triangle for triangle with the same positions to the bit, so they
// draw with no crack; each chunk's own vertices are its cells'.
TEST(LodLevels, ChunkMeshesTogetherAreTheWholeMesh) {
  const World w = spot_world(160);
  auto level_of = [&](const glm::ivec3& c) { return levels_test::scrambled_level(c, 3, 7); };
  const ContourMesh whole = contour_levels(w, level_of, levels_test::plain_config()).value();
  std::vector<test::TrianglePositions> got;
  const std::vector<test::TrianglePositions> expected = test::sorted_triangle_positions(whole);
  size_t own = 0;
  for (int z = w.chunk_origin().z - 1; z < w.chunk_origin().z + w.chunk_dims().z; ++z)
    for (int y = w.chunk_origin().y - 1; y < w.chunk_origin().y + w.chunk_dims().y; ++y)
      for (int x = w.chunk_origin().x - 1; x < w.chunk_origin().x + w.chunk_dims().x; ++x) {
        Result<ChunkMesh> m = contour_chunk_levels(w, {x, y, z}, level_of, levels_test::plain_config());
        ASSERT_TRUE(m.ok()) << m.status().message();
        const ChunkMesh& cm = m.value();
        ASSERT_EQ(cm.vertex_cell.size(), cm.mesh.positions.size());
        for (size_t i = 0; i < cm.own_vertices; ++i)
          EXPECT_EQ(cm.vertex_cell[i] >> w.chunk_shift(), glm::ivec3(x, y, z)) << "chunk " << x << "," << y << "," << z;
        own += cm.own_vertices;
        const std::vector<test::TrianglePositions> part = test::sorted_triangle_positions(cm.mesh);
        got.insert(got.end(), part.begin(), part.end());
      }
  EXPECT_EQ(own, whole.vertex_count());
  std::sort(got.begin(), got.end(), test::triangle_positions_less);
  ASSERT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
}

// A chunk's mesh reads the levels and rays of its 26 neighbours only: other
// levels beyond them, or a dig two chunks away, leave it as it was.
TEST(LodLevels, AChunkMeshDependsOnlyOnItsNeighbours) {
  const World w = spot_world(160);
  auto base = [](const glm::ivec3& c) { return levels_test::scrambled_level(c, 3, 11); };
  const glm::ivec3 centre = w.chunk_origin() + w.chunk_dims() / 2;
  size_t meshed = 0;
  w.for_each_chunk([&](const glm::ivec3& chunk, ChunkKind, const Chunk*) {
    auto near_only = [&](const glm::ivec3& c) {
      const glm::ivec3 d = glm::abs(c - chunk);
      return std::max({d.x, d.y, d.z}) <= 1 ? base(c) : levels_test::scrambled_level(c, 3, 99);
    };
    const ChunkMesh a = contour_chunk_levels(w, chunk, base).value();
    const ChunkMesh b = contour_chunk_levels(w, chunk, near_only).value();
    EXPECT_EQ(a.mesh.positions, b.mesh.positions) << "chunk " << chunk.x << "," << chunk.y << "," << chunk.z;
    EXPECT_EQ(a.mesh.triangles, b.mesh.triangles) << "chunk " << chunk.x << "," << chunk.y << "," << chunk.z;
    meshed += a.mesh.triangle_count() > 0;
  });
  EXPECT_GT(meshed, 20u);
  // Empty every chunk two or more away from the centre chunk: its mesh stays.
  World cut = w;
  cut.for_each_chunk([&](const glm::ivec3& c, ChunkKind, const Chunk*) {
    const glm::ivec3 d = glm::abs(c - centre);
    if (std::max({d.x, d.y, d.z}) >= 2) cut.set_uniform_chunk(c, false);
  });
  const ChunkMesh whole = contour_chunk_levels(w, centre, base).value();
  const ChunkMesh alone = contour_chunk_levels(cut, centre, base).value();
  EXPECT_GT(whole.mesh.triangle_count(), 0u);
  EXPECT_EQ(whole.mesh.positions, alone.mesh.positions);
  EXPECT_EQ(whole.mesh.triangles, alone.mesh.triangles);
}

// --- LevelChunkedMesh: chunk meshes at levels, kept up to date -----------------------

namespace levels_test {


// Levels by distance from a point, as a camera would give them.
LevelChunkedMesh::LevelOf by_distance(const World& w, const glm::dvec3& from, double near, double far) {
  return [&w, from, near, far](const glm::ivec3& c) {
    return lod_level({.start = {near, far}, .hysteresis = 0.0}, chunk_distance(w.lattice(), w.chunk_size(), c, from), 0);
  };
}

}  // namespace levels_test

TEST(LevelChunkedMesh, ABuildAssemblesToContourLevelsMesh) {
  const World w = spot_world(160);
  auto level_of = [](const glm::ivec3& c) { return levels_test::scrambled_level(c, 3, 5); };
  LevelChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(w, level_of).ok());
  const ContourMesh assembled = meshes.assemble();
  const ContourMesh whole = contour_levels(w, level_of, levels_test::plain_config()).value();
  EXPECT_EQ(assembled.vertex_count(), whole.vertex_count());
  EXPECT_TRUE(test::sorted_triangle_positions(assembled) == test::sorted_triangle_positions(whole));
  EXPECT_TRUE(mesh_quality(assembled).watertight());
  EXPECT_GT(meshes.version(), 0u);
  for (const ChunkMesh* m : meshes.chunks()) EXPECT_EQ(m->version, meshes.version());
}

// The camera moves: the levels change, and the update re-meshes what they
// touch, giving what a fresh build at the new levels gives; chunks no level
// change reaches keep their meshes (and versions) and are not reported.
TEST(LevelChunkedMesh, AnUpdateAfterTheLevelsChangeEqualsAFreshBuild) {
  const World w = spot_world(160);
  const glm::dvec3 lo = w.box().min, hi = w.box().max;
  const double diag = glm::length(hi - lo);
  auto before = levels_test::by_distance(w, lo, diag / 3.0, 2.0 * diag / 3.0);
  auto after = levels_test::by_distance(w, lo + 0.15 * (hi - lo), diag / 3.0, 2.0 * diag / 3.0);
  LevelChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(w, before).ok());
  const uint64_t built = meshes.version();
  std::map<std::tuple<int, int, int>, uint64_t> versions;
  for (const ChunkMesh* m : meshes.chunks()) versions[{m->chunk.x, m->chunk.y, m->chunk.z}] = m->version;
  Result<MeshUpdate> u = meshes.update(w, {}, after);
  ASSERT_TRUE(u.ok()) << u.status().message();
  ASSERT_FALSE(u->changes.empty());
  EXPECT_GT(meshes.version(), built);
  LevelChunkedMesh fresh;
  ASSERT_TRUE(fresh.build(w, after).ok());
  EXPECT_TRUE(test::sorted_triangle_positions(meshes.assemble()) == test::sorted_triangle_positions(fresh.assemble()));
  size_t kept = 0;
  for (const ChunkMesh* m : meshes.chunks()) {
    const bool reported = std::any_of(u->changes.begin(), u->changes.end(),
                                      [&](const ChunkMeshChange& c) { return c.chunk == m->chunk; });
    if (reported) {
      EXPECT_EQ(m->version, meshes.version());
      const auto it = std::find_if(u->changes.begin(), u->changes.end(),
                                   [&](const ChunkMeshChange& c) { return c.chunk == m->chunk; });
      EXPECT_EQ(it->level, after(m->chunk));
    } else {
      EXPECT_EQ(m->version, (versions[{m->chunk.x, m->chunk.y, m->chunk.z}]));
      ++kept;
    }
    EXPECT_EQ(meshes.level(m->chunk), after(m->chunk));
  }
  EXPECT_GT(kept, 0u);
}

// A dig: the update with its dirty chunks gives what a fresh build of the
// dug world gives.
TEST(LevelChunkedMesh, AnUpdateAfterADigEqualsAFreshBuild) {
  World w = spot_world(160);
  auto level_of = [](const glm::ivec3& c) { return levels_test::scrambled_level(c, 3, 8); };
  LevelChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(w, level_of).ok());
  const WorldBox box = w.box();
  WorldEditor editor(std::move(w));
  ASSERT_TRUE(editor.apply(Brush::sphere(0.5 * (box.min + box.max), 0.12 * glm::length(box.max - box.min)),
                           EditOp::kSubtract)
                  .ok());
  std::vector<glm::ivec3> dirty;
  for (const DirtyChunk& d : editor.take_dirty()) dirty.push_back(d.chunk);
  ASSERT_FALSE(dirty.empty());
  Result<MeshUpdate> u = meshes.update(editor.world(), dirty, level_of);
  ASSERT_TRUE(u.ok()) << u.status().message();
  EXPECT_FALSE(u->changes.empty());
  LevelChunkedMesh fresh;
  ASSERT_TRUE(fresh.build(editor.world(), level_of).ok());
  EXPECT_TRUE(test::sorted_triangle_positions(meshes.assemble()) == test::sorted_triangle_positions(fresh.assemble()));
  EXPECT_TRUE(mesh_quality(meshes.assemble()).watertight());
}

TEST(LevelChunkedMesh, ABadLevelIsRefusedAndTheMeshesStay) {
  const World w = spot_world(96);
  LevelChunkedMesh meshes;
  ASSERT_TRUE(meshes.build(w, [](const glm::ivec3&) { return 1; }).ok());
  const size_t triangles = meshes.assemble().triangle_count();
  Result<MeshUpdate> u = meshes.update(w, {}, [](const glm::ivec3&) { return 7; });
  ASSERT_FALSE(u.ok());
  EXPECT_EQ(u.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(meshes.assemble().triangle_count(), triangles);
  EXPECT_EQ(meshes.level(w.chunk_origin()), 1);
}

TEST(LodLevels, AChunkOutsideTheMeshableBoxIsRefused) {
  const World w = spot_world(64);
  Result<ChunkMesh> r = contour_chunk_levels(w, w.chunk_origin() - 2, [](const glm::ivec3&) { return 0; });
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("outside the world's box"), std::string::npos) << r.status().message();
}

TEST(LodLevels, ALevelOutOfRangeIsRefusedNamingTheChunk) {
  const World w = spot_world(64);
  Result<ContourMesh> r = contour_levels(w, [](const glm::ivec3& c) { return c == glm::ivec3(1, 0, 0) ? 3 : 0; });
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("chunk (1, 0, 0) has level 3, outside 0 .. 2"), std::string::npos)
      << r.status().message();
  Result<ContourMesh> none = contour_levels(w, nullptr);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), ErrorCode::kInvalidArgument);
}

}  // namespace
}  // namespace ldc
