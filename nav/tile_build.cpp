// Building one tile: floors from the vertical rays, links to the neighbour
// columns, erosion by the agent radius, rectangles, portals.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "nav/detail/nav_data.h"

namespace ldc::detail {

size_t NavTile::memory_bytes() const {
  return sizeof(NavTile) + column_first.capacity() * sizeof(uint16_t) +
         floors.capacity() * sizeof(NavFloor) + regions.capacity() * sizeof(NavRegion) +
         chains.capacity() * sizeof(NavChain) + portals.capacity() * sizeof(NavPortal);
}

int NavData::column_in_tile(const glm::ivec2& col, int* slot_out) const {
  const glm::ivec2 tile = tile_of_column(col);
  if (!contains_tile(tile)) return -1;
  const int slot = tile_slot(tile);
  const NavTile& t = tiles[size_t(slot)];
  if (t.empty()) return -1;
  const glm::ivec2 local = col - tile * chunk_size;
  if (slot_out) *slot_out = slot;
  return local.y * chunk_size + local.x;
}

std::span<const NavFloor> NavData::column(const glm::ivec2& col) const {
  int slot = 0;
  const int index = column_in_tile(col, &slot);
  if (index < 0) return {};
  const NavTile& t = tiles[size_t(slot)];
  return {t.floors.data() + t.column_first[size_t(index)],
          size_t(t.column_first[size_t(index) + 1] - t.column_first[size_t(index)])};
}

glm::dvec3 NavData::to_nav(const glm::dvec3& world) const {
  const glm::dvec3 l = lattice.to_lattice(world);
  return {l[axis_u], l[axis_v], l[up]};
}

glm::dvec3 NavData::to_world(const glm::dvec3& nav) const {
  glm::dvec3 l;
  l[axis_u] = nav.x;
  l[axis_v] = nav.y;
  l[up] = nav.z;
  return lattice.to_world(l);
}

void setup_nav_data(NavData& data, const World& world, const NavConfig& config) {
  data.config = config;
  data.lattice = world.lattice();
  data.chunk_size = world.chunk_size();
  data.chunk_shift = world.chunk_shift();
  data.up = config.up_axis;
  data.axis_u = axis_u(config.up_axis);
  data.axis_v = axis_v(config.up_axis);
  const glm::ivec3 o = world.chunk_origin(), d = world.chunk_dims();
  data.world_chunk_origin = o;
  data.world_chunk_dims = d;
  data.tile_origin = {o[data.axis_u], o[data.axis_v]};
  data.tile_dims = {d[data.axis_u], d[data.axis_v]};
  const double h = world.lattice().cell_size;
  data.climb_cells = float(config.max_climb / h);
  data.height_cells = float(config.agent_height / h);
  data.min_normal_up = float(std::cos(config.max_slope_degrees * M_PI / 180.0));
  const double max_gradient = std::tan(config.max_slope_degrees * M_PI / 180.0);
  data.max_gradient_sq = float(max_gradient * max_gradient);
  data.erode_cells = int(std::ceil(config.agent_radius / h - 1e-9));
  data.tiles.assign(size_t(data.tile_dims.x) * size_t(data.tile_dims.y), NavTile{});
  for (int y = 0; y < data.tile_dims.y; ++y) {
    for (int x = 0; x < data.tile_dims.x; ++x) {
      data.tiles[size_t(y * data.tile_dims.x + x)].coord = data.tile_origin + glm::ivec2(x, y);
    }
  }
}

// ---- floors ----------------------------------------------------------------

namespace {

// The chunks of one tile's vertical stack, bottom to top (nullptr: uniform).
std::vector<const Chunk*> tile_stack(const NavData& data, const World& world,
                                     const glm::ivec2& tile) {
  std::vector<const Chunk*> stack;
  glm::ivec3 ch(0);
  ch[data.axis_u] = tile.x;
  ch[data.axis_v] = tile.y;
  for (int k = 0; k < data.world_chunk_dims[data.up]; ++k) {
    ch[data.up] = data.world_chunk_origin[data.up] + k;
    stack.push_back(world.chunk(ch));
  }
  return stack;
}

// Recast's rcFilterLowHangingWalkableObstacles on one column (floors from
// `start`, bottom to top): a steep floor at most max_climb above a floor that
// was walkable by its own normal becomes walkable.
void lift_low_hanging(const NavData& data, std::vector<NavFloor>& floors, size_t start) {
  bool below_walkable = false;
  float below_height = 0.0f;
  for (size_t k = start; k < floors.size(); ++k) {
    NavFloor& f = floors[k];
    const bool own_walkable = !f.steep_normal;
    if (f.steep_normal && below_walkable && f.height - below_height <= data.climb_cells) {
      f.steep_normal = false;
    }
    below_walkable = own_walkable;
    below_height = f.height;
  }
}

}  // namespace

void extract_tile(const NavData& data, const World& world, NavTile& tile) {
  tile.floors.clear();
  tile.regions.clear();
  tile.chains.clear();
  tile.portals.clear();
  tile.column_first.clear();
  tile.dropped_floors = 0;
  const int c = data.chunk_size;
  const std::vector<const Chunk*> stack = tile_stack(data, world, tile.coord);
  if (std::all_of(stack.begin(), stack.end(), [](const Chunk* ch) { return ch == nullptr; })) {
    return;  // uniform all the way up: no surface, no floors
  }
  const double steps = depth_steps_per_cell(c);
  const int bottom = data.world_chunk_origin[data.up] * c;
  tile.column_first.assign(size_t(c * c + 1), 0);
  for (int ray = 0; ray < c * c; ++ray) {
    tile.column_first[size_t(ray)] = uint16_t(tile.floors.size());
    const size_t column_start = tile.floors.size();
    bool open_floor = false;  // the last floor waits for its ceiling
    for (size_t k = 0; k < stack.size(); ++k) {
      if (!stack[k]) continue;
      const double segment = bottom + double(k) * c;
      for (const PackedPoint& p : stack[k]->axis[size_t(data.up)].points(ray)) {
        const double depth = segment + p.depth / steps;
        if (p.enters()) {
          if (open_floor) tile.floors.back().ceiling = float(depth);
          open_floor = false;
          continue;
        }
        if (tile.floors.size() - column_start >= size_t(kMaxLevels) ||
            tile.floors.size() >= kMaxTileFloors) {
          ++tile.dropped_floors;
          continue;
        }
        NavFloor f;
        f.height = float(depth);
        f.ceiling = std::numeric_limits<float>::infinity();
        const float normal_up = decode_normal(p.normal)[data.up];
        f.steep_normal = normal_up < data.min_normal_up;
        f.riser = normal_up < kRiserNormalUp;
        f.area = p.material < data.config.material_areas.size() ? data.config.material_areas[p.material] : 0;
        tile.floors.push_back(f);
        open_floor = true;
      }
    }
    if (data.config.filter_low_hanging_obstacles) lift_low_hanging(data, tile.floors, column_start);
    // Drop floors without room for the agent.
    if (!data.config.filter_low_height_spans) continue;
    auto first = tile.floors.begin() + std::ptrdiff_t(column_start);
    tile.floors.erase(std::remove_if(first, tile.floors.end(),
                                     [&](const NavFloor& f) {
                                       return f.ceiling - f.height < data.height_cells;
                                     }),
                      tile.floors.end());
  }
  tile.column_first[size_t(c * c)] = uint16_t(tile.floors.size());
  if (tile.floors.empty()) tile.column_first.clear();
}

// ---- links -----------------------------------------------------------------

namespace {

uint8_t best_link(const NavData& data, const NavFloor& f, std::span<const NavFloor> column) {
  uint8_t best = kNoLink;
  float best_step = 0.0f;
  for (size_t j = 0; j < column.size(); ++j) {
    const NavFloor& g = column[j];
    const float step = std::fabs(g.height - f.height);
    if (step > data.climb_cells) continue;
    const float gap = std::min(f.ceiling, g.ceiling) - std::max(f.height, g.height);
    if (gap < data.height_cells && data.config.filter_low_height_spans) continue;
    if (best == kNoLink || step < best_step) {
      best = uint8_t(j);
      best_step = step;
    }
  }
  return best;
}

// Walkable when the stored normal is within max_slope. A steeper normal is
// only a point of the surface: the floor is still walkable when the ground
// is within max_slope at the scale of a cell, i.e. the height steps to the
// linked neighbours (the larger one on each axis, so a V-groove's bottom is
// as steep as its walls) make a gradient within tan(max_slope); ripples
// finer than a cell are walked over, a slope or a crease steeper than
// max_slope over a cell is not. A riser (a normal within 10 degrees of
// horizontal: the ray caught a kerb face, a step's riser or a wall top's
// edge, which have no floor area of their own) is walkable when a linked
// neighbour's normal is: it is the edge of that neighbour's step.
// (Measured against analytic terrains by bench/nav_truth.cpp.)
bool slope_walkable(const NavData& data, const NavFloor& f, const std::array<const NavFloor*, 4>& side) {
  if (!f.steep_normal) return true;
  if (f.riser) {
    for (const NavFloor* g : side) {
      if (g && !g->steep_normal) return true;
    }
    return false;
  }
  float gradient_sq = 0.0f;
  for (int axis = 0; axis < 2; ++axis) {
    float step = 0.0f;
    for (int d : {axis, axis + 2}) {
      if (side[size_t(d)]) step = std::max(step, std::fabs(side[size_t(d)]->height - f.height));
    }
    gradient_sq += step * step;
  }
  return gradient_sq <= data.max_gradient_sq;
}

// Recast's rcFilterLedgeSpans: a side with no linked floor is a ledge when
// the neighbour column's floors all lie more than max_climb below f, or the
// column is beyond the world's edge. A side blocked by a higher floor is
// not. A column inside the world with no floor at all (solid up to a
// ceiling, or a hole with nothing below) reads as a wall: only erosion by
// agent_radius closes such a hole's rim.
bool has_ledge(const NavData& data, const NavFloor& f, const glm::ivec2& col) {
  for (int d = 0; d < 4; ++d) {
    if (f.link[d] != kNoLink) continue;
    const glm::ivec2 side = col + kDirStep[d];
    if (!data.contains_tile(data.tile_of_column(side))) return true;
    const std::span<const NavFloor> floors = data.column(side);
    if (floors.empty()) continue;
    const bool drop = std::all_of(floors.begin(), floors.end(), [&](const NavFloor& g) {
      return g.height < f.height - data.climb_cells;
    });
    if (drop) return true;
  }
  return false;
}

}  // namespace

void link_tile(const NavData& data, NavTile& tile) {
  if (tile.empty()) return;
  const int c = data.chunk_size;
  const glm::ivec2 base = tile.coord * c;
  for (int lv = 0; lv < c; ++lv) {
    for (int lu = 0; lu < c; ++lu) {
      const int ray = lv * c + lu;
      const std::span<const NavFloor> own = data.column(base + glm::ivec2(lu, lv));
      for (uint32_t i = tile.column_first[size_t(ray)]; i < tile.column_first[size_t(ray) + 1]; ++i) {
        NavFloor& f = tile.floors[i];
        std::array<const NavFloor*, 4> side{};
        const uint32_t level = i - tile.column_first[size_t(ray)];
        for (int d = 0; d < 4; ++d) {
          std::span<const NavFloor> col = data.column(base + glm::ivec2(lu, lv) + kDirStep[d]);
          const uint8_t j = best_link(data, f, col);
          // Both ways or not at all: the neighbour's best floor back must be this one.
          const bool mutual = j != kNoLink && best_link(data, col[j], own) == level;
          f.link[d] = mutual ? j : kNoLink;
          if (mutual) side[size_t(d)] = &col[j];
        }
        // With an agent radius, a ledge's rim is an unlinked side and erosion
        // measures the radius from it; filtering the rim as well would erode
        // a cell further than the radius (bench/nav_truth.cpp measured it).
        const bool ledge_filter = data.config.filter_ledge_spans && data.erode_cells == 0;
        f.walkable = slope_walkable(data, f, side) && !(ledge_filter && has_ledge(data, f, base + glm::ivec2(lu, lv)));
      }
    }
  }
}

// ---- erosion ---------------------------------------------------------------

namespace {

// The columns around a tile, within the erosion reach, with their floors
// numbered consecutively so distances fit in one array.
struct ErosionWindow {
  glm::ivec2 lo{0};
  int size = 0;
  std::vector<uint32_t> first;            // per window column, into the floor numbering
  std::vector<const NavFloor*> floors;    // per window column, its floors (or nullptr)

