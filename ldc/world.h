// The Layered Depth Cube world: lattice, chunks, span lists, queries, validate().
//
// Geometry. A world has a lattice: an origin and a cell size h. Lattice nodes
// sit at origin + h * (i, j, k). For each axis there is a family of rays, one
// through every node of the perpendicular lattice plane; a ray of axis a is
// named by its two other node coordinates (u, v) in cyclic order:
//   X rays by (y, z),  Y rays by (z, x),  Z rays by (x, y).
// Depth along a ray is measured in cells from the lattice origin, so node i of
// an X ray is at depth i. Each ray stores the sorted points where it crosses
// the surface of the solid, each with a normal pointing out of the solid, a
// material id and whether the ray enters or exits the solid there.
//
// Chunks. The world is cut into cubes of C^3 cells (C = chunk_size). Chunk c
// owns nodes [c*C, c*C + C) on each axis, i.e. C*C rays per axis, and the part
// of each of those rays with depth in [c*C, c*C + C). A chunk whose rays hold
// no points and are all outside (all inside) is stored as the flag kEmpty
// (kSolid) only. Everything outside the world's chunk box is empty.
//
// Storage. A point takes 8 bytes (PackedPoint). Its depth is a 16-bit fixed
// point offset from the chunk start with Q = 65536 / C steps per cell (2048 at
// C = 32: at most h/4096 error). No point ever sits exactly on a node, so
// whether a node is inside is never ambiguous: node n of a ray is inside when
// the ray starts inside and an even number of points lie before it, or starts
// outside and an odd number does. The three rays through any node agree; that
// is one of the invariants validate() checks.
//
// Thread safety: const methods may be called concurrently. Mutation is not
// thread-safe. Chunks are immutable once stored and shared between copies of
// a World, so copying a World is cheap (a snapshot).
#pragma once

#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/status.h"

namespace ldc {

enum class Axis : uint8_t { kX = 0, kY = 1, kZ = 2 };

// The coordinates naming rays of axis a, in cyclic order after a.
constexpr int axis_u(int a) { return (a + 1) % 3; }
constexpr int axis_v(int a) { return (a + 2) % 3; }
const char* axis_name(int a);

inline constexpr int kMinChunkSize = 8;
inline constexpr int kMaxChunkSize = 64;
inline constexpr uint32_t kDepthSteps = 65536;  // depth steps per chunk segment
// Chunk slots in one world's box; beyond this, create() refuses.
inline constexpr int64_t kMaxChunkSlots = int64_t{1} << 22;
// Largest node coordinate magnitude: keeps exact predicates in 128 bits.
inline constexpr int64_t kMaxNodeCoordinate = int64_t{1} << 20;

// Depth steps per cell for a chunk size: 65536 / C.
constexpr uint32_t depth_steps_per_cell(int chunk_size) {
  return kDepthSteps / static_cast<uint32_t>(chunk_size);
}

struct Lattice {
  glm::dvec3 origin{0.0};  // world position of node (0, 0, 0) [Units: m]
  double cell_size = 0.2;  // h [Units: m] [Limit: > 0, finite]

  glm::dvec3 node_position(const glm::ivec3& node) const {
    return origin + cell_size * glm::dvec3(node);
  }
  // World position to lattice coordinates (cells, fractional).
  glm::dvec3 to_lattice(const glm::dvec3& p) const { return (p - origin) / cell_size; }
  glm::dvec3 to_world(const glm::dvec3& lattice_coords) const {
    return origin + cell_size * lattice_coords;
  }
};

// ---------------------------------------------------------------------------
// Points

// One surface crossing, 8 bytes.
struct PackedPoint {
  uint16_t depth = 0;     // steps from the chunk segment start; never a multiple of Q
  uint16_t material = 0;  // material id
  uint32_t normal = 0;    // bits 0-14, 15-29: octahedral normal; bit 30: exit; bit 31: 0

