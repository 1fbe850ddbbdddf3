// A* over rectangles (with a node budget, one expansion at a time so it can
// run in slices), string pulling, and the plain grid A* baseline.
#include <algorithm>
#include <cmath>
#include <limits>

#include "nav/detail/nav_search.h"

namespace ldc::detail {

// ---- search nodes ----------------------------------------------------------

void SearchNodes::reset(uint32_t count) {
  if (stamp.size() != count) {
    stamp.assign(count, 0);
    cost.assign(count, 0.0f);
    estimate.assign(count, 0.0f);
    parent.assign(count, UINT32_MAX);
    via.assign(count, 0);
    position.assign(count, glm::vec3(0.0f));
    closed.assign(count, 0);
    generation = 0;
  }
  if (++generation == 0) {  // wrapped: clear once every 2^32 searches
    std::fill(stamp.begin(), stamp.end(), 0u);
    generation = 1;
  }
  heap.clear();
  used = 0;
}

void SearchNodes::touch(uint32_t n) {
  stamp[n] = generation;
  closed[n] = 0;
  parent[n] = UINT32_MAX;
  ++used;
}

namespace {
// A function object, not a function pointer, so the heap's compares inline
// (they were a tenth of the landscape's query time).
struct HeapLess {
  bool operator()(const std::pair<float, uint32_t>& a, const std::pair<float, uint32_t>& b) const {
    return a.first > b.first;  // std heap is a max-heap: invert for the smallest f on top
  }
};
}  // namespace

void SearchNodes::push(uint32_t n, float f) {
  heap.emplace_back(f, n);
  std::push_heap(heap.begin(), heap.end(), HeapLess{});
}

bool SearchNodes::pop(uint32_t* n) {
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), HeapLess{});
    const uint32_t top = heap.back().second;
    heap.pop_back();
    if (!closed[top]) {  // entries left behind by a later, cheaper push are skipped
      *n = top;
      return true;
    }
  }
  return false;
}

// ---- region A* -------------------------------------------------------------

const NavRegion& dense_to_region(const NavData& data, uint32_t dense, uint32_t* slot) {
  const uint32_t s = data.dense_tile[dense];
  if (slot) *slot = s;
  const NavTile& t = data.tiles[s];
  return t.regions[dense - t.dense_first];
}

glm::dvec3 nearest_point_of_region(const NavData& data, uint32_t dense, const glm::dvec3& q) {
  uint32_t slot = 0;
  const NavRegion& r = dense_to_region(data, dense, &slot);
  const glm::dvec2 p(std::clamp(q.x, r.lo.x - 0.5, r.hi.x + 0.5),
                     std::clamp(q.y, r.lo.y - 0.5, r.hi.y + 0.5));
  const glm::ivec2 col(std::clamp(int(std::lround(p.x)), r.lo.x, r.hi.x),
                       std::clamp(int(std::lround(p.y)), r.lo.y, r.hi.y));
  const uint16_t local = uint16_t(dense - data.tiles[slot].dense_first);
  for (const NavFloor& f : data.column(col)) {
    if (f.region == local) return {p, f.height};
  }
  return {p, r.height_min};
}


namespace {

// Where the straight line from `from` to `goal` crosses the portal (in the
// ground plane), clamped to the portal: the entry point that keeps g + h
// closest to the taut path, so A* strays less than with portal midpoints.
inline glm::vec3 crossing_point(const NavPortal& p, const glm::vec3& from, const glm::vec3& goal) {
  const glm::vec2 d = glm::vec2(goal) - glm::vec2(from), e = p.b - p.a;
  const float denom = d.x * e.y - d.y * e.x;
  float t = 0.5f;
  if (std::fabs(denom) > 1e-12f) {
    const glm::vec2 w = p.a - glm::vec2(from);
    t = std::clamp((d.y * w.x - d.x * w.y) / denom, 0.0f, 1.0f);
  }
  return {p.a + t * e, p.height_a + t * (p.height_b - p.height_a)};
}

// The portal ends as seen walking through it (left is a quarter turn
// counter-clockwise from the walking direction in the (u, v) plane).
FunnelPortal oriented(const NavPortal& p) {
  const glm::dvec3 a(p.a.x, p.a.y, p.height_a), b(p.b.x, p.b.y, p.height_b);
  const bool b_is_left = p.dir == 0 || p.dir == 3;
  return b_is_left ? FunnelPortal{b, a} : FunnelPortal{a, b};
}

}  // namespace

