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
bool heap_less(const std::pair<float, uint32_t>& a, const std::pair<float, uint32_t>& b) {
  return a.first > b.first;  // std heap is a max-heap: invert for the smallest f on top
}
}  // namespace

void SearchNodes::push(uint32_t n, float f) {
  heap.emplace_back(f, n);
  std::push_heap(heap.begin(), heap.end(), heap_less);
}

bool SearchNodes::pop(uint32_t* n) {
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), heap_less);
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
glm::vec3 crossing_point(const NavPortal& p, const glm::vec3& from, const glm::vec3& goal) {
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

void NavSearch::reset(uint32_t region_count) {
  nodes.reset(region_count);
  done = reached = out_of_nodes = goal_reachable = false;
}

void NavSearch::push_start(uint32_t region, const glm::dvec3& at, double to_target) {
  nodes.touch(region);
  nodes.cost[region] = 0.0f;
  nodes.position[region] = glm::vec3(at);
  nodes.push(region, float(to_target));
  best = region;
  best_distance = to_target;
}

namespace {

const NavRegion& portal_target(const NavData& data, const NavPortal& p) {
  return data.tiles[p.to_tile].regions[p.to_region];
}

}  // namespace

void NavSearch::relax(const NavData& data, uint32_t n, uint32_t m, const glm::vec3& at, float g,
                      uint32_t via, int max_nodes) {
  float h = glm::length(glm::vec3(target) - at);
  if (m == target_region) {  // the last stretch, at the goal region's cost
    g += h * float(filter.cost(dense_to_region(data, m).area));
    h = 0.0f;
  }
  if (!nodes.seen(m)) {
    if (nodes.used >= max_nodes) {
      out_of_nodes = true;
      return;
    }
    nodes.touch(m);
  } else if (g >= nodes.cost[m]) {
    return;
  }
  nodes.cost[m] = g;
  nodes.parent[m] = n;
  nodes.via[m] = via;
  nodes.position[m] = at;
  nodes.push(m, g + heuristic_scale * h);
  if (h < best_distance) {
    best = m;
    best_distance = h;
  }
}

bool NavSearch::expand_one(const NavData& data, int max_nodes) {
  uint32_t n = 0;
  if (!nodes.pop(&n)) {
    done = true;
    return false;
  }
  nodes.closed[n] = 1;
  if (n == target_region) {
    reached = done = true;
    return false;
  }
  uint32_t slot = 0;
  const NavRegion& r = dense_to_region(data, n, &slot);
  const NavTile& tile = data.tiles[slot];
  const glm::vec3 from = nodes.position[n];
  const float own_cost = float(filter.cost(r.area));  // walking inside r
  for (uint32_t k = 0; k < r.portal_count; ++k) {
    const NavPortal& p = tile.portals[r.first_portal + k];
    const uint32_t m = p.to_dense;
    if (nodes.seen(m) && nodes.closed[m]) continue;
    if (filter_areas && !filter.passes(portal_target(data, p).area)) continue;
    const glm::vec3 at = crossing_point(p, from, glm::vec3(target));
    relax(data, n, m, at, nodes.cost[n] + own_cost * glm::length(at - from), r.first_portal + k, max_nodes);
  }
  // Off-mesh links leaving r: walk to the link's start, then take it.
  auto exits = std::equal_range(data.link_exits.begin(), data.link_exits.end(), LinkExit{n, 0, false});
  for (auto e = exits.first; e != exits.second; ++e) {
    const NavLinkSlot& link = data.links[e->slot];
    const uint32_t m = e->reversed ? link.region_a : link.region_b;
    if (nodes.seen(m) && nodes.closed[m]) continue;
    if (!filter.passes_flags(link.link.flags) || !filter.passes(dense_to_region(data, m).area)) continue;
    const glm::vec3 take_off(e->reversed ? link.b : link.a), landing(e->reversed ? link.a : link.b);
    const float jump = link.link.cost < 0.0 ? glm::length(landing - take_off)
                                            : float(link.link.cost / data.lattice.cell_size);
    const float g = nodes.cost[n] + own_cost * glm::length(take_off - from) + jump;
    relax(data, n, m, landing, g, kViaLink | uint32_t(e - data.link_exits.begin()), max_nodes);
  }
  return true;
}

NavPath NavSearch::make_path(const NavData& data) const {
  NavPath path;
  const uint32_t end_node = reached ? target_region : best;
  const glm::dvec3 end = reached ? target : nearest_point_of_region(data, end_node, target);
  if (reached) {
    path.status = goal_reachable ? PathStatus::kComplete : PathStatus::kUnreachable;
  } else {
    path.status = out_of_nodes ? PathStatus::kOutOfNodes : PathStatus::kUnreachable;
  }
  std::vector<uint32_t> chain;
  for (uint32_t n = end_node; n != UINT32_MAX; n = nodes.parent[n]) chain.push_back(n);
  std::reverse(chain.begin(), chain.end());
  // Pull the string through each stretch between links; a link's ends are corners.
  std::vector<FunnelPortal> portals;
  glm::dvec3 stretch_start = start;
  path.corners.push_back(start);
  auto pull = [&](const glm::dvec3& stretch_end) {
    const std::vector<glm::dvec3> pulled = pull_string(stretch_start, stretch_end, portals);
    path.corners.insert(path.corners.end(), pulled.begin() + 1, pulled.end());
    portals.clear();
  };
  for (size_t i = 1; i < chain.size(); ++i) {
    const uint32_t via = nodes.via[chain[i]];
    if (via & kViaLink) {
      const LinkExit& e = data.link_exits[via & ~kViaLink];
      const NavLinkSlot& link = data.links[e.slot];
      pull(e.reversed ? link.b : link.a);
      path.links.push_back({link.id, path.corners.size() - 1});
      stretch_start = e.reversed ? link.a : link.b;
      path.corners.push_back(stretch_start);
      continue;
    }
    const NavTile& t = data.tiles[data.dense_tile[chain[i - 1]]];
    portals.push_back(oriented(t.portals[via]));
  }
  pull(end);
  for (size_t i = 1; i < path.corners.size(); ++i) {
    path.length += glm::length(path.corners[i] - path.corners[i - 1]);
  }
  path.regions = chain.size();
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

std::vector<glm::dvec3> pull_string(const glm::dvec3& start, const glm::dvec3& end,
                                    const std::vector<FunnelPortal>& inner) {
  std::vector<FunnelPortal> portals;
  portals.reserve(inner.size() + 2);
  portals.push_back({start, start});
  portals.insert(portals.end(), inner.begin(), inner.end());
  portals.push_back({end, end});
  std::vector<glm::dvec3> out{start};
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
  if (!same_2d(out.back(), end) || out.size() == 1) out.push_back(end);
  return out;
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
