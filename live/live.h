// One live world for engines: the World, its editor, and everything kept
// up to date from it.
//
// A game edits the world (dig, build, paint, undo) and, once a frame, brings
// what it draws, walks on and lights up to date. A LiveWorld owns the pieces
// that takes and does the fan-out of dirty chunks in one place:
//
//   - the World and its WorldEditor (csg/csg.h): apply, apply_batch, undo;
//   - chunk meshes (contour/contour.h, ChunkedMesh), when turned on; at
//     levels of detail by distance to the camera (LevelChunkedMesh) with
//     LiveConfig::lod;
//   - the navigation mesh and a path query on it (nav/nav.h), when turned on;
//   - game queries (ldc/query.h, Queries): ray and sphere casts, overlaps;
//   - voxel cascades (voxelize/voxelize.h), any number, added by the caller.
//
// Every edit's dirty chunks go to each consumer's pending list (cascades get
// them at once: marking voxels is cheap). update() then re-meshes, updates
// the nav mesh and refreshes the query caches, and returns which chunk
// meshes changed or were removed, each with its version, so an engine
// re-uploads exactly those. The per-consumer calls (update_meshes,
// update_nav, ...) do one consumer alone, for callers that pull lazily.
//
//   LiveConfig config;
//   config.meshes = true;
//   config.nav = true;
//   Result<LiveWorld> live = LiveWorld::create(std::move(world), config);
//   if (!live) return live.status();
//   // each frame:
//   (void)live->apply(Brush::sphere(player, 1.2), EditOp::kSubtract);
//   Result<LiveUpdate> u = live->update();
//   for (const ChunkMeshChange& c : u->meshes)
//     c.removed() ? drop(c.chunk) : upload(*live->meshes()->find(c.chunk));
//
// Thread safety: a LiveWorld is not thread-safe (one owner, e.g. the game
// thread). Its work runs in parallel inside (TBB); cap the threads with a
// tbb::task_arena around the calls (see docs/engine.md). Between calls, the
// world, meshes, nav mesh and queries may be read from other threads under
// the rules of their own modules (queries are const and concurrent).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/lod.h"
#include "ldc/context.h"
#include "ldc/query.h"
#include "ldc/status.h"
#include "ldc/world.h"
#include "nav/nav.h"
#include "voxelize/voxelize.h"

namespace ldc {

namespace detail {
struct LiveState;
}

struct LiveConfig {
  BooleanConfig boolean;  // how edits merge (csg/csg.h)
  // Keep chunk meshes: built at create (or enable_meshes), re-meshed from
  // the dirty chunks at each update. [Default: off]
  bool meshes = false;
  // Chunk meshes are watertight 2-manifolds (no boundary, no non-manifold
  // edge or vertex), placed for sharp features with relaxed material borders,
  // but not free of self-intersecting triangle pairs: 29 on the default
  // landscape (472,032 triangles), 401 after 300 random edits (594,164;
  // bench_csg_game --validity, docs/live.md). A render mesh or a physics
  // triangle collider does not mind them; a convex decomposition, a slicer
  // or another boolean does. For those:
  // - {.placement = Placement::kMassPoint, .relax_iterations = 0} measured no
  //   pair at all, and re-meshes a 2 m dig 2.3 times faster, but keeps no
  //   sharp edge and no relaxed material border (fandisk at 256 cells: normal
  //   error near sharp edges 8.1 degrees against 0.22);
  // - untangle = true keeps both and clears 83 and 95% of the pairs (5 and
  //   21 are left), at 4 times the re-mesh time;
  // - or run untangle_mesh on assemble()'s mesh before it leaves the game.
  ContourConfig contour{.untangle = false};
  // Chunk meshes at levels of detail by distance to the camera
  // (set_camera): each chunk at lod_level(*lod, its distance, its level now),
  // meshed by LevelChunkedMesh (seams between levels closed; no relaxation
  // or untangling), read with level_meshes() instead of meshes(). A change
  // of level re-meshes the chunk and its 26 neighbours at the next update.
  // [Limit: check_lod_bands; at most max_lod_level(C) bands] [Default: none: one level]
  std::optional<LodBands> lod;
  // Keep a navigation mesh: built at create (or enable_nav), updated from
  // the dirty chunks at each update. [Default: off]
  bool nav = false;
  NavConfig nav_config;
  // The A* node budget of the path query kept with the nav mesh
  // [Limit: 16 .. 1 << 20] [Default: 2048, Detour's].
  int max_path_nodes = 2048;
};

Status check_live_config(const LiveConfig& config, const World& world);

// A chunk an edit changed, and what of it: for engines that keep their own
// per-chunk data (collision, GPU voxels). Sorted by chunk_order_less.
struct ChunkChange {
  glm::ivec3 chunk{0};
  bool data = false;      // its rays changed: node_lo, node_hi and version say where and when
  bool mesh = false;      // its chunk mesh may change (chunks_a_remesh_may_change)
  uint64_t version = 0;   // the edit that last changed its rays (0 when data is false)
  glm::ivec3 node_lo{0};  // data: the box of lattice nodes that changed (global)
  glm::ivec3 node_hi{0};  // exclusive
};

// What one update() did.
struct LiveUpdate {
  size_t dirty_chunks = 0;               // world chunks the edits since the last update changed
  std::vector<ChunkMeshChange> meshes;   // chunk meshes changed or removed since the last update
  size_t chunks_remeshed = 0;            // chunk meshes re-spliced (changed or not)
  NavUpdateStats nav;                    // zero when nav is off or had nothing to do
  double mesh_seconds = 0.0;
  double nav_seconds = 0.0;
  double query_seconds = 0.0;
};

// An id for cascades a LiveWorld owns.
using CascadesId = uint32_t;

class LiveWorld {
 public:
  // Takes the world; builds the consumers the config turns on (the chunk
  // meshes and nav mesh, in parallel inside). Queries are derived on first use.
  static Result<LiveWorld> create(World world, const LiveConfig& config = {}, Context* ctx = nullptr);