void NavSearch::reset(uint32_t node_count) {
  nodes.reset(node_count);
  done = reached = out_of_nodes = goal_reachable = false;
}

void NavSearch::push_start(uint32_t node, const glm::dvec3& at, double to_target) {
  nodes.touch(node);
  nodes.cost[node] = 0.0f;
  nodes.estimate[node] = float(to_target);
  nodes.position[node] = glm::vec3(at);
  nodes.push(node, float(to_target));
  best = node;
  best_distance = to_target;
}

namespace {

const NavRegion& portal_target(const NavData& data, const NavPortal& p) {
  return data.tiles[p.to_tile].regions[p.to_region];
}

// A search node's chain and its tile slot.
const NavChain& node_chain(const NavData& data, uint32_t node, uint32_t* slot) {
  *slot = data.node_tile[node];
  const NavTile& t = data.tiles[*slot];
  return t.chains[node - t.node_first];
}

// The portal from local region a to its chain neighbour b = a +- 1.
const NavPortal* inner_portal(const NavTile& tile, uint16_t a, uint16_t b) {
  const NavRegion& r = tile.regions[a];
  const uint8_t offset = b > a ? r.to_next : r.to_previous;
  return offset == kNoPortal ? nullptr : &tile.portals[r.first_portal + offset];
}

}  // namespace

void NavSearch::relax(const NavData& data, uint32_t n, uint32_t m, const glm::vec3& at, float g,
                      uint32_t via, int max_nodes) {
  float h = glm::length(glm::vec3(target) - at);
  if (m == target_node) {  // the last stretch, at the goal region's cost
    g += h * float(filter.cost(dense_to_region(data, target_region).area));
    h = 0.0f;
  }
  if (!nodes.seen(m)) {
    if (nodes.used >= max_nodes) {
      out_of_nodes = true;
      return;
    }
    nodes.touch(m);
  } else if (g + heuristic_scale * h >= nodes.estimate[m]) {
    // A chain is one node entered at one point: of two entries, the one on
    // the better way to the target (lower g + h), not the one reached more
    // cheaply (lower g), which may lie off it.
    return;
  }
  nodes.cost[m] = g;
  nodes.estimate[m] = g + heuristic_scale * h;
  nodes.parent[m] = n;
  nodes.via[m] = via;
  nodes.position[m] = at;
  nodes.push(m, nodes.estimate[m]);
  if (h < best_distance) {
    best = m;
    best_distance = h;
  }
}

// The rectangle (local) node n was entered by: the start's, a portal's
// target or a link's landing.
uint16_t NavSearch::entry_region(const NavData& data, uint32_t n) const {
  auto local = [&](uint32_t dense) { return uint16_t(dense - data.tiles[data.dense_tile[dense]].dense_first); };
  if (nodes.parent[n] == UINT32_MAX) return local(start_region);
  const uint32_t via = nodes.via[n];
  if (via & kViaLink) {
    const LinkExit& e = data.link_exits[via & ~kViaLink];
    return local(e.landing(data.links[e.slot]));
  }
  return data.tiles[data.node_tile[nodes.parent[n]]].portals[via].to_region;
}

