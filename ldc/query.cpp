// Queries: the per-chunk cache of derived bits, and ray casts.
#include "ldc/query.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <tbb/parallel_for.h>

#include "ldc/detail/cell_index.h"
#include "ldc/internal/ray_math.h"
#include "ldc/internal/vec_text.h"

namespace ldc {

using detail::CellIndex;

Queries::Queries(const World& world) : world_(&world) { reset_slots(); }

Queries::~Queries() { delete_slots(); }

size_t Queries::slot_count() const { return size_t(slot_dims_.x) * slot_dims_.y * slot_dims_.z; }

void Queries::delete_slots() {
  if (!slots_) return;
  for (size_t i = 0; i < slot_count(); ++i) delete slots_[i].exchange(nullptr);
}

void Queries::reset_slots() {
  delete_slots();
  // One extra layer below the box: those cells touch the box's first nodes.
  slot_origin_ = world_->chunk_origin() - 1;
  slot_dims_ = world_->chunk_dims() + 1;
  const size_t n = slot_count();
  slots_ = std::make_unique<std::atomic<CellIndex*>[]>(n);
  for (size_t i = 0; i < n; ++i) slots_[i].store(nullptr, std::memory_order_relaxed);
}

void Queries::refresh() {
  {
    std::lock_guard<std::mutex> lock(retired_mutex_);
    retired_.clear();
  }
  if (world_->chunk_origin() - 1 != slot_origin_ || world_->chunk_dims() + 1 != slot_dims_) {
    reset_slots();
    return;
  }
  size_t i = 0;
  for (int z = 0; z < slot_dims_.z; ++z)
    for (int y = 0; y < slot_dims_.y; ++y)
      for (int x = 0; x < slot_dims_.x; ++x, ++i) {
        CellIndex* e = slots_[i].load(std::memory_order_relaxed);
        if (!e || e->checked_stamp.load(std::memory_order_relaxed) == world_->stamp()) continue;  // checked against this world
        // A cube of clear chunks would be checked chunk by chunk (up to 125
        // of them): dropped instead, and derived again if a ray comes by.
        if (e->clear_radius > 1 || !detail::index_current(*e, *world_, slot_origin_ + glm::ivec3(x, y, z))) {
          delete e;
          slots_[i].store(nullptr, std::memory_order_relaxed);
        }
      }
}

QueryCacheStats Queries::cache_stats() const {
  QueryCacheStats stats;
  for (size_t i = 0; i < slot_count(); ++i) {
    const CellIndex* e = slots_[i].load(std::memory_order_acquire);
    if (!e) continue;
    ++stats.chunks_indexed;
    stats.bytes += e->memory_bytes();
  }
  std::lock_guard<std::mutex> lock(retired_mutex_);
  stats.retired = retired_.size();
  for (const auto& e : retired_) stats.bytes += e->memory_bytes();
  return stats;
}

const CellIndex* Queries::cell_index(const glm::ivec3& c) const {
  const glm::ivec3 r = c - slot_origin_;
  if (r.x < 0 || r.y < 0 || r.z < 0 || r.x >= slot_dims_.x || r.y >= slot_dims_.y || r.z >= slot_dims_.z) {
    // Outside the cached layout: beyond the box (empty), or the box grew since refresh().
    return lookup_slow(c, nullptr);
  }
  std::atomic<CellIndex*>* slot = &slots_[(size_t(r.z) * slot_dims_.y + r.y) * slot_dims_.x + r.x];
  const CellIndex* e = slot->load(std::memory_order_acquire);
  if (e && e->checked_stamp.load(std::memory_order_relaxed) == world_->stamp()) return e;
  return lookup_slow(c, slot);
}

const CellIndex* Queries::lookup_slow(const glm::ivec3& c, std::atomic<CellIndex*>* slot) const {
  if (!slot) {
    // Chunks past every face of the box and its lower layer are empty, and so are their cells.
    static const std::unique_ptr<CellIndex> kOutside = [] {
      auto e = std::make_unique<CellIndex>();
      e->clear = true;
      return e;
    }();
    bool touches_box = false;
    for (const glm::ivec3& offset : detail::kIndexSourceOffsets) touches_box |= world_->contains_chunk(c + offset);
    if (!touches_box) return kOutside.get();
    // The box grew since the layout was made: keep a per-thread copy for this chunk.
    thread_local std::unique_ptr<CellIndex> scratch;
    thread_local glm::ivec3 scratch_chunk;
    thread_local uint64_t scratch_stamp = 0;
    if (!scratch || scratch_chunk != c || scratch_stamp != world_->stamp()) {
      scratch = detail::build_cell_index(*world_, c);
      scratch_chunk = c;
      scratch_stamp = world_->stamp();
    }
    return scratch.get();
  }
  CellIndex* current = slot->load(std::memory_order_acquire);
  for (;;) {
    if (current && detail::index_current(*current, *world_, c)) {
      current->checked_stamp.store(world_->stamp(), std::memory_order_relaxed);
      return current;
    }
    std::unique_ptr<CellIndex> fresh = detail::build_cell_index(*world_, c);
    if (slot->compare_exchange_strong(current, fresh.get(), std::memory_order_acq_rel)) {
      if (current) {
        std::lock_guard<std::mutex> lock(retired_mutex_);
        retired_.emplace_back(current);  // other threads may still read it until refresh()
      }
      return fresh.release();
    }
    // Another thread stored one first: `current` now holds it; check it.
  }
}

// ---------------------------------------------------------------------------
// Ray casts

Status detail::check_ray(const Ray& ray, const char* what) {
  using detail::vec_text;
  const std::string head = std::string(what) + ": ";
  if (!detail::is_finite(ray.origin))
    return {ErrorCode::kInvalidArgument, head + "origin " + vec_text(ray.origin) + " is not finite"};
  if (!detail::is_finite(ray.direction))
    return {ErrorCode::kInvalidArgument, head + "direction " + vec_text(ray.direction) + " is not finite"};
  const double len = glm::length(ray.direction);
  if (!(len > 1e-300) || !std::isfinite(len))
    return {ErrorCode::kInvalidArgument, head + "direction " + vec_text(ray.direction) + " has no length"};
  if (!(ray.max_distance >= 0.0)) {
    std::ostringstream s;
    s << head << "max_distance " << ray.max_distance << " must be >= 0";
    return {ErrorCode::kInvalidArgument, s.str()};
  }
  return {};
}

namespace {

// A ray along a lattice axis whose origin lies on a lattice line: the axis, or -1.
int lattice_line_axis(const glm::dvec3& o, const glm::dvec3& d) {
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) continue;
    if (axis >= 0) return -1;
    axis = a;
  }
  if (axis < 0) return -1;
  for (int a : {axis_u(axis), axis_v(axis)})
    if (std::abs(o[a] - std::round(o[a])) > 1e-9) return -1;
  return axis;
}

