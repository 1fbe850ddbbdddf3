// Game queries on a World: ray casts, sphere casts, overlap tests and closest
// surface points, answered from the span lists with no acceleration structure
// to rebuild after edits.
//
// The surface. Between lattice nodes the world is known only through the
// points its rays store on each cell edge (position, normal, material). A query
// sees, in each cell that holds such points, the solid bounded by the tangent
// planes of those points: their intersection where the points lie on a convex
// piece of surface, their union where it is concave, and one averaged plane
// where it is neither (saddles). This is the surface that dual contouring
// places its vertices on (at the planes' meeting point), so hits agree with
// the contoured mesh (contour/contour.h) within kQuerySurfaceTolerance cells
// (except the ~1% of vertices that untangling moves next to folds at sharp
// edges, up to about 0.4 cells);
// tests/test_query.cpp measures it on spheres, boxes and cylinders at several
// resolutions. Cells between nodes that all agree and hold no points are
// wholly inside or outside. Nothing can pass through the solid: a ray that
// reaches an inside cell without having hit a plane hits the cell's face.
//
// Rays along a lattice line. A ray whose direction is a lattice axis and whose
// origin lies on a lattice line (within 1e-9 cells) returns exactly the stored
// crossing: the point, normal and material the world holds.
//
// Starting inside. A ray or sphere cast whose start is already inside the solid
// (or, for a sphere, already touching it) hits at distance 0 with
// `started_inside` set and the normal pointing back along the direction.
//
// Speed. Queries walk the lattice cell by cell but skip, whole, every 4^3 brick
// and every chunk that holds no surface (and a cube of up to 5^3 chunks when
// all of them are empty air): per chunk a few kilobytes of bits are
// derived on first use (tens of microseconds) and kept until the chunk or one
// of its neighbours changes; an edit therefore costs later queries only the
// re-derivation of the chunks it changed.
//
// Thread safety: all query methods are const and may run concurrently with
// each other. Editing the world while queries run is not allowed (the World
// rule). After edits, queries pick up the changes by themselves; call
// refresh() now and then (e.g. once per frame, when no query runs) to free
// what was derived from replaced chunks.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/context.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

namespace detail {
struct CellIndex;
}

// How far a query's surface may lie from the dual-contoured mesh of the same
// world on smooth surfaces [Units: cells (h)]. Measured by tests/test_query.cpp;
// at sharp features and thin parts (below about 2 cells) it can be larger.
inline constexpr double kQuerySurfaceTolerance = 0.25;

struct Ray {
  glm::dvec3 origin{0.0};     // [Units: m] [Limit: finite]
  glm::dvec3 direction{0.0, 0.0, -1.0};  // any length > 0; normalized by the query [Limit: finite]
  double max_distance = std::numeric_limits<double>::infinity();  // [Units: m] [Limit: >= 0]
};

struct RayHit {
  bool hit = false;
  double distance = 0.0;     // along the normalized direction [Units: m]
  glm::dvec3 point{0.0};     // origin + distance * direction (for a sphere cast: the contact point)
  glm::vec3 normal{0.0f};    // unit, pointing out of the solid
  uint16_t material = 0;
  bool started_inside = false;  // the start was inside (touching, for spheres): distance 0
};

// Result of an overlap test.
struct Overlap {
  bool overlaps = false;
  double depth = 0.0;          // how far to move the shape along `normal` to separate it [Units: m]
  glm::vec3 normal{0.0f};      // unit, out of the solid, at the deepest contact
  glm::dvec3 point{0.0};       // the surface point of the deepest contact
};

struct ClosestPoint {
  bool found = false;          // false when no surface lies within the search distance
  glm::dvec3 point{0.0};       // [Units: m]
  glm::vec3 normal{0.0f};      // unit, out of the solid
  double distance = 0.0;       // from the query point [Units: m]
  uint16_t material = 0;
  bool query_inside = false;   // whether the query point itself is inside the solid
};

