// Queries: closest points, overlaps and sphere casts, all read from the same
// per-cell tangent-plane solids as ray casts (detail/cell_index.h).
#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

#include "ldc/detail/cell_index.h"
#include "ldc/internal/ray_math.h"
#include "ldc/internal/vec_text.h"
#include "ldc/query.h"

namespace ldc {
namespace {

using detail::CellIndex;
using detail::CellSurface;

constexpr double kMaxSearchCells = 64.0;  // closest_point's search limit
constexpr double kDeepCells = 16.0;       // overlap: how far below the surface depth is measured
constexpr double kContactGap = 0.01;      // cells: a sphere this close touches
constexpr int kMaxCastSteps = 4096;

Status check_point(const char* what, const glm::dvec3& p) {
  if (detail::is_finite(p)) return {};
  return {ErrorCode::kInvalidArgument, std::string(what) + " " + detail::vec_text(p) + " is not finite"};
}

Status check_positive(const char* what, double value) {
  if (value > 0.0 && std::isfinite(value)) return {};
  std::ostringstream s;
  s << what << " " << value << " must be finite and > 0";
  return {ErrorCode::kInvalidArgument, s.str()};
}

// The nearest surface point found so far, in lattice coordinates.
struct Nearest {
  bool found = false;
  glm::dvec3 point{0.0};
  glm::dvec3 normal{0.0};
  uint16_t material = 0;
  double distance2 = 0.0;
};

double box_distance2(const glm::dvec3& x, const glm::dvec3& lo, const glm::dvec3& hi) {
  const glm::dvec3 d = glm::max(glm::max(lo - x, x - hi), glm::dvec3(0.0));
  return glm::dot(d, d);
}

// Bits of a 4^3 brick's word whose cells lie in [lo, hi] (brick-local, inclusive).
uint64_t brick_range_mask(const glm::ivec3& lo, const glm::ivec3& hi) {
  const uint64_t row = ((uint64_t{1} << (hi.x + 1)) - 1) & ~((uint64_t{1} << lo.x) - 1);
  uint64_t mask = 0;
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y) mask |= row << (((z << 2) | y) << 2);
  return mask;
}

// Calls fn(cell) for every surface cell in [lo, hi] (inclusive), chunk by
// chunk and brick by brick, skipping chunks and bricks without surface.
template <class Fn>
void for_surface_cells(const Queries& q, const glm::ivec3& lo, const glm::ivec3& hi, Fn&& fn) {
  const int c = q.world().chunk_size();
  const glm::ivec3 box_lo = q.world().node_min() - 1, box_hi = q.world().node_end() - 1;
  const glm::ivec3 clo = glm::max(lo, box_lo), chi = glm::min(hi, box_hi);
  if (glm::any(glm::greaterThan(clo, chi))) return;
  const glm::ivec3 k_lo = q.world().chunk_of_node(clo), k_hi = q.world().chunk_of_node(chi);
  for (int kz = k_lo.z; kz <= k_hi.z; ++kz)
    for (int ky = k_lo.y; ky <= k_hi.y; ++ky)
      for (int kx = k_lo.x; kx <= k_hi.x; ++kx) {
        const glm::ivec3 k(kx, ky, kz);
        const CellIndex* index = q.cell_index(k);
        if (index->clear) continue;
        // Local cell range in this chunk, then brick range.
        const glm::ivec3 a = glm::max(clo - k * c, glm::ivec3(0)), b = glm::min(chi - k * c, glm::ivec3(c - 1));
        const glm::ivec3 ba = a >> detail::kBrickShift, bb = b >> detail::kBrickShift;
        for (int bz = ba.z; bz <= bb.z; ++bz)
          for (int by = ba.y; by <= bb.y; ++by)
            for (int bx = ba.x; bx <= bb.x; ++bx) {
              const glm::ivec3 brick(bx, by, bz), first = brick << detail::kBrickShift;
              uint64_t w = index->surface[size_t(index->brick_of(first))];
              if (!w) continue;
              w &= brick_range_mask(glm::max(a - first, glm::ivec3(0)), glm::min(b - first, glm::ivec3(3)));
              while (w) {
                const int bit = std::countr_zero(w);
                w &= w - 1;
                if constexpr (std::is_same_v<decltype(fn(glm::ivec3())), bool>) {
                  if (fn(k * c + first + glm::ivec3(bit & 3, (bit >> 2) & 3, bit >> 4))) return;
                } else {
                  fn(k * c + first + glm::ivec3(bit & 3, (bit >> 2) & 3, bit >> 4));
                }
              }
            }
      }
}

// Whether any surface cell lies within Chebyshev distance `reach` of x.
bool any_surface_near(const Queries& q, const glm::dvec3& x, double reach) {
  bool any = false;
  for_surface_cells(q, glm::ivec3(glm::floor(x - reach)), glm::ivec3(glm::floor(x + reach)),
                    [&](const glm::ivec3&) { return any = true; });
  return any;
}

// Nearest surface point to x within `radius` cells, searching outwards in
// boxes of doubling reach; within a box, cells nearest first, so that the
// best point found soon rules out the rest without reading them.
Nearest nearest_surface(const Queries& q, const glm::dvec3& x, double radius) {
  Nearest best;
  std::vector<std::pair<double, glm::ivec3>> candidates;
  double reach = std::min(2.0, radius), searched = -1.0;
  for (;;) {
    const glm::ivec3 lo(glm::floor(x - reach)), hi(glm::floor(x + reach));
    candidates.clear();
    for_surface_cells(q, lo, hi, [&](const glm::ivec3& cell) {
      const glm::dvec3 cell_lo(cell);
      const double d2 = box_distance2(x, cell_lo, cell_lo + 1.0);
      if (d2 > searched * searched || searched < 0.0) candidates.emplace_back(d2, cell);  // not read before
    });
    std::sort(candidates.begin(), candidates.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [d2, cell] : candidates) {
      if (best.found && d2 >= best.distance2) break;
      const CellSurface* surface = detail::cached_cell_surface(q.world(), cell);
      if (!surface) continue;
      const glm::dvec3 cell_lo(cell);
      detail::CellClosest cc;
      if (!detail::closest_in_cell(*surface, x - cell_lo, &cc)) continue;
      if (best.found && cc.distance2 >= best.distance2) continue;
      const detail::CellPlane& plane = surface->planes[size_t(cc.plane)];
      best = Nearest{true, cell_lo + cc.point, plane.n, plane.material, cc.distance2};
    }
    if ((best.found && best.distance2 <= reach * reach) || reach >= radius) break;
    searched = reach;
    reach = std::min(2.0 * reach, radius);
  }
  if (best.found && best.distance2 > radius * radius) best.found = false;
  return best;
}

// Whether a lattice position is inside the query solid.
bool inside_solid(const Queries& q, const glm::dvec3& x) {
  const int c = q.world().chunk_size();
  const glm::ivec3 cell(glm::floor(x));
  const glm::ivec3 k = q.world().chunk_of_node(cell);  // a cell is named by its first node
  const CellIndex* index = q.cell_index(k);
  if (index->clear) return index->clear_inside;
  const glm::ivec3 l = cell - k * c;
  if (!index->is_surface(l)) return index->is_inside(l);
  const CellSurface* surface = detail::cached_cell_surface(q.world(), cell);
  if (!surface) return index->is_inside(l);
  return surface->contains(x - glm::dvec3(cell));
}

// A convex shape for overlap tests, in lattice coordinates.
struct ConvexShape {
  virtual ~ConvexShape() = default;
  virtual glm::dvec3 support(const glm::dvec3& dir) const = 0;  // farthest point along dir
  virtual bool contains(const glm::dvec3& x) const = 0;
  virtual glm::dvec3 centre() const = 0;
};

struct BoxShape : ConvexShape {
  glm::dvec3 c, e;
  glm::dmat3 r;
  glm::dvec3 support(const glm::dvec3& dir) const override {
    glm::dvec3 s = c;
    for (int a = 0; a < 3; ++a) s += r[a] * (glm::dot(r[a], dir) >= 0.0 ? e[a] : -e[a]);
    return s;
  }
  bool contains(const glm::dvec3& x) const override {
    for (int a = 0; a < 3; ++a)
      if (std::abs(glm::dot(r[a], x - c)) > e[a]) return false;
    return true;
  }
  glm::dvec3 centre() const override { return c; }
};

struct CapsuleShape : ConvexShape {
  glm::dvec3 a, b;
  double radius;
  glm::dvec3 support(const glm::dvec3& dir) const override {
    const double len = glm::length(dir);
    const glm::dvec3 u = len > 0.0 ? dir / len : glm::dvec3(0.0);
    return (glm::dot(b - a, u) >= 0.0 ? b : a) + radius * u;
  }
  bool contains(const glm::dvec3& x) const override {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(x - a, ab) / len2, 0.0, 1.0) : 0.0;
    const glm::dvec3 d = x - (a + t * ab);
    return glm::dot(d, d) <= radius * radius;
  }
  glm::dvec3 centre() const override { return 0.5 * (a + b); }
};

