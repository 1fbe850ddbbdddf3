// Internals of nav/: tiles of floors, rectangles, portals. Everything here is
// in lattice units: a column is named by its global node coordinates (u, v)
// on the two horizontal axes (axis_u(up), axis_v(up)), a height is a depth
// along the up axis in cells.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/world.h"
#include "nav/nav.h"

namespace ldc::detail {

inline constexpr uint8_t kNoLink = 0xFF;
inline constexpr float kRiserNormalUp = 0.17364818f;  // sin(10 degrees)
inline constexpr uint16_t kNoRegion = 0xFFFF;       // not walkable, or eroded away
inline constexpr uint16_t kUnassigned = 0xFFFE;     // kept by erosion, not yet in a rectangle
inline constexpr uint8_t kNoPortal = 0xFF;
inline constexpr int kMaxLevels = 254;  // floors per column kept (link indices are bytes)
// Floors per tile kept (16-bit offsets and region ids): 63 floors in every
// column of a 32 x 32 tile, 15 at C = 64. Floors beyond it are dropped and
// counted (NavStats::dropped_floors).
inline constexpr size_t kMaxTileFloors = 65000;

// Directions in the ground plane: 0 +u, 1 +v, 2 -u, 3 -v.
inline constexpr glm::ivec2 kDirStep[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
inline constexpr int opposite(int dir) { return (dir + 2) & 3; }

// One floor: the top of a solid span with enough room above. Each building
// phase writes only its own tile's fields and reads its neighbours' fields
// that earlier phases wrote, so tiles build in parallel without races:
// extraction sets steep_normal, linking sets link and walkable, erosion
// sets region to kUnassigned (kept) or kNoRegion, covering sets region.
struct NavFloor {
  float height = 0.0f;   // depth of the floor along up [Units: cells]
  float ceiling = 0.0f;  // depth of the next solid above, or +inf
  uint8_t link[4] = {kNoLink, kNoLink, kNoLink, kNoLink};  // floor index in the neighbour column (both ways)
  bool steep_normal = false;  // the stored normal is steeper than max_slope
  bool riser = false;         // the stored normal is within 10 degrees of horizontal
  bool walkable = false;      // slope walkable (its normal or a linked neighbour's)
  uint16_t region = kNoRegion;  // rectangle (local to the tile) holding it
  uint8_t area = 0;             // NavConfig::material_areas of its surface's material

  bool kept() const { return region != kNoRegion; }  // walkable and survived erosion
};

// A rectangle of columns [lo, hi] (inclusive, global) whose floors are linked.
struct NavRegion {
  glm::ivec2 lo{0};
  glm::ivec2 hi{0};
  float height_min = 0.0f;
  float height_max = 0.0f;
  uint32_t first_portal = 0;  // into NavTile::portals
  uint32_t portal_count = 0;
  uint32_t component = 0;     // connected island id (valid after relabelling)
  uint8_t area = 0;           // every floor of a rectangle has the same
  uint16_t chain = 0;         // the tile's chain holding it (the A* node)
  // The portals to the next and the previous rectangle of the chain (offsets
  // from first_portal; kNoPortal at the chain's ends).
  uint8_t to_next = kNoPortal;
  uint8_t to_previous = kNoPortal;
};

// A chain: rectangles of one tile and area, each the next one's neighbour
// across its +u side (or each across its +v side), numbered consecutively
// in that order: regions [first, first + count). The A* runs over chains
// (the landscape's 1,646 rectangles, mostly one-cell strips along diagonal
// edges, make 616 chains) and the funnel over the rectangles of the chains
// it chose, entry to exit, so paths stay exact. Chains stay inside a tile,
// so an update re-chains only the tiles it re-covers.
struct NavChain {
  uint16_t first = 0;
  uint16_t count = 0;
  bool holds(uint16_t region) const { return uint16_t(region - first) < count; }
};

// A directed portal from a region to a neighbouring one: the shared side's
// segment from a to b (2D lattice coordinates), heights at both ends.
struct NavPortal {
  uint32_t to_tile = 0;
  uint32_t to_node = 0;  // the target's search node: its chain's dense index (set by relabel)
  uint16_t to_region = 0;
  uint16_t from_region = 0;  // the source region (in this tile)
  uint8_t dir = 0;  // side of the source region it lies on
  glm::vec2 a{0.0f};
  glm::vec2 b{0.0f};
  float height_a = 0.0f;
  float height_b = 0.0f;
};

// A region's ground-plane squares and height range, for finding the region
// of an island nearest a point without touching the tiles.
struct RegionBox {
  glm::vec2 lo{0.0f};  // corners of its columns' squares (columns -/+ half a cell)
  glm::vec2 hi{0.0f};
  float height_min = 0.0f;
  float height_max = 0.0f;
  uint32_t dense = 0;
  uint8_t area = 0;
};

// The boxes of one component in one tile (a run of NavData::component_boxes)
// and the box bounding them all: a scan skips the run when that is too far.
struct RegionBoxRun {
  RegionBox bounds;
  uint32_t first = 0;
  uint32_t count = 0;
};

struct NavTile {
  glm::ivec2 coord{0};                 // chunk coordinates on (u, v)
  std::vector<uint16_t> column_first;  // C*C + 1 offsets into floors; empty when no floors
  std::vector<NavFloor> floors;
  std::vector<NavRegion> regions;      // grouped by chain, in chain order
  std::vector<NavChain> chains;
  std::vector<NavPortal> portals;      // grouped by region
  uint32_t dense_first = 0;            // first dense region index
  uint32_t node_first = 0;             // first search node (dense chain index)
  uint32_t dense_floor_first = 0;      // first dense floor index (for grid searches)
  uint32_t dropped_floors = 0;         // floors beyond kMaxTileFloors, left out

  bool empty() const { return floors.empty(); }
  size_t memory_bytes() const;
};

// An off-mesh link and where its ends landed (dense regions, nav points).
struct NavLinkSlot {
  uint32_t id = 0;
  NavLink link;
  bool attached = false;
  uint32_t region_a = 0, region_b = 0;
  glm::dvec3 a{0.0}, b{0.0};
};

// A way out of a search node (a chain) by a link: its slot, and whether it runs b -> a.
struct LinkExit {
  uint32_t node = 0;
  uint32_t slot = 0;
  bool reversed = false;
  bool operator<(const LinkExit& o) const { return node < o.node; }
  // The regions (dense) it takes off from and lands in.
  uint32_t take_off(const NavLinkSlot& l) const { return reversed ? l.region_b : l.region_a; }
  uint32_t landing(const NavLinkSlot& l) const { return reversed ? l.region_a : l.region_b; }
};

struct NavData {
  NavConfig config;
  Lattice lattice;
  int chunk_size = 32;
  int up = 2, axis_u = 0, axis_v = 1;  // lattice axes
  int chunk_shift = 5;                 // log2(chunk_size)
  glm::ivec2 tile_origin{0};           // first tile (chunk coordinates on u, v)
  glm::ivec2 tile_dims{0};
  glm::ivec3 world_chunk_origin{0};    // box the mesh was built for
  glm::ivec3 world_chunk_dims{0};
  // Agent limits in cells.
  float climb_cells = 0.0f;
  float height_cells = 0.0f;
  float min_normal_up = 0.0f;
  float max_gradient_sq = 0.0f;        // tan^2(max_slope): cell-scale slope limit
  int erode_cells = 0;                 // ceil(radius / h)
  std::vector<NavTile> tiles;          // tile_dims.x * tile_dims.y, x fastest
  std::vector<uint32_t> dense_tile;    // dense region index -> tile slot
  uint32_t dense_count = 0;
  std::vector<uint32_t> node_tile;     // search node (dense chain index) -> tile slot
  uint32_t node_count = 0;
  uint32_t dense_floor_count = 0;
  uint32_t component_count = 0;
  // Region boxes grouped by component (then by tile, in dense order), in runs
  // per tile; component c's runs are [component_run_first[c], [c + 1]).
  std::vector<RegionBox> component_boxes;
  std::vector<RegionBoxRun> component_runs;
  std::vector<uint32_t> component_run_first;
  // Off-mesh links, the exits they give each region (sorted by region), and
  // per component the island it joins through links (the island check).
  std::vector<NavLinkSlot> links;
  uint32_t next_link_id = 0;
  std::vector<LinkExit> link_exits;
  std::vector<uint32_t> island_of_component;
  uint32_t island(uint32_t component) const {
    return component < island_of_component.size() ? island_of_component[component] : component;
  }

  int tile_slot(const glm::ivec2& tile) const {
    const glm::ivec2 t = tile - tile_origin;
    return t.y * tile_dims.x + t.x;
  }
  bool contains_tile(const glm::ivec2& tile) const {
    const glm::ivec2 t = tile - tile_origin;
    return t.x >= 0 && t.y >= 0 && t.x < tile_dims.x && t.y < tile_dims.y;
  }
  glm::ivec2 tile_of_column(const glm::ivec2& column) const {
    return {column.x >> chunk_shift, column.y >> chunk_shift};
  }
  // Floors of a global column; empty when outside the mesh or floorless.
  std::span<const NavFloor> column(const glm::ivec2& column) const;
  // The column's index in its tile (its vertical ray), and the tile slot;
  // -1 when outside the mesh or in a floorless tile.
  int column_in_tile(const glm::ivec2& column, int* tile_slot_out) const;

  // The search node (chain) of a dense region.
  uint32_t node_of(uint32_t dense_region) const {
    const NavTile& t = tiles[dense_tile[dense_region]];
    return t.node_first + t.regions[dense_region - t.dense_first].chain;
  }

  // Lattice (u, v, up) of a world position, and back.
  glm::dvec3 to_nav(const glm::dvec3& world) const;
  glm::dvec3 to_world(const glm::dvec3& nav) const;
};

// Region reference: tile slot in the high bits, region in the low 16.
inline uint64_t region_ref(uint32_t tile, uint16_t region) {
  return (uint64_t{tile} << 16) | region;
}
inline uint32_t ref_tile(uint64_t ref) { return uint32_t(ref >> 16); }
inline uint16_t ref_region(uint64_t ref) { return uint16_t(ref & 0xFFFF); }

// --- building steps (nav/tile_build.cpp) ---
void setup_nav_data(NavData& data, const World& world, const NavConfig& config);
// Floors of one tile from the world's vertical rays; links within the tile
// and to the neighbours' floors are left for link_tile().
void extract_tile(const NavData& data, const World& world, NavTile& tile);
// Links every floor of the tile to its neighbour columns' floors, both ways
// (a link holds only when each floor is the other's best: neighbour tiles
// must be extracted), and decides whether its slope is walkable: by its
// stored normal, or by a linked neighbour's (see slope_walkable). Point
// normals see every ripple finer than a cell: on the default landscape, thin
// creases of steep normals alone split the walkable ground into many more
// islands than a navmesh of the contoured mesh has.
void link_tile(const NavData& data, NavTile& tile);
// Erosion (needs the neighbours linked), then rectangles.
void erode_tile(const NavData& data, NavTile& tile);
void cover_tile(const NavData& data, NavTile& tile);
// Portals of every region of the tile (neighbours covered).
void connect_tile(const NavData& data, NavTile& tile);
// Dense numbering and connected components over all tiles.
void relabel(NavData& data);
// Snaps every link's ends to floors and rebuilds link_exits and the islands
// (nav/links.cpp); after every relabel and every link change.
void attach_links(NavData& data);
// The same for one newly added link slot k, leaving the others as they are.
void attach_one(NavData& data, uint32_t k);

}  // namespace ldc::detail
