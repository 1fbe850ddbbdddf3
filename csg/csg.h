// Booleans and brush edits on span lists.
//
// A boolean of two solids on one lattice is a merge of their points ray by
// ray, in time linear in the points: the result is inside where the operation
// of the two inside states says so, and a point is kept where that result
// changes. Because the inputs agree at every lattice node and no point sits on
// a node, the result agrees at every node too: booleans never break validate().
//
// Rules (documented choices):
// - A kept point keeps the normal and material of the surface it comes from;
//   a surface exposed by a difference (the cutter's surface inside the other
//   solid) gets the cutter's normal reversed and the material of the span it
//   cuts into (or BooleanConfig::cut_material); where that span has no
//   surface on the ray segment (deep inside solid chunks) it gets material 0.
// - Points at equal depth are taken together, so touching solids merge: two
//   boxes sharing a face union into one solid with no surface between them.
// - Spans and gaps thinner than BooleanConfig::sliver that lie between two
//   lattice nodes are removed (a removed gap joins the spans around it); no
//   lattice node changes side, so the three axes still agree.
//
// Brush edits apply a boolean of the world with a brush (a primitive, a
// triangle mesh or a noisy sphere) placed by a transform, rasterized straight
// onto the rays of the chunks it overlaps; no other chunk is read or written.
// Every edit marks the chunks it changed dirty with a version number and
// returns an undo handle.
//
// Thread safety: boolean(), mesh_boolean() and rasterize_brush() only read
// their inputs and may run concurrently; results share unchanged chunks with
// the inputs (cheap, immutable). A WorldEditor is not thread-safe (see the
// class); its world() may be read by queries between edits.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_map>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/build.h"
#include "ldc/context.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

// One name per operation across the C++ API, the C API, edit scripts and
// the command line: union, subtract, intersect (and paint, for edits).
enum class BooleanOp {
  kUnion,
  kSubtract,   // a minus b
  kIntersect,
  kDifference [[deprecated("use BooleanOp::kSubtract")]] = kSubtract,      // 0.2 spelling; removed after 0.3
  kIntersection [[deprecated("use BooleanOp::kIntersect")]] = kIntersect,  // 0.2 spelling; removed after 0.3
};
// "union", "subtract", "intersect".
const char* boolean_op_name(BooleanOp op);
// By name; the 0.2 spellings "difference" and "intersection" are accepted.
std::optional<BooleanOp> boolean_op_from_name(std::string_view name);

struct BooleanConfig {
  // Spans and gaps thinner than this, between two lattice nodes, are removed.
  // [Units: cells] [Limit: 0 .. 0.5] [Default: 0.01]
  double sliver = 0.01;
  // Material of surfaces a difference exposes; -1 keeps the material of the
  // span the cutter cuts into. [Limit: -1 .. 65535]
  int cut_material = -1;
};

Status check_boolean_config(const BooleanConfig& config);

// a op b. Both worlds must share their lattice (origin and h, to the last
// bit) and chunk size; the result's chunk box covers both boxes (only the
// overlap for an intersection). Parallel over chunks.
Result<World> boolean(const World& a, const World& b, BooleanOp op, const BooleanConfig& config = {},
                      Context* ctx = nullptr);

struct MeshBooleanOptions {
  GridConfig grid;        // as for build_from_mesh, applied to the meshes' joint bounds
  BooleanConfig boolean;  // how the two LDCs merge
  Context* ctx = nullptr;                         // progress and cancel (may be null)
  std::array<BuildReport, 2>* reports = nullptr;  // out, when set: the two builds' reports, a's first
};

// Builds two meshes into one lattice sized for both and combines them: what
// `ldc boolean` does. Open, self-intersecting and non-manifold meshes are
// accepted (their LDCs are repaired, see build_from_mesh).
Result<World> mesh_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op,
                           const MeshBooleanOptions& options);
// The same with only the grid chosen.
Result<World> mesh_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, const GridConfig& grid);
[[deprecated("pass a MeshBooleanOptions")]] Result<World> mesh_boolean(
    const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, const GridConfig& grid, const BooleanConfig& config,
    Context* ctx = nullptr, std::array<BuildReport, 2>* reports = nullptr);

// --- Brushes --------------------------------------------------------------------

// A sphere whose radius is displaced by fractal noise: natural-looking digging.
// The noise (three octaves of gradient noise over the direction) is tabulated
// once per (frequency, seed) on a cube map of 32 * frequency texels a face
// edge (32 .. 256) and shared by every brush that uses it; the brush is that
// map's bilinear interpolation, continuous over the sphere.
struct NoiseSphere {
  double radius = 1.0;      // mean radius [Units: m] [Limit: > 0]
  double amplitude = 0.25;  // displacement as a fraction of the radius [Limit: 0 .. 0.9]
  double frequency = 2.0;   // noise cycles per radius [Limit: > 0 .. 64]
  uint32_t seed = 1;
};