// Where each rectangle of node n's chain is reached walking from its entry
// along the chain, and at what cost: the entry and cost the A* over single
// rectangles would have given them along that way. Straight lines across a
// chain that turns could cut through walls; this does not.
void NavSearch::walk_chain(const NavData& data, uint32_t n, float own_cost) {
  uint32_t slot = 0;
  const NavChain& chain = node_chain(data, n, &slot);
  const NavTile& tile = data.tiles[slot];
  chain_at.resize(chain.count);
  chain_cost.resize(chain.count);
  const int entry = entry_region(data, n) - chain.first;
  chain_at[size_t(entry)] = nodes.position[n];
  chain_cost[size_t(entry)] = nodes.cost[n];
  for (int step : {1, -1}) {
    for (int k = entry + step; k >= 0 && k < chain.count; k += step) {
      const size_t from = size_t(k - step);
      const NavPortal* p = inner_portal(tile, uint16_t(chain.first + from), uint16_t(chain.first + k));
      const glm::vec3 at = p ? crossing_point(*p, chain_at[from], glm::vec3(target)) : chain_at[from];
      chain_at[size_t(k)] = at;
      chain_cost[size_t(k)] = chain_cost[from] + own_cost * glm::length(at - chain_at[from]);
    }
  }
}

bool NavSearch::expand_one(const NavData& data, int max_nodes) {
  uint32_t n = 0;
  if (!nodes.pop(&n)) {
    done = true;
    return false;
  }
  nodes.closed[n] = 1;
  if (n == target_node) {
    reached = done = true;
    return false;
  }
  uint32_t slot = 0;
  const NavChain& chain = node_chain(data, n, &slot);
  const NavTile& tile = data.tiles[slot];
  const NavRegion& first = tile.regions[chain.first];
  const NavRegion& last = tile.regions[chain.first + chain.count - 1u];
  const float own_cost = float(filter.cost(first.area));  // walking inside the chain
  walk_chain(data, n, own_cost);
  // The chain's rectangles' portals are consecutive; those between its own
  // rectangles are skipped.
  for (uint32_t k = first.first_portal; k < last.first_portal + last.portal_count; ++k) {
    const NavPortal& p = tile.portals[k];
    if (p.to_tile == slot && chain.holds(p.to_region)) continue;
    const uint32_t m = p.to_node;
    if (nodes.seen(m) && nodes.closed[m]) continue;
    if (filter_areas && !filter.passes(portal_target(data, p).area)) continue;
    const size_t member = size_t(p.from_region - chain.first);
    const glm::vec3& from = chain_at[member];
    const glm::vec3 at = crossing_point(p, from, glm::vec3(target));
    relax(data, n, m, at, chain_cost[member] + own_cost * glm::length(at - from), k, max_nodes);
  }
  // Off-mesh links leaving the chain: walk to the link's start, then take it.
  if (data.link_exits.empty()) return true;
  auto exits = std::equal_range(data.link_exits.begin(), data.link_exits.end(), LinkExit{n, 0, false});
  for (auto e = exits.first; e != exits.second; ++e) {
    const NavLinkSlot& link = data.links[e->slot];
    const uint32_t landing = e->landing(link);
    const uint32_t m = data.node_of(landing);
    if (nodes.seen(m) && nodes.closed[m]) continue;
    if (!filter.passes_flags(link.link.flags) || !filter.passes(dense_to_region(data, landing).area)) continue;
    const glm::vec3 take_off(e->reversed ? link.b : link.a), land(e->reversed ? link.a : link.b);
    const float jump = link.link.cost < 0.0 ? glm::length(land - take_off)
                                            : float(link.link.cost / data.lattice.cell_size);
    const size_t member = size_t(e->take_off(link) - tile.dense_first - chain.first);
    const float g = chain_cost[member] + own_cost * glm::length(take_off - chain_at[member]) + jump;
    relax(data, n, m, land, g, kViaLink | uint32_t(e - data.link_exits.begin()), max_nodes);
  }
  return true;
}