  bool exits() const { return (normal >> 30) & 1u; }
  bool enters() const { return !exits(); }
};
static_assert(sizeof(PackedPoint) == 8);

inline constexpr uint32_t kPointExitBit = 1u << 30;
inline constexpr uint32_t kPointReservedBit = 1u << 31;

// Octahedral normal code of 30 bits (Cigolle et al. 2014, kNormalOctBits per
// component); the decoded normal is within 0.02 degrees of the input
// (measured by tests/test_world.cpp).
inline constexpr int kNormalOctBits = 15;
uint32_t encode_normal(const glm::dvec3& unit_normal);
// Inline, as walks decode a normal per point: out of line it cost a coarse
// cascade level 4 to 8% and random ray casts 6% more (same bits either way).
inline glm::vec3 decode_normal(uint32_t code) {
  constexpr uint32_t kOctMax = (1u << kNormalOctBits) - 1;
  const double px = static_cast<double>(code & kOctMax) / kOctMax * 2.0 - 1.0;
  const double py = static_cast<double>((code >> kNormalOctBits) & kOctMax) / kOctMax * 2.0 - 1.0;
  glm::dvec3 n(px, py, 1.0 - std::abs(px) - std::abs(py));
  if (n.z < 0.0) {
    n.x = (1.0 - std::abs(py)) * (px >= 0.0 ? 1.0 : -1.0);
    n.y = (1.0 - std::abs(px)) * (py >= 0.0 ? 1.0 : -1.0);
  }
  return glm::vec3(glm::normalize(n));
}

// A decoded point.
struct SurfacePoint {
  double depth = 0.0;  // lattice units along the ray's axis (global)
  glm::vec3 normal{0.0f};
  uint16_t material = 0;
  bool enter = true;
};

// A solid interval [enter.depth, exit.depth] of one ray.
struct Span {
  SurfacePoint enter;
  SurfacePoint exit;
  double length() const { return exit.depth - enter.depth; }
};

// ---------------------------------------------------------------------------
// Chunks

// All rays of one axis inside one chunk: C*C rays, ray index = v_local*C + u_local.
// Frozen structure of arrays: the points of all rays in one array, ray after
// ray, located by a two-bit code per ray (empty and outside at its start,
// empty and inside, one point, several: their count in a byte beside) and
// the first point of each row of C rays: about 0.38 byte per ray. A ray's
// start (inside or not) is its first point's sense, or the code of an empty
// ray; a family whose start bits disagree with its points (invalid, but
// kept for validate() to report) keeps a start bit per ray as well. A family
// with a ray of more than 255 points, or of more than 65535 points in all,
// keeps a 32-bit offset and a start bit per ray instead.
class RayFamily {
 public:
  // A family whose rays hold no points and are all outside / all inside.
  static RayFamily uniform(bool inside);
  RayFamily() = default;  // uniform outside

