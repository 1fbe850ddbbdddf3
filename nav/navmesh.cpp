// NavMesh: builds every tile, and rebuilds only what an edit reached.
#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include <tbb/parallel_for.h>

#include "nav/detail/nav_data.h"

namespace ldc {

using detail::NavData;
using detail::NavTile;

namespace {

Status bad_config(const std::string& field, double value, const std::string& limit) {
  std::ostringstream os;
  os << "NavConfig." << field << " = " << value << ": " << limit;
  return Status(ErrorCode::kInvalidArgument, os.str());
}

// Runs fn(tile) for the listed tile slots, in parallel when there are many.
template <class Fn>
void for_tiles(NavData& data, const std::vector<int>& slots, Fn fn) {
  auto one = [&](size_t k) { fn(data.tiles[size_t(slots[k])]); };
  if (slots.size() < 4) {
    for (size_t k = 0; k < slots.size(); ++k) one(k);
    return;
  }
  tbb::parallel_for(size_t(0), slots.size(), one);
}

// Slots of the listed tiles and their four side neighbours, sorted and unique.
std::vector<int> with_side_neighbours(const NavData& data, const std::vector<int>& slots) {
  std::set<int> out;
  for (int s : slots) {
    const glm::ivec2 t = data.tiles[size_t(s)].coord;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx != 0 && dy != 0) continue;
        const glm::ivec2 n = t + glm::ivec2(dx, dy);
        if (data.contains_tile(n)) out.insert(data.tile_slot(n));
      }
    }
  }
  return {out.begin(), out.end()};
}

std::vector<int> all_slots(const NavData& data) {
  std::vector<int> slots(data.tiles.size());
  for (size_t i = 0; i < slots.size(); ++i) slots[i] = int(i);
  return slots;
}

// The building steps after extraction, over the given sets.
void link_to_relabel(NavData& data, const std::vector<int>& link, const std::vector<int>& cover,
                     const std::vector<int>& connect) {
  for_tiles(data, link, [&](NavTile& t) { detail::link_tile(data, t); });
  for_tiles(data, cover, [&](NavTile& t) { detail::erode_tile(data, t); });
  for_tiles(data, cover, [&](NavTile& t) { detail::cover_tile(data, t); });
  for_tiles(data, connect, [&](NavTile& t) { detail::connect_tile(data, t); });
  detail::relabel(data);
  detail::attach_links(data);
}

}  // namespace

Status check_nav_config(const NavConfig& config, const World& world) {
  if (config.up_axis < 0 || config.up_axis > 2) {
    return bad_config("up_axis", config.up_axis, "must be 0 (x), 1 (y) or 2 (z)");
  }
  if (!std::isfinite(config.agent_height) || config.agent_height <= 0.0 ||
      config.agent_height > 1000.0) {
    return bad_config("agent_height", config.agent_height, "must be > 0 and <= 1000 m");
  }
  const double half_chunk = 0.5 * world.chunk_size() * world.lattice().cell_size;
  if (!std::isfinite(config.agent_radius) || config.agent_radius < 0.0 ||
      config.agent_radius > half_chunk) {
    return bad_config("agent_radius", config.agent_radius,
                      "must be >= 0 and at most half a chunk (" + std::to_string(half_chunk) + " m)");
  }
  if (!std::isfinite(config.max_climb) || config.max_climb < 0.0) {
    return bad_config("max_climb", config.max_climb, "must be >= 0 m");
  }
  if (!std::isfinite(config.max_slope_degrees) || config.max_slope_degrees < 0.0 ||
      config.max_slope_degrees > 89.0) {
    return bad_config("max_slope_degrees", config.max_slope_degrees, "must be in [0, 89]");
  }
  for (size_t m = 0; m < config.material_areas.size(); ++m) {
    if (config.material_areas[m] > 63) {
      return bad_config("material_areas[" + std::to_string(m) + "]", config.material_areas[m], "must be in 0 .. 63");
    }
  }
  return {};
}

Result<NavMesh> NavMesh::build(const World& world, const NavConfig& config, Context* ctx) {
  if (Status s = check_nav_config(config, world); !s.ok()) return s;
  ScopedTimer timer(ctx, "nav build");
  auto data = std::make_unique<NavData>();
  detail::setup_nav_data(*data, world, config);
  const std::vector<int> slots = all_slots(*data);
  for_tiles(*data, slots, [&](NavTile& t) { detail::extract_tile(*data, world, t); });
  if (ctx && ctx->cancelled()) return Status(ErrorCode::kCancelled, "nav build cancelled");
  if (ctx) ctx->report_progress("nav build", 0.5);
  link_to_relabel(*data, slots, slots, slots);
  if (ctx) ctx->report_progress("nav build", 1.0);
  return NavMesh(std::move(data));
}