// Deepest contact of a convex shape with the surface planes near it: for each
// plane, how deep the shape's support point lies behind it, kept when that
// contact lies on the surface within its own cell. Lattice units.
Overlap shape_overlap(const Queries& q, const ConvexShape& shape, double h) {
  Overlap out;
  glm::dvec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    glm::dvec3 axis(0.0);
    axis[a] = 1.0;
    hi[a] = shape.support(axis)[a];
    lo[a] = shape.support(-axis)[a];
  }
  constexpr double kSlack = 0.25;  // cells around a plane's own cell where its contact may lie
  double deepest = 0.0;
  bool touching = false;
  CellSurface surface;
  for_surface_cells(q, glm::ivec3(glm::floor(lo)) - 1, glm::ivec3(glm::floor(hi)) + 1, [&](const glm::ivec3& cell) {
    if (!detail::gather_cell_surface(q.world(), cell, &surface)) return;
    const glm::dvec3 base(cell);
    for (int i = 0; i < surface.count; ++i) {
      const detail::CellPlane& pl = surface.planes[size_t(i)];
      const glm::dvec3 p = base + pl.p;
      const glm::dvec3 s = shape.support(-pl.n);
      const double depth = glm::dot(pl.n, p - s);
      if (depth < 0.0) continue;
      // The contact: the support point moved onto the plane; it must lie on this cell's surface.
      const glm::dvec3 contact = s + depth * pl.n - base;
      const bool local = glm::all(glm::greaterThanEqual(contact, glm::dvec3(-kSlack))) &&
                         glm::all(glm::lessThanEqual(contact, glm::dvec3(1.0 + kSlack))) &&
                         surface.inside_value(contact) <= kSlack;
      if (!local && !shape.contains(p)) continue;
      touching = true;
      if (depth > deepest || out.depth == 0.0) {
        deepest = depth;
        out.depth = depth * h;
        out.normal = glm::vec3(pl.n);
        out.point = q.world().lattice().to_world(s + depth * pl.n);
      }
    }
  });
  out.overlaps = touching || inside_solid(q, shape.centre());
  return out;
}

}  // namespace