  bool is_uniform() const { return size_ == 0; }
  int size() const { return size_; }  // C, or 0 when uniform
  bool uniform_inside() const { return uniform_inside_; }
  bool starts_inside(int ray) const;
  // The same, given the ray's points (as points(ray) or a walk along a row
  // gives them): saves the offset sum.
  bool starts_inside(int ray, std::span<const PackedPoint> ray_points) const {
    if (is_uniform()) return uniform_inside_;
    if (!inside_.empty()) return (inside_[size_t(ray) >> 6] >> (ray & 63)) & 1u;
    if (ray_points.empty()) return ray_code(ray) & 1u;
    return (ray_points.front().normal & kPointExitBit) != 0;
  }
  std::span<const PackedPoint> points(int ray) const;
  // Index in all_points() of the ray's first point (sums the counts of the
  // rays before it in its row). Walks over a family's rays in order use a
  // RayReader instead.
  uint32_t first_point(int ray) const;
  // The same, with the point counts of `counts.size()` rays from `ray` on in
  // its row, in one pass (cell walks read two neighbouring rays).
  uint32_t first_point(int ray, std::span<uint32_t> counts) const;
  bool holds_points(int ray) const {
    if (is_uniform()) return false;
    if (!first_.empty()) return first_[size_t(ray) + 1] != first_[size_t(ray)];
    return ray_code(ray) >= kOnePoint;
  }
  // Points on one ray, in constant time (its code; a ray of several points
  // also counts the codes before it in its row): lets walks skip empty rays.
  uint32_t point_count(int ray) const {
    if (is_uniform()) return 0;
    if (!first_.empty()) return first_[size_t(ray) + 1] - first_[size_t(ray)];
    const uint32_t code = ray_code(ray);
    return code < kOnePoint ? 0u : code == kOnePoint ? 1u : several_count(ray);
  }
  size_t point_count() const { return points_.size(); }
  // Starts loading what first_point(ray) reads, so that a caller about to
  // read several rays waits for memory once, not once per ray.
  void prefetch_ray(int ray) const {
    if (is_uniform()) return;
    if (!first_.empty()) {
      __builtin_prefetch(first_.data() + ray);
      return;
    }
    __builtin_prefetch(codes_.data() + (size_t(ray) >> 5));
    __builtin_prefetch(rows_.data() + 2 * size_t(ray / size_));
  }
  // The same for the points from index `first` of all_points() on.
  void prefetch_points(uint32_t first) const { __builtin_prefetch(points_.data() + first); }
  size_t memory_bytes() const;

  // Raw arrays, for file I/O and validate(); empty when uniform.
  std::vector<uint64_t> start_bits() const;  // bit r: starts_inside(r)
  std::span<const PackedPoint> all_points() const { return points_; }
  // Checks the offset arrays against each other; returns "" or what is wrong.
  std::string check_structure() const;

 private:
  friend class RayFamilyWriter;
  friend class RayReader;
  // Ray codes: empty rays by their start, then one point, then several.
  static constexpr uint32_t kEmptyOutside = 0, kEmptyInside = 1, kOnePoint = 2, kSeveral = 3;
  struct RowPrefix {
    uint32_t single = 0, several = 0;  // rays before the ray in its row with one point, with several
  };
  uint32_t ray_code(int ray) const { return uint32_t(codes_[size_t(ray) >> 5] >> ((ray & 31) * 2)) & 3u; }
  // Set bits of x, which has bits at even positions only. Arithmetic rather
  // than std::popcount: without -mpopcnt, which the build does not assume,
  // that is a libgcc call, and ray casts run this per cell (13% of landscape
  // ray-cast time when it was).
  static uint32_t count_even_bits(uint64_t x) {
    x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return uint32_t((x * 0x0101010101010101ull) >> 56);
  }
  // Rays coded one point and several among the codes in x.
  static RowPrefix code_counts(uint64_t x) {
    constexpr uint64_t kLow = 0x5555555555555555ull;
    const uint64_t high = (x >> 1) & kLow, low = x & kLow;
    return {count_even_bits(high & ~low), count_even_bits(high & low)};
  }
  // The counts over the codes of the rays of `ray`'s row before it. A row is
  // 2C bits: one word at C = 32, part of one below (rows never straddle
  // words), two at C = 64.
  RowPrefix row_prefix(int ray) const {
    if (size_ > 32) return wide_row_prefix(ray);
    const int in_row = ray % size_;
    const uint64_t word = codes_[size_t(ray) >> 5] >> ((size_t(ray - in_row) * 2) & 63);
    return code_counts(word & ((uint64_t{1} << (2 * in_row)) - 1));
  }
  RowPrefix wide_row_prefix(int ray) const;
  uint32_t several_count(int ray) const;
  uint32_t row_first(size_t row) const { return rows_[2 * row]; }
  uint32_t row_several(size_t row) const { return rows_[2 * row + 1]; }