Result<NavUpdateStats> NavMesh::update(const World& world, std::span<const DirtyChunk> dirty) {
  const ScopedTimer timer(nullptr, "");
  NavUpdateStats stats;
  NavData& data = *data_;
  const bool same_box = world.chunk_origin() == data.world_chunk_origin &&
                        world.chunk_dims() == data.world_chunk_dims &&
                        world.chunk_size() == data.chunk_size &&
                        world.lattice().cell_size == data.lattice.cell_size &&
                        world.lattice().origin == data.lattice.origin;
  if (!same_box) {
    Result<NavMesh> rebuilt = build(world, data.config);
    if (!rebuilt.ok()) return rebuilt.status();
    // The links outlive the rebuild, ids and all.
    rebuilt.value().data_->links = std::move(data.links);
    rebuilt.value().data_->next_link_id = data.next_link_id;
    detail::attach_links(*rebuilt.value().data_);
    *this = std::move(rebuilt.value());
    stats.full_rebuild = true;
    stats.dirty_tiles = stats.recovered_tiles = data_->tiles.size();
  } else {
    std::set<int> extract_set, cover_set;
    for (const DirtyChunk& d : dirty) {
      const glm::ivec2 tile(d.chunk[data.axis_u], d.chunk[data.axis_v]);
      if (!data.contains_tile(tile)) continue;
      extract_set.insert(data.tile_slot(tile));
      // Erosion reaches erode_cells columns (plus the changed links) around the change.
      const glm::ivec2 reach(data.erode_cells + 1);
      const glm::ivec2 lo = glm::ivec2(d.node_lo[data.axis_u], d.node_lo[data.axis_v]) - reach;
      const glm::ivec2 hi = glm::ivec2(d.node_hi[data.axis_u], d.node_hi[data.axis_v]) + reach;
      const glm::ivec2 tlo = data.tile_of_column(lo), thi = data.tile_of_column(hi);
      for (int y = tlo.y; y <= thi.y; ++y) {
        for (int x = tlo.x; x <= thi.x; ++x) {
          if (data.contains_tile({x, y})) cover_set.insert(data.tile_slot({x, y}));
        }
      }
    }
    const std::vector<int> extract(extract_set.begin(), extract_set.end());
    const std::vector<int> cover(cover_set.begin(), cover_set.end());
    for_tiles(data, extract, [&](NavTile& t) { detail::extract_tile(data, world, t); });
    link_to_relabel(data, with_side_neighbours(data, extract), cover, with_side_neighbours(data, cover));
    stats.dirty_tiles = extract.size();
    stats.recovered_tiles = cover.size();
  }
  stats.seconds = timer.seconds();
  return stats;
}

NavStats NavMesh::stats() const {
  NavStats s;
  const NavData& d = *data_;
  s.memory_bytes = sizeof(NavData) + (d.dense_tile.capacity() + d.node_tile.capacity()) * sizeof(uint32_t) +
                   d.component_boxes.capacity() * sizeof(detail::RegionBox) +
                   d.component_runs.capacity() * sizeof(detail::RegionBoxRun) +
                   d.component_run_first.capacity() * sizeof(uint32_t);
  for (const NavTile& t : data_->tiles) {
    s.memory_bytes += t.memory_bytes();
    s.dropped_floors += t.dropped_floors;
    if (t.empty()) continue;
    ++s.tiles;
    s.floors += t.floors.size();
    s.walkable += size_t(std::count_if(t.floors.begin(), t.floors.end(),
                                       [](const detail::NavFloor& f) { return f.kept(); }));
    s.regions += t.regions.size();
    s.chains += t.chains.size();
    s.portals += t.portals.size();
  }
  s.components = data_->component_count;
  return s;
}

const NavConfig& NavMesh::config() const { return data_->config; }
const Lattice& NavMesh::lattice() const { return data_->lattice; }

NavMesh::NavMesh(std::unique_ptr<NavData> data) : data_(std::move(data)) {}
NavMesh::NavMesh(NavMesh&&) noexcept = default;
NavMesh& NavMesh::operator=(NavMesh&&) noexcept = default;
NavMesh::~NavMesh() = default;

const char* path_status_name(PathStatus status) {
  switch (status) {
    case PathStatus::kComplete: return "complete";
    case PathStatus::kUnreachable: return "unreachable";
    case PathStatus::kOutOfNodes: return "out_of_nodes";
  }
  return "unknown";
}

}  // namespace ldc