Result<ClosestPoint> Queries::closest_point(const glm::dvec3& p, double max_distance) const {
  Status s = check_point("closest_point: point", p);
  if (!s.ok()) return s;
  const double h = world_->lattice().cell_size;
  if (!(max_distance >= 0.0) || max_distance > kMaxSearchCells * h) {
    std::ostringstream m;
    m << "closest_point: max_distance " << max_distance << " m must be in [0, " << kMaxSearchCells * h
      << "] (64 cells of " << h << " m)";
    return Status(ErrorCode::kInvalidArgument, m.str());
  }
  const glm::dvec3 x = world_->lattice().to_lattice(p);
  ClosestPoint out;
  out.query_inside = inside_solid(*this, x);
  Nearest n = nearest_surface(*this, x, max_distance / h);
  if (!n.found) return out;
  out.found = true;
  out.point = world_->lattice().to_world(n.point);
  out.normal = glm::vec3(n.normal);
  out.material = n.material;
  out.distance = std::sqrt(n.distance2) * h;
  return out;
}

Result<Overlap> Queries::overlap(const glm::dvec3& centre, double radius) const {
  Status s = check_point("overlap: sphere centre", centre);
  if (s.ok()) s = check_positive("overlap: sphere radius", radius);
  if (!s.ok()) return s;
  const double h = world_->lattice().cell_size;
  const glm::dvec3 x = world_->lattice().to_lattice(centre);
  const double r = radius / h;
  const bool inside = inside_solid(*this, x);
  // Inside, the sphere must move out by its radius past the nearest surface.
  Nearest n = nearest_surface(*this, x, inside ? r + kDeepCells : r);
  Overlap out;
  if (!inside && !n.found) return out;
  out.overlaps = true;
  if (!n.found) {  // deep inside: at least this deep
    out.depth = (r + r + kDeepCells) * h;
    out.normal = glm::vec3(0.0f, 0.0f, 1.0f);
    out.point = centre;
    return out;
  }
  const double dist = std::sqrt(n.distance2);
  out.depth = (inside ? r + dist : r - dist) * h;
  glm::dvec3 away = inside ? n.point - x : x - n.point;
  out.normal = glm::vec3(dist > 1e-6 ? away / dist : n.normal);
  out.point = world_->lattice().to_world(n.point);
  return out;
}