  int column_index(const glm::ivec2& col) const {
    const glm::ivec2 w = col - lo;
    if (w.x < 0 || w.y < 0 || w.x >= size || w.y >= size) return -1;
    return w.y * size + w.x;
  }
};

ErosionWindow make_window(const NavData& data, const NavTile& tile) {
  ErosionWindow w;
  w.lo = tile.coord * data.chunk_size - glm::ivec2(data.erode_cells);
  w.size = data.chunk_size + 2 * data.erode_cells;
  w.first.assign(size_t(w.size * w.size + 1), 0);
  w.floors.assign(size_t(w.size * w.size), nullptr);
  uint32_t count = 0;
  for (int y = 0; y < w.size; ++y) {
    for (int x = 0; x < w.size; ++x) {
      const int i = y * w.size + x;
      w.first[size_t(i)] = count;
      std::span<const NavFloor> col = data.column(w.lo + glm::ivec2(x, y));
      if (!col.empty()) w.floors[size_t(i)] = col.data();
      count += uint32_t(col.size());
    }
  }
  w.first.back() = count;
  return w;
}

}  // namespace

// Chamfer distance (2 along a side, 3 across a corner, in half cells, as
// Recast's rcErodeWalkableArea) from every walkable floor to the nearest one
// that misses a link to a walkable floor on one of its four sides; floors
// nearer than 2 * erode_cells go. Floors too steep are not nodes at all.
void erode_tile(const NavData& data, NavTile& tile) {
  if (tile.empty()) return;
  const int limit = 2 * data.erode_cells;
  if (limit == 0) {
    for (NavFloor& f : tile.floors) f.region = f.walkable ? kUnassigned : kNoRegion;
    return;
  }
  const ErosionWindow w = make_window(data, tile);
  std::vector<uint8_t> dist(w.first.back(), uint8_t(limit));
  std::vector<std::vector<uint32_t>> buckets(static_cast<size_t>(limit));
  // Each queue entry: window column index and floor index in that column.
  auto pack = [](int col, int floor) { return uint32_t(col) << 8 | uint32_t(floor); };
  auto floor_at = [&](int col, int k) -> const NavFloor& { return w.floors[size_t(col)][k]; };
  // The walkable floor linked from f (at window column col) towards s: its
  // window column and index, or col = -1.
  auto walkable_side = [&](int col, const NavFloor& f, int s) -> std::pair<int, int> {
    if (f.link[s] == kNoLink) return {-1, 0};
    const glm::ivec2 at = w.lo + glm::ivec2(col % w.size, col / w.size) + kDirStep[s];
    const int side = w.column_index(at);
    if (side < 0) {  // beyond the window: only its linked-ness matters (it is not updated)
      const std::span<const NavFloor> c = data.column(at);
      return {c[f.link[s]].walkable ? -2 : -1, f.link[s]};
    }
    if (!floor_at(side, f.link[s]).walkable) return {-1, 0};
    return {side, f.link[s]};
  };
  for (int col = 0; col < w.size * w.size; ++col) {
    const uint32_t n = w.first[size_t(col) + 1] - w.first[size_t(col)];
    for (uint32_t k = 0; k < n; ++k) {
      const NavFloor& f = floor_at(col, int(k));
      bool border = !f.walkable;  // not a node: 0, never queued below
      for (int s = 0; s < 4 && !border; ++s) border = walkable_side(col, f, s).first == -1;
      if (!border) continue;
      dist[w.first[size_t(col)] + k] = 0;
      if (f.walkable) buckets[0].push_back(pack(col, int(k)));
    }
  }
  auto relax = [&](int col, int floor, int d) {
    if (col < 0 || d >= limit) return;
    uint8_t& slot = dist[w.first[size_t(col)] + uint32_t(floor)];
    if (d < slot) {
      slot = uint8_t(d);
      buckets[size_t(d)].push_back(pack(col, floor));
    }
  };
  for (int d = 0; d < limit; ++d) {
    for (size_t q = 0; q < buckets[size_t(d)].size(); ++q) {
      const uint32_t e = buckets[size_t(d)][q];
      const int col = int(e >> 8), floor = int(e & 0xFF);
      if (dist[w.first[size_t(col)] + uint32_t(floor)] != d) continue;  // stale
      const NavFloor& f = floor_at(col, floor);
      for (int s = 0; s < 4; ++s) {
        const auto [side, k] = walkable_side(col, f, s);
        if (side < 0) continue;
        relax(side, k, d + 2);
        // Across the corner: the side neighbour, then a quarter turn.
        const auto [corner, kc] = walkable_side(side, floor_at(side, k), (s + 1) & 3);
        relax(corner, kc, d + 3);
      }
    }
  }
  const glm::ivec2 own = tile.coord * data.chunk_size - w.lo;
  const int c = data.chunk_size;
  for (int lv = 0; lv < c; ++lv) {
    for (int lu = 0; lu < c; ++lu) {
      const int ray = lv * c + lu;
      const int col = (own.y + lv) * w.size + own.x + lu;
      for (uint32_t i = tile.column_first[size_t(ray)]; i < tile.column_first[size_t(ray) + 1]; ++i) {
        const uint32_t k = i - tile.column_first[size_t(ray)];
        NavFloor& f = tile.floors[i];
        f.region = f.walkable && dist[w.first[size_t(col)] + k] >= limit ? kUnassigned : kNoRegion;
      }
    }
  }
}

// ---- rectangles ------------------------------------------------------------

namespace {

struct TileFloors {
  const NavData& data;
  NavTile& tile;
  // Index of floor `level` of local column (lu, lv) in tile.floors, or -1.
  int at(int lu, int lv, int level) const {
    const int c = data.chunk_size;
    if (lu < 0 || lv < 0 || lu >= c || lv >= c || level == kNoLink) return -1;
    const int ray = lv * c + lu;
    const int i = tile.column_first[size_t(ray)] + level;
    return i < tile.column_first[size_t(ray) + 1] ? i : -1;
  }
  // The kept, unassigned floor linked from floor i at (lu, lv) in direction d, or -1.
  int free_neighbour(int lu, int lv, int i, int d) const {
    const NavFloor& f = tile.floors[size_t(i)];
    const int nu = lu + kDirStep[d].x, nv = lv + kDirStep[d].y;
    const int j = at(nu, nv, f.link[d]);
    if (j < 0) return -1;
    const NavFloor& g = tile.floors[size_t(j)];
    // One area per rectangle, so a filter's cost and flags hold for all of it.
    return g.region == kUnassigned && g.area == f.area ? j : -1;
  }
};

// The region of floor i's neighbour across side d, when it is in the tile
// and kept; -1 otherwise.
int region_across(const TileFloors& tf, int lu, int lv, int i, int d) {
  const int j = tf.at(lu + kDirStep[d].x, lv + kDirStep[d].y, tf.tile.floors[size_t(i)].link[d]);
  if (j < 0) return -1;
  const uint16_t region = tf.tile.floors[size_t(j)].region;
  return region < kUnassigned ? int(region) : -1;
}

// The floor of region `id` in local column (lu, lv), or -1.
int floor_of_region(const TileFloors& tf, int lu, int lv, uint16_t id) {
  const int ray = lv * tf.data.chunk_size + lu;
  for (int i = tf.tile.column_first[size_t(ray)]; i < tf.tile.column_first[size_t(ray) + 1]; ++i) {
    if (tf.tile.floors[size_t(i)].region == id) return i;
  }
  return -1;
}

// The first region (along the side) across side d (0: +u, 1: +v) of region
// `id` that is not in a chain yet and has the same area; -1 when none.
int next_in_chain(const TileFloors& tf, uint16_t id, int d, const std::vector<int>& chain_of) {
  const NavRegion& r = tf.tile.regions[id];
  const glm::ivec2 lo = r.lo - tf.tile.coord * tf.data.chunk_size, hi = r.hi - tf.tile.coord * tf.data.chunk_size;
  const int along = d == 0 ? 1 : 0;
  glm::ivec2 col = hi;
  for (int k = lo[along]; k <= hi[along]; ++k) {
    col[along] = k;
    const int i = floor_of_region(tf, col.x, col.y, id);
    const int other = i < 0 ? -1 : region_across(tf, col.x, col.y, i, d);
    if (other >= 0 && chain_of[size_t(other)] < 0 && tf.tile.regions[size_t(other)].area == r.area) return other;
  }
  return -1;
}

// Chains the tile's rectangles (see NavChain) and renumbers them so each
// chain's are consecutive, in chain order. From each rectangle not yet
// chained, in order: along +u while a next one is found, else along +v.
void chain_regions(const TileFloors& tf) {
  NavTile& tile = tf.tile;
  const size_t n = tile.regions.size();
  std::vector<int> chain_of(n, -1);
  std::vector<uint16_t> order;  // old ids, chain by chain
  order.reserve(n);
  tile.chains.clear();
  for (uint16_t r = 0; r < n; ++r) {
    if (chain_of[r] >= 0) continue;
    const int c = int(tile.chains.size());
    tile.chains.push_back({uint16_t(order.size()), 1});
    chain_of[r] = c;
    order.push_back(r);
    for (int d : {0, 1}) {
      for (int next = next_in_chain(tf, r, d, chain_of); next >= 0;
           next = next_in_chain(tf, order.back(), d, chain_of)) {
        chain_of[size_t(next)] = c;
        order.push_back(uint16_t(next));
      }
      if (order.size() - tile.chains.back().first > 1) break;
    }
    tile.chains.back().count = uint16_t(order.size() - tile.chains.back().first);
  }
  std::vector<uint16_t> new_id(n);
  std::vector<NavRegion> regions(n);
  for (size_t k = 0; k < n; ++k) {
    new_id[order[k]] = uint16_t(k);
    regions[k] = tile.regions[order[k]];
    regions[k].chain = uint16_t(chain_of[order[k]]);
  }
  tile.regions = std::move(regions);
  for (NavFloor& f : tile.floors) {
    if (f.region < kUnassigned) f.region = new_id[f.region];
  }
}

}  // namespace

// Greedy: from each free floor in scan order, the widest row, then as many
// rows as fit under it. On irregular ground most rectangles are one-cell
// strips (1,261 of the landscape's 1,646); chain_regions groups them. (The
// largest rectangle from each corner made as many rectangles, 1,651, that
// chained worse: 718 chains against 616.)
void cover_tile(const NavData& data, NavTile& tile) {
  tile.regions.clear();
  tile.chains.clear();
  tile.portals.clear();
  if (tile.empty()) return;
  const int c = data.chunk_size;
  const TileFloors tf{data, tile};
  const glm::ivec2 base = tile.coord * c;
  std::vector<int> row, next;
  for (int lv = 0; lv < c; ++lv) {
    for (int lu = 0; lu < c; ++lu) {
      const int ray = lv * c + lu;
      for (int i = tile.column_first[size_t(ray)]; i < tile.column_first[size_t(ray) + 1]; ++i) {
        if (tile.floors[size_t(i)].region != kUnassigned) continue;
        const uint16_t id = uint16_t(tile.regions.size());
        // Grow along +u.
        row.assign(1, i);
        tile.floors[size_t(i)].region = id;
        for (int u = lu; ; ++u) {
          const int j = tf.free_neighbour(u, lv, row.back(), 0);
          if (j < 0) break;
          tile.floors[size_t(j)].region = id;
          row.push_back(j);
        }
        // Grow along +v while the whole next row is free, linked upward and along.
        int rows = 1;
        for (int v = lv; v + 1 < c; ++v) {
          next.clear();
          for (size_t k = 0; k < row.size(); ++k) {
            const int j = tf.free_neighbour(lu + int(k), v, row[k], 1);
            if (j < 0) break;
            if (k > 0) {  // the new row's floors must be linked to each other
              const NavFloor& prev = tile.floors[size_t(next.back())];
              if (tf.at(lu + int(k), v + 1, prev.link[0]) != j) break;
            }
            next.push_back(j);
          }
          if (next.size() != row.size()) break;
          for (int j : next) tile.floors[size_t(j)].region = id;
          row = next;
          ++rows;
        }
        NavRegion r;
        r.lo = base + glm::ivec2(lu, lv);
        r.hi = r.lo + glm::ivec2(int(row.size()) - 1, rows - 1);
        r.area = tile.floors[size_t(i)].area;
        tile.regions.push_back(r);
      }
    }
  }
  // Height range of each region.
  for (NavRegion& r : tile.regions) {
    r.height_min = std::numeric_limits<float>::infinity();
    r.height_max = -std::numeric_limits<float>::infinity();
  }
  for (const NavFloor& f : tile.floors) {
    if (f.region == kNoRegion) continue;
    NavRegion& r = tile.regions[f.region];
    r.height_min = std::min(r.height_min, f.height);
    r.height_max = std::max(r.height_max, f.height);
  }
  chain_regions(tf);
}

// ---- portals ---------------------------------------------------------------

namespace {

// The floor of region `id` in a column of its rectangle.
const NavFloor* region_floor(const NavData& data, const glm::ivec2& col, uint16_t id) {
  for (const NavFloor& f : data.column(col)) {
    if (f.region == id) return &f;
  }
  return nullptr;
}

struct PortalRun {
  bool open = false;
  uint32_t tile = 0;
  uint16_t region = 0;
  glm::ivec2 first{0}, last{0};
  float height_first = 0.0f, height_last = 0.0f;
};

// The offset of region `from`'s first portal to region `to` of the same
// tile, or kNoPortal.
uint8_t portal_offset(const NavTile& tile, uint32_t slot, uint16_t from, uint16_t to) {
  const NavRegion& r = tile.regions[from];
  for (uint32_t k = 0; k < r.portal_count && k < kNoPortal; ++k) {
    const NavPortal& p = tile.portals[r.first_portal + k];
    if (p.to_tile == slot && p.to_region == to) return uint8_t(k);
  }
  return kNoPortal;
}

// Each rectangle's portals to its chain neighbours (NavRegion::to_next).
void link_chain_portals(const NavData& data, NavTile& tile) {
  const uint32_t slot = uint32_t(data.tile_slot(tile.coord));
  for (const NavChain& c : tile.chains) {
    for (uint16_t r = c.first; r < c.first + c.count; ++r) {
      NavRegion& reg = tile.regions[r];
      reg.to_next = r + 1 < c.first + c.count ? portal_offset(tile, slot, r, uint16_t(r + 1)) : kNoPortal;
      reg.to_previous = r > c.first ? portal_offset(tile, slot, r, uint16_t(r - 1)) : kNoPortal;
    }
  }
}

}  // namespace

void connect_tile(const NavData& data, NavTile& tile) {
  tile.portals.clear();
  for (uint16_t id = 0; id < tile.regions.size(); ++id) {
    NavRegion& r = tile.regions[id];
    r.first_portal = uint32_t(tile.portals.size());
    for (int d = 0; d < 4; ++d) {
      // Columns along side d, in increasing order of the other coordinate.
      const int along = (d == 0 || d == 2) ? 1 : 0;  // coordinate that varies
      glm::ivec2 col = (d == 0 || d == 1) ? r.hi : r.lo;
      const int from = r.lo[along], to = r.hi[along];
      PortalRun run;
      auto close = [&]() {
        if (!run.open) return;
        NavPortal p;
        p.to_tile = run.tile;
        p.to_region = run.region;
        p.from_region = id;
        p.dir = uint8_t(d);
        // The side lies half a cell out from the columns, the run's ends half a cell beyond.
        const glm::vec2 out = glm::vec2(kDirStep[d]) * 0.5f;
        glm::vec2 a = glm::vec2(run.first) + out, b = glm::vec2(run.last) + out;
        a[along] -= 0.5f;
        b[along] += 0.5f;
        p.a = a;
        p.b = b;
        p.height_a = run.height_first;
        p.height_b = run.height_last;
        tile.portals.push_back(p);
        run.open = false;
      };
      for (int k = from; k <= to; ++k) {
        col[along] = k;
        const NavFloor* f = region_floor(data, col, id);
        const glm::ivec2 other = col + kDirStep[d];
        int other_slot = 0;
        const int other_index = f ? data.column_in_tile(other, &other_slot) : -1;
        const NavFloor* g = nullptr;
        if (other_index >= 0 && f->link[d] != kNoLink) {
          const NavTile& ot = data.tiles[size_t(other_slot)];
          const uint32_t gi = ot.column_first[size_t(other_index)] + f->link[d];
          if (gi < ot.column_first[size_t(other_index) + 1]) g = &ot.floors[gi];
        }
        if (!g || !g->kept()) {
          close();
          continue;
        }
        const float hh = 0.5f * (f->height + g->height);
        if (run.open && (run.tile != uint32_t(other_slot) || run.region != g->region)) close();
        if (!run.open) {
          run = {true, uint32_t(other_slot), g->region, col, col, hh, hh};
        } else {
          run.last = col;
          run.height_last = hh;
        }
      }
      close();
    }
    r.portal_count = uint32_t(tile.portals.size()) - r.first_portal;
  }
  link_chain_portals(data, tile);
}

// ---- components ------------------------------------------------------------

namespace {

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];
    x = parent[x];
  }
  return x;
}

