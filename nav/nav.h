// Navigation on a World: walkable surfaces read off the vertical span lists,
// a region graph over them, A* with a node budget (runnable in slices), path
// smoothing by string pulling, and incremental rebuilds after edits.
//
// Walkable surfaces. The lattice's rays along the up axis are the columns of
// a heightfield with any number of levels (caves, overhangs, bridges): every
// exit point of a vertical ray is the top of a solid span, a floor. A floor is
// walkable when its stored normal is within max_slope of up and the free
// height above it (to the next span, or the top of the world) is at least
// agent_height; a steeper normal is walkable where the height steps to the
// neighbouring columns keep the ground within max_slope over a cell (ripples
// finer than a cell do not block), and a riser (a normal within 10 degrees
// of horizontal, where the ray caught a step's edge) where it is linked to a
// floor with a walkable normal. Two floors in side-by-side columns are linked when the step
// between them is at most max_climb and the gap between the higher floor and
// the lower ceiling still holds the agent. Walkable floors within
// agent_radius of an unlinked side (a wall, a drop, the world's edge) are
// eroded away, so the agent's centre can go anywhere that remains. The
// navigation cell is the lattice cell h: each column stands for the h x h
// square around it.
//
// Regions. Per tile (the column of chunks above one chunk of the ground plane)
// the remaining floors are covered greedily by rectangles of columns whose
// floors are all linked to each other; a straight line inside a rectangle
// stays on linked floors. Rectangles meet at portals (the runs of linked
// floors along their shared sides). Along irregular edges most rectangles
// are one-cell strips, so each tile's rectangles are chained: each the next
// one's neighbour across its +u side (or each across its +v side). A* runs
// over the chains (the landscape's 1,646 rectangles make 616 chains; tens to
// hundreds of times fewer nodes than the floor grid, measured by
// bench/bench_nav.cpp), walking each chain's rectangles in order from where
// it is entered, and string pulling (the funnel algorithm) through the
// portals of the chosen rectangles gives the shortest any-angle polyline
// within them. Connected components of the region graph are kept up to
// date, so a query for an unreachable goal knows at once and returns the
// path to the point of the start's island that is nearest the goal (found
// over that island's rectangles only, skipping tiles' runs of them that are
// farther than the best so far), with status kUnreachable.
//
// Incremental. NavMesh::update() takes the chunks an edit changed
// (WorldEditor::take_dirty) and re-extracts only their tiles, re-erodes and
// re-covers those and the neighbours within agent_radius of the change,
// reconnects their portals and relabels the components.
//
// Thread safety: a NavMesh is immutable between update() calls and may be
// read by any number of NavQuery objects at once, one per thread. A NavQuery
// holds one search's state and is not thread-safe; it must not outlive its
// NavMesh, and update() must not run while queries do.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/context.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

namespace detail {
struct NavData;
struct NavSearch;
}  // namespace detail

// The agent and the ground it walks on. Defaults are RecastDemo's.
struct NavConfig {
  int up_axis = 2;                  // lattice axis pointing up: 0 x, 1 y, 2 z [Limit: 0, 1, 2]
  double agent_height = 2.0;        // free height needed above a floor [Units: m] [Limit: > 0, <= 1000]
  double agent_radius = 0.6;        // erosion from walls and drops [Units: m] [Limit: 0 .. chunk width / 2]
  double max_climb = 0.9;           // highest step between neighbouring floors [Units: m] [Limit: >= 0]
  double max_slope_degrees = 45.0;  // steepest walkable floor [Units: degrees] [Limit: 0 .. 89]
  // Recast's span filters (rcFilter*), each on by default as in RecastDemo:
  // A floor too steep to walk, at most max_climb above a walkable floor in
  // the same column (a kerb or a stair nosing), is walkable.
  bool filter_low_hanging_obstacles = true;
  // A floor with a drop deeper than max_climb on one of its four sides (a
  // ledge; the world's edge counts) is not walkable. Applied when the
  // agent's radius rounds to 0 cells: with a radius, erosion already keeps
  // the agent that far from the ledge.
  bool filter_ledge_spans = true;
  // A floor with less than agent_height free above it is not walkable. Off:
  // such floors (and the links between them) are kept, e.g. for an agent
  // that may crouch, and only the slope and climb rules apply.
  bool filter_low_height_spans = true;
  // Areas, as Recast's area ids: a floor's area is material_areas[its
  // surface's material] (materials past the end: area 0). NavFilter's costs
  // and flags are per area, and a rectangle never spans two areas. The
  // default, empty, puts everything in area 0 (fewest rectangles); give the
  // materials a filter must tell apart their own areas. [Limit: areas 0 .. 63]
  std::vector<uint8_t> material_areas;
};

