// Voxel export: solid occupancy, the six-face volumetric G-buffer,
// camera-centred cascades with scrolling, static polygon objects.
//
// Voxels. A voxel grid shares the world's lattice: its voxel size s is m * h
// for a whole number m of cells (VoxelConfig::voxel_size; other sizes are
// refused), and voxel g (global voxel coordinates, any sign) is the cube of
// lattice nodes [m*g, m*g + m] on each axis, i.e. the world box
// origin + s*g .. origin + s*(g + 1). Grids of different sizes (cascade
// levels) nest: voxel g of size 2s holds voxels 2g .. 2g + 1 of size s.
//
// Occupancy. The fraction of a voxel's volume inside the solid, integrated
// from the spans of one ray family (VoxelConfig::axis, z by default): the
// voxel's cross-section is sampled by the rays through it, every
// `stride` nodes (stride = 1 up to m = supersampling, see VoxelConfig),
// n + 1 rays per edge with n = m / stride, (n + 1)^2 in all, each weighted
// by the 2D trapezoid rule (1/4 at the corners, 1/2 on the edges, 1 inside,
// over n^2). Along a ray the inside length within the voxel is exact (to the
// stored depth, h / (65536 / C)). All arithmetic is in integers, so:
//  - a voxel whose rays are all inside over its whole extent has occupancy
//    exactly 1, and one whose rays are all outside exactly 0 (no hollow
//    voxels inside a solid, ever);
//  - the occupancies of a grid covering the solid sum (times s^3) to the
//    trapezoid-rule volume, which with stride 1 is World::volume(axis).
// Error. The trapezoid rule is exact where the inside length along the
// rays varies bilinearly across each lattice cell of the cross-section
// (e.g. any planar face through the voxel that every sampled ray crosses).
// Elsewhere its error per voxel is bounded by the spread of the inside
// lengths over the cross-section cells at the solid's silhouette: at most
// (number of silhouette cells of the cross-section) / n^2 of the voxel,
// which is O(1/n) at a silhouette and O(1/n^2) for smooth surfaces crossing
// the voxel. tests/test_voxelize.cpp measures spheres and boxes against the
// exact per-voxel volume (errors as fractions of a voxel): a sphere of 21 h
// radius, mean |error| 0.0024 and max 0.032 at m = 4, 0.0099 and 0.44 at
// m = 1 (only 4 rays per voxel: a silhouette voxel can be off by about half);
// a box with faces between rays, mean 0.024 and max 0.071 at m = 4 (bound
// 0.5 / n per axis whose faces cross the voxel).
//
// Uniform chunks. A chunk column (along the ray axis) whose chunks are all
// empty or solid is added in closed form (no ray is read); empty chunks cost
// nothing. Chunks outside the world's box are empty.
//
// Six-face G-buffer. For each voxel and each face direction (+x, -x, +y,
// -y, +z, -z, in that order, kFaceNames) a FaceSample holds what a viewer on
// that side of the voxel sees of the surface inside it: along each sampled
// ray of the face's axis, the surface point nearest to that face inside the
// voxel (for -x the first point where an X ray enters the solid, for +x the
// last point where it leaves), its albedo and emission from the MaterialTable
// and its normal, averaged over the rays with their trapezoid weights:
//   albedo.rgb   mean albedo of those points; albedo.a the weight: the
//                fraction of the face's rays that saw a surface point;
//   normal       normalised mean normal (0 where no point);
//   occupancy    the face's opacity: the fraction of the face's rays that
//                pass through solid inside the voxel (equal for +a and -a);
//   emission     mean emission.
// So a box with six materials inside one voxel gives six face albedos.
// Propagation (the talk's post-processing): a voxel with solid in it but no
// surface point seen from face f takes face f's albedo, normal and emission
// from its neighbour on that side when that neighbour holds its own surface
// for face f, so cones cannot pass the surface's information by stepping over
// a thin surface voxel. One layer only; faces keep their own occupancy.
// Neighbours outside the grid (or cascade level) are not used.
//
// Surface voxels: voxels holding a surface point of a sampled ray of a
// voxelized axis, or with 0 < occupancy < 1.
//
// Thread safety: free functions are re-entrant and read the World only
// (const; no edit may run meanwhile). A Cascades object is not thread-safe;
// each call runs in parallel (TBB) over blocks of voxels internally.
// Results are identical for any thread count.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/context.h"
#include "ldc/mesh.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