RegionBox box_of(const NavRegion& r, uint32_t dense) {
  RegionBox b;
  b.lo = glm::vec2(r.lo) - 0.5f;
  b.hi = glm::vec2(r.hi) + 0.5f;
  b.height_min = r.height_min;
  b.height_max = r.height_max;
  b.dense = dense;
  b.area = r.area;
  return b;
}

void grow(RegionBox& bounds, const RegionBox& b) {
  bounds.lo = glm::min(bounds.lo, b.lo);
  bounds.hi = glm::max(bounds.hi, b.hi);
  bounds.height_min = std::min(bounds.height_min, b.height_min);
  bounds.height_max = std::max(bounds.height_max, b.height_max);
}

// NavData::component_boxes and their runs (a counting sort by component,
// stable, so each component's boxes stay in dense order).
void group_boxes_by_component(NavData& data) {
  std::vector<uint32_t> first(data.component_count + 1, 0);
  for (const NavTile& t : data.tiles) {
    for (const NavRegion& r : t.regions) ++first[r.component + 1];
  }
  std::partial_sum(first.begin(), first.end(), first.begin());
  data.component_boxes.resize(data.dense_count);
  std::vector<uint32_t> next(first.begin(), first.end() - 1);
  for (const NavTile& t : data.tiles) {
    for (uint32_t r = 0; r < t.regions.size(); ++r) {
      data.component_boxes[next[t.regions[r].component]++] = box_of(t.regions[r], t.dense_first + r);
    }
  }
  data.component_runs.clear();
  data.component_run_first.assign(data.component_count + 1, 0);
  for (uint32_t c = 0; c < data.component_count; ++c) {
    data.component_run_first[c] = uint32_t(data.component_runs.size());
    for (uint32_t i = first[c]; i < first[c + 1]; ++i) {
      const RegionBox& b = data.component_boxes[i];
      const bool same_tile =
          i > first[c] && data.dense_tile[b.dense] == data.dense_tile[data.component_boxes[i - 1].dense];
      if (!same_tile) data.component_runs.push_back({b, i, 0});
      RegionBoxRun& run = data.component_runs.back();
      grow(run.bounds, b);
      ++run.count;
    }
  }
  data.component_run_first[data.component_count] = uint32_t(data.component_runs.size());
}

}  // namespace

