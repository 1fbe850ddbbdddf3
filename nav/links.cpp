// Off-mesh links: snapping their ends to floors, the exits they give each
// region, and the islands they join (so the island check stays right).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "ldc/internal/vec_text.h"
#include "nav/detail/nav_data.h"
#include "nav/detail/nav_search.h"

namespace ldc {
namespace detail {

namespace {

// Union-find over component ids.
uint32_t find_root(std::vector<uint32_t>& parent, uint32_t c) {
  while (parent[c] != c) c = parent[c] = parent[parent[c]];
  return c;
}

bool snap_end(const NavData& data, const glm::dvec3& world, double radius, uint32_t* region,
              glm::dvec3* at) {
  const glm::dvec3 reach(radius / data.lattice.cell_size);
  const auto hit = nearest_floor(data, data.to_nav(world), reach);
  if (!hit) return false;
  const NavTile& t = data.tiles[size_t(hit->tile)];
  *region = t.dense_first + t.floors[hit->floor].region;
  *at = hit->point;
  return true;
}

}  // namespace

void attach_links(NavData& data) {
  data.link_exits.clear();
  std::vector<uint32_t> parent(data.component_count);
  std::iota(parent.begin(), parent.end(), 0u);
  for (uint32_t k = 0; k < data.links.size(); ++k) {
    NavLinkSlot& s = data.links[k];
    s.attached = snap_end(data, s.link.a, s.link.radius, &s.region_a, &s.a) &&
                 snap_end(data, s.link.b, s.link.radius, &s.region_b, &s.b);
    if (!s.attached) continue;
    data.link_exits.push_back({s.region_a, k, false});
    if (s.link.bidirectional) data.link_exits.push_back({s.region_b, k, true});
    // One-way links join islands too: the island check only rules out goals
    // no link can reach; A* decides the rest.
    const uint32_t ca = find_root(parent, dense_to_region(data, s.region_a).component);
    const uint32_t cb = find_root(parent, dense_to_region(data, s.region_b).component);
    parent[std::max(ca, cb)] = std::min(ca, cb);
  }
  std::stable_sort(data.link_exits.begin(), data.link_exits.end());
  data.island_of_component.resize(data.component_count);
  for (uint32_t c = 0; c < data.component_count; ++c) data.island_of_component[c] = find_root(parent, c);
}

}  // namespace detail

Result<uint32_t> NavMesh::add_link(const NavLink& link) {
  if (!detail::is_finite(link.a) || !detail::is_finite(link.b)) {
    return Status(ErrorCode::kInvalidArgument, "NavLink ends " + detail::vec_text(link.a) + " and " +
                                                   detail::vec_text(link.b) + " must be finite");
  }
  if (!std::isfinite(link.cost)) {
    return Status(ErrorCode::kInvalidArgument, "NavLink.cost must be finite (< 0: the straight distance)");
  }
  if (!(link.radius > 0.0 && link.radius <= 100.0)) {
    return Status(ErrorCode::kInvalidArgument,
                  "NavLink.radius " + std::to_string(link.radius) + " must be in (0, 100] m");
  }
  detail::NavData& data = *data_;
  detail::NavLinkSlot slot;
  slot.id = data.next_link_id++;
  slot.link = link;
  data.links.push_back(slot);
  detail::attach_links(data);
  return slot.id;
}

Status NavMesh::remove_link(uint32_t id) {
  detail::NavData& data = *data_;
  auto it = std::find_if(data.links.begin(), data.links.end(),
                         [&](const detail::NavLinkSlot& s) { return s.id == id; });
  if (it == data.links.end()) {
    return Status(ErrorCode::kInvalidArgument, "no off-mesh link with id " + std::to_string(id));
  }
  data.links.erase(it);
  detail::attach_links(data);
  return {};
}

bool NavMesh::link_attached(uint32_t id) const {
  for (const detail::NavLinkSlot& s : data_->links) {
    if (s.id == id) return s.attached;
  }
  return false;
}

}  // namespace ldc
