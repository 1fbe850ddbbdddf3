// NavQuery: input checks, snapping to the nearest walkable floor, the island
// check and the sliced search's entry points (the searches themselves and
// string pulling are in astar.cpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include "ldc/internal/vec_text.h"
#include "nav/detail/nav_data.h"
#include "nav/detail/nav_search.h"

namespace ldc {

using detail::NavData;
using detail::NavFloor;
using detail::NavPortal;
using detail::NavRegion;
using detail::NavTile;

namespace detail {

// ---- nearest floor ---------------------------------------------------------

std::optional<FloorHit> nearest_floor(const NavData& data, const glm::dvec3& q,
                                      const glm::dvec3& reach, const NavFilter* filter) {
  // q and reach in nav coordinates (cells). Rings of columns outward from
  // q's column; stops once a ring is farther than the best hit.
  std::optional<FloorHit> best;
  const glm::ivec2 centre(int(std::lround(q.x)), int(std::lround(q.y)));
  const int rings = int(std::ceil(std::max(reach.x, reach.y))) + 1;
  auto visit = [&](const glm::ivec2& col) {
    // The nearest point of the column's square.
    const glm::dvec2 p(std::clamp(q.x, col.x - 0.5, col.x + 0.5), std::clamp(q.y, col.y - 0.5, col.y + 0.5));
    if (std::abs(p.x - q.x) > reach.x || std::abs(p.y - q.y) > reach.y) return;
    int slot = 0;
    const int index = data.column_in_tile(col, &slot);
    if (index < 0) return;
    const NavTile& t = data.tiles[size_t(slot)];
    for (uint32_t i = t.column_first[size_t(index)]; i < t.column_first[size_t(index) + 1]; ++i) {
      const NavFloor& f = t.floors[i];
      if (!f.kept() || (filter && !filter->passes(f.area))) continue;
      if (std::abs(f.height - q.z) > reach.z) continue;
      const glm::dvec3 at(p, f.height);
      const double d = glm::length(at - q);
      if (!best || d < best->distance) best = FloorHit{slot, i, col, at, d};
    }
  };
  // q lies in its column's square, `off` from its centre (Chebyshev): every
  // square of ring r is at least r - 0.5 - off away.
  const double off = std::max(std::abs(q.x - centre.x), std::abs(q.y - centre.y));
  for (int ring = 0; ring <= rings; ++ring) {
    const double ring_gap = std::max(0.0, ring - 0.5 - off);  // least horizontal distance in this ring
    if (best && ring_gap > best->distance) break;
    // The ring's columns in rows (dy), each row's in dx order: full rows at
    // the top and bottom, the two ends between (the order the square scan had).
    for (int dy = -ring; dy <= ring; ++dy) {
      const bool full_row = dy == -ring || dy == ring;
      for (int dx = -ring; dx <= ring; dx += full_row || ring == 0 ? 1 : 2 * ring) {
        visit(centre + glm::ivec2(dx, dy));
      }
    }
  }
  return best;
}

}  // namespace detail

namespace {

Status not_finite(const char* what, const glm::dvec3& p) {
  return Status(ErrorCode::kInvalidArgument,
                std::string(what) + " " + detail::vec_text(p) + " is not finite");
}

glm::dvec3 to_nav_extent(const NavData& data, const glm::dvec3& half) {
  const double h = data.lattice.cell_size;
  return glm::dvec3(half[data.axis_u], half[data.axis_v], half[data.up]) / h;
}

Status check_extents(const glm::dvec3& half) {
  if (!detail::is_finite(half) || half.x <= 0 || half.y <= 0 || half.z <= 0) {
    return Status(ErrorCode::kInvalidArgument,
                  "search half extents " + detail::vec_text(half) + " must be finite and > 0");
  }
  return {};
}

Status check_path_input(const glm::dvec3& from, const glm::dvec3& to,
                        const PathQueryOptions& options) {
  if (!detail::is_finite(from)) return not_finite("path start", from);
  if (!detail::is_finite(to)) return not_finite("path goal", to);
  if (Status s = check_nav_filter(options.filter); !s.ok()) return s;
  return check_extents(options.search_half_extents);
}

// Detour's H_SCALE (a hair under 1 keeps the heuristic admissible despite
// float rounding), times the cheapest cost a step can have.
float heuristic_scale(const NavFilter& filter) {
  double cheapest = 1.0;  // areas the filter does not list cost 1
  for (double c : filter.area_cost) cheapest = std::min(cheapest, c);
  return float(0.999 * cheapest);
}

// Distance from q to a region box (its rectangle and height range).
double box_distance(const detail::RegionBox& b, const glm::dvec3& q) {
  const glm::dvec3 near(std::clamp(q.x, double(b.lo.x), double(b.hi.x)),
                        std::clamp(q.y, double(b.lo.y), double(b.hi.y)),
                        std::clamp(q.z, double(b.height_min), double(b.height_max)));
  return glm::length(near - q);
}

// The filter-passing region of `island` nearest `aim` by box distance (no
// floor lookups), the lowest dense index on ties; `fallback` when none.
// Runs of boxes (a component's regions in one tile) whose bounds are farther
// than the best so far are skipped; the nearest run is scanned first so the
// best is good early.
uint32_t nearest_island_region(const NavData& data, uint32_t island, const glm::dvec3& aim,
                               const NavFilter& filter, uint32_t fallback) {
  double best = std::numeric_limits<double>::infinity();
  uint32_t best_region = fallback;
  auto scan = [&](const detail::RegionBoxRun& run) {
    for (uint32_t i = run.first; i < run.first + run.count; ++i) {
      const detail::RegionBox& b = data.component_boxes[i];
      if (!filter.passes(b.area)) continue;
      const double d = box_distance(b, aim);
      if (d < best || (d == best && b.dense < best_region)) {
        best = d;
        best_region = b.dense;
      }
    }
  };
  auto for_island_runs = [&](auto fn) {
    for (uint32_t c = 0; c < data.component_count; ++c) {
      if (data.island(c) != island) continue;
      for (uint32_t k = data.component_run_first[c]; k < data.component_run_first[c + 1]; ++k) {
        fn(k, box_distance(data.component_runs[k].bounds, aim));
      }
    }
  };
  uint32_t nearest_run = UINT32_MAX;
  double nearest_run_distance = std::numeric_limits<double>::infinity();
  for_island_runs([&](uint32_t k, double d) {
    if (d < nearest_run_distance) {
      nearest_run_distance = d;
      nearest_run = k;
    }
  });
  if (nearest_run == UINT32_MAX) return fallback;
  scan(data.component_runs[nearest_run]);
  for_island_runs([&](uint32_t k, double d) {
    if (k != nearest_run && d <= best) scan(data.component_runs[k]);
  });
  return best_region;
}

uint32_t dense_region(const NavData& data, const detail::FloorHit& hit) {
  const NavTile& t = data.tiles[size_t(hit.tile)];
  return t.dense_first + t.floors[hit.floor].region;
}

}  // namespace

// ---- NavQuery --------------------------------------------------------------

Status check_nav_filter(const NavFilter& filter) {
  for (size_t m = 0; m < filter.area_cost.size(); ++m) {
    const double c = filter.area_cost[m];
    if (!std::isfinite(c) || c < 0.01) {
      return Status(ErrorCode::kInvalidArgument, "NavFilter.area_cost[" + std::to_string(m) +
                                                     "] = " + std::to_string(c) + ": must be finite and >= 0.01");
    }
  }
  return {};
}

namespace {

// "no walkable floor within ..." and, when the mesh has none at all, why.
Status no_floor(const NavMesh& mesh, const std::string& what) {
  const NavStats s = mesh.stats();
  if (s.walkable > 0) return {ErrorCode::kInvalidArgument, what};
  return {ErrorCode::kInvalidArgument,
          what + ": the level has no walkable floor for this agent at all (" + std::to_string(s.floors) +
              " floors with room above; none left by max_slope, max_climb, the filters and agent_radius)"};
}

}  // namespace

NavQuery::NavQuery(const NavMesh& mesh, int max_nodes)
    : mesh_(mesh),
      max_nodes_(std::clamp(max_nodes, 16, 1 << 20)),
      search_(std::make_unique<detail::NavSearch>()) {}

NavQuery::~NavQuery() = default;

Result<NavPoint> NavQuery::nearest_walkable(const glm::dvec3& p, const glm::dvec3& half) const {
  if (!detail::is_finite(p)) return not_finite("position", p);
  if (Status s = check_extents(half); !s.ok()) return s;
  const NavData& data = *mesh_.data_;
  const auto hit = detail::nearest_floor(data, data.to_nav(p), to_nav_extent(data, half));
  if (!hit) {
    return no_floor(mesh_, "no walkable floor within " + detail::vec_text(half) + " m of " +
                               detail::vec_text(p));
  }
  NavPoint out;
  out.position = data.to_world(hit->point);
  out.region = detail::region_ref(uint32_t(hit->tile), data.tiles[size_t(hit->tile)].floors[hit->floor].region);
  out.distance = hit->distance * data.lattice.cell_size;
  return out;
}

Status NavQuery::begin_path(const glm::dvec3& from, const glm::dvec3& to,
                            const PathQueryOptions& options) {
  detail::NavSearch& s = *search_;
  s.active = false;
  if (Status st = check_path_input(from, to, options); !st.ok()) return st;
  const NavData& data = *mesh_.data_;
  const glm::dvec3 reach = to_nav_extent(data, options.search_half_extents);
  const auto start = detail::nearest_floor(data, data.to_nav(from), reach, &options.filter);
  if (!start) {
    return no_floor(mesh_, "no walkable floor within " + detail::vec_text(options.search_half_extents) +
                               " m of the path start " + detail::vec_text(from));
  }
  s.reset(data.node_count);
  s.filter = options.filter;
  s.heuristic_scale = heuristic_scale(options.filter);
  // Areas missing from area_flags have flags 1: a filter that passes flag 1
  // and lists no flags passes every area.
  s.filter_areas = !options.filter.area_flags.empty() || !options.filter.passes_flags(1);
  s.start = start->point;
  s.start_region = dense_region(data, *start);
  const uint32_t island = data.island(detail::dense_to_region(data, s.start_region).component);
  const glm::dvec3 goal_nav = data.to_nav(to);
  const auto goal = detail::nearest_floor(data, goal_nav, reach, &options.filter);
  if (goal && data.island(detail::dense_to_region(data, dense_region(data, *goal)).component) == island) {
    s.target = goal->point;
    s.target_region = dense_region(data, *goal);
    s.goal_reachable = true;
  } else {
    // Unreachable: aim at the start island's point nearest the goal.
    const glm::dvec3 aim = goal ? goal->point : goal_nav;
    s.target_region = nearest_island_region(data, island, aim, options.filter, s.start_region);
    s.target = detail::nearest_point_of_region(data, s.target_region, aim);
    s.goal_reachable = false;
  }
  s.start_node = data.node_of(s.start_region);
  s.target_node = data.node_of(s.target_region);
  s.push_start(s.start_node, s.start, glm::length(s.target - s.start));
  s.active = true;
  return {};
}

Result<SliceStatus> NavQuery::step(int max_expansions) {
  detail::NavSearch& s = *search_;
  if (!s.active) return Status(ErrorCode::kInvalidArgument, "step() without a begun path search");
  if (s.done) return SliceStatus::kDone;
  const NavData& data = *mesh_.data_;
  for (int e = 0; e < max_expansions; ++e) {
    if (!s.expand_one(data, max_nodes_)) return SliceStatus::kDone;
  }
  return s.done ? SliceStatus::kDone : SliceStatus::kInProgress;
}

Result<NavPath> NavQuery::finish_path() {
  detail::NavSearch& s = *search_;
  if (!s.active) return Status(ErrorCode::kInvalidArgument, "finish_path() without a begun path search");
  const NavData& data = *mesh_.data_;
  NavPath path = s.make_path(data);
  for (glm::dvec3& p : path.corners) p = data.to_world(p);
  path.length *= data.lattice.cell_size;
  s.active = false;
  return path;
}

Result<NavPath> NavQuery::find_path(const glm::dvec3& from, const glm::dvec3& to,
                                    const PathQueryOptions& options) {
  if (Status st = begin_path(from, to, options); !st.ok()) return st;
  while (true) {
    Result<SliceStatus> r = step(1 << 30);
    if (!r.ok()) return r.status();
    if (r.value() == SliceStatus::kDone) break;
  }
  return finish_path();
}

Result<NavPath> NavQuery::find_grid_path(const glm::dvec3& from, const glm::dvec3& to,
                                         const PathQueryOptions& options) {
  if (Status st = check_path_input(from, to, options); !st.ok()) return st;
  const NavData& data = *mesh_.data_;
  const glm::dvec3 reach = to_nav_extent(data, options.search_half_extents);
  const auto start = detail::nearest_floor(data, data.to_nav(from), reach);
  const auto goal = detail::nearest_floor(data, data.to_nav(to), reach);
  if (!start || !goal) {
    return no_floor(mesh_, std::string("no walkable floor within the search extents of the path ") +
                               (start ? "goal " + detail::vec_text(to) : "start " + detail::vec_text(from)));
  }
  NavPath path = detail::grid_search(data, *start, *goal, max_nodes_, search_->grid);
  for (glm::dvec3& p : path.corners) p = data.to_world(p);
  path.length *= data.lattice.cell_size;
  return path;
}

}  // namespace ldc