Result<Overlap> Queries::overlap(const OrientedBox& box) const {
  Status s = check_point("overlap: box centre", box.centre);
  for (int a = 0; a < 3 && s.ok(); ++a) s = check_positive("overlap: box half extent", box.half_extents[a]);
  if (!s.ok()) return s;
  const glm::dmat3 rtr = glm::transpose(box.rotation) * box.rotation;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!(std::abs(rtr[i][j] - (i == j ? 1.0 : 0.0)) <= 1e-6))
        return Status(ErrorCode::kInvalidArgument, "overlap: box rotation is not orthonormal");
  const double h = world_->lattice().cell_size;
  BoxShape shape;
  shape.c = world_->lattice().to_lattice(box.centre);
  shape.e = box.half_extents / h;
  shape.r = box.rotation;
  return shape_overlap(*this, shape, h);
}

Result<Overlap> Queries::overlap(const Capsule& capsule) const {
  Status s = check_point("overlap: capsule end a", capsule.a);
  if (s.ok()) s = check_point("overlap: capsule end b", capsule.b);
  if (s.ok()) s = check_positive("overlap: capsule radius", capsule.radius);
  if (!s.ok()) return s;
  const double h = world_->lattice().cell_size;
  CapsuleShape shape;
  shape.a = world_->lattice().to_lattice(capsule.a);
  shape.b = world_->lattice().to_lattice(capsule.b);
  shape.radius = capsule.radius / h;
  return shape_overlap(*this, shape, h);
}

Result<RayHit> Queries::sphere_cast(const Ray& ray, double radius) const {
  Status s = detail::check_ray(ray, "sphere_cast");
  if (s.ok()) s = check_positive("sphere_cast: radius", radius);
  if (!s.ok()) return s;
  const double h = world_->lattice().cell_size;
  const glm::dvec3 dir = glm::normalize(ray.direction);
  const glm::dvec3 o = world_->lattice().to_lattice(ray.origin);
  const double r = radius / h;
  double t_max = ray.max_distance / h;
  RayHit hit;
  // Every cell outside the world's box is empty: once the sphere is more
  // than r past the box, nothing can touch it (a miss used to take all
  // kMaxCastSteps steps of at most 32 cells). Steps before are unchanged,
  // so hits are exactly as before.
  const glm::dvec3 inv_d = detail::inverse_direction(dir);
  const double grow = r + kContactGap + 1.0;
  double t_in = 0.0;
  if (!detail::clip_to_box(o, inv_d, glm::dvec3(world_->node_min() - 1) - grow,
                           glm::dvec3(world_->node_end()) + grow, &t_in, &t_max))
    return hit;
  // Conservative advancement: the sphere moves by its gap to the nearest
  // surface (by the search reach where none is near).
  const double search = r + 4.0;
  double t = 0.0;
  for (int step = 0; step < kMaxCastSteps; ++step) {
    const glm::dvec3 x = o + t * dir;
    const bool inside = inside_solid(*this, x);
    // The brick scan answers "nothing near" cheaply; only then is the nearest point searched.
    const bool near = any_surface_near(*this, x, search);
    const Nearest n = near ? nearest_surface(*this, x, search) : Nearest{};
    const double dist = n.found ? std::sqrt(n.distance2) : search;
    if (inside || dist <= r + kContactGap) {
      hit.hit = true;
      hit.started_inside = t == 0.0;
      hit.distance = t * h;
      hit.material = n.material;
      if (hit.started_inside) {
        hit.normal = glm::vec3(-dir);
        hit.point = ray.origin;
      } else {
        hit.point = world_->lattice().to_world(n.found ? n.point : x);
        hit.normal = glm::vec3(n.found && dist > 1e-6 ? (x - n.point) / dist : -dir);
      }
      return hit;
    }
    if (t >= t_max) break;
    // Open space: move by the widest empty box around the sphere (up to 32 cells).
    double free = dist;
    if (!near)
      while (free < r + 32.0 && !any_surface_near(*this, x, 2.0 * free)) free *= 2.0;
    t = std::min(t_max, t + std::max(free - r, kContactGap));
  }
  return hit;
}

}  // namespace ldc
