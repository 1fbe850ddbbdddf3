// Builders: triangle meshes, analytic primitives, implicit solids, heightfields
// and the procedural landscape, each into a World. All run in parallel over
// chunk columns and axes with TBB, and none leave a half-built World behind:
// on error (or cancel) they return a Status and no World.
//
// Thread safety and ownership: builders only read their inputs (meshes,
// solids, heightfields: const, not kept after the call) and return a new
// World by value; any number may run at once. ImplicitSolid::value(),
// normal() and classify() are called from several worker threads at once and
// must be safe for that (const and free of shared mutable state).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/context.h"
#include "ldc/mesh.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {

// How the lattice is chosen around the input.
struct GridConfig {
  // Cells along the longest axis of the input's bounding box; used when
  // cell_size is 0. [Limit: 1 .. 65536] [Default: 128]
  int cells = 128;
  // Cell size h; overrides `cells` when > 0. [Units: m]
  double cell_size = 0.0;
  // Chunk size C. [Limit: 8, 16, 32 or 64] [Units: cells] [Default: 32]
  int chunk_size = 32;
  // Empty cells kept between the input's bounds and the world's box, so that
  // every ray starts and ends outside. [Limit: 1 .. 64] [Units: cells]
  int padding = 2;
  // Refuse builds whose estimated memory exceeds this. [Units: bytes] [Default: 8 GiB]
  size_t max_memory = size_t{8} << 30;
  // When set, use this lattice origin instead of one derived from the bounds
  // (the world box still grows to hold the input). Lets separately built
  // worlds share one lattice.
  bool use_origin = false;
  glm::dvec3 origin{0.0};
};

// What a build did, for `ldc info` and the tests.
struct BuildReport {
  double seconds = 0.0;
  size_t triangles = 0;              // mesh builds: triangles read
  size_t degenerate_triangles = 0;   // zero-area after snapping, skipped
  bool input_closed = true;          // every edge used equally in both directions
  size_t boundary_edges = 0;
  size_t crossings = 0;              // raw ray/surface crossings before the winding rule
  size_t repaired_rays = 0;          // rays whose spans were decided by the repair
  size_t synthesized_points = 0;     // points added where a hole left no crossing
  size_t dropped_crossings = 0;      // crossings removed by the repair
  size_t normal_flips = 0;           // normals turned to point out of the solid
  size_t nudged_points = 0;          // points moved off a lattice node by one depth step
  // How the mesh's connected components were read (BuildConfig::mode).
  size_t solid_components = 0;       // read as solids (winding number)
  size_t surface_components = 0;     // read as thin shells under their triangles
  size_t shell_triangles = 0;        // input triangles that became shells
};

// --- Triangle meshes ---------------------------------------------------------
//
// Watertight by construction: vertices are snapped to a fixed-point grid of
// h/65536 and every decision (does a ray hit a triangle, is a crossing before or
// after a node) is an exact integer predicate with a symbolic perturbation
// (simulation of simplicity) as tie-break, so a ray through a shared edge or
// vertex counts exactly once. Inside means a non-zero winding number: overlapping
// parts union, inverted parts still count as solid.
//
// Meshes that are not closed (holes, open sheets, flipped faces) cannot define a
// winding number. Then every lattice node votes with the six half-rays through it
// (each axis, counted from either end); the majority decides the node, and every
// ray is rebuilt between consecutive nodes to agree with the votes: keeping its
// own crossings where they fit, dropping those that do not, and adding a point
// halfway between two nodes where a hole left none. The rays changed are counted
// in BuildReport::repaired_rays.
Result<World> build_from_mesh(const TriangleMesh& mesh, const GridConfig& grid,
                              Context* ctx = nullptr, BuildReport* report = nullptr);

// How a mesh's triangles become a solid.
//
// Game levels are rarely closed: floors are one-sided planes, rooms are open
// on a side, walls are single quads, props float. No winding number (and no
// vote) can say what such a sheet encloses, because it encloses nothing. The
// surface reading gives every such triangle a thin closed shell instead: a
// prism whose top face is the triangle itself (exact crossings and normals)
// and which reaches `shell_thickness` below it, on the side away from up
// (for a wall: behind its front face). Prisms are closed, so their union is
// read by the exact winding rule and needs no repair. This is what Recast's
// rasterization of each triangle into the spans of its cells does, kept
// exact.
enum class BuildMode : uint8_t {
  kSolid,    // the whole mesh as one solid, repaired by votes where it is open (as build_from_mesh above)
  kSurface,  // every triangle a shell
  kAuto,     // per connected component: closed, outward-facing and thicker
             // than half a shell -> solid; anything else (open, inside-out,
             // double-sided, flat) -> shells
};
const char* build_mode_name(BuildMode mode);

struct BuildConfig {
  BuildMode mode = BuildMode::kSolid;
  // How far a shell reaches below its triangle. 0: a little over one cell
  // (h * 65/64), so that every lattice column under a wall or across a sheet
  // sees it, as Recast's conservative rasterization does.
  // [Units: m] [Limit: 0, or h/16 .. 16 h]
  double shell_thickness = 0.0;
  // Lattice axis pointing up: shells hang below floors and ceilings, so a
  // floor's top stays exact whichever way its triangle is wound. [Limit: 0, 1, 2]
  int up_axis = 2;
};