// ---------------------------------------------------------------------------
// Configuration

inline constexpr int kFaces = 6;
// Face f looks along axis f / 2, from the + side when f is even.
inline constexpr std::array<const char*, kFaces> kFaceNames = {"+x", "-x", "+y", "-y", "+z", "-z"};
inline constexpr int face_axis(int face) { return face / 2; }
inline constexpr bool face_positive(int face) { return face % 2 == 0; }

// Largest m (voxel size / h) accepted, and largest voxel count of a dense grid.
inline constexpr int kMaxVoxelCells = 1024;
inline constexpr int64_t kMaxDenseVoxels = int64_t{1} << 30;

struct VoxelMaterial {
  glm::vec3 albedo{0.5f};    // [Limit: 0 .. 1 per channel] [Default: 0.5 grey]
  glm::vec3 emission{0.0f};  // [Units: linear radiance, any scale] [Limit: 0 .. 65000 (R11G11B10F)]
};

// Albedo and emission per material id (the ids stored in the LDC points).
struct MaterialTable {
  std::vector<VoxelMaterial> materials;  // index = material id
  VoxelMaterial fallback;                // for ids past the end
  const VoxelMaterial& operator[](uint16_t id) const {
    return id < materials.size() ? materials[id] : fallback;
  }
};
// The one palette's albedos (ldc/materials.h, material_albedo) for ids
// 0 .. kPaletteSize - 1, the landscape's first (ldc/terrain.h: rock, grass,
// dirt, sand); later ids take the fallback, 0.5 grey.
MaterialTable default_material_table();
// Checks every channel's range; the error names the material id and field.
Status check_material_table(const MaterialTable& table);

struct VoxelConfig {
  // Voxel edge s. Must be m * h for a whole m (within 1e-6 relative).
  // [Units: m] [Limit: h .. 1024 h] [Default: 0.2, the game's h]
  double voxel_size = 0.2;
  // Ray family integrated for the volume occupancy. [Limit: 0 .. 2] [Default: 2 (z)]
  int axis = 2;
  // Most ray intervals sampled per voxel edge: rays are taken every
  // `stride` nodes, stride the largest power of two dividing m with
  // m / stride >= supersampling (1 when m <= supersampling). The talk's
  // 16x supersampling per axis. [Limit: 1 .. 1024] [Default: 16]
  int supersampling = 16;
};

// m = voxel_size / h, or an error naming the value.
Result<int> voxel_cells(const Lattice& lattice, const VoxelConfig& config);
Status check_voxel_config(const Lattice& lattice, const VoxelConfig& config);

// A box of voxels in global voxel coordinates: [lo, lo + dims).
struct VoxelBox {
  glm::ivec3 lo{0};
  glm::ivec3 dims{0};  // [Limit: >= 0]
  glm::ivec3 hi() const { return lo + dims; }
  size_t count() const { return size_t(dims.x) * size_t(dims.y) * size_t(dims.z); }
  bool empty() const { return dims.x <= 0 || dims.y <= 0 || dims.z <= 0; }
  bool contains(const glm::ivec3& g) const {
    return glm::all(glm::greaterThanEqual(g, lo)) && glm::all(glm::lessThan(g, hi()));
  }
  // Row-major index of a voxel inside the box, x fastest.
  size_t index(const glm::ivec3& g) const {
    const glm::ivec3 l = g - lo;
    return (size_t(l.z) * size_t(dims.y) + size_t(l.y)) * size_t(dims.x) + size_t(l.x);
  }
};
VoxelBox intersect(const VoxelBox& a, const VoxelBox& b);