  uint8_t size_ = 0;  // C, or 0 when uniform
  bool uniform_inside_ = false;
  std::vector<uint64_t> codes_;         // two bits a ray, ray r at bit 2 (r mod 32) of word r / 32 (compact form)
  std::vector<uint8_t> several_;        // point counts of the rays coded kSeveral, in ray order
  std::vector<uint16_t> rows_;          // per row r <= C: first point, first entry of several_ (compact form)
  std::vector<uint32_t> first_;         // first point of each ray, C*C + 1 entries (wide form)
  std::vector<uint64_t> inside_;        // start bit per ray: wide form, or starts that disagree with the points
  std::vector<PackedPoint> points_;
};

// One ray of a family: its start and its points.
struct RayPoints {
  bool starts_inside = false;
  std::span<const PackedPoint> points;
};

// Reads a family's rays in order 0 .. C*C-1, each in constant time (random
// access through RayFamily sums offsets along the ray's row). Keeps a
// reference: the family must outlive it.
class RayReader {
 public:
  explicit RayReader(const RayFamily& family) : family_(family) {}
  RayPoints next();
  // Skips the rays before `ray` (each in constant time) and reads it: for
  // walks that visit a subset of the rays in order. `ray` must not be before
  // the next one.
  RayPoints next_at(int ray);

 private:
  const RayFamily& family_;
  int ray_ = 0;
  uint32_t first_ = 0;    // first point of the next ray
  uint32_t several_ = 0;  // next entry of the several-point counts
};

// Builds a RayFamily ray by ray, in ray order 0 .. C*C-1.
class RayFamilyWriter {
 public:
  explicit RayFamilyWriter(int chunk_size);
  void begin_ray(bool starts_inside);
  void add_point(const PackedPoint& p) { points_.push_back(p); }
  // Collapses to a uniform family when no ray holds points and all start alike.
  RayFamily finish();

 private:
  void fill_compact(RayFamily& f);

  int chunk_size_;
  int rays_ = 0;
  bool any_inside_ = false;
  bool any_outside_ = false;
  std::vector<uint32_t> first_;
  std::vector<uint64_t> inside_;
  std::vector<PackedPoint> points_;
};

enum class ChunkKind : uint8_t { kEmpty = 0, kSolid = 1, kMixed = 2 };
const char* chunk_kind_name(ChunkKind kind);

struct Chunk {
  std::array<RayFamily, 3> axis;

  // True, with *inside set, when all three families are uniform and alike.
  bool is_uniform(bool* inside) const;
  size_t point_count() const;
  size_t memory_bytes() const;
};

// ---------------------------------------------------------------------------
// World

struct WorldConfig {
  Lattice lattice;
  int chunk_size = 32;            // C [Limit: 8, 16, 32 or 64] [Units: cells]
  glm::ivec3 chunk_origin{0};     // first chunk of the world's box [Units: chunks]
  glm::ivec3 chunk_dims{1};       // chunks per axis [Limit: >= 1, product <= kMaxChunkSlots]
};

struct WorldStats {
  size_t chunks_total = 0;
  size_t chunks_empty = 0;
  size_t chunks_solid = 0;
  size_t chunks_mixed = 0;
  size_t rays_stored = 0;      // rays held explicitly (non-uniform families)
  size_t points = 0;
  size_t point_bytes = 0;      // points * sizeof(PackedPoint)
  size_t memory_bytes = 0;     // everything the world holds, chunk table included
  double bytes_per_point() const {
    return points ? static_cast<double>(memory_bytes) / static_cast<double>(points) : 0.0;
  }
};

// A number naming a world's content: it changes whenever chunks or the box
// change and is unique across the process, so two worlds with equal stamps
// hold the same chunks (one is a copy of the other). Queries use it to know
// that what they derived from the chunks is still current.
class ContentStamp {
 public:
  ContentStamp() { renew(); }
  ContentStamp(const ContentStamp& other) : value_(other.value()) {}
  ContentStamp& operator=(const ContentStamp& other) {
    value_.store(other.value(), std::memory_order_relaxed);
    return *this;
  }
  uint64_t value() const { return value_.load(std::memory_order_relaxed); }
  void renew();