namespace {

// Distance from q to region `dense`'s rectangle and height range.
double region_box_distance(const NavData& data, uint32_t dense, const glm::dvec3& q) {
  const NavRegion& r = dense_to_region(data, dense);
  const glm::dvec3 near(std::clamp(q.x, r.lo.x - 0.5, r.hi.x + 0.5), std::clamp(q.y, r.lo.y - 0.5, r.hi.y + 0.5),
                        std::clamp(q.z, double(r.height_min), double(r.height_max)));
  return glm::length(near - q);
}

// The rectangle of node `node` nearest q (the first of equals), as a dense region.
uint32_t nearest_region_of_node(const NavData& data, uint32_t node, const glm::dvec3& q) {
  uint32_t slot = 0;
  const NavChain& chain = node_chain(data, node, &slot);
  const uint32_t first = data.tiles[slot].dense_first + chain.first;
  uint32_t best = first;
  double best_distance = region_box_distance(data, first, q);
  for (uint32_t r = first + 1; r < first + chain.count; ++r) {
    const double d = region_box_distance(data, r, q);
    if (d < best_distance) {
      best_distance = d;
      best = r;
    }
  }
  return best;
}

// The portals walking through one chain from rectangle `entry` to `exit`
// (dense regions of that chain), in chain order forwards or backwards.
void chain_portals(const NavData& data, uint32_t entry, uint32_t exit, std::vector<FunnelPortal>& out) {
  const uint32_t slot = data.dense_tile[entry];
  const NavTile& tile = data.tiles[slot];
  const int a = int(entry - tile.dense_first), b = int(exit - tile.dense_first);
  const int step = b > a ? 1 : -1;
  for (int r = a; r != b; r += step) {
    const NavPortal* p = inner_portal(tile, uint16_t(r), uint16_t(r + step));
    if (p) out.push_back(oriented(*p));
  }
}

}  // namespace

NavPath NavSearch::make_path(const NavData& data) {
  NavPath path;
  const uint32_t end_node = reached ? target_node : best;
  const uint32_t end_region = reached ? target_region : nearest_region_of_node(data, end_node, target);
  const glm::dvec3 end = reached ? target : nearest_point_of_region(data, end_region, target);
  if (reached) {
    path.status = goal_reachable ? PathStatus::kComplete : PathStatus::kUnreachable;
  } else {
    path.status = out_of_nodes ? PathStatus::kOutOfNodes : PathStatus::kUnreachable;
  }
  std::vector<uint32_t>& chain = corridor;
  chain.clear();
  for (uint32_t n = end_node; n != UINT32_MAX; n = nodes.parent[n]) chain.push_back(n);
  std::reverse(chain.begin(), chain.end());
  // Pull the string through each stretch between links; a link's ends are
  // corners. The portals hold the stretch's start and end as their first and last.
  std::vector<FunnelPortal>& portals = funnel;
  glm::dvec3 stretch_start = start;
  path.corners.push_back(start);
  portals.assign(1, {start, start});
  auto pull = [&](const glm::dvec3& stretch_end) {
    portals.push_back({stretch_end, stretch_end});
    pull_string_onto(portals, path.corners);
    portals.clear();
  };
  uint32_t entry = start_region;  // the rectangle the current chain was entered by
  for (size_t i = 1; i < chain.size(); ++i) {
    const uint32_t via = nodes.via[chain[i]];
    if (via & kViaLink) {
      const LinkExit& e = data.link_exits[via & ~kViaLink];
      const NavLinkSlot& link = data.links[e.slot];
      chain_portals(data, entry, e.take_off(link), portals);
      path.regions += size_t(std::abs(int(e.take_off(link)) - int(entry))) + 1;
      pull(e.reversed ? link.b : link.a);
      path.links.push_back({link.id, path.corners.size() - 1});
      stretch_start = e.reversed ? link.a : link.b;
      path.corners.push_back(stretch_start);
      portals.push_back({stretch_start, stretch_start});
      entry = e.landing(link);
      continue;
    }
    const uint32_t slot = data.node_tile[chain[i - 1]];
    const NavTile& t = data.tiles[slot];
    const NavPortal& p = t.portals[via];
    const uint32_t exit = t.dense_first + p.from_region;
    chain_portals(data, entry, exit, portals);
    path.regions += size_t(std::abs(int(exit) - int(entry))) + 1;
    portals.push_back(oriented(p));
    entry = data.tiles[p.to_tile].dense_first + p.to_region;
  }
  chain_portals(data, entry, end_region, portals);
  path.regions += size_t(std::abs(int(end_region) - int(entry))) + 1;
  pull(end);
  for (size_t i = 1; i < path.corners.size(); ++i) {
    path.length += glm::length(path.corners[i] - path.corners[i - 1]);
  }
  path.nodes_searched = size_t(nodes.used);
  return path;
}

