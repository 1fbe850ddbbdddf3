// LiveWorld: one owner of the world and everything kept up to date from it.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <tuple>

#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

#include "ldc/build.h"
#include "ldc/terrain.h"
#include "live/live.h"
#include "test_util.h"

namespace ldc {
namespace {

// A 16 x 16 m landscape at h = 0.25 m with chunks of 16 cells: small enough
// for a fast test, with several chunks per axis.
World small_landscape() {
  TerrainConfig t;
  t.size_x = 16.0;
  t.size_y = 16.0;
  t.arches = 0;
  return build_terrain(t, 0.25, 16).value();
}

// The ground height under (x, y): a ray straight down.
double ground_z(const Queries& q, double x, double y) {
  Result<RayHit> hit = q.ray_cast({{x, y, 40.0}, {0.0, 0.0, -1.0}});
  EXPECT_TRUE(hit.ok() && hit->hit) << "no ground under " << x << ", " << y;
  return hit.ok() && hit->hit ? hit->point.z : -1.0;
}

using Key = std::tuple<int, int, int>;
Key key(const glm::ivec3& c) { return {c.z, c.y, c.x}; }

// Chunk meshes as a map, by chunk.
std::map<Key, const ChunkMesh*> by_chunk(const ChunkedMesh& m) {
  std::map<Key, const ChunkMesh*> out;
  for (const ChunkMesh& c : m.chunks()) out[key(c.chunk)] = &c;
  return out;
}

::testing::AssertionResult meshes_equal_fresh_build(const LiveWorld& live) {
  ChunkedMesh fresh(live.config().contour);
  if (!fresh.build(live.world()).ok()) return ::testing::AssertionFailure() << "fresh build failed";
  return test::same_chunk_meshes(*live.meshes(), fresh);
}

TEST(LiveWorld, UpdateReportsTheChunkMeshesAnEditChangedAndMatchesAFreshBuild) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape(), {.meshes = true});
  ASSERT_TRUE(live.ok()) << live.status().message();
  const double z = ground_z(live->queries(), 8.0, 8.0);
  std::map<Key, uint64_t> uploaded;  // what an engine holds: chunk -> version
  for (const ChunkMesh& m : live->meshes()->chunks()) uploaded[key(m.chunk)] = m.version;

  ASSERT_TRUE(live->apply(Brush::sphere({8.0, 8.0, z}, 1.5), EditOp::kSubtract).ok());
  ASSERT_TRUE(live->apply(Brush::box({4.0, 4.0, z + 0.5}, glm::dvec3(0.6), kMaterialDirt), EditOp::kUnion).ok());
  Result<LiveUpdate> u = live->update();
  ASSERT_TRUE(u.ok()) << u.status().message();
  EXPECT_GT(u->dirty_chunks, 0u);
  EXPECT_FALSE(u->meshes.empty());
  EXPECT_TRUE(std::is_sorted(u->meshes.begin(), u->meshes.end(),
                             [](const auto& a, const auto& b) { return chunk_order_less(a.chunk, b.chunk); }));
  // Re-uploading exactly the reported chunks gives the engine the current meshes.
  for (const ChunkMeshChange& c : u->meshes) {
    if (c.removed()) uploaded.erase(key(c.chunk));
    else uploaded[key(c.chunk)] = c.version;
  }
  const auto now = by_chunk(*live->meshes());
  ASSERT_EQ(uploaded.size(), now.size());
  for (const auto& [k, m] : now) EXPECT_EQ(uploaded[k], m->version);
  EXPECT_TRUE(meshes_equal_fresh_build(*live));
  // Nothing new: nothing reported.
  Result<LiveUpdate> idle = live->update();
  ASSERT_TRUE(idle.ok());
  EXPECT_TRUE(idle->meshes.empty());
  EXPECT_EQ(idle->dirty_chunks, 0u);
}

