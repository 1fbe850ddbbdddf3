// Internals of nav/: search state kept by a NavQuery between calls.
// Positions are nav coordinates (u, v, height) in cells.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "nav/detail/nav_data.h"

namespace ldc::detail {

struct FloorHit {
  int tile = 0;          // tile slot
  uint32_t floor = 0;    // index in the tile's floors
  glm::ivec2 column{0};  // the floor's column
  glm::dvec3 point{0.0};  // in the column's square (its edge may round to the next column)
  double distance = 0.0;
};

// The kept floor nearest q within reach (both in cells), searched in rings
// of columns; only floors the filter passes, when one is given.
std::optional<FloorHit> nearest_floor(const NavData& data, const glm::dvec3& q,
                                      const glm::dvec3& reach, const NavFilter* filter = nullptr);

// The region of a dense index (and its tile slot when asked).
const NavRegion& dense_to_region(const NavData& data, uint32_t dense, uint32_t* slot = nullptr);
// The point of region `dense` nearest q: inside its rectangle, on its floor.
glm::dvec3 nearest_point_of_region(const NavData& data, uint32_t dense, const glm::dvec3& q);

// Per-node arrays stamped with a generation, so a new search needs no clearing.
struct SearchNodes {
  std::vector<uint32_t> stamp;
  std::vector<float> cost;           // g
  std::vector<float> estimate;       // f = g + h, as pushed
  std::vector<uint32_t> parent;      // node index, or UINT32_MAX
  std::vector<uint32_t> via;         // chain search: portal index in the parent's tile, or kViaLink | link exit
  std::vector<glm::vec3> position;   // where the node is entered
  std::vector<uint8_t> closed;
  std::vector<std::pair<float, uint32_t>> heap;  // (f, node), min-heap by f
  uint32_t generation = 0;
  int used = 0;

  void reset(uint32_t count);
  bool seen(uint32_t n) const { return stamp[n] == generation; }
  void touch(uint32_t n);
  void push(uint32_t n, float f);
  bool pop(uint32_t* n);
};

struct GridSearchState {
  SearchNodes nodes;
};

// A* over the 8-connected floor grid (no corner cutting); lengths in cells.
NavPath grid_search(const NavData& data, const FloorHit& start, const FloorHit& goal,
                    int max_nodes, GridSearchState& state);

inline constexpr uint32_t kViaLink = 0x80000000u;

// A portal's ends as seen walking through it (for string pulling).
struct FunnelPortal {
  glm::dvec3 left{0.0};
  glm::dvec3 right{0.0};
};

struct NavSearch {
  SearchNodes nodes;
  NavFilter filter;
  float heuristic_scale = 0.999f;  // Detour's H_SCALE times the cheapest cost
  bool filter_areas = false;       // the filter turns some area away (else no area lookups)
  GridSearchState grid;
  bool active = false;
  bool done = false;
  bool reached = false;
  bool out_of_nodes = false;
  bool goal_reachable = false;
  glm::dvec3 start{0.0}, target{0.0};
  uint32_t start_region = 0, target_region = 0;  // dense regions
  uint32_t start_node = 0, target_node = 0;      // their chains: the search's nodes
  uint32_t best = 0;  // explored node nearest the target
  double best_distance = 0.0;

  void reset(uint32_t node_count);
  void push_start(uint32_t node, const glm::dvec3& at, double to_target);
  // Scratch for expand_one: per rectangle of the chain expanded, where it is
  // entered and the cost there.
  std::vector<glm::vec3> chain_at;
  std::vector<float> chain_cost;
  uint16_t entry_region(const NavData& data, uint32_t n) const;
  void walk_chain(const NavData& data, uint32_t n, float own_cost);
  // Expands the cheapest open node; false when the search is over.
  bool expand_one(const NavData& data, int max_nodes);
  // Offers node m, entered at `at` from n with cost g so far.
  void relax(const NavData& data, uint32_t n, uint32_t m, const glm::vec3& at, float g, uint32_t via,
             int max_nodes);
  // The corridor to the target (or the best node) pulled taut; lengths in cells.
  NavPath make_path(const NavData& data);
  std::vector<uint32_t> corridor;  // scratch for make_path
  std::vector<FunnelPortal> funnel;
};

// String pulling (the funnel algorithm) over portals whose first and last
// are the start and the end (as {p, p}): appends the corners after the start
// to `out`, whose last is the start.
void pull_string_onto(const std::vector<FunnelPortal>& portals, std::vector<glm::dvec3>& out);

}  // namespace ldc::detail