 private:
  std::atomic<uint64_t> value_{0};
};

struct WorldBox {
  glm::dvec3 min{0.0};
  glm::dvec3 max{0.0};
};

class World {
 public:
  // Checks the config; an error names the bad field and value.
  static Result<World> create(const WorldConfig& config);
  World();  // one empty chunk at the origin, h = 0.2

  const Lattice& lattice() const { return config_.lattice; }
  const WorldConfig& config() const { return config_; }
  int chunk_size() const { return config_.chunk_size; }
  glm::ivec3 chunk_origin() const { return config_.chunk_origin; }
  glm::ivec3 chunk_dims() const { return config_.chunk_dims; }
  glm::ivec3 node_min() const { return config_.chunk_origin * config_.chunk_size; }
  glm::ivec3 node_end() const {  // one past the last node on each axis
    return (config_.chunk_origin + config_.chunk_dims) * config_.chunk_size;
  }
  // The lattice region the world can hold, in world units.
  WorldBox box() const;

  bool contains_chunk(const glm::ivec3& chunk) const;
  size_t chunk_slot(const glm::ivec3& chunk) const;  // requires contains_chunk
  // Inline: queries call it for every cell they look at. C is a power of
  // two, so an arithmetic shift is the floor division.
  glm::ivec3 chunk_of_node(const glm::ivec3& node) const {
    const int shift = chunk_shift();
    return {node.x >> shift, node.y >> shift, node.z >> shift};
  }
  int chunk_shift() const { return std::countr_zero(static_cast<unsigned>(config_.chunk_size)); }
  // kEmpty for chunks outside the box.
  ChunkKind chunk_kind(const glm::ivec3& chunk) const;
  // The chunk's data, or nullptr for uniform chunks and chunks outside the box.
  const Chunk* chunk(const glm::ivec3& chunk) const;
  std::shared_ptr<const Chunk> chunk_shared(const glm::ivec3& chunk) const;

  // Grows the chunk box to include chunks [lo, hi) (exclusive); new chunks are
  // empty, existing ones keep their data. Fails (and changes nothing) past
  // the limits World::create enforces.
  Status grow_to_include(const glm::ivec3& lo, const glm::ivec3& hi);

  // Stores a chunk, collapsing it to a flag when uniform. Requires contains_chunk.
  void set_chunk(const glm::ivec3& chunk, std::shared_ptr<const Chunk> data);
  void set_uniform_chunk(const glm::ivec3& chunk, bool solid);

  // Calls fn(chunk coordinate, kind, data or nullptr) for every chunk slot, in
  // slot order (x fastest).
  void for_each_chunk(
      const std::function<void(const glm::ivec3&, ChunkKind, const Chunk*)>& fn) const;

  // --- Queries ---
  // Is the lattice node inside the solid? (Answered from its X ray; the three
  // rays agree in a valid world.) Nodes outside the box are outside.
  bool inside_node(const glm::ivec3& node) const;
  // Is a world position inside? Majority of the three rays nearest to p
  // (each evaluated at p's depth), so it matches inside_node at nodes.
  bool inside(const glm::dvec3& p) const;
  // The start state and points of one whole ray, depths global (cells).
  bool ray_starts_inside(int axis, const glm::ivec2& uv, int chunk_along) const;
  std::vector<SurfacePoint> ray_points(int axis, const glm::ivec2& uv) const;
  std::vector<Span> ray_spans(int axis, const glm::ivec2& uv) const;

  // Solid volume integrated from one axis's spans [Units: m^3].
  double volume(int axis) const;
  // Tight world box of all surface points and solid chunks; nullopt when empty.
  std::optional<WorldBox> solid_bounds() const;
  WorldStats stats() const;