// Re-meshes keep a mesher per thread between updates (contour/mesh_patch.cpp);
// it must not carry anything from one world or config to the next: a
// landscape of several materials (relaxed, no untangle) and a sphere of one
// material (untangled, relaxation off) edited in turn each match a fresh build.
TEST(LiveWorld, MeshesOfTwoWorldsEditedInTurnMatchFreshBuilds) {
  Result<LiveWorld> land = LiveWorld::create(small_landscape(), {.meshes = true});
  World sphere_world = build_from_mesh(test::sphere_mesh({0, 0, 0}, 1.0, 4), {.cells = 64, .chunk_size = 16}).value();
  LiveConfig sphere_config{.meshes = true, .contour = {.relax_iterations = 0, .untangle = true}};
  Result<LiveWorld> sphere = LiveWorld::create(std::move(sphere_world), sphere_config);
  ASSERT_TRUE(land.ok() && sphere.ok());
  for (int round = 0; round < 2; ++round) {
    const double x = 5.0 + 4.0 * round, z = ground_z(land->queries(), x, 8.0);
    ASSERT_TRUE(land->apply(Brush::sphere({x, 8.0, z}, 1.2), EditOp::kSubtract).ok());
    ASSERT_TRUE(land->update().ok());
    EXPECT_TRUE(meshes_equal_fresh_build(*land)) << "landscape, round " << round;
    ASSERT_TRUE(sphere->apply(Brush::sphere({0.0, 0.0, round ? -1.0 : 1.0}, 0.25), EditOp::kSubtract).ok());
    ASSERT_TRUE(sphere->update().ok());
    EXPECT_TRUE(meshes_equal_fresh_build(*sphere)) << "sphere, round " << round;
  }
}

TEST(LiveWorld, UndoIsFannedOutLikeAnEdit) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape(), {.meshes = true});
  ASSERT_TRUE(live.ok());
  const double z = ground_z(live->queries(), 6.0, 9.0);
  Result<EditReceipt> r = live->apply(Brush::sphere({6.0, 9.0, z}, 1.2), EditOp::kSubtract);
  ASSERT_TRUE(r.ok());
  ASSERT_TRUE(live->update().ok());
  EXPECT_LT(ground_z(live->queries(), 6.0, 9.0), z - 1.0);
  ASSERT_TRUE(live->undo(r.value()).ok());
  Result<LiveUpdate> u = live->update();
  ASSERT_TRUE(u.ok());
  EXPECT_FALSE(u->meshes.empty());
  EXPECT_NEAR(ground_z(live->queries(), 6.0, 9.0), z, 1e-9);
  EXPECT_TRUE(meshes_equal_fresh_build(*live));
  EXPECT_TRUE(test::is_valid(live->world()));
}

TEST(LiveWorld, NavMeshFollowsEditsAsAFreshBuildWould) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape(), {.nav = true});
  ASSERT_TRUE(live.ok()) << live.status().message();
  const double z = ground_z(live->queries(), 8.0, 8.0);
  // A wall of digs across the middle.
  for (double y = 0.5; y < 16.0; y += 1.0) {
    ASSERT_TRUE(live->apply(Brush::sphere({8.0, y, z}, 1.0), EditOp::kSubtract).ok());
  }
  Result<NavQuery*> q = live->path_query();
  ASSERT_TRUE(q.ok()) << q.status().message();
  const glm::dvec3 from{4.0, 8.0, ground_z(live->queries(), 4.0, 8.0)};
  const glm::dvec3 to{12.0, 8.0, ground_z(live->queries(), 12.0, 8.0)};
  Result<NavPath> incremental = (*q)->find_path(from, to);
  Result<NavMesh> fresh = NavMesh::build(live->world(), {});
  ASSERT_TRUE(fresh.ok());
  NavQuery fresh_query(fresh.value());
  Result<NavPath> expected = fresh_query.find_path(from, to);
  ASSERT_EQ(incremental.ok(), expected.ok());
  if (expected.ok()) {
    EXPECT_EQ(incremental->status, expected->status);
    EXPECT_NEAR(incremental->length, expected->length, 1e-9);
  }
}

TEST(LiveWorld, PathQueryWithoutNavIsRefusedByName) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape());
  ASSERT_TRUE(live.ok());
  Result<NavQuery*> q = live->path_query();
  ASSERT_FALSE(q.ok());
  EXPECT_NE(q.status().message().find("navigation is off"), std::string::npos);
}

