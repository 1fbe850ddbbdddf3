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

// Snaps link slot k's ends and, when both land, adds its exits (in order)
// and joins the islands of its ends' components.
void attach_one(NavData& data, uint32_t k) {
  NavLinkSlot& s = data.links[k];
  s.attached = snap_end(data, s.link.a, s.link.radius, &s.region_a, &s.a) &&
               snap_end(data, s.link.b, s.link.radius, &s.region_b, &s.b);
  if (!s.attached) return;
  auto add_exit = [&](const LinkExit& e) {
    data.link_exits.insert(std::upper_bound(data.link_exits.begin(), data.link_exits.end(), e), e);
  };
  add_exit({data.node_of(s.region_a), k, false});
  if (s.link.bidirectional) add_exit({data.node_of(s.region_b), k, true});
  const uint32_t ia = data.island(dense_to_region(data, s.region_a).component);
  const uint32_t ib = data.island(dense_to_region(data, s.region_b).component);
  if (ia == ib) return;
  for (uint32_t& island : data.island_of_component) {
    if (island == std::max(ia, ib)) island = std::min(ia, ib);
  }
}

void attach_links(NavData& data) {
  data.link_exits.clear();
  data.island_of_component.resize(data.component_count);
  std::iota(data.island_of_component.begin(), data.island_of_component.end(), 0u);
  for (uint32_t k = 0; k < data.links.size(); ++k) attach_one(data, k);
}

}  // namespace detail

Status check_nav_link(const NavLink& link) {
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
  return {};
}

Result<uint32_t> NavMesh::add_link(const NavLink& link) {
  if (Status s = check_nav_link(link); !s.ok()) return s;
  detail::NavData& data = *data_;
  detail::NavLinkSlot slot;
  slot.id = data.next_link_id++;
  slot.link = link;
  data.links.push_back(slot);
  // Only the new link is snapped (build and update attach the rest): adding
  // n links costs n snaps, not n^2.
  detail::attach_one(data, uint32_t(data.links.size() - 1));
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
