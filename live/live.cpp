#include "live/live.h"

#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>

namespace ldc {

namespace {

struct ChunkOrder {
  bool operator()(const glm::ivec3& a, const glm::ivec3& b) const { return chunk_order_less(a, b); }
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Status check_max_path_nodes(int max_nodes) {
  if (max_nodes >= 16 && max_nodes <= (1 << 20)) return {};
  return {ErrorCode::kInvalidArgument,
          "max_path_nodes " + std::to_string(max_nodes) + " is out of range: use 16 .. 1048576"};
}

}  // namespace

namespace detail {

// Everything a LiveWorld owns, on the heap so that the Queries' and the path
// query's references to the world and the nav mesh survive a move.
struct LiveState {
  LiveState(World world, const LiveConfig& c) : editor(std::move(world), c.boolean), config(c) {}

  WorldEditor editor;
  LiveConfig config;

  std::optional<ChunkedMesh> meshes;
  std::optional<LevelChunkedMesh> level_meshes;  // instead of meshes, with config.lod
  glm::dvec3 camera{0.0};
  bool camera_moved = false;
  std::vector<DirtyChunk> mesh_pending;
  std::map<glm::ivec3, ChunkMeshChange, ChunkOrder> mesh_changes;  // since the last update()
  size_t remeshed_since_update = 0;

  std::optional<NavMesh> nav;
  std::unique_ptr<NavQuery> path_query;  // on *nav
  std::vector<DirtyChunk> nav_pending;

  std::unique_ptr<Queries> queries;  // on first use
  bool queries_stale = false;

  std::map<CascadesId, std::unique_ptr<Cascades>> cascades;
  CascadesId next_cascades_id = 1;

  std::map<glm::ivec3, ChunkChange, ChunkOrder> changes;        // since the last take_changes()
  std::set<glm::ivec3, ChunkOrder> dirty_since_update;           // chunks, since the last update()

  const World& world() const { return editor.world(); }

  void note_mesh_changes(const MeshUpdate& u) {
    for (const ChunkMeshChange& c : u.changes) mesh_changes[c.chunk] = c;
    remeshed_since_update += u.chunks_remeshed;
  }

  // Every chunk mesh held now (of either kind) reported removed, and every
  // one of the new meshes reported changed: what an engine sees when
  // meshing restarts (or stops, with none).
  void note_rebuild(const ChunkedMesh* now_uniform, const LevelChunkedMesh* now_levels) {
    if (meshes) {
      for (const ChunkMesh& m : meshes->chunks()) mesh_changes[m.chunk] = {m.chunk, 0};
    }
    if (level_meshes) {
      for (const ChunkMesh* m : level_meshes->chunks()) mesh_changes[m->chunk] = {m->chunk, 0};
    }
    if (now_uniform) {
      for (const ChunkMesh& m : now_uniform->chunks()) mesh_changes[m.chunk] = {m.chunk, m.version};
    }
    if (now_levels) {
      for (const ChunkMesh* m : now_levels->chunks())
        mesh_changes[m->chunk] = {m->chunk, m->version, now_levels->level(m->chunk)};
    }
  }

  void record_change(const DirtyChunk& d) {
    auto [it, added] = changes.try_emplace(d.chunk);
    ChunkChange& c = it->second;
    if (added) c.chunk = d.chunk;
    if (c.data) {
      c.node_lo = glm::min(c.node_lo, d.node_lo);
      c.node_hi = glm::max(c.node_hi, d.node_hi);
    } else {
      c.node_lo = d.node_lo;
      c.node_hi = d.node_hi;
    }
    c.data = true;
    c.version = d.version;
    dirty_since_update.insert(d.chunk);
  }

  // Each chunk's level by its distance to the camera, from its level now.
  LevelChunkedMesh::LevelOf level_of() const {
    return [this](const glm::ivec3& c) {
      const int now = level_meshes ? level_meshes->level(c) : 0;
      return lod_level(*config.lod, chunk_distance(world().lattice(), world().chunk_size(), c, camera), now);
    };
  }