// ---- string pulling --------------------------------------------------------

namespace {

// Twice the signed area of (a, b, c) in the ground plane; > 0 when c lies to
// the right of a -> b (the sign Mononen's "simple stupid funnel" uses).
double triarea2(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
  const double ax = b.x - a.x, ay = b.y - a.y;
  const double bx = c.x - a.x, by = c.y - a.y;
  return bx * ay - ax * by;
}

bool same_2d(const glm::dvec3& a, const glm::dvec3& b) {
  const double dx = a.x - b.x, dy = a.y - b.y;
  return dx * dx + dy * dy < 1e-12;
}

}  // namespace

void pull_string_onto(const std::vector<FunnelPortal>& portals, std::vector<glm::dvec3>& out) {
  const glm::dvec3 start = portals.front().left, end = portals.back().left;
  const size_t first = out.size();
  glm::dvec3 apex = start, left = start, right = start;
  size_t apex_i = 0, left_i = 0, right_i = 0;
  for (size_t i = 1; i < portals.size(); ++i) {
    const glm::dvec3& l = portals[i].left;
    const glm::dvec3& r = portals[i].right;
    if (triarea2(apex, right, r) <= 0.0) {
      if (same_2d(apex, right) || triarea2(apex, left, r) > 0.0) {
        right = r;
        right_i = i;
      } else {  // the right side crossed the left: the left end is a corner
        out.push_back(left);
        apex = right = left;
        apex_i = right_i = left_i;
        i = apex_i;
        continue;
      }
    }
    if (triarea2(apex, left, l) >= 0.0) {
      if (same_2d(apex, left) || triarea2(apex, right, l) < 0.0) {
        left = l;
        left_i = i;
      } else {
        out.push_back(right);
        apex = left = right;
        apex_i = left_i = right_i;
        i = apex_i;
        continue;
      }
    }
  }
  if (!same_2d(out.back(), end) || out.size() == first) out.push_back(end);
}

// ---- grid A* ---------------------------------------------------------------

namespace {

struct GridFloor {
  uint32_t slot = 0;
  uint32_t index = 0;  // in the tile's floors
};

// The kept floor `level` of a column, or nullopt.
std::optional<GridFloor> floor_at(const NavData& data, const glm::ivec2& col, uint8_t level) {
  if (level == kNoLink) return std::nullopt;
  int slot = 0;
  const int ray = data.column_in_tile(col, &slot);
  if (ray < 0) return std::nullopt;
  const NavTile& t = data.tiles[size_t(slot)];
  const uint32_t i = t.column_first[size_t(ray)] + level;
  if (i >= t.column_first[size_t(ray) + 1] || !t.floors[i].kept()) return std::nullopt;
  return GridFloor{uint32_t(slot), i};
}

const NavFloor& floor_of(const NavData& data, const GridFloor& g) {
  return data.tiles[g.slot].floors[g.index];
}

uint32_t dense_floor(const NavData& data, const GridFloor& g) {
  return data.tiles[g.slot].dense_floor_first + g.index;
}

}  // namespace