  LiveWorld(LiveWorld&&) noexcept;
  LiveWorld& operator=(LiveWorld&&) noexcept;
  ~LiveWorld();

  const World& world() const;
  const LiveConfig& config() const;
  uint64_t version() const;  // of the last edit (WorldEditor::version)

  // --- Edits: as WorldEditor's; on error nothing changes. -------------------
  Result<EditReceipt> apply(const Brush& brush, EditOp op, Context* ctx = nullptr);
  Result<EditReceipt> apply_batch(std::span<const WorldEditor::Edit> edits, Context* ctx = nullptr);
  Status undo(const EditReceipt& receipt);

  // --- Bringing consumers up to date ------------------------------------------
  // Every consumer at once: chunk meshes, nav mesh, query caches. Returns
  // the chunk meshes changed since the last update() (also those changed by
  // update_meshes() calls in between). On error the consumers that failed
  // keep their pending edits and the next update tries them again.
  Result<LiveUpdate> update(Context* ctx = nullptr);
  // One consumer alone (update() calls these).
  Status update_meshes(Context* ctx = nullptr);
  Result<NavUpdateStats> update_nav(Context* ctx = nullptr);
  void update_queries();

  // The chunks changed since the last call (data and the meshes they may
  // change), merged per chunk and sorted by chunk_order_less; clears the list.
  std::vector<ChunkChange> take_changes();
  // How many take_changes() would return, without clearing.
  size_t pending_changes() const;

  // --- Consumers ----------------------------------------------------------------
  // Turns the chunk meshes on (or rebuilds them with a new config) from the
  // world as it is now. On error they stay as they were.
  Status enable_meshes(const ContourConfig& config, Context* ctx = nullptr);
  Status enable_nav(const NavConfig& config, Context* ctx = nullptr);
  // The A* node budget of the kept path query [Limit: 16 .. 1 << 20].
  Status set_max_path_nodes(int max_nodes);
  void disable_meshes();
  void disable_nav();

  // Null when off. The meshes and nav mesh are as of the last update of
  // that consumer: call update() (or update_meshes / update_nav) first.
  // meshes() is null and level_meshes() set when config.lod is.
  const ChunkedMesh* meshes() const;
  const LevelChunkedMesh* level_meshes() const;
  // Where the camera is, for levels of detail (config.lod): the next
  // update_meshes() gives each chunk its level by its distance from here.
  // [Units: m] [Limit: finite; otherwise ignored] [Default: the world's origin]
  void set_camera(const glm::dvec3& position);
  const NavMesh* nav() const;
  // The nav mesh for changes that need no edit: off-mesh links
  // (NavMesh::add_link / remove_link; not while its path query runs). They
  // are kept by update_nav; a mesh enable_nav builds again starts with none.
  NavMesh* nav();
  // The path query on the nav mesh (null when nav is off); it keeps its
  // search arrays between paths. Brings the nav mesh up to date first.
  Result<NavQuery*> path_query(Context* ctx = nullptr);
  // Game queries on the world, created on first use. Edits are seen at
  // once; update() (or update_queries) frees what replaced chunks left.
  const Queries& queries() const;

  // Voxel cascades kept invalidated by every edit; the caller still moves
  // them to the camera (Cascades::frame / update_level with world()).
  Result<CascadesId> add_cascades(const CascadeConfig& config);
  // Null for an unknown id.
  Cascades* cascades(CascadesId id);
  // Stops feeding the cascades and hands them over (null for an unknown
  // id); drop the result to remove them.
  std::unique_ptr<Cascades> release_cascades(CascadesId id);

 private:
  explicit LiveWorld(std::unique_ptr<detail::LiveState> state);
  void fan_out(const std::vector<DirtyChunk>& dirty);
  std::unique_ptr<detail::LiveState> state_;
};

}  // namespace ldc