  // The chunks whose meshes a change of `dirty` may change.
  std::vector<glm::ivec3> mesh_chunks_of(std::span<const DirtyChunk> dirty) const {
    if (!config.lod) return chunks_a_remesh_may_change(dirty, config.contour, world().chunk_size());
    std::vector<glm::ivec3> chunks;
    for (const DirtyChunk& d : dirty) chunks.push_back(d.chunk);
    return LevelChunkedMesh::chunks_a_change_reaches(chunks);
  }

  void record_mesh_flags(std::span<const DirtyChunk> dirty) {
    for (const glm::ivec3& ch : mesh_chunks_of(dirty)) {
      if (!world().contains_chunk(ch)) continue;
      auto [it, added] = changes.try_emplace(ch);
      if (added) it->second.chunk = ch;
      it->second.mesh = true;
    }
  }
};

}  // namespace detail

Status check_live_config(const LiveConfig& config, const World& world) {
  if (Status s = check_boolean_config(config.boolean); !s.ok()) return s;
  if (Status s = check_contour_config(config.contour); !s.ok()) return s;
  if (config.lod) {
    if (Status s = check_lod_bands(*config.lod); !s.ok()) return s;
    if (int(config.lod->start.size()) > max_lod_level(world.chunk_size())) {
      return Status(ErrorCode::kInvalidArgument,
                    "live config: lod has " + std::to_string(config.lod->start.size()) + " bands; chunks of " +
                        std::to_string(world.chunk_size()) + " cells allow up to " +
                        std::to_string(max_lod_level(world.chunk_size())));
    }
  }
  if (config.nav) {
    if (Status s = check_nav_config(config.nav_config, world); !s.ok()) return s;
  }
  return check_max_path_nodes(config.max_path_nodes);
}

LiveWorld::LiveWorld(std::unique_ptr<detail::LiveState> state) : state_(std::move(state)) {}
LiveWorld::LiveWorld(LiveWorld&&) noexcept = default;
LiveWorld& LiveWorld::operator=(LiveWorld&&) noexcept = default;
LiveWorld::~LiveWorld() = default;

Result<LiveWorld> LiveWorld::create(World world, const LiveConfig& config, Context* ctx) {
  if (Status s = check_live_config(config, world); !s.ok()) return s;
  LiveWorld live(std::make_unique<detail::LiveState>(std::move(world), config));
  live.state_->config.meshes = false;
  live.state_->config.nav = false;
  if (config.meshes) {
    if (Status s = live.enable_meshes(config.contour, ctx); !s.ok()) return s;
  }
  if (config.nav) {
    if (Status s = live.enable_nav(config.nav_config, ctx); !s.ok()) return s;
  }
  live.state_->mesh_changes.clear();  // the first meshes are not changes: the caller reads them all
  return live;
}

const World& LiveWorld::world() const { return state_->world(); }
const LiveConfig& LiveWorld::config() const { return state_->config; }
uint64_t LiveWorld::version() const { return state_->editor.version(); }

// --- Edits ----------------------------------------------------------------------

void LiveWorld::fan_out(const std::vector<DirtyChunk>& dirty) {
  detail::LiveState& s = *state_;
  for (const DirtyChunk& d : dirty) s.record_change(d);
  s.record_mesh_flags(dirty);
  // Only what is built needs the list: a later build reads the world as it is.
  if (s.meshes || s.level_meshes) s.mesh_pending.insert(s.mesh_pending.end(), dirty.begin(), dirty.end());
  if (s.nav) s.nav_pending.insert(s.nav_pending.end(), dirty.begin(), dirty.end());
  for (auto& [id, c] : s.cascades) c->invalidate(dirty);
  if (!dirty.empty()) s.queries_stale = true;
}

Result<EditReceipt> LiveWorld::apply(const Brush& brush, EditOp op, Context* ctx) {
  Result<EditReceipt> r = state_->editor.apply(brush, op, ctx);
  fan_out(state_->editor.take_dirty());
  return r;
}

Result<EditReceipt> LiveWorld::apply_batch(std::span<const WorldEditor::Edit> edits, Context* ctx) {
  Result<EditReceipt> r = state_->editor.apply_batch(edits, ctx);
  fan_out(state_->editor.take_dirty());
  return r;
}

Status LiveWorld::undo(const EditReceipt& receipt) {
  Status s = state_->editor.undo(receipt);
  fan_out(state_->editor.take_dirty());
  return s;
}

// --- Updates --------------------------------------------------------------------

Status LiveWorld::update_meshes(Context* ctx) {
  detail::LiveState& s = *state_;
  if (s.level_meshes) {
    if (s.mesh_pending.empty() && !s.camera_moved) return {};
    std::vector<glm::ivec3> chunks;
    for (const DirtyChunk& d : s.mesh_pending) chunks.push_back(d.chunk);
    Result<MeshUpdate> r = s.level_meshes->update(s.world(), chunks, s.level_of(), ctx);
    if (!r.ok()) return r.status();
    s.note_mesh_changes(r.value());
    s.mesh_pending.clear();
    s.camera_moved = false;
    return {};
  }
  if (!s.meshes || s.mesh_pending.empty()) return {};
  Result<MeshUpdate> r = s.meshes->update(s.world(), s.mesh_pending, ctx);
  if (!r.ok()) return r.status();
  s.note_mesh_changes(r.value());
  s.mesh_pending.clear();
  return {};
}

Result<NavUpdateStats> LiveWorld::update_nav(Context* ctx) {
  detail::LiveState& s = *state_;
  if (!s.nav || s.nav_pending.empty()) return NavUpdateStats{};
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "nav update: cancelled");
  Result<NavUpdateStats> r = s.nav->update(s.world(), s.nav_pending);
  if (r.ok()) s.nav_pending.clear();
  return r;
}

void LiveWorld::update_queries() {
  detail::LiveState& s = *state_;
  if (s.queries && s.queries_stale) s.queries->refresh();
  s.queries_stale = false;
}

Result<LiveUpdate> LiveWorld::update(Context* ctx) {
  detail::LiveState& s = *state_;
  LiveUpdate u;
  auto t = std::chrono::steady_clock::now();
  if (Status st = update_meshes(ctx); !st.ok()) return st;
  u.mesh_seconds = seconds_since(t);
  t = std::chrono::steady_clock::now();
  Result<NavUpdateStats> nav = update_nav(ctx);
  if (!nav.ok()) return nav.status();
  u.nav = nav.value();
  u.nav_seconds = seconds_since(t);
  t = std::chrono::steady_clock::now();
  update_queries();
  u.query_seconds = seconds_since(t);
  u.dirty_chunks = s.dirty_since_update.size();
  u.chunks_remeshed = s.remeshed_since_update;
  for (const auto& [chunk, change] : s.mesh_changes) u.meshes.push_back(change);
  s.mesh_changes.clear();
  s.dirty_since_update.clear();
  s.remeshed_since_update = 0;
  return u;
}

std::vector<ChunkChange> LiveWorld::take_changes() {
  std::vector<ChunkChange> out;
  out.reserve(state_->changes.size());
  for (const auto& [chunk, change] : state_->changes) out.push_back(change);
  state_->changes.clear();
  return out;
}

size_t LiveWorld::pending_changes() const { return state_->changes.size(); }

// --- Consumers ------------------------------------------------------------------

Status LiveWorld::enable_meshes(const ContourConfig& config, Context* ctx) {
  detail::LiveState& s = *state_;
  if (s.config.lod) {
    LevelChunkedMesh built(config);
    if (Status st = built.build(s.world(), s.level_of(), ctx); !st.ok()) return st;
    s.note_rebuild(nullptr, &built);
    s.meshes.reset();
    s.level_meshes.emplace(std::move(built));
    s.mesh_pending.clear();
    s.camera_moved = false;
    s.config.contour = config;
    s.config.meshes = true;
    return {};
  }
  Result<ChunkedMesh> built = ChunkedMesh::create(s.world(), config, ctx);
  if (!built) return built.status();
  s.note_rebuild(&*built, nullptr);
  s.level_meshes.reset();
  s.meshes.emplace(std::move(built).value());
  s.mesh_pending.clear();
  s.config.contour = config;
  s.config.meshes = true;
  return {};
}

void LiveWorld::disable_meshes() {
  detail::LiveState& s = *state_;
  s.note_rebuild(nullptr, nullptr);
  s.meshes.reset();
  s.level_meshes.reset();
  s.mesh_pending.clear();
  s.config.meshes = false;
}

Status LiveWorld::enable_nav(const NavConfig& config, Context* ctx) {
  detail::LiveState& s = *state_;
  Result<NavMesh> built = NavMesh::build(s.world(), config, ctx);
  if (!built.ok()) return built.status();
  s.path_query.reset();  // it refers to the old nav mesh
  s.nav.emplace(std::move(built).value());
  s.path_query = std::make_unique<NavQuery>(*s.nav, s.config.max_path_nodes);
  s.nav_pending.clear();
  s.config.nav_config = config;
  s.config.nav = true;
  return {};
}

void LiveWorld::disable_nav() {
  detail::LiveState& s = *state_;
  s.path_query.reset();
  s.nav.reset();
  s.nav_pending.clear();
  s.config.nav = false;
}

Status LiveWorld::set_max_path_nodes(int max_nodes) {
  if (Status st = check_max_path_nodes(max_nodes); !st.ok()) return st;
  detail::LiveState& s = *state_;
  s.config.max_path_nodes = max_nodes;
  if (s.nav) s.path_query = std::make_unique<NavQuery>(*s.nav, max_nodes);
  return {};
}

const ChunkedMesh* LiveWorld::meshes() const { return state_->meshes ? &*state_->meshes : nullptr; }
const LevelChunkedMesh* LiveWorld::level_meshes() const {
  return state_->level_meshes ? &*state_->level_meshes : nullptr;
}

void LiveWorld::set_camera(const glm::dvec3& position) {
  detail::LiveState& s = *state_;
  if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z)) return;
  if (position == s.camera) return;
  s.camera = position;
  s.camera_moved = true;
}
const NavMesh* LiveWorld::nav() const { return state_->nav ? &*state_->nav : nullptr; }
NavMesh* LiveWorld::nav() { return state_->nav ? &*state_->nav : nullptr; }