// An error naming the bad field, or ok.
Status check_nav_config(const NavConfig& config, const World& world);

struct NavStats {
  size_t tiles = 0;            // tiles holding walkable floors
  size_t floors = 0;           // floors with room for the agent
  size_t dropped_floors = 0;   // floors left out: over 254 in a column or 65,000 in a tile
  size_t walkable = 0;         // floors left after erosion
  size_t regions = 0;          // rectangles
  size_t chains = 0;           // chains of rectangles: the A* nodes
  size_t portals = 0;          // directed portals
  size_t components = 0;       // connected walkable islands
  size_t memory_bytes = 0;     // everything the NavMesh holds
  double bytes_per_floor() const { return floors ? double(memory_bytes) / double(floors) : 0.0; }
};

struct NavUpdateStats {
  size_t dirty_tiles = 0;      // tiles re-extracted from the world
  size_t recovered_tiles = 0;  // tiles re-eroded and re-covered (dirty ones and neighbours)
  bool full_rebuild = false;   // the world's box changed: everything was rebuilt
  double seconds = 0.0;
};

// An off-mesh link: a jump, a ladder, a teleporter. Its ends snap to the
// nearest walkable floor within `radius` (Detour's offMeshConRad); a link
// whose end has no floor there is kept but unused until an update puts one
// there (NavMesh::link_attached says which).
struct NavLink {
  glm::dvec3 a{0.0}, b{0.0};  // ends [Units: m]
  bool bidirectional = true;  // false: from a to b only
  // Cost of taking the link, in metres of walking on cost-1 ground; < 0
  // means the straight distance between the ends. [Limit: finite]
  double cost = -1.0;
  uint16_t flags = 1;   // matched by NavFilter's include/exclude flags
  double radius = 1.0;  // [Units: m] [Limit: > 0, <= 100]
};

// An error naming the bad NavLink field, or ok (what add_link checks first).
Status check_nav_link(const NavLink& link);

class NavMesh {
 public:
  // Builds from the whole world; parallel over tiles (TBB). The config is
  // checked first; ctx may cancel.
  static Result<NavMesh> build(const World& world, const NavConfig& config,
                               Context* ctx = nullptr);

  // Brings the mesh up to date with `world` after the edits that changed the
  // listed chunks. On error the mesh is left as it was.
  Result<NavUpdateStats> update(const World& world, std::span<const DirtyChunk> dirty);

  // Off-mesh links, added and removed at any time without a rebuild (not
  // while queries run: like update()). Ids are never reused.
  Result<uint32_t> add_link(const NavLink& link);
  Status remove_link(uint32_t id);
  // Whether both ends of link `id` found a walkable floor (false for unknown ids).
  bool link_attached(uint32_t id) const;

  const NavConfig& config() const;
  const Lattice& lattice() const;
  NavStats stats() const;

  NavMesh(NavMesh&&) noexcept;
  NavMesh& operator=(NavMesh&&) noexcept;
  ~NavMesh();

 private:
  friend class NavQuery;
  explicit NavMesh(std::unique_ptr<detail::NavData> data);
  std::unique_ptr<detail::NavData> data_;
};

// A walkable place: a position on a floor and the region holding it.
struct NavPoint {
  glm::dvec3 position{0.0};  // on the floor [Units: m]
  uint64_t region = 0;       // opaque region reference
  double distance = 0.0;     // from the point asked about [Units: m]
};

enum class PathStatus : uint8_t {
  kComplete = 0,     // reaches the goal
  kUnreachable = 1,  // the goal's island differs: ends at the start island's point nearest the goal
  kOutOfNodes = 2,   // the node budget ran out: ends at the explored region nearest the goal
};
const char* path_status_name(PathStatus status);