// The mesh read as `config` says; BuildConfig{} gives build_from_mesh above.
// The report counts the components read each way.
Result<World> build_from_mesh(const TriangleMesh& mesh, const GridConfig& grid,
                              const BuildConfig& config, Context* ctx = nullptr,
                              BuildReport* report = nullptr);

// --- Implicit solids ----------------------------------------------------------
//
// A solid given by a function that is negative inside. Node signs are sampled
// from the function, and each ray gets one point in every cell edge whose two
// nodes differ, placed by a root search (or the solid's exact segment_root).
// Features that fit between nodes are therefore not kept.
class ImplicitSolid {
 public:
  enum class BoxClass { kUnknown, kOutside, kInside };

  virtual ~ImplicitSolid() = default;
  // Negative inside, positive outside. Need not be a distance.
  virtual double value(const glm::dvec3& p) const = 0;
  // Unit outward normal at a surface point p. Default: central differences.
  virtual glm::dvec3 normal(const glm::dvec3& p, double step) const;
  virtual uint16_t material(const glm::dvec3& /*p*/) const { return 0; }
  // A world box that contains the whole solid.
  virtual WorldBox bounds() const = 0;
  // Optional: is the box entirely outside or inside? Lets builders skip chunks.
  virtual BoxClass classify(const WorldBox& /*box*/) const { return BoxClass::kUnknown; }
  // Optional exact root on the segment a -> b (value(a), value(b) of opposite
  // signs): return true and t in [0, 1]. Default: false (a root search is used).
  virtual bool segment_root(const glm::dvec3& /*a*/, const glm::dvec3& /*b*/, double* /*t*/) const {
    return false;
  }
};

Result<World> build_from_implicit(const ImplicitSolid& solid, const GridConfig& grid,
                                  Context* ctx = nullptr, BuildReport* report = nullptr);

// One chunk of the world build_from_implicit makes, built alone (the chunk
// sources of ldc/store.h build a large world a chunk at a time). Given the
// lattice of that build and `bounds` = solid.bounds(), the result equals the
// whole build's chunk bit for bit (same families; uniform families where the
// build stores a flag). Chunks outside the bounds come out uniform outside.
// Thread safety: as build_from_implicit (the solid is only read).
Chunk build_implicit_chunk(const ImplicitSolid& solid, const WorldBox& bounds, const Lattice& lattice,
                           int chunk_size, const glm::ivec3& chunk);

// --- Analytic primitives ------------------------------------------------------

struct Primitive {
  enum class Shape { kSphere, kBox, kCapsule, kCylinder };
  Shape shape = Shape::kSphere;
  // Local shape, centred on the origin, axis along z for capsule and cylinder:
  //   sphere: radius; box: half_extents; capsule: radius and half_height of the
  //   segment between the cap centres; cylinder: radius and half_height.
  double radius = 1.0;                   // [Units: m] [Limit: > 0]
  double half_height = 1.0;              // [Units: m] [Limit: > 0]
  glm::dvec3 half_extents{1.0};          // [Units: m] [Limit: > 0]
  glm::dmat4 transform{1.0};             // local -> world, affine and invertible
  uint16_t material = 0;
};

const char* primitive_shape_name(Primitive::Shape shape);
// Exact analytic crossings and normals under the affine transform.
std::unique_ptr<ImplicitSolid> make_primitive_solid(const Primitive& primitive);
Status check_primitive(const Primitive& primitive);
Result<World> build_from_primitive(const Primitive& primitive, const GridConfig& grid,
                                   Context* ctx = nullptr, BuildReport* report = nullptr);

// --- Heightfields -------------------------------------------------------------

struct Heightfield {
  int width = 0;                 // samples along x [Limit: >= 2]
  int height = 0;                // samples along y [Limit: >= 2]
  std::vector<float> samples;    // row-major, width*height, in [0, 1] for images
  double spacing = 0.2;          // distance between samples [Units: m] [Limit: > 0]
  double height_scale = 10.0;    // z = base + height_scale * sample [Units: m]
  double base = 1.0;             // z of sample value 0 [Units: m]
  double floor = 0.0;            // solid extends down to this z [Units: m] [Limit: < base]
  uint16_t material = 0;
};

// Builds the heightfield from a callback z = f(x, y) sampled on a grid.
Heightfield heightfield_from_function(int width, int height, double spacing,
                                      const std::function<double(double, double)>& f,
                                      double floor);
// Reads an 8- or 16-bit grayscale (or RGB, using luminance) PNG.
Result<Heightfield> load_heightfield_png(const std::string& path, double spacing,
                                         double height_scale, double base, double floor);
Status check_heightfield(const Heightfield& field);
// Solid between `floor` and the bilinear surface; exact crossings on every ray.
std::unique_ptr<ImplicitSolid> make_heightfield_solid(const Heightfield& field);
Result<World> build_from_heightfield(const Heightfield& field, const GridConfig& grid,
                                     Context* ctx = nullptr, BuildReport* report = nullptr);

}  // namespace ldc