Result<NavQuery*> LiveWorld::path_query(Context* ctx) {
  if (!state_->nav) {
    return Status(ErrorCode::kInvalidArgument, "path query: navigation is off (LiveConfig::nav or enable_nav)");
  }
  Result<NavUpdateStats> r = update_nav(ctx);
  if (!r.ok()) return r.status();
  return state_->path_query.get();
}

const Queries& LiveWorld::queries() const {
  if (!state_->queries) state_->queries = std::make_unique<Queries>(state_->world());
  return *state_->queries;
}

Result<CascadesId> LiveWorld::add_cascades(const CascadeConfig& config) {
  detail::LiveState& s = *state_;
  Result<Cascades> c = Cascades::create(s.world().lattice(), config);
  if (!c.ok()) return c.status();
  const CascadesId id = s.next_cascades_id++;
  s.cascades.emplace(id, std::make_unique<Cascades>(std::move(c).value()));
  return id;
}

Cascades* LiveWorld::cascades(CascadesId id) {
  auto it = state_->cascades.find(id);
  return it == state_->cascades.end() ? nullptr : it->second.get();
}

std::unique_ptr<Cascades> LiveWorld::release_cascades(CascadesId id) {
  auto it = state_->cascades.find(id);
  if (it == state_->cascades.end()) return nullptr;
  std::unique_ptr<Cascades> out = std::move(it->second);
  state_->cascades.erase(it);
  return out;
}

}  // namespace ldc