// An off-mesh link the path takes: from corners[corner] to corners[corner + 1].
struct NavPathLink {
  uint32_t id = 0;
  size_t corner = 0;
};

struct NavPath {
  PathStatus status = PathStatus::kComplete;
  std::vector<glm::dvec3> corners;  // start, turning points, end; on the floors [Units: m]
  std::vector<NavPathLink> links;   // off-mesh links taken, in order
  double length = 0.0;              // of the corner polyline, in 3D [Units: m]
  size_t regions = 0;               // rectangles in the corridor
  size_t nodes_searched = 0;        // A* nodes used (the budget counts these)
};

// Which ground a query may use and what it costs, as Detour's dtQueryFilter,
// keyed by the floor's area (NavConfig::material_areas). A floor is usable
// when its area's flags share a bit with include_flags and none with
// exclude_flags; walking a metre on it costs its area's cost. Off-mesh links
// are matched by their own flags.
struct NavFilter {
  std::vector<double> area_cost;     // by area; missing areas cost 1 [Limit: >= 0.01, finite]
  std::vector<uint16_t> area_flags;  // by area; missing areas have flags 1
  uint16_t include_flags = 0xFFFF;
  uint16_t exclude_flags = 0;

  double cost(uint8_t area) const { return area < area_cost.size() ? area_cost[area] : 1.0; }
  uint16_t flags(uint8_t area) const { return area < area_flags.size() ? area_flags[area] : uint16_t{1}; }
  bool passes_flags(uint16_t f) const { return (f & include_flags) != 0 && (f & exclude_flags) == 0; }
  bool passes(uint8_t area) const { return passes_flags(flags(area)); }
};
// An error naming the bad cost, or ok.
Status check_nav_filter(const NavFilter& filter);

struct PathQueryOptions {
  // Start and goal snap to floors the filter passes; the search uses only
  // those, at their costs. The straight-line heuristic is scaled by the
  // cheapest cost, so paths stay shortest by cost (links cheaper than their
  // length can make them not so).
  NavFilter filter;
  // How far from the start and goal a floor may be found [Units: m] [Limit: > 0]
  glm::dvec3 search_half_extents{2.0, 2.0, 4.0};  // along x, y, z (the up axis: 4)
};

// Whether a sliced search needs more steps.
enum class SliceStatus : uint8_t { kInProgress, kDone };

class NavQuery {
 public:
  // max_nodes: the A* node budget, in chains of rectangles [Limit: 16 .. 1 << 20]
  // (Detour's default is 2048).
  explicit NavQuery(const NavMesh& mesh, int max_nodes = 2048);
  ~NavQuery();
  NavQuery(const NavQuery&) = delete;
  NavQuery& operator=(const NavQuery&) = delete;

  // The nearest walkable floor within the half extents of p (the up axis
  // component is the vertical reach). kInvalidArgument for non-finite input
  // or extents <= 0, and "no walkable floor within ..." when there is none.
  Result<NavPoint> nearest_walkable(const glm::dvec3& p, const glm::dvec3& half_extents) const;

  // The whole search in one call: begin_path + step until done + finish_path.
  Result<NavPath> find_path(const glm::dvec3& from, const glm::dvec3& to,
                            const PathQueryOptions& options = {});

  // Sliced form for spreading one search over frames: begin_path, then
  // step(n) (at most n node expansions per call) until kDone, then
  // finish_path. Any call starts over a search begun before it.
  Status begin_path(const glm::dvec3& from, const glm::dvec3& to,
                    const PathQueryOptions& options = {});
  Result<SliceStatus> step(int max_expansions);
  Result<NavPath> finish_path();

  // Plain A* over the 8-connected floor grid (no regions, no smoothing):
  // the baseline the region search is measured against (bench/bench_nav.cpp)
  // and a reference for tests. Length is along grid steps.
  Result<NavPath> find_grid_path(const glm::dvec3& from, const glm::dvec3& to,
                                 const PathQueryOptions& options = {});

  int max_nodes() const { return max_nodes_; }

 private:
  const NavMesh& mesh_;
  int max_nodes_;
  std::unique_ptr<detail::NavSearch> search_;
};

}  // namespace ldc