NavPath grid_search(const NavData& data, const FloorHit& start, const FloorHit& goal,
                    int max_nodes, GridSearchState& state) {
  SearchNodes& nodes = state.nodes;
  nodes.reset(data.dense_floor_count);
  const GridFloor s{uint32_t(start.tile), start.floor}, t{uint32_t(goal.tile), goal.floor};
  const uint32_t sn = dense_floor(data, s), tn = dense_floor(data, t);
  const glm::dvec3 target(glm::dvec2(goal.column), floor_of(data, t).height);
  auto column_point = [&](const GridFloor& g, const glm::ivec2& col) {
    return glm::dvec3(col.x, col.y, floor_of(data, g).height);
  };
  std::vector<GridFloor> floor_of_node(0);
  auto visit = [&](uint32_t n, const GridFloor& g) {
    if (floor_of_node.size() <= size_t(nodes.used)) floor_of_node.resize(size_t(nodes.used) + 1);
    nodes.via[n] = uint32_t(nodes.used);  // where its GridFloor sits
    floor_of_node[size_t(nodes.used)] = g;
    nodes.touch(n);
  };
  visit(sn, s);
  nodes.cost[sn] = 0.0f;
  nodes.position[sn] = glm::vec3(glm::dvec2(start.column), floor_of(data, s).height);
  nodes.push(sn, float(glm::length(target - glm::dvec3(nodes.position[sn]))));
  uint32_t best = sn;
  double best_h = glm::length(target - glm::dvec3(nodes.position[sn]));
  bool reached = false, out_of_nodes = false;
  uint32_t n = 0;
  while (nodes.pop(&n)) {
    nodes.closed[n] = 1;
    if (n == tn) {
      reached = true;
      break;
    }
    const GridFloor g = floor_of_node[nodes.via[n]];
    const glm::dvec3 at(nodes.position[n]);
    const glm::ivec2 col(int(at.x), int(at.y));
    auto relax = [&](const GridFloor& next, const glm::ivec2& next_col) {
      const uint32_t m = dense_floor(data, next);
      if (nodes.seen(m) && nodes.closed[m]) return;
      const glm::dvec3 p = column_point(next, next_col);
      const double cost = nodes.cost[n] + glm::length(p - at);
      if (!nodes.seen(m)) {
        if (nodes.used >= max_nodes) {
          out_of_nodes = true;
          return;
        }
        visit(m, next);
      } else if (cost >= nodes.cost[m]) {
        return;
      }
      nodes.cost[m] = float(cost);
      nodes.parent[m] = n;
      nodes.position[m] = glm::vec3(p);
      const double h = glm::length(target - p);
      nodes.push(m, float(cost + h));
      if (h < best_h) {
        best_h = h;
        best = m;
      }
    };
    const NavFloor& f = floor_of(data, g);
    for (int d = 0; d < 4; ++d) {
      const glm::ivec2 side_col = col + kDirStep[d];
      const auto side = floor_at(data, side_col, f.link[d]);
      if (!side) continue;
      relax(*side, side_col);
      // Diagonal: both ways round the corner must reach the same floor.
      const int e = (d + 1) & 3;
      const glm::ivec2 corner_col = side_col + kDirStep[e];
      const auto corner = floor_at(data, corner_col, floor_of(data, *side).link[e]);
      const auto other_side = floor_at(data, col + kDirStep[e], f.link[e]);
      if (!corner || !other_side) continue;
      const auto corner2 = floor_at(data, corner_col, floor_of(data, *other_side).link[d]);
      if (!corner2 || corner2->index != corner->index || corner2->slot != corner->slot) continue;
      relax(*corner, corner_col);
    }
  }
  NavPath path;
  path.status = reached ? PathStatus::kComplete
                        : (out_of_nodes ? PathStatus::kOutOfNodes : PathStatus::kUnreachable);
  for (uint32_t k = reached ? tn : best; k != UINT32_MAX; k = nodes.parent[k]) {
    path.corners.push_back(glm::dvec3(nodes.position[k]));
  }
  std::reverse(path.corners.begin(), path.corners.end());
  for (size_t i = 1; i < path.corners.size(); ++i) {
    path.length += glm::length(path.corners[i] - path.corners[i - 1]);
  }
  path.regions = path.corners.size();
  path.nodes_searched = size_t(nodes.used);
  return path;
}

}  // namespace ldc::detail