  // Changes with every set_chunk, set_uniform_chunk and grow_to_include.
  uint64_t stamp() const { return stamp_.value(); }

  // Free-form key/value notes saved with the world (source file, build report).
  std::vector<std::pair<std::string, std::string>>& metadata() { return metadata_; }
  const std::vector<std::pair<std::string, std::string>>& metadata() const { return metadata_; }
  void set_metadata(const std::string& key, const std::string& value);
  std::string metadata_value(const std::string& key) const;

 private:
  explicit World(const WorldConfig& config);
  WorldConfig config_;
  ContentStamp stamp_;
  std::vector<ChunkKind> kinds_;
  std::vector<std::shared_ptr<const Chunk>> chunks_;
  std::vector<std::pair<std::string, std::string>> metadata_;
};

// A chunk an edit changed (WorldEditor::take_dirty lists them, and
// ChunkedMesh::update re-meshes from them): which edit, and the box of lattice
// nodes whose state, or whose cell edges' crossings, changed in the chunk's
// rays (both ends of each changed edge: the box may hold the first node of
// the next chunk).
struct DirtyChunk {
  glm::ivec3 chunk{0};
  uint64_t version = 0;   // the edit that last changed it
  glm::ivec3 node_lo{0};  // global node coordinates
  glm::ivec3 node_hi{0};  // exclusive
};

// The one order of chunks across the library: by z, then y, then x. Dirty
// lists, chunk meshes and the C API's lists are sorted by it.
inline bool chunk_order_less(const glm::ivec3& a, const glm::ivec3& b) {
  if (a.z != b.z) return a.z < b.z;
  if (a.y != b.y) return a.y < b.y;
  return a.x < b.x;
}

// Decodes a packed point of the ray segment starting at global depth `segment_start`.
SurfacePoint decode_point(const PackedPoint& p, int chunk_size, int segment_start);

// ---------------------------------------------------------------------------
// Invariants

struct ValidationReport {
  bool ok = true;
  size_t errors = 0;                  // all errors found
  std::vector<std::string> messages;  // the first few, each naming chunk, axis, ray
  size_t nodes_checked = 0;           // lattice nodes in mixed chunks checked across axes
  std::string summary() const;
};

struct ValidateOptions {
  bool check_cross_axis = true;  // agreement of the three rays at every node
  size_t max_messages = 20;
};

// Checks every invariant of a world: points sorted, off the nodes, in range,
// alternating enter/exit consistently with each ray's start state; rays
// continuous across chunk boundaries and outside at the world's box faces;
// normals finite, unit and pointing out of the solid; reserved bits clear;
// uniform chunks stored as flags; and, with check_cross_axis, that the three
// rays through every lattice node agree on whether it is inside.
ValidationReport validate(const World& world, const ValidateOptions& options = {});

// Whether every ray of a mixed chunk on the world's box faces starts and
// ends outside there: the part of validate() that meshing relies on, in
// O(rays on the box faces). A World that breaks it (a window of a
// PagedWorld, ldc/store.h, cut through the ground) is refused by
// contour_world, ChunkedMesh::build and marching_cubes; solid chunks on a
// face are allowed (they mesh to nothing there). kInvalidArgument names the
// first face chunk and ray.
Status check_box_faces_outside(const World& world);
// The same for the part of the box faces that lattice nodes [node_lo,
// node_hi) (exclusive) reach: what meshing part of a world reads
// (contour_chunk: one chunk and its reach). A face the range stops short of
// is not checked.
Status check_box_faces_outside(const World& world, const glm::ivec3& node_lo, const glm::ivec3& node_hi);

// Checks the invariants local to one chunk (everything but cross-chunk
// continuity). Used by the file loader on each chunk it reads.
Status validate_chunk(const Chunk& chunk, int chunk_size, bool check_cross_axis);

}  // namespace ldc