// Exact answer from the stored points of the ray the cast runs along.
RayHit cast_along_lattice_line(const World& world, const glm::dvec3& o, int axis, bool forward, double max_cells) {
  RayHit hit;
  const glm::ivec2 uv(int(std::lround(o[axis_u(axis)])), int(std::lround(o[axis_v(axis)])));
  const std::vector<SurfacePoint> points = world.ray_points(axis, uv);
  const double start = o[axis];
  // Points before the start decide whether it is inside (rays start outside).
  size_t before = 0;
  while (before < points.size() && points[before].depth <= start) ++before;
  if (before % 2 == 1) {
    hit.hit = hit.started_inside = true;
    return hit;
  }
  const SurfacePoint* p = nullptr;
  if (forward && before < points.size()) p = &points[before];
  if (!forward && before > 0) p = &points[before - 1];
  if (!p || std::abs(p->depth - start) > max_cells) return hit;
  hit.hit = true;
  hit.distance = std::abs(p->depth - start) * world.lattice().cell_size;
  hit.normal = p->normal;
  hit.material = p->material;
  return hit;
}

}  // namespace

Result<RayHit> Queries::ray_cast(const Ray& ray) const {
  Status s = detail::check_ray(ray, "ray_cast");
  if (!s.ok()) return s;
  return cast_checked(ray);
}

RayHit Queries::cast_checked(const Ray& ray) const {
  const World& world = *world_;
  const double h = world.lattice().cell_size;
  const glm::dvec3 dir = glm::normalize(ray.direction);
  const glm::dvec3 o = world.lattice().to_lattice(ray.origin), d = dir / h;
  RayHit hit;
  const int line_axis = lattice_line_axis(o, d);
  if (line_axis >= 0) {
    hit = cast_along_lattice_line(world, o, line_axis, d[line_axis] > 0.0, ray.max_distance / h);
  } else {
    uint16_t last_material = 0;
    // The normal of the cell face the walk entered through (back along the ray for the first cell).
    auto face_normal = [&](int entry_axis) {
      glm::vec3 n = entry_axis >= 0 ? glm::vec3(0.0f) : glm::vec3(-dir);
      if (entry_axis >= 0) n[entry_axis] = d[entry_axis] > 0.0 ? -1.0f : 1.0f;
      return n;
    };
    detail::walk_cells(*this, world, o, d, 0.0, ray.max_distance,
                       [&](const glm::ivec3& cell, detail::CellKind kind, double t0, double t1, int entry_axis) {
                         if (kind == detail::CellKind::kInside) {
                           // Reached an inside cell without meeting a plane: hit its face.
                           hit.hit = true;
                           hit.distance = t0;
                           hit.material = last_material;
                           hit.normal = face_normal(entry_axis);
                           return true;
                         }
                         const detail::CellSurface* surface = detail::cached_cell_surface(world, cell);
                         if (!surface) return false;
                         const glm::dvec3 local = o - glm::dvec3(cell);
                         detail::CellHit ch = detail::intersect_cell(*surface, local, d, t0, t1);
                         last_material = surface->planes[0].material;
                         if (!ch.hit) return false;
                         const detail::CellPlane& plane = surface->planes[size_t(ch.plane)];
                         hit.hit = true;
                         hit.distance = ch.t;
                         hit.normal = glm::vec3(plane.n);
                         hit.material = plane.material;
                         // Inside the cell's planes on entry, with the nearest plane facing away
                         // (a step or thin lip between cells): the face entered is the surface hit.
                         if (glm::dot(plane.n, d) > 0.0) hit.normal = face_normal(entry_axis);
                         return true;
                       });
    if (hit.hit && hit.distance <= 0.0) hit.started_inside = true;
  }
  if (hit.started_inside) {
    hit.distance = 0.0;
    hit.normal = glm::vec3(-dir);
  }
  if (hit.hit) hit.point = ray.origin + hit.distance * dir;
  return hit;
}

Status Queries::ray_cast(std::span<const Ray> rays, std::span<RayHit> hits, Context* ctx) const {
  if (hits.size() < rays.size()) {
    return {ErrorCode::kInvalidArgument, "ray_cast: " + std::to_string(hits.size()) + " hit slots for " +
                                             std::to_string(rays.size()) + " rays"};
  }
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::string what = "ray_cast: ray " + std::to_string(i);
    Status s = detail::check_ray(rays[i], what.c_str());
    if (!s.ok()) return s;
  }
  ScopedTimer timer(ctx, "ray_cast");
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i < r.end(); ++i) hits[i] = cast_checked(rays[i]);
  });
  return {};
}

}  // namespace ldc
