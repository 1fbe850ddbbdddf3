// What queries derive from the span lists: per chunk, which cells hold
// surface and which are inside (CellIndex); per surface cell, the tangent
// planes of the points on its twelve edges (CellSurface); and the walk of a
// ray through the cells that skips bricks and chunks without surface.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/query.h"
#include "ldc/world.h"

namespace ldc::detail {

// The chunk's own data and the neighbours whose rays hold edges of its cells:
// +x, +y, +z, +xy, +yz, +zx.
inline constexpr int kIndexSources = 7;
inline const std::array<glm::ivec3, kIndexSources> kIndexSourceOffsets = {
    glm::ivec3(0, 0, 0), glm::ivec3(1, 0, 0), glm::ivec3(0, 1, 0), glm::ivec3(0, 0, 1),
    glm::ivec3(1, 1, 0), glm::ivec3(0, 1, 1), glm::ivec3(1, 0, 1)};

inline constexpr int kBrickShift = 2;  // bricks of 4^3 cells

// The cells of one chunk: cell (i, j, k) spans nodes i..i+1, j..j+1, k..k+1
// (local), so the cells at the far faces need the neighbours' rays.
struct CellIndex {
  // The chunks it was derived from (held, so that no other chunk can take
  // their addresses while it lives) and their kinds.
  std::array<std::shared_ptr<const Chunk>, kIndexSources> sources;
  std::array<ChunkKind, kIndexSources> kinds{};
  std::atomic<uint64_t> checked_stamp{0};  // world stamp at which the sources were last current

  int size = 0;               // C
  int bricks_per_axis = 0;    // B = C / 4
  bool clear = false;         // no surface cell: every cell is inside (clear_inside) or outside
  bool clear_inside = false;
  // One 64-bit word per 4^3 brick (brick (bz*B + by)*B + bx), bit
  // ((z&3)*4 + (y&3))*4 + (x&3) per cell.
  std::vector<uint64_t> surface;  // the cell has points on an edge
  std::vector<uint64_t> inside;   // the cell's first corner is inside
  // Per brick without surface or inside cells: r >= 1 such that every brick
  // within Chebyshev distance r - 1 in this chunk is so too. 0 for the others.
  std::vector<uint8_t> empty_radius;
  // Local cells [busy_lo, busy_hi) hold every surface and inside cell (brick-aligned).
  glm::ivec3 busy_lo{0}, busy_hi{0};
  // For a clear chunk outside the solid: r >= 1 such that every chunk within
  // Chebyshev distance r - 1 is one too (all chunks within r - 1 of it, and
  // one more layer above, are empty), so that a ray leaves that cube of
  // chunks in one step: camera rays cross several such chunks before they
  // reach the surface. 1 for every other chunk. index_current checks it.
  int clear_radius = 1;
  static constexpr int kMaxClearRadius = 3;

  static int cell_bit(const glm::ivec3& l) { return (((l.z & 3) << 2 | (l.y & 3)) << 2) | (l.x & 3); }
  int brick_of(const glm::ivec3& l) const {
    return ((l.z >> kBrickShift) * bricks_per_axis + (l.y >> kBrickShift)) * bricks_per_axis + (l.x >> kBrickShift);
  }
  bool is_surface(const glm::ivec3& l) const { return (surface[size_t(brick_of(l))] >> cell_bit(l)) & 1u; }
  bool is_inside(const glm::ivec3& l) const { return (inside[size_t(brick_of(l))] >> cell_bit(l)) & 1u; }
  size_t memory_bytes() const;
};

// The checks every cast shares; `what` starts the message ("sphere_cast").
Status check_ray(const Ray& ray, const char* what);

// Whether the index still describes chunk c of the world.
bool index_current(const CellIndex& index, const World& world, const glm::ivec3& c);
std::unique_ptr<CellIndex> build_cell_index(const World& world, const glm::ivec3& c);

// One tangent plane: a surface point (cell-local coordinates, cells) and its normal.
// Left uninitialized on purpose: a CellSurface is made per query, and only
// its first `count` planes are ever read.
struct CellPlane {
  glm::dvec3 p;
  glm::dvec3 n;
  uint16_t material;
};

enum class CellShape : uint8_t {
  kConvex,   // solid = intersection of the planes' inner half-spaces
  kConcave,  // solid = union of them
  kPlane,    // neither: one averaged plane (planes[0])
};

// The surface in one cell, in coordinates local to the cell (its first node at 0).
struct CellSurface {
  static constexpr int kMaxPlanes = 24;
  std::array<CellPlane, kMaxPlanes> planes;
  int count = 0;
  CellShape shape = CellShape::kConvex;

  // Signed distance-like value: <= 0 inside the solid model [Units: cells].
  double inside_value(const glm::dvec3& x, int* plane = nullptr) const;
  bool contains(const glm::dvec3& x) const { return inside_value(x) <= 0.0; }
};

// Gathers the points on the cell's twelve edges (cell = its first node, global)
// and classifies their planes. Returns false when the cell holds no point.
bool gather_cell_surface(const World& world, const glm::ivec3& cell, CellSurface* out);

// gather_cell_surface through a small cache per thread of the cells it
// gathered last, keyed by the world's content stamp (so an edit or another
// world never reads a stale entry): neighbouring camera rays cross the same
// cells. The surface stays valid until this thread's next call; nullptr when
// the cell holds no point.
const CellSurface* cached_cell_surface(const World& world, const glm::ivec3& cell);

// First entry of x(t) = o + t*d into the cell's solid for t in [t0, t1]
// (cell-local o). `plane` is the plane entered (its normal is the hit normal).
struct CellHit {
  bool hit = false;
  double t = 0.0;
  int plane = 0;
};
CellHit intersect_cell(const CellSurface& surface, const glm::dvec3& o, const glm::dvec3& d, double t0,
                       double t1);

// Nearest point of the cell's surface to x (cell-local), searched within the
// cell's box [0,1]^3; false when the model has no surface in the box.
struct CellClosest {
  glm::dvec3 point{0.0};
  double distance2 = 0.0;
  int plane = 0;
};
bool closest_in_cell(const CellSurface& surface, const glm::dvec3& x, CellClosest* out);

// What the walk reports for a cell that is not wholly outside.
enum class CellKind : uint8_t { kSurface, kInside };

// Walks the cells of x(t) = o + t*d (lattice coordinates, d in cells per unit
// of t) for t in [t_begin, t_end], in order, skipping bricks and chunks with
// no surface and nothing inside. visit(cell, kind, t0, t1, entry_axis) returns
// true to stop; entry_axis is the axis of the face the walk entered the cell
// through (-1 for the first cell).
template <class Visit>
void walk_cells(const Queries& queries, const World& world, const glm::dvec3& o, const glm::dvec3& d,
                double t_begin, double t_end, Visit&& visit);

}  // namespace ldc::detail

#include "ldc/detail/cell_walk.h"