void relabel(NavData& data) {
  uint32_t count = 0, floors = 0, nodes = 0;
  data.dense_tile.clear();
  data.node_tile.clear();
  for (uint32_t s = 0; s < data.tiles.size(); ++s) {
    NavTile& t = data.tiles[s];
    t.dense_first = count;
    t.node_first = nodes;
    t.dense_floor_first = floors;
    floors += uint32_t(t.floors.size());
    count += uint32_t(t.regions.size());
    nodes += uint32_t(t.chains.size());
    data.dense_tile.insert(data.dense_tile.end(), t.regions.size(), s);
    data.node_tile.insert(data.node_tile.end(), t.chains.size(), s);
  }
  data.dense_count = count;
  data.node_count = nodes;
  for (NavTile& t : data.tiles) {
    for (NavPortal& p : t.portals) {
      const NavTile& to = data.tiles[p.to_tile];
      p.to_node = to.node_first + to.regions[p.to_region].chain;
    }
  }
  data.dense_floor_count = floors;
  std::vector<uint32_t> parent(count);
  std::iota(parent.begin(), parent.end(), 0u);
  for (const NavTile& t : data.tiles) {
    for (uint32_t r = 0; r < t.regions.size(); ++r) {
      const NavRegion& reg = t.regions[r];
      for (uint32_t k = 0; k < reg.portal_count; ++k) {
        const NavPortal& p = t.portals[reg.first_portal + k];
        const uint32_t a = find_root(parent, t.dense_first + r);
        const uint32_t b = find_root(parent, data.tiles[p.to_tile].dense_first + p.to_region);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
  }
  std::vector<uint32_t> label(count, UINT32_MAX);
  uint32_t components = 0;
  for (NavTile& t : data.tiles) {
    for (uint32_t r = 0; r < t.regions.size(); ++r) {
      const uint32_t root = find_root(parent, t.dense_first + r);
      if (label[root] == UINT32_MAX) label[root] = components++;
      t.regions[r].component = label[root];
    }
  }
  data.component_count = components;
  group_boxes_by_component(data);
}

}  // namespace ldc::detail