struct OrientedBox {
  glm::dvec3 centre{0.0};        // [Units: m] (0.2 spelled it center)
  glm::dvec3 half_extents{0.5};  // [Units: m] [Limit: > 0]
  glm::dmat3 rotation{1.0};      // columns: the box's axes in world space [Limit: orthonormal]
};

struct Capsule {
  glm::dvec3 a{0.0}, b{0.0, 0.0, 1.0};  // end points of the core segment [Units: m]
  double radius = 0.5;                  // [Units: m] [Limit: > 0]
};

// What the per-chunk bits cost.
struct QueryCacheStats {
  size_t chunks_indexed = 0;   // chunks with derived bits in use
  size_t bytes = 0;            // memory they take
  size_t retired = 0;          // entries of replaced chunks waiting for refresh()
};

class Queries {
 public:
  // Keeps a reference: the world must outlive this object and stay at its
  // address (WorldEditor::world() does).
  explicit Queries(const World& world);
  ~Queries();
  Queries(const Queries&) = delete;
  Queries& operator=(const Queries&) = delete;

  const World& world() const { return *world_; }

  // First hit along the ray within max_distance; hit = false when none.
  // Errors: a NaN or infinite origin or direction, a zero direction, a
  // negative or NaN max_distance. Each thread that casts keeps the surface
  // of the last cells it crossed (64 cells, about 90 KB, tagged with the
  // world's content stamp, so edits are always seen): neighbouring camera
  // rays read a cell once.
  Result<RayHit> ray_cast(const Ray& ray) const;

  // Many rays in parallel (TBB) into caller-owned hits (hits.size() >=
  // rays.size()). Every ray is checked first: an error names the first bad ray
  // and leaves `hits` untouched.
  Status ray_cast(std::span<const Ray> rays, std::span<RayHit> hits, Context* ctx = nullptr) const;

  // A sphere of `radius` swept from ray.origin along ray.direction: the first
  // distance at which it touches the surface, with the contact point and
  // normal. Accurate to 0.05 h plus kQuerySurfaceTolerance.
  Result<RayHit> sphere_cast(const Ray& ray, double radius) const;

  // Overlap of a shape with the solid: whether it touches or is inside, how
  // deep it is (to within 0.1 h), and the normal of the deepest contact. A
  // sphere whose centre lies more than radius + 16 h below the surface reports
  // that much as its depth, with the normal +z: the surface is not searched
  // further. A box or capsule wholly inside the solid overlaps with depth 0.
  Result<Overlap> overlap(const glm::dvec3& centre, double radius) const;  // sphere
  Result<Overlap> overlap(const OrientedBox& box) const;
  Result<Overlap> overlap(const Capsule& capsule) const;

  // The surface point nearest to p within max_distance [Units: m] [Limit: >= 0,
  // at most 64 cells: the search visits every cell in that ball].
  Result<ClosestPoint> closest_point(const glm::dvec3& p, double max_distance) const;

  // The core's node-vote inside test (World::inside), unchanged.
  bool inside(const glm::dvec3& p) const { return world_->inside(p); }

  // Frees what was derived from chunks that have since been replaced, and
  // follows the world's box if it grew. Not concurrent with queries.
  void refresh();
  QueryCacheStats cache_stats() const;

  // Internal: the derived bits of chunk c, built on first use. Never null.
  const detail::CellIndex* cell_index(const glm::ivec3& c) const;

 private:
  RayHit cast_checked(const Ray& ray) const;  // ray_cast after the ray passed check_ray
  const detail::CellIndex* lookup_slow(const glm::ivec3& c, std::atomic<detail::CellIndex*>* slot) const;
  size_t slot_count() const;
  void delete_slots();
  void reset_slots();

  const World* world_;
  glm::ivec3 slot_origin_{0};  // chunk of slot 0: one below the world's first chunk
  glm::ivec3 slot_dims_{0};
  std::unique_ptr<std::atomic<detail::CellIndex*>[]> slots_;
  mutable std::mutex retired_mutex_;
  mutable std::vector<std::unique_ptr<detail::CellIndex>> retired_;
};

}  // namespace ldc