TEST(LiveWorld, CascadesAreInvalidatedByEveryEdit) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape());
  ASSERT_TRUE(live.ok());
  const CascadeConfig config{.levels = 2, .resolution = 16, .voxel_size = 0.25};
  Result<CascadesId> id = live->add_cascades(config);
  ASSERT_TRUE(id.ok()) << id.status().message();
  const glm::dvec3 camera{8.0, 8.0, 6.0};
  ASSERT_TRUE(live->cascades(*id)->update_all(live->world(), camera).ok());
  const double z = ground_z(live->queries(), 8.0, 8.0);
  ASSERT_TRUE(live->apply(Brush::sphere({8.0, 8.0, z}, 1.5), EditOp::kSubtract).ok());
  ASSERT_TRUE(live->cascades(*id)->refresh(live->world()).ok());
  Result<Cascades> fresh = Cascades::create(live->world().lattice(), config);
  ASSERT_TRUE(fresh.ok());
  ASSERT_TRUE(fresh->update_all(live->world(), camera).ok());
  for (int level = 0; level < 2; ++level) {
    EXPECT_EQ(live->cascades(*id)->level_occupancy(level), fresh->level_occupancy(level)) << "level " << level;
  }
  std::unique_ptr<Cascades> released = live->release_cascades(*id);
  EXPECT_NE(released, nullptr);
  EXPECT_EQ(live->cascades(*id), nullptr);
  EXPECT_EQ(live->release_cascades(*id), nullptr);
}

TEST(LiveWorld, TakeChangesMergesEditsPerChunkAndFlagsMeshNeighbours) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape());
  ASSERT_TRUE(live.ok());
  const double z = ground_z(live->queries(), 8.0, 8.0);
  ASSERT_TRUE(live->apply(Brush::sphere({7.9, 8.0, z}, 0.5), EditOp::kSubtract).ok());
  Result<EditReceipt> second = live->apply(Brush::sphere({8.3, 8.0, z}, 0.5), EditOp::kSubtract);
  ASSERT_TRUE(second.ok());
  EXPECT_EQ(live->pending_changes(), live->pending_changes());
  const size_t pending = live->pending_changes();
  const std::vector<ChunkChange> changes = live->take_changes();
  EXPECT_EQ(changes.size(), pending);
  EXPECT_EQ(live->pending_changes(), 0u);
  size_t data = 0;
  std::set<Key> seen;
  for (const ChunkChange& c : changes) {
    EXPECT_TRUE(seen.insert(key(c.chunk)).second) << "a chunk listed twice";
    EXPECT_TRUE(live->world().contains_chunk(c.chunk));
    if (!c.data) continue;
    ++data;
    EXPECT_TRUE(c.mesh) << "a chunk whose rays changed has its mesh changed";
    EXPECT_TRUE(glm::all(glm::lessThan(c.node_lo, c.node_hi)));
  }
  EXPECT_GT(data, 0u);
  EXPECT_GT(changes.size(), data);  // mesh-only neighbours within the re-mesh margin
  EXPECT_TRUE(std::is_sorted(changes.begin(), changes.end(),
                             [](const auto& a, const auto& b) { return chunk_order_less(a.chunk, b.chunk); }));
  for (const glm::ivec3& c : second->changed_chunks) {
    auto it = std::find_if(changes.begin(), changes.end(), [&](const ChunkChange& x) { return x.chunk == c; });
    ASSERT_NE(it, changes.end());
    EXPECT_EQ(it->version, second->version);
  }
}

TEST(LiveWorld, BadConfigIsRefusedByName) {
  LiveConfig config;
  config.max_path_nodes = 3;
  Result<LiveWorld> live = LiveWorld::create(small_landscape(), config);
  ASSERT_FALSE(live.ok());
  EXPECT_NE(live.status().message().find("max_path_nodes 3"), std::string::npos);
  config = {};
  config.meshes = true;
  config.contour.relax_iterations = 99;
  live = LiveWorld::create(small_landscape(), config);
  ASSERT_FALSE(live.ok());
  EXPECT_EQ(live.status().code(), ErrorCode::kInvalidArgument);
}