// The voxels (of m cells) covering the world's solid (solid_bounds), or an
// empty box for an empty world.
VoxelBox solid_voxel_box(const World& world, int m);

// ---------------------------------------------------------------------------
// Results

// What one voxel face holds (float form; see the header comment).
struct FaceSample {
  glm::vec4 albedo{0.0f};    // rgb in [0, 1]; a = surface weight in [0, 1]
  glm::vec3 normal{0.0f};    // unit, or 0 where no surface
  float occupancy = 0.0f;    // opacity through this face, [0, 1]
  glm::vec3 emission{0.0f};
  uint8_t flags = 0;         // kFaceOwn, kFacePropagated or 0
};
inline constexpr uint8_t kFaceOwn = 1;         // the face holds a surface point of its own
inline constexpr uint8_t kFacePropagated = 2;  // copied from the neighbour (first subsurface layer)

using VoxelFaces = std::array<FaceSample, kFaces>;

// A dense occupancy grid and its surface voxels. Owns its arrays.
struct VoxelGrid {
  VoxelBox box;
  double voxel_size = 0.0;        // [Units: m]
  glm::dvec3 origin{0.0};         // world position of voxel (0,0,0)'s low corner (the lattice origin)
  std::vector<float> occupancy;   // box.count(), x fastest: box.index(g)
  // Surface voxels (global coordinates) in a fixed order (by blocks of
  // voxels, z, y, x within each), the same for any thread count.
  std::vector<glm::ivec3> surface;
  bool has_faces = false;                 // VoxelizeOptions::faces
  std::vector<VoxelFaces> surface_faces;  // with faces: surface_faces[i] of surface[i]

  float at(const glm::ivec3& g) const { return box.contains(g) ? occupancy[box.index(g)] : 0.0f; }
  glm::dvec3 voxel_min(const glm::ivec3& g) const { return origin + voxel_size * glm::dvec3(g); }
  // Sum of occupancy times the voxel volume [Units: m^3].
  double volume() const;
};

// The six-face G-buffer of a box, dense, float form (for CPU code).
struct GBuffer {
  VoxelBox box;
  double voxel_size = 0.0;
  glm::dvec3 origin{0.0};
  std::vector<float> occupancy;        // box.count(): volume fraction
  std::vector<FaceSample> faces;       // kFaces * box.count(): face f of voxel g at f * count + box.index(g)
  std::vector<glm::ivec3> surface;     // surface voxels, in VoxelGrid::surface's order

  const FaceSample& face(int f, const glm::ivec3& g) const { return faces[size_t(f) * box.count() + box.index(g)]; }
};

// Counts of one call, for benchmarks and the tool.
struct VoxelStats {
  double seconds = 0.0;
  size_t voxels = 0;              // voxels written
  size_t blocks = 0;              // blocks of voxels processed
  size_t chunk_columns_closed = 0;  // chunk columns added in closed form (uniform) or skipped (empty)
  size_t chunk_columns_walked = 0;  // chunk columns whose rays were read
  size_t rays_walked = 0;
  size_t surface_voxels = 0;
};

// Static polygon objects (buildings, props) voxelized beside the landscape.
// The object's mesh is built into an LDC of cell size s / 16 on the
// landscape's lattice origin (the watertight mesh builder; open meshes are
// repaired as build_from_mesh says) and voxelized from its spans with m = 16,
// i.e. 16x supersampling per axis. Combined with the landscape per voxel:
// occupancy and face opacity min(1, a + b) (objects are assumed to touch the
// ground, not to overlap it much), face albedo, normal and emission the
// weight-averaged mean of both.
struct StaticObject {
  std::shared_ptr<const TriangleMesh> mesh;  // counter-clockwise seen from outside
  glm::dmat4 transform{1.0};                 // mesh -> world, affine
  // Material id of triangles without one; triangles with an id t get
  // material_base + t. Ids index the MaterialTable.
  uint16_t material = 0;
  uint16_t material_base = 0;
};
Status check_static_object(const StaticObject& object);