// A triangle mesh placed by `transform` (local -> world).
struct MeshShape {
  std::shared_ptr<const TriangleMesh> mesh;
  glm::dmat4 transform{1.0};
};

// A noisy sphere centred at `transform`'s origin (local -> world).
struct NoiseShape {
  NoiseSphere noise;
  glm::dmat4 transform{1.0};
};

// A brush is one shape and the material of what it adds or paints. A new
// kind of brush is one more alternative of `shape`, one case in check_brush
// and one in rasterize_brush.
struct Brush {
  std::variant<Primitive, MeshShape, NoiseShape> shape;  // a Primitive is placed by its own transform
  uint16_t material = 0;  // (a Primitive's own material field is not read)

  // The shape's local -> world transform, whichever the shape: compose a
  // rotation or a move with it.
  glm::dmat4& transform();
  const glm::dmat4& transform() const;

  static Brush sphere(const glm::dvec3& centre, double radius, uint16_t material = 0);
  static Brush box(const glm::dvec3& centre, const glm::dvec3& half_extents, uint16_t material = 0);
  static Brush capsule(const glm::dvec3& a, const glm::dvec3& b, double radius, uint16_t material = 0);
  static Brush cylinder(const glm::dvec3& a, const glm::dvec3& b, double radius, uint16_t material = 0);
  static Brush noisy_sphere(const glm::dvec3& centre, const NoiseSphere& noise, uint16_t material = 0);
  static Brush from_mesh(std::shared_ptr<const TriangleMesh> mesh, const glm::dmat4& transform,
                         uint16_t material = 0);
};

Status check_brush(const Brush& brush);

// The brush rasterized on a world's lattice and chunk grid: an LDC whose
// chunks line up with the world's, covering the brush plus one cell.
// Primitives and noise spheres are built like implicit solids (node signs
// sampled; primitives get exact analytic crossings), meshes by the watertight
// mesh builder (open or self-intersecting brush meshes are repaired). Every
// point takes the brush's material. `ctx` (optional) gets its progress as one
// stage, "rasterize" from 0 to 1 (a 300 m brush takes minutes), and may
// cancel it (kCancelled).
Result<World> rasterize_brush(const Brush& brush, const Lattice& lattice, int chunk_size, Context* ctx = nullptr);

enum class EditOp {
  kUnion,      // world union brush (build)
  kSubtract,   // world minus brush (dig)
  kIntersect,  // world inside the brush only
  kPaint,      // surface points inside the brush take the brush's material
  kAdd [[deprecated("use EditOp::kUnion")]] = kUnion,  // 0.2 spelling; removed after 0.3
};
// "union", "subtract", "intersect", "paint".
const char* edit_op_name(EditOp op);
// By name; the 0.2 spelling "add" is accepted.
std::optional<EditOp> edit_op_from_name(std::string_view name);

// What an edit changed, and how to take it back.
struct EditReceipt {
  uint64_t version = 0;
  std::vector<glm::ivec3> changed_chunks;
  std::shared_ptr<const struct EditSnapshot> undo;  // opaque
};

// Owns a World and applies brush edits to it. Not thread-safe; the work of one
// call runs in parallel over chunks.
class WorldEditor {
 public:
  // Checks the config and takes the world: the way to make one.
  static Result<WorldEditor> create(World world, const BooleanConfig& config = {});
  // The same without the config check (a bad config fails at the first edit).
  explicit WorldEditor(World world, BooleanConfig config = {});

  const World& world() const { return world_; }
  uint64_t version() const { return version_; }

  // Applies one edit. On error the world is unchanged.
  Result<EditReceipt> apply(const Brush& brush, EditOp op, Context* ctx = nullptr);

  struct Edit {
    Brush brush;
    EditOp op = EditOp::kSubtract;
  };
  // Applies edits in order, as one undo step; chunks in parallel.
  Result<EditReceipt> apply_batch(std::span<const Edit> edits, Context* ctx = nullptr);

  // Restores the chunks an edit changed. Undo in reverse order: refused (and
  // nothing changes) if a later edit changed one of the same chunks.
  Status undo(const EditReceipt& receipt);

  // The chunks changed since the last call, sorted by (z, y, x), and clears the list.
  std::vector<DirtyChunk> take_dirty();

 private:
  World world_;
  BooleanConfig config_;
  uint64_t version_ = 0;
  std::unordered_map<uint64_t, uint64_t> chunk_version_;  // chunk key -> the last edit that changed it
  std::map<uint64_t, DirtyChunk> dirty_;                  // chunk key -> what changed since take_dirty
};

}  // namespace ldc