TEST(LiveWorld, AFailedEditChangesNothingAndReportsNothing) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape(), {.meshes = true});
  ASSERT_TRUE(live.ok());
  const uint64_t version = live->version();
  Result<EditReceipt> r = live->apply(Brush::sphere({8.0, 8.0, 5.0}, -1.0), EditOp::kSubtract);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(live->version(), version);
  EXPECT_EQ(live->pending_changes(), 0u);
  Result<LiveUpdate> u = live->update();
  ASSERT_TRUE(u.ok());
  EXPECT_TRUE(u->meshes.empty());
}

TEST(LiveWorld, ACancelledUpdateKeepsItsEditsForTheNextOne) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape(), {.meshes = true});
  ASSERT_TRUE(live.ok());
  const double z = ground_z(live->queries(), 8.0, 8.0);
  ASSERT_TRUE(live->apply(Brush::sphere({8.0, 8.0, z}, 1.5), EditOp::kSubtract).ok());
  Context cancelled;
  cancelled.cancel();
  Result<LiveUpdate> u = live->update(&cancelled);
  ASSERT_FALSE(u.ok());
  EXPECT_EQ(u.status().code(), ErrorCode::kCancelled);
  u = live->update();
  ASSERT_TRUE(u.ok()) << u.status().message();
  EXPECT_FALSE(u->meshes.empty());
  EXPECT_TRUE(meshes_equal_fresh_build(*live));
}

TEST(LiveWorld, EnablingMeshesLaterReportsEveryChunkMesh) {
  Result<LiveWorld> live = LiveWorld::create(small_landscape());
  ASSERT_TRUE(live.ok());
  EXPECT_EQ(live->meshes(), nullptr);
  ASSERT_TRUE(live->enable_meshes({}).ok());
  Result<LiveUpdate> u = live->update();
  ASSERT_TRUE(u.ok());
  EXPECT_EQ(u->meshes.size(), live->meshes()->chunks().size());
  live->disable_meshes();
  EXPECT_EQ(live->meshes(), nullptr);
  u = live->update();
  ASSERT_TRUE(u.ok());
  for (const ChunkMeshChange& c : u->meshes) EXPECT_TRUE(c.removed());
}

TEST(LiveWorld, AMovedLiveWorldKeepsItsQueriesAndPathQuery) {
  Result<LiveWorld> created = LiveWorld::create(small_landscape(), {.nav = true});
  ASSERT_TRUE(created.ok());
  const double before = ground_z(created->queries(), 5.0, 5.0);
  LiveWorld moved = std::move(created).value();
  ASSERT_TRUE(moved.apply(Brush::sphere({5.0, 5.0, before}, 1.0), EditOp::kSubtract).ok());
  EXPECT_LT(ground_z(moved.queries(), 5.0, 5.0), before - 0.5);
  Result<NavQuery*> q = moved.path_query();
  ASSERT_TRUE(q.ok());
  EXPECT_TRUE((*q)->nearest_walkable({12.0, 12.0, ground_z(moved.queries(), 12.0, 12.0)}, {2.0, 2.0, 4.0}).ok());
}

// Counts the threads that run work in one arena.
class ArenaThreads : public tbb::task_scheduler_observer {
 public:
  explicit ArenaThreads(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) { observe(true); }
  ~ArenaThreads() override { observe(false); }
  void on_scheduler_entry(bool) override {
    std::lock_guard<std::mutex> lock(mutex_);
    ids_.insert(std::this_thread::get_id());
  }
  size_t count() {
    std::lock_guard<std::mutex> lock(mutex_);
    return ids_.size();
  }

 private:
  std::mutex mutex_;
  std::set<std::thread::id> ids_;
};