// ---------------------------------------------------------------------------
// Dense voxelization

struct VoxelizeOptions {
  // The voxels to compute; unset = solid_voxel_box(world, m).
  std::optional<VoxelBox> box;
  // Also compute each surface voxel's six FaceSamples (all three ray families).
  bool faces = false;
  const MaterialTable* materials = nullptr;  // nullptr = default_material_table()
  std::span<const StaticObject> objects;     // voxelized and combined (see StaticObject)
};

// Occupancy of every voxel of the box and the surface voxels (with faces
// when options.faces). Fails, naming the value, on a bad config or a box of
// more than kMaxDenseVoxels voxels.
Result<VoxelGrid> voxelize(const World& world, const VoxelConfig& config, const VoxelizeOptions& options = {},
                           Context* ctx = nullptr, VoxelStats* stats = nullptr);

// The dense six-face G-buffer of a box, propagation applied within the box.
// Uses about 270 bytes per voxel: meant for cascade-sized boxes.
Result<GBuffer> voxelize_gbuffer(const World& world, const VoxelConfig& config, const VoxelBox& box,
                                 const MaterialTable& materials, std::span<const StaticObject> objects = {},
                                 Context* ctx = nullptr, VoxelStats* stats = nullptr);

// ---------------------------------------------------------------------------
// GPU formats (the talk's volumetric G-buffer table)

// VK_FORMAT_R8G8B8A8_UNORM: r in the low byte.
uint32_t pack_unorm8x4(const glm::vec4& v);
glm::vec4 unpack_unorm8x4(uint32_t bits);
// VK_FORMAT_R8G8B8A8_SNORM: round(clamp(x, -1, 1) * 127), x in the low byte.
uint32_t pack_snorm8x4(const glm::vec4& v);
glm::vec4 unpack_snorm8x4(uint32_t bits);
// VK_FORMAT_B10G11R11_UFLOAT_PACK32: r bits 0-10, g 11-21, b 22-31; unsigned
// floats with 5-bit exponents, rounded to nearest; negative and NaN give 0,
// values past 65024 (r, g) / 64512 (b) the largest finite value.
uint32_t pack_r11g11b10f(const glm::vec3& v);
glm::vec3 unpack_r11g11b10f(uint32_t bits);

// The cascades' G-buffer as four 3D textures (one per attribute), each of
// extent (6N, K*N, N), x fastest: texel (f*N + x, k*N + y, z) is face f of
// voxel (x, y, z) of level k: faces tiled in x, levels in y, as in the talk.
// Sample with the coordinates clamped to a face's tile (no bleeding).
struct PackedGBuffer {
  int resolution = 0;  // N
  int levels = 0;      // K
  std::vector<uint32_t> albedo;    // R8G8B8A8_UNORM: rgb albedo, a = surface weight
  std::vector<uint32_t> normal;    // R8G8B8A8_SNORM: xyz normal, a = 127 own surface, 64 propagated, 0 none
  std::vector<uint8_t> occupancy;  // R8_UNORM: face opacity
  std::vector<uint32_t> emission;  // B10G11R11_UFLOAT_PACK32

  glm::ivec3 extent() const { return {kFaces * resolution, levels * resolution, resolution}; }
  size_t texel_count() const { return size_t(kFaces) * size_t(levels) * size_t(resolution) * resolution * resolution; }
  size_t texel(int face, int level, const glm::ivec3& local) const {
    const size_t n = size_t(resolution);
    return (size_t(local.z) * n * size_t(levels) + size_t(level) * n + size_t(local.y)) * n * kFaces +
           size_t(face) * n + size_t(local.x);
  }
  size_t bytes() const { return texel_count() * 13; }
  void resize(int n, int k);
  FaceSample sample(int face, int level, const glm::ivec3& local) const;  // decoded
};

// ---------------------------------------------------------------------------
// Cascades

struct CascadeConfig {
  int levels = 6;              // K [Limit: 1 .. 16]
  int resolution = 32;         // N voxels per axis and level [Limit: even, 4 .. 256]
  // Level 0's voxel edge; level k's is voxel_size * 2^k. Must be a whole
  // number of cells, as VoxelConfig::voxel_size. [Units: m] [Default: 0.2]
  double voxel_size = 0.2;
  int axis = 2;                // as VoxelConfig::axis
  int supersampling = 16;      // as VoxelConfig::supersampling
  MaterialTable materials = default_material_table();
};
Status check_cascade_config(const Lattice& lattice, const CascadeConfig& config);

// What one update did.
struct CascadeUpdate {
  int level = -1;               // the level updated (-1: none this frame)
  glm::ivec3 shift{0};          // how far the level moved [Units: its voxels]
  bool full = false;            // voxelized whole (first use, or moved N or more)
  size_t voxels = 0;            // voxels voxelized (exposed slabs, dirty boxes)
  size_t dirty_boxes = 0;       // dirty boxes refreshed
  double seconds = 0.0;
};

// K levels of N^3 voxels, each covering twice the extent of the previous,
// centred on the camera: level k's box is [c - N/2, c + N/2) with c the
// camera's position in level-k voxels rounded to the nearest whole voxel.
//
// Storage. The G-buffer lives in a PackedGBuffer whose tiles use toroidal
// addressing: global voxel g of level k is stored at tile coordinate g mod N
// (per axis). A move therefore writes only the newly exposed slabs (up to
// three, each N*N*|shift| voxels); nothing is copied. pack() writes the
// camera-centred form (tile coordinate g - lo) for a GPU that samples with
// hardware trilinear filtering; a GPU that wraps its coordinates (mod N)
// itself can upload texture() as it is and skip that copy.
//
// Edits. invalidate() takes the chunks WorldEditor::take_dirty reported;
// the voxels whose nodes [m*g, m*g + m] meet a chunk's dirty node box are
// re-voxelized at the level's next update (refresh() does it at once for
// every level), plus one ring of voxels around them whose propagated face
// attributes may change. Voxels elsewhere are not touched.
//
// Schedule (the talk's): frame() updates one level per frame, level 0 every
// 2 frames, level 1 every 4, ..., level k every 2^(k+1) (level = the number of
// trailing one bits of the frame counter); the frames where no level is due
// (1 in 2^K) go to the last level.
//
// The World is passed to every call (the cascade keeps no pointer to it);
// its lattice must stay the one the cascade was made for.
class Cascades {
 public:
  static Result<Cascades> create(const Lattice& lattice, const CascadeConfig& config);

  const CascadeConfig& config() const { return config_; }
  // World position of voxel (0,0,0)'s low corner at every level (the lattice origin).
  const glm::dvec3& origin() const { return lattice_.origin; }
  int levels() const { return config_.levels; }
  int resolution() const { return config_.resolution; }
  double voxel_size(int level) const { return config_.voxel_size * double(1 << level); }
  // The level's voxel box (global coordinates of that level's voxels).
  VoxelBox level_box(int level) const { return boxes_[size_t(level)]; }
  bool level_valid(int level) const { return valid_[size_t(level)]; }
  uint64_t frame_counter() const { return frame_; }
  static int scheduled_level(uint64_t frame, int levels);

  // Static objects: added once, voxelized into every level they overlap
  // (their LDC per level is built on first use and cached).
  Status add_object(const StaticObject& object);

  // Updates every level to the camera (a full voxelization where needed).
  Status update_all(const World& world, const glm::dvec3& camera, Context* ctx = nullptr);
  // Moves one level to the camera: scrolls and voxelizes the exposed slabs,
  // and refreshes its pending dirty voxels.
  Result<CascadeUpdate> update_level(const World& world, int level, const glm::dvec3& camera,
                                     Context* ctx = nullptr);
  // One frame of the staggered schedule: update_level(scheduled_level(frame)).
  Result<CascadeUpdate> frame(const World& world, const glm::dvec3& camera, Context* ctx = nullptr);