// The pattern docs/engine.md gives for capping the library inside an
// engine's own job system: run the calls in a task_arena of that many threads.
TEST(LiveWorld, ATaskArenaCapsTheThreadsItsWorkRunsOn) {
  tbb::task_arena one_thread(1);
  ArenaThreads threads(one_thread);
  bool ok = false;
  one_thread.execute([&] {
    Result<LiveWorld> live = LiveWorld::create(small_landscape(), {.meshes = true, .nav = true});
    ok = live.ok() && live->apply(Brush::sphere({8.0, 8.0, 6.0}, 2.0), EditOp::kSubtract).ok() &&
         live->update().ok();
  });
  EXPECT_TRUE(ok);
  EXPECT_EQ(threads.count(), 1u);
}

// --- Levels of detail (LiveConfig::lod) ----------------------------------------------

namespace live_lod {

LiveConfig lod_config() {
  LiveConfig config;
  config.meshes = true;
  config.lod = LodBands{.start = {5.0}, .hysteresis = 0.5};  // chunks of 16 cells: levels 0 and 1
  return config;
}

// The live world's level meshes against a fresh LevelChunkedMesh at the same levels.
::testing::AssertionResult level_meshes_equal_fresh_build(const LiveWorld& live) {
  const LevelChunkedMesh& meshes = *live.level_meshes();
  LevelChunkedMesh fresh(live.config().contour);
  if (!fresh.build(live.world(), [&](const glm::ivec3& c) { return meshes.level(c); }).ok())
    return ::testing::AssertionFailure() << "fresh build failed";
  if (test::sorted_triangle_positions(meshes.assemble()) != test::sorted_triangle_positions(fresh.assemble()))
    return ::testing::AssertionFailure() << "the triangles differ from a fresh build's";
  return ::testing::AssertionSuccess();
}

}  // namespace live_lod

TEST(LiveWorldLod, MeshesFollowTheCameraAndReportTheirLevels) {
  LiveWorld live = LiveWorld::create(small_landscape(), live_lod::lod_config()).value();
  ASSERT_EQ(live.meshes(), nullptr);
  ASSERT_NE(live.level_meshes(), nullptr);
  EXPECT_EQ(live.level_meshes()->level({0, 0, 0}), 0);  // the camera starts at the origin
  EXPECT_EQ(live.level_meshes()->level(live.world().chunk_origin() + live.world().chunk_dims() - 1), 1);
  live.set_camera({16.0, 16.0, 4.0});
  const LiveUpdate u = live.update().value();
  ASSERT_FALSE(u.meshes.empty());
  for (const ChunkMeshChange& c : u.meshes) {
    if (c.removed()) continue;
    EXPECT_EQ(c.level, live.level_meshes()->level(c.chunk));
    ASSERT_NE(live.level_meshes()->find(c.chunk), nullptr);
  }
  EXPECT_EQ(live.level_meshes()->level({0, 0, 0}), 1);
  EXPECT_TRUE(live_lod::level_meshes_equal_fresh_build(live));
  EXPECT_TRUE(mesh_quality(live.level_meshes()->assemble()).watertight());
  EXPECT_TRUE(live.update()->meshes.empty());  // nothing moved, nothing dug
}

TEST(LiveWorldLod, ADigIsRemeshedAtTheChunksLevels) {
  LiveWorld live = LiveWorld::create(small_landscape(), live_lod::lod_config()).value();
  live.set_camera({8.0, 8.0, 4.0});
  ASSERT_TRUE(live.update().ok());
  const double z = ground_z(live.queries(), 8.0, 8.0);
  ASSERT_TRUE(live.apply(Brush::sphere({8.0, 8.0, z}, 1.5), EditOp::kSubtract).ok());
  const LiveUpdate u = live.update().value();
  EXPECT_FALSE(u.meshes.empty());
  EXPECT_TRUE(live_lod::level_meshes_equal_fresh_build(live));
  EXPECT_TRUE(mesh_quality(live.level_meshes()->assemble()).watertight());
}

TEST(LiveWorldLod, MoreBandsThanTheChunkSizeAllowsAreRefused) {
  LiveConfig config = live_lod::lod_config();
  config.lod->start = {5.0, 10.0};
  Result<LiveWorld> r = LiveWorld::create(small_landscape(), config);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("lod has 2 bands; chunks of 16 cells allow up to 1"), std::string::npos)
      << r.status().message();
}

}  // namespace
}  // namespace ldc