  // Marks the voxels under dirty chunks for refresh at each level's next update.
  void invalidate(std::span<const DirtyChunk> dirty);
  // Forgets a level's content: its next update voxelizes it whole.
  void invalidate_level(int level);
  // Re-voxelizes every level's pending dirty voxels now (levels stay put).
  Result<size_t> refresh(const World& world, Context* ctx = nullptr);

  // The toroidal storage (see above) and each level's volume occupancy
  // (N^3 floats, toroidal: index of g mod N, x fastest).
  const PackedGBuffer& texture() const { return texture_; }
  const std::vector<float>& level_occupancy(int level) const { return occupancy_[size_t(level)]; }
  // Decoded face f of global voxel g of a level (zero outside its box).
  FaceSample sample(int level, int face, const glm::ivec3& g) const;
  float occupancy(int level, const glm::ivec3& g) const;

  // Writes the camera-centred textures (tile coordinate g - lo) into `out`
  // (resized as needed): for upload. pack_level writes only one level's tiles.
  void pack(PackedGBuffer* out) const;
  void pack_level(int level, PackedGBuffer* out) const;
  // One level as a dense grid with its surface voxels (decoded faces): for
  // export and CPU code.
  VoxelGrid level_grid(int level) const;

  Cascades(Cascades&&) noexcept;
  Cascades& operator=(Cascades&&) noexcept;
  ~Cascades();

 private:
  struct ObjectCache;
  Cascades() = default;
  Status voxelize_regions(const World& world, int level, const std::vector<VoxelBox>& regions, bool moved,
                          Context* ctx, VoxelStats* stats);
  Status object_sources(int level, Context* ctx);

  Lattice lattice_;
  CascadeConfig config_;
  int base_cells_ = 1;  // m of level 0
  PackedGBuffer texture_;
  std::vector<std::vector<float>> occupancy_;
  // Per level and voxel (toroidal, as occupancy_): bit f set where face f
  // holds its own surface / a propagated copy. Lets propagation skip texels.
  std::vector<std::vector<uint8_t>> own_faces_;
  std::vector<std::vector<uint8_t>> propagated_faces_;
  std::vector<VoxelBox> boxes_;
  std::vector<bool> valid_;
  std::vector<std::vector<VoxelBox>> pending_;  // per level: dirty voxel boxes
  std::vector<StaticObject> objects_;
  std::unique_ptr<ObjectCache> object_cache_;
  uint64_t frame_ = 0;
};

// Every valid level of `cascades` as a grid with its name suffix ("_L<k>"),
// in level order: what the .vdb export writes as occupancy_L<k>, normal_L<k>
// and albedo_L<k>.
struct NamedLevelGrid {
  VoxelGrid grid;
  std::string suffix;
};
std::vector<NamedLevelGrid> valid_level_grids(const Cascades& cascades);

// ---------------------------------------------------------------------------
// Raw export

// Writes `<stem>.raw` (little-endian arrays, back to back) and `<stem>.json`
// (a header naming each array's name, type, shape, byte offset and size,
// plus the grid's box, voxel size and origin). `path` may end in .json or
// .raw or neither; the stem is the path without that extension. Arrays:
// occupancy float32 [dims.z][dims.y][dims.x]; surface_voxels int32 [S][3];
// with faces, surface_faces float32 [S][6][12] (albedo rgba, normal xyz,
// occupancy, emission rgb, flags).
Status save_raw(const VoxelGrid& grid, const std::string& path);
// The cascades' camera-centred textures (pack()) and level occupancies:
// albedo/normal/emission uint32 and occupancy uint8 of extent (6N, KN, N),
// level_occupancy float32 [K][N][N][N]; the header lists each level's box
// and voxel size and the Vulkan format of each texture.
Status save_raw(const Cascades& cascades, const std::string& path);

}  // namespace ldc
