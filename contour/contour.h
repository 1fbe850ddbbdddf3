// Dual contouring on LDC rays: the surface a player sees.
//
// Every edge of a lattice cell is a segment of an LDC ray, so the surface
// crossings on a cell's 12 edges, with their exact normals, are read straight
// out of the span lists. One vertex per sheet of surface through a cell
// (usually one sheet, whenever the cell's corners differ), placed by the
// Hermite planes of the sheet's crossings; one quad per edge whose ends
// differ, joining the sheets that hold the edge in the four cells around it,
// split into two triangles and oriented with its normal pointing out of the
// solid.
//
// Topology: the sheets of a cell come from its corners' signs alone, with
// faces that hold two diagonal inside corners keeping them apart, the same
// rule from both cells sharing a face (contour/detail/cell_sheets.h; the
// dual of marching cubes on that table, as in Nielson's dual marching
// cubes). So every vertex's triangles form one disk and every edge has two
// triangles: the output is a closed 2-manifold. (Where both cells sharing an
// ambiguous face would pass one sheet through both of its segments, a
// tunnel thinner than a cell, that face joins its inside corners instead.)
//
// Rules this module follows (documented choices):
// - An edge with several crossings (an odd number when its ends differ)
//   contributes the crossing nearest to its outside end: the surface seen from
//   outside. Counted in ContourStats::multi_crossing_edges.
// - An edge whose ends agree but which holds crossings (a feature thinner than
//   the cell) contributes nothing. Counted in ContourStats::thin_edges.
// - A quad is split along the diagonal whose midpoint fits the Hermite planes
//   of the diagonal's two end cells best (least summed squared distance); a
//   diagonal lying on a crease fits exactly. Ties go to the shorter diagonal.
// - A quad takes the material of its edge's crossing. A vertex takes the most
//   common material among its cell's crossings (ties: the smaller id).
// - A vertex's normal is the mean of its cell's crossing normals (the exact
//   surface normals the LDC stores), so it needs no neighbours and agrees
//   across chunk borders.
//
// Chunked meshing: each chunk meshes the cells it owns and the quads of the
// edges it owns, reading its neighbours' rays for the cells and edges across
// its border. The assembled mesh equals meshing the world in one piece.
//
// Thread safety: contour_world, contour_chunk, marching_cubes and
// mesh_quality only read their inputs (const; no edit may run meanwhile) and
// may run concurrently. A ChunkedMesh is not thread-safe (one owner, e.g. the
// render thread); each build/update is parallel inside (TBB) and gives the
// same mesh for any thread count. Meshes are returned by value.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/context.h"
#include "ldc/status.h"
#include "ldc/world.h"

namespace ldc {
namespace detail {
struct MeshPatch;
}

// Where a cell's vertex goes, given the Hermite planes of its crossings.
enum class Placement {
  // Schmitz, Dietrich & Comba 2009: start at the mass point and move the
  // vertex `iterations` times by `step` times the mean pull of the planes,
  // sum_i n_i (n_i . (p_i - x)) / N. Simple, GPU-friendly; sharp edges come
  // out slightly wobbly when the iterations are few (see `iterations`).
  kIterative,
  // Ju et al. 2002: minimise the quadratic error sum_i (n_i . (x - p_i))^2
  // with a pseudo-inverse about the mass point, dropping eigenvalues below
  // qef_truncation times the largest (the rank is recorded).
  kQef,
  // The mean of the crossings (no use of normals): the baseline.
  kMassPoint,
};
const char* placement_name(Placement p);

struct ContourConfig {
  Placement placement = Placement::kIterative;
  // kIterative: moves per vertex [Limit: 0 .. 1000] and step [Limit: (0, 2)].
  // The moves are linear, so k of them are computed at once in the QEF's
  // eigenbasis: their cost does not grow with k. Few moves leave the vertex
  // near the mass point along directions the planes barely constrain (the
  // talk's "wobbly edges"); more moves sharpen features (on spot at 256
  // cells, 64 -> 256 moves takes the normal error near sharp edges from 2.0
  // to 1.4 degrees). A vertex whose moves leave its cell is moved again step
  // by step, each step projected into the cell (at most 64 steps).
  int iterations = 256;
  double step = 1.0;
  // kQef: relative eigenvalue cut-off [Limit: [0, 1)].
  double qef_truncation = 0.1;
  // How far a vertex may leave its cell, as a fraction of h [Limit: 0 .. 1].
  // Where a feature's planes meet outside the cell, the vertex goes to the
  // best point inside the cell grown by this slack (for kQef and kIterative),
  // which is off the surface: with 0, vertices next to features that cross a
  // cell border sit up to about a third of a cell off; with 1, rotated boxes
  // come out with every vertex within 0.001 h of a face and every corner kept
  // (tests/test_contour.cpp measures both). A vertex whose planes meet
  // round the far side of the solid corners its sheet wraps stays in its
  // cell, however much slack (that would turn its surface inside out). More
  // slack lets neighbouring triangles fold over more easily; untangle_mesh
  // does not always clear what slack 1 folds (random blocks of 3^3 cells
  // keep up to 19 pairs), and the quality report then says so.
  double cell_slack = 0.0;
  // Material-border relaxation: vertices whose quads have different
  // materials move `relax_iterations` times by `relax_strength` towards the
  // mean of their neighbours on the border (an elastic net), then back onto
  // their planes (8 particle steps of size `relax_plane_pull`), so they slide
  // along the surface, staying in their cell.
  int relax_iterations = 4;        // [Limit: 0 .. 16]; 0 turns it off
  double relax_strength = 0.5;     // [Limit: [0, 1]]
  double relax_plane_pull = 1.0;   // [Limit: [0, 1]]
  // Self-intersections: placement for sharp features can fold a vertex's
  // triangles through its neighbours'. With untangle, the vertices within a
  // cell of any intersecting triangle pair go to their mass points (the mean
  // of their crossings), where folds all but vanish; sharp features are kept
  // everywhere else (contour/untangle.cpp; ContourStats::untangled_vertices
  // counts the moves, mesh_quality what is left). It reads placed vertices
  // 4 + ceil(2 cell_slack) cells around each vertex, so chunks and edits
  // re-mesh that much margin. For a mesh in one piece, untangle = false and
  // then untangle_mesh (after simplify_mesh, if any) is better, and is what
  // the tools do: it moves only the vertices that cross, so sharp features
  // stay sharper (fandisk-with-cylinder union at 256 cells: Hausdorff error
  // 1.7e-3 -> 4.0e-4 of the diagonal, 10,210 -> 5,512 adaptive triangles),
  // and contouring takes about a third of the time.
  bool untangle = true;
  // Mesh the world chunk by chunk in parallel (the default), or in one
  // piece (for tests; refuses worlds larger than 256 cells along an axis).
  bool chunked = true;
};

Status check_contour_config(const ContourConfig& config);

// A triangle mesh in world coordinates.
struct ContourMesh {
  std::vector<glm::dvec3> positions;
  std::vector<glm::vec3> normals;             // one per vertex, unit
  std::vector<uint16_t> vertex_material;      // one per vertex
  std::vector<glm::uvec3> triangles;          // counter-clockwise seen from outside
  std::vector<uint16_t> triangle_material;    // one per triangle

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return triangles.size(); }
};

struct ContourStats {
  double seconds = 0.0;
  size_t chunks_meshed = 0;
  size_t cells = 0;                  // cells that got a vertex
  size_t quads = 0;
  size_t multi_crossing_edges = 0;   // sign-changing edges with 3 or more crossings
  size_t thin_edges = 0;             // edges with crossings but equal ends (ignored)
  size_t clamped_vertices = 0;       // vertices the cell (plus slack) held back from their planes' optimum
  size_t relaxed_vertices = 0;       // vertices on a material border
  size_t untangled_vertices = 0;     // vertices moved to their mass point by untangling
  size_t qef_rank[4] = {0, 0, 0, 0};  // kQef: how many cells solved with rank 0..3

  // Adds another run's counts to these (seconds are left as they are).
  void add_counts(const ContourStats& other);
};

// Meshes the whole world.
Result<ContourMesh> contour_world(const World& world, const ContourConfig& config = {},
                                  Context* ctx = nullptr, ContourStats* stats = nullptr);

// The mesh of one chunk: its own vertices first, then copies of the
// neighbours' vertices its quads use, so it renders on its own without cracks.
struct ChunkMesh {
  glm::ivec3 chunk{0};
  ContourMesh mesh;
  size_t own_vertices = 0;          // mesh.positions[0 .. own_vertices) belong to this chunk
  std::vector<glm::ivec3> vertex_cell;  // the lattice cell of every vertex
  // Which sheet of surface through its cell each vertex stands for: a cell
  // that two or more separate sheets cross (a thin wall, two surfaces
  // meeting at a corner) has a vertex per sheet, numbered from 0.
  std::vector<uint8_t> vertex_sheet;
  // ChunkedMesh: the build or update that last changed this mesh (see
  // ChunkedMesh::version); an engine re-uploads a chunk whose version moved.
  uint64_t version = 0;
};

// What a ChunkedMesh::update changed: a chunk mesh whose content differs from
// before (version > 0: its new ChunkMesh::version) or that no longer exists
// (version 0: the chunk has no surface now; drop its draw call).
struct ChunkMeshChange {
  glm::ivec3 chunk{0};
  uint64_t version = 0;
  int level = 0;  // LevelChunkedMesh: the level of detail it was meshed at (0 otherwise)
  bool removed() const { return version == 0; }
};

struct MeshUpdate {
  std::vector<ChunkMeshChange> changes;  // sorted by chunk_order_less, each chunk once
  size_t chunks_remeshed = 0;            // chunk meshes re-spliced, changed or not
};

// The chunks whose meshes an update for `dirty` may change: every chunk a
// re-mesh box (the dirty node box grown by relax_iterations + 1 cells, and
// 4 + ceil(2 cell_slack) more with untangle, plus the quads around it) overlaps, sorted by chunk_order_less. Meshes outside
// them are untouched; an engine can mark these before re-meshing.
std::vector<glm::ivec3> chunks_a_remesh_may_change(std::span<const DirtyChunk> dirty, const ContourConfig& config,
                                                   int chunk_size);

// Whether a chunk and its 26 neighbours are all empty or all solid: no
// surface near it, so every mesher here gives it an empty mesh (an engine
// can skip it).
bool chunk_is_quiet(const World& world, const glm::ivec3& chunk);
// The chunks the meshers mesh: the world's, and the layer below its box on
// each axis (whose cells straddle the box's lower faces), sorted by chunk (z, y, x).
std::vector<glm::ivec3> chunks_to_mesh(const World& world);

// Meshes one chunk. Chunks that are empty or solid, and whose neighbours
// along the low side are too, produce an empty mesh without reading a ray.
Result<ChunkMesh> contour_chunk(const World& world, const glm::ivec3& chunk,
                                const ContourConfig& config = {}, ContourStats* stats = nullptr);

// Keeps one mesh per chunk and re-meshes only the chunks it is told changed.
//
// Adaptive chunk meshes: run simplify_mesh on a copy of a chunk's mesh (for
// rendering or physics; keep the ChunkMesh itself for updates). It never
// moves a boundary vertex, and a chunk mesh's boundary is its seam with its
// neighbours, so chunks simplified one by one, each when it changed, still
// meet without a crack (tests/test_chunk_adaptive.cpp: fandisk at 96 cells,
// C = 16, within 0.2 h: the welded chunks stay watertight with under a
// third of the triangles). Collapses are checked for self-intersections
// against the chunk's own triangles only, not its neighbours'.
class ChunkedMesh {
 public:
  // Checks the config and meshes every chunk of the world (in parallel): the
  // way to make one. (An empty ChunkedMesh(config) followed by build() is
  // the same in two steps.)
  static Result<ChunkedMesh> create(const World& world, const ContourConfig& config = {}, Context* ctx = nullptr);
  explicit ChunkedMesh(ContourConfig config = {}) : config_(config) {}
  // Meshes every chunk of the world (in parallel).
  Status build(const World& world, Context* ctx = nullptr);
  // Re-meshes the given chunks and the margin of cells around them that
  // their change can reach (see the next overload); leaves every other chunk
  // mesh as it was.
  Result<MeshUpdate> update(const World& world, std::span<const glm::ivec3> changed_chunks,
                            Context* ctx = nullptr);
  // Re-meshes only the cells whose vertices the dirty boxes can move (each
  // box grown by relax_iterations + 1 cells, and the untangle margin) and the quads around them, and
  // splices them into the chunk meshes they fall in; the result equals a
  // fresh build. Returns the chunk meshes whose content changed or that were
  // removed; on error (cancelled) the meshes spliced so far stay spliced.
  Result<MeshUpdate> update(const World& world, std::span<const DirtyChunk> dirty, Context* ctx = nullptr);
  const std::vector<ChunkMesh>& chunks() const { return chunks_; }
  // The chunk's mesh, or null when it has none (no surface, or not built).
  const ChunkMesh* find(const glm::ivec3& chunk) const;
  const ContourConfig& config() const { return config_; }
  // Counts builds and updates that changed something; starts at 0 (nothing built).
  uint64_t version() const { return version_; }
  // One welded mesh: every vertex once, chunk by chunk, in a fixed order.
  ContourMesh assemble() const;
  const ContourStats& stats() const { return stats_; }

 private:
  size_t splice(const detail::MeshPatch& patch, std::vector<glm::ivec3>& changed);

  ContourConfig config_;
  int chunk_size_ = 32;
  uint64_t version_ = 0;
  std::vector<ChunkMesh> chunks_;  // non-empty chunk meshes, sorted by chunk (z, y, x)
  ContourStats stats_;
};

// --- Chunks at different levels of detail (ldc/lod.h) ----------------------------
//
// The world meshed with each chunk at its own level, level_of_chunk(chunk)
// in 0 .. max_lod_level(C) for every chunk of the world's box: a chunk at
// level k is meshed from every 2^k-th ray (as contour_world meshes coarsen(
// world, k)), and where chunks of different levels meet, the coarse cells
// along the seam take the fine side's nodes on their shared faces and edges,
// so the seam closes with no skirt: the mesh is a closed 2-manifold, like a
// one-level mesh (contour/levels.cpp says why). Edits stay on `world` (level
// 0); mesh again after them. Nothing is coarsened: each level's rays are
// read from `world` in place. Cost: about that of meshing each chunk at its
// level (a chunk beside a finer one costs more).
//
// Differences from contour_world (and contour_chunk_levels from contour_chunk): no relaxation of material borders (vertices
// stay at their Hermite placement) and no local untangling round; with
// config.untangle (the default), untangle_mesh runs on the whole result
// (the vertices it moved are counted in stats->untangled_vertices).
// config.chunked is ignored (always chunk by chunk, in parallel). Errors:
// kInvalidArgument for a bad config, a missing function or a level out of
// range (naming the chunk); kInvalidArgument from check_box_faces_outside;
// kCancelled through ctx. Stage timer "contour_levels"; progress
// "contour levels".
Result<ContourMesh> contour_levels(const World& world, const std::function<int(const glm::ivec3&)>& level_of_chunk,
                                   const ContourConfig& config = {}, Context* ctx = nullptr,
                                   ContourStats* stats = nullptr);

// One chunk's part of contour_levels's mesh (before untangling), as
// contour_chunk is of contour_world's: the polygons of the crossing edges the
// chunk's cells emit, with the vertices of its own cells first
// (own_vertices), then those of neighbouring chunks' cells that its polygons
// use; vertex_cell is a vertex's cell's lowest node (level-0 lattice) and
// vertex_sheet its sheet there. A vertex appears, bit for bit the same, in
// every chunk mesh that uses it, so the chunk meshes of one level map
// together are contour_levels's mesh and draw with no crack. A chunk's mesh
// depends only on the rays and the levels of the chunk and its 26
// neighbours (everything it meshes lies within two cells of it, and a cell
// is at most C / 8 wide), so when a chunk changes level or its rays change,
// re-mesh it and its 26 neighbours. The box faces it reaches (within C / 4
// of the chunk) must be outside (check_box_faces_outside over that range: a
// chunk beside a window's face cut through the ground is refused).
// `chunk` may be any chunk of the box or of the layer below it
// (kInvalidArgument otherwise). Thread-safe as contour_chunk.
Result<ChunkMesh> contour_chunk_levels(const World& world, const glm::ivec3& chunk,
                                       const std::function<int(const glm::ivec3&)>& level_of_chunk,
                                       const ContourConfig& config = {}, ContourStats* stats = nullptr);

// --- Levels the surface allows (adaptive output) ---------------------------------
//
// Each chunk's coarsest level k (at most max_level, and max_lod_level(C))
// at which meshing it from every 2^k-th ray keeps its surface: in every
// level-k cell of the chunk, each level-0 crossing lies within `tolerance`
// (cells of h) of the Hermite plane of a crossing of the same material on
// that cell's own edges, and no level-k edge of the chunk holds several
// crossings or a crossing its ends' signs do not show. Flat faces and the
// creases and corners between them go coarse; curvature whose sag over a
// level-k cell passes the tolerance, detail thinner or smaller than the cell
// and material borders that do not line up stay finer. Chunks with no
// surface get max_level. Feed the result to contour_levels, then
// simplify_mesh: the simplifier then starts from far fewer triangles where
// the surface is plain (see docs/contour.md for the figures). Parallel over
// chunks; the same levels for any thread count. Errors: kInvalidArgument for
// a negative or non-finite tolerance or a negative max_level; kCancelled
// through ctx. Stage timer "surface_levels".
struct SurfaceLevelOptions {
  double tolerance = 0.02;  // [Units: cells of h] [Limit: >= 0]
  int max_level = 2;        // [Limit: >= 0; capped at max_lod_level(C)]
};

// A level for every chunk of a world's box.
struct ChunkLevels {
  glm::ivec3 first{0}, dims{0};  // the box's chunks, as World::chunk_origin / chunk_dims
  std::vector<uint8_t> level;    // x fastest
  std::vector<uint8_t> surface;  // 1 where the chunk's level-0 lattice has a crossing
  // A chunk's surface holds several materials (contour_levels does not relax material borders).
  bool several_materials = false;
  // The level of `chunk`, clamped into the box (0 when empty): a level_of_chunk for contour_levels.
  int operator()(const glm::ivec3& chunk) const;
  size_t surface_chunks(int k) const;  // chunks with surface at level k
};

Result<ChunkLevels> surface_levels(const World& world, const SurfaceLevelOptions& options = {},
                                   Context* ctx = nullptr);

// Whether contour_levels at `levels` then simplify_mesh is expected to be
// faster than contour_world then simplify_mesh (a cost model of the chunks
// with surface at each level; see surface_levels.cpp). The outputs of both
// ways are closed 2-manifolds; only the time and, within the tolerance, the
// surface differ.
bool surface_levels_pay_off(const ChunkLevels& levels);

// Contouring for adaptive output, as `ldc remesh`, `ldc boolean` and `ldc
// contour --max-error` do it before simplify_mesh: surface_levels at
// `tolerance` (cells of h), then contour_levels at those levels when
// surface_levels_pay_off says so, the surface holds one material or
// config.relax_iterations is 0 (contour_levels does not relax material
// borders), and its mesh has no non-manifold edge or vertex; otherwise
// contour_world. (The check is a guard: it caught a seam contour_levels
// left non-manifold on sharp CSG solids, since mended.) `config` as for
// either (untangle as given). Errors: those of the three calls.
struct SurfaceLevelChoice {
  ChunkLevels levels;            // as surface_levels chose them
  bool used = false;             // the mesh is contour_levels's at `levels`
  bool borders_relaxed = false;  // one level because several materials' borders are to be relaxed
  bool fell_back = false;        // contour_levels's mesh was non-manifold: contour_world's instead
  double levels_seconds = 0.0;  // surface_levels's time
};
// The tolerance the tools give contour_at_surface_levels for an adaptive
// bound (both in cells of h): a tenth of it, so that coarse levels add
// little to the simplifier's error.
inline double surface_level_tolerance(double max_error_cells) { return max_error_cells / 10.0; }
Result<ContourMesh> contour_at_surface_levels(const World& world, double tolerance, const ContourConfig& config = {},
                                              Context* ctx = nullptr, ContourStats* stats = nullptr,
                                              SurfaceLevelChoice* choice = nullptr);

// Chunk meshes at levels of detail, kept up to date: what ChunkedMesh is to
// contour_chunk, for contour_chunk_levels. Holds every chunk's mesh at its
// level (chunks the world's box holds, and the layer below it; chunks with
// no surface near them hold none). update() re-meshes, all at once and from
// one level map, every chunk within one chunk of a chunk whose rays changed
// or whose level changed, so the meshes it holds always fit together: no
// crack between levels at any moment. Levels come from a function of the
// chunk (often lod_level of its distance to the camera; level(chunk) is
// its level now, for hysteresis). Not thread-safe (one owner); each build
// and update meshes in parallel inside (TBB) and gives the same meshes for
// any thread count.
class LevelChunkedMesh {
 public:
  using LevelOf = std::function<int(const glm::ivec3&)>;
  explicit LevelChunkedMesh(ContourConfig config = {}) : config_(config) {}

  // Meshes every chunk at level_of(chunk). On error (a bad config or level,
  // box faces inside the solid, cancelled) the meshes stay as they were.
  Status build(const World& world, const LevelOf& level_of, Context* ctx = nullptr);
  // Re-meshes the chunks within one chunk of a chunk of `changed_chunks`
  // (their rays changed) or of a chunk whose level_of() differs from its
  // level now. Returns the meshes that changed (with their levels) or went.
  // A world whose chunk box changed is meshed anew (every mesh reported).
  // On error nothing changes.
  Result<MeshUpdate> update(const World& world, std::span<const glm::ivec3> changed_chunks, const LevelOf& level_of,
                            Context* ctx = nullptr);

  const ChunkMesh* find(const glm::ivec3& chunk) const;
  // The chunks whose meshes a change of `changed` (rays or level) may change:
  // each and its 26 neighbours, sorted by chunk_order_less, each once.
  static std::vector<glm::ivec3> chunks_a_change_reaches(std::span<const glm::ivec3> changed);
  // The chunk's level now (clamped into the box; 0 before any build).
  int level(const glm::ivec3& chunk) const;
  // Every non-empty chunk mesh, sorted by chunk (z, y, x).
  std::vector<const ChunkMesh*> chunks() const;
  // All chunk meshes as one, their shared vertices welded (by cell and
  // sheet): contour_levels's mesh before untangling.
  ContourMesh assemble() const;
  uint64_t version() const { return version_; }

 private:
  struct Box {
    glm::ivec3 origin{0}, dims{0};
    bool operator==(const Box&) const = default;
  };
  Result<std::vector<int8_t>> levels_of(const World& world, const LevelOf& level_of) const;
  Status mesh_chunks(const World& world, const std::vector<glm::ivec3>& chunks, const std::vector<int8_t>& levels,
                     std::vector<ChunkMesh>& out, Context* ctx) const;
  // The chunks within one of a changed one (rays, or a level other than levels_), sorted.
  std::vector<glm::ivec3> near_changes(const World& world, std::span<const glm::ivec3> changed_chunks,
                                       const std::vector<int8_t>& levels) const;
  // Takes the meshes made in: changed ones get the next version; returns the changes.
  MeshUpdate merge(std::vector<ChunkMesh>& made, bool whole, const LevelOf& level_now);

  ContourConfig config_;
  Box box_;
  std::vector<int8_t> levels_;  // per chunk of box_, x fastest
  std::vector<ChunkMesh> meshes_;  // non-empty, sorted by chunk (z, y, x)
  uint64_t version_ = 0;
};

// Marching cubes on the same data (vertices at the edge crossings, faces
// resolved consistently): the baseline for tests and benchmarks.
Result<ContourMesh> marching_cubes(const World& world, Context* ctx = nullptr);

// --- Mesh quality -------------------------------------------------------------

// What a mesh is, topologically and geometrically. Vertices are identified by
// index (a mesh that repeats a position under two indices is not welded).
struct MeshQuality {
  size_t triangles = 0;
  size_t vertices = 0;
  size_t boundary_edges = 0;        // edges used by one triangle
  size_t nonmanifold_edges = 0;     // edges used by more than two triangles
  size_t unpaired_edges = 0;        // edges not used once in each direction (boundary edges included)
  // Vertices whose triangles do not form one fan (a disc, or a half-disc at a
  // boundary) through edges used by exactly two triangles: bow-ties, the ends
  // of non-manifold edges. The vertices CGAL's orient_polygon_soup would
  // duplicate on a consistently oriented mesh.
  size_t nonmanifold_vertices = 0;
  // Pairs of triangles that intersect beyond the vertices and edge they share
  // (exact predicates; touching counts; see contour/detail/triangle_intersection.h):
  // two triangles on one edge folded onto each other in one plane, a triangle
  // through another, two triangles at one vertex that overlap. The count
  // CGAL's Polygon_mesh_processing::self_intersections reports, without the
  // degenerate triangles it lists as pairs of one triangle.
  size_t self_intersecting_pairs = 0;
  // Zero area: a repeated or bad index (left out of every count above), or
  // corners on one line (sine of the angle below 1e-15; left out of the
  // self-intersection test, as CGAL leaves them out: it reports each as a
  // pair of one triangle).
  size_t degenerate_triangles = 0;
  size_t unused_vertices = 0;
  // Minimum angle of each triangle, in bins of 10 degrees: [0,10), [10,20) .. [50,60].
  size_t min_angle_histogram[6] = {0, 0, 0, 0, 0, 0};
  double min_angle_deg = 0.0;
  double area = 0.0;
  double volume = 0.0;              // signed, from the triangles

  // Every edge used once in each direction: no cracks, consistently oriented
  // (non-manifold edges used twice each way and bow-tie vertices allowed).
  bool watertight() const { return boundary_edges == 0 && unpaired_edges == 0; }
  // A closed 2-manifold without self-intersections: watertight, no
  // non-manifold edge or vertex, no intersecting triangle pair and no
  // degenerate triangle (which CGAL's does_self_intersect counts too). What a
  // slicer, a physics engine's decomposition or another boolean needs.
  bool closed() const {
    return watertight() && nonmanifold_edges == 0 && nonmanifold_vertices == 0 && self_intersecting_pairs == 0 &&
           degenerate_triangles == 0;
  }
};

// Measures the mesh. Linear in its size plus the self-intersection test (a
// uniform grid over the triangles' boxes, parallel with TBB): about 0.8 s per
// million triangles on 2 cores, 0.6 s of it the self-intersection test. The
// same result for any thread count.
struct QualityOptions {
  // Take this as the self-intersecting pair count instead of searching: for a
  // mesh untangle_mesh has just left (UntangleMeshStats::pairs_after is
  // exact: it re-tests every triangle that moved and carries the pairs of
  // the rest), which saves the search, about 0.6 s per million triangles.
  std::optional<size_t> known_self_intersecting_pairs;
};
MeshQuality mesh_quality(const ContourMesh& mesh, const QualityOptions& options = {});

// What keeps the mesh from being closed(), e.g. "12 boundary edges, 3
// non-manifold vertices, 40 self-intersecting triangle pairs"; "" when closed.
std::string quality_failures(const MeshQuality& quality);

// --- Adaptive output: simplification within an error bound ---------------------
//
// Contouring gives a uniform mesh: about two triangles per cell of surface,
// flat faces included. simplify_mesh collapses flat regions and simple creases
// with half-edge collapses (a vertex moves onto a neighbour, so every position
// that survives is an original contour vertex and sharp corners stay exact),
// cheapest first by Garland-Heckbert quadric error.
//
// The error bound: each vertex carries the planes of the original triangles
// (and, on material borders, planes through the border edge standing on its
// triangles) that were merged into it, with weight 1 each: not area-weighted,
// so that sqrt(quadric error) >= the distance to every single plane. A
// collapse is made only when sqrt(error at the kept vertex) <= max_error: the
// kept vertex lies within max_error of the plane of every original triangle
// its new fan replaced. (A large triangle's interior is bounded only through
// its corners: on curved surfaces it may lie a little further, as for any
// vertex-quadric method; tests/test_simplify.cpp measures a sphere.)
//
// What it never does (each refusal counted in SimplifyStats):
// - change topology: a vertex moves only when it is a manifold interior
//   vertex (one disc of triangles, every edge used twice, once each way, no
//   degenerate triangle); the collapsed edge passes the link condition (the
//   two ends share exactly the two opposite vertices) and the kept vertex
//   keeps at least 3 triangles. Boundary and non-manifold vertices and
//   vertices on degenerate triangles never move, so existing defects do not
//   grow (they may still receive a neighbour);
// - move a material border: a vertex whose triangles have one material may
//   collapse onto any neighbour; a vertex on a border between exactly two
//   materials (two border edges, at least two triangles of each) only slides
//   along the border onto one of its two border neighbours; a vertex where
//   three materials meet, or with more border edges, never moves;
// - flip or crush a triangle: every changed triangle keeps its normal within
//   max_normal_change_deg, is not degenerate (exact collinearity test), and
//   its smallest angle is not below min_angle_deg unless it was already;
// - add a self-intersection: every changed triangle is checked against
//   every triangle near it and the other changed triangles, by the rules of
//   mesh_quality (contour/detail/triangle_intersection.h): pairs that
//   floating-point tests with a margin over rounding prove apart (a
//   separating axis; fans that are certainly stars around their vertex) are
//   skipped, the rest go to the exact predicates; a collapse is refused if
//   any pair meets, unless the triangles
//   it replaces were in more intersecting pairs (folds the input already had
//   may be collapsed away). mesh_quality's self_intersecting_pairs never grows.
//
// Parallel and deterministic: space is cut into blocks (block_size); blocks
// are simplified in parallel, each moving only vertices whose triangles lie
// in the block; then again with blocks shifted by half a block, so that the
// seams are simplified too; a last pass over the whole mesh in one piece
// finishes what both block layouts left (vertices near where seams of the two
// layouts cross, and collapses that need a fan wider than a block: a cube
// becomes 12 triangles). Each block works in a fixed order, so the output is
// the same for any thread count. Cost: about linear in the triangles.
struct SimplifyOptions {
  // The error bound, in world units (metres) [Limit: >= 0, finite]. 0 leaves
  // the mesh untouched (uniform output). Tools take it in cells of h.
  double max_error = 0.0;
  // Stop once the mesh has at most this many triangles (0 = no target)
  // [Limit: >= 0]. The bound still holds: when every collapse within
  // max_error is made and the mesh is still above the target, it stops there
  // (above the target). While a target is set, each parallel pass lets a block
  // remove only its share (by triangles) of the excess, and the last pass,
  // in one piece and cheapest first, stops at the target: the result has
  // target or target - 1 triangles when the bound allows (a collapse removes 2).
  size_t target_triangles = 0;
  // Largest angle a changed triangle's normal may turn by [Limit: (0, 180)]
  // [Units: degrees]. Below 90 refuses flips; 75 lets the triangles that
  // bevel a right-angled crease fold onto its faces.
  double max_normal_change_deg = 75.0;
  // A changed triangle's smallest angle may not fall below this unless it
  // already was [Limit: [0, 30]] [Units: degrees]. Keeps slivers out.
  double min_angle_deg = 1.0;
  // Edge of the blocks simplified in parallel [Limit: >= 0, finite] [Units:
  // world]; 0 = 32 times the mean edge length of the input (32 cells on a
  // contoured mesh). Larger blocks leave fewer seams, smaller ones balance
  // threads better.
  double block_size = 0.0;
};

struct SimplifyStats {
  size_t triangles_before = 0;
  size_t triangles_after = 0;
  size_t vertices_before = 0;
  size_t vertices_after = 0;           // vertices still used (unused ones are dropped)
  size_t collapses = 0;
  size_t locked_vertices = 0;          // boundary, non-manifold or on a degenerate triangle: never moved
  // Collapses within the bound that were refused, by the first check that failed:
  size_t rejected_topology = 0;        // link condition, or too few triangles left
  size_t rejected_flip = 0;            // a normal turned too far, or a triangle degenerate
  size_t rejected_sliver = 0;          // a triangle's smallest angle fell below min_angle_deg
  size_t rejected_intersection = 0;    // a changed triangle would meet another
  size_t passes = 0;                   // passes run (blocks, shifted blocks, whole mesh)
  size_t blocks = 0;                   // blocks simplified, over all passes
  double max_error_reached = 0.0;      // largest sqrt(quadric error) of a collapse made (world units)
  double seconds = 0.0;
};

Status check_simplify_options(const SimplifyOptions& options);

// Simplifies `mesh` in place within options.max_error (see above). Surviving
// vertices keep their position, normal and material, and triangles their
// material and orientation; triangles and vertices keep their relative order
// (dead ones removed, unused vertices dropped). max_error == 0 returns at once
// with the mesh unchanged. Errors: bad options (kInvalidArgument, naming the
// field); cancellation through ctx (kCancelled, mesh unchanged). Stage timer
// "simplify" on ctx.
Result<SimplifyStats> simplify_mesh(ContourMesh& mesh, const SimplifyOptions& options, Context* ctx = nullptr);

// --- Untangling the assembled mesh ------------------------------------------------
//
// Sharp-feature placement folds a few of a uniform mesh's triangles through
// their neighbours (fandisk at 256 cells: 21 pairs in 159,940 triangles).
// ContourConfig::untangle clears most of these while contouring (one local
// round at the mass points), but not all (tiny blobs around a lattice node,
// saddles, two sheets in one cell), and blunts features. untangle_mesh clears them on a whole mesh (contoured with or
// without that round, simplified, or any triangle mesh): the
// vertices of every intersecting triangle pair move to the centroid of their
// neighbours, a move that would turn a triangle over is halved or undone,
// and further rounds widen the moved area by a ring of neighbours, until no
// pair is left (contour/untangle_mesh.cpp). It returns the positions of the
// round that left the fewest pairs: on a simplified mesh, whose vertices'
// neighbours lie far apart, a round can make more pairs than it clears
// (an edited landscape's 57 pairs became 90). Boundary and non-manifold
// vertices never move. Pairs are those mesh_quality counts.
// The tools contour without the local round, simplify, then run it.
//
// Specks: a lattice node inside the solid with all six neighbours outside
// (or the reverse) contours to a closed blob of 8 vertices and 12 triangles
// around the node, a fraction of a cell across. Sharp-feature placement
// pins several of its vertices onto the same cell faces, where they crumple
// it through itself, and smoothing moves them towards each other without
// opening it (measured: a 0.01-cell blob in a spot-and-spot intersection
// left 4 pairs after any number of rounds). What the rounds leave in a
// closed component of at most max_speck_vertices vertices is therefore
// removed, speck and all: the only change of topology untangle_mesh makes,
// counted in specks_removed. Its triangles go, and then every vertex no
// triangle uses (the rest keep their order; normals and materials follow).
struct UntangleMeshOptions {
  // Rounds before giving up [Limit: 0..1000]; 0 only counts the pairs.
  int max_rounds = 50;
  // Farthest a vertex may end from where it started [Units: world]
  // [Limit: >= 0, finite]; 0 = no limit. On a simplified mesh the centroid
  // of a vertex's neighbours can lie many cells off the surface (rounds
  // that widened the moved area moved an edited landscape's vertices so far
  // that its volume fell by a third): the tools limit the moves there to
  // one cell h, which also let that case converge.
  double max_move = 0.0;
  // Largest closed component still intersecting itself after the rounds
  // that is removed [Limit: 0..64] [Units: vertices]. 12 takes specks of one
  // and two lattice nodes; 0 removes nothing.
  int max_speck_vertices = 12;
};

struct UntangleMeshStats {
  size_t pairs_before = 0;    // intersecting pairs found first
  size_t pairs_after = 0;     // left at the end (0 unless it gave up); never above pairs_before
  size_t vertices_moved = 0;  // vertices not where they started
  size_t rounds = 0;
  size_t specks_removed = 0;           // closed components removed (see above)
  size_t speck_triangles_removed = 0;  // their triangles
};

Status check_untangle_mesh_options(const UntangleMeshOptions& options);

// Moves vertices of `mesh` until no triangle pair intersects or
// options.max_rounds is spent (see above). Cost: one pair search over the
// whole mesh (as in mesh_quality), then per round a search around the moved
// vertices only. Errors: bad options or a vertex index out of range
// (kInvalidArgument); cancellation through ctx (kCancelled, positions
// restored). Stage timer "untangle_mesh" on ctx.
Result<UntangleMeshStats> untangle_mesh(ContourMesh& mesh, const UntangleMeshOptions& options = {},
                                        Context* ctx = nullptr);

// --- Simplified and untangled: what the tools run --------------------------------
//
// simplify_mesh, then untangle_mesh with `untangle` (the tools cap its
// max_move at one cell h; few pairs are left on few triangles, so this is
// cheap). Where pairs remain, it starts again from the mesh as given:
// untangle_mesh without the cap (moves are small on a uniform mesh),
// simplify_mesh (which never adds a pair), untangle_mesh with `untangle`
// again, and keeps the result with fewer pairs. Costs a copy of the mesh;
// the second way runs only when the first leaves pairs. Errors: those of
// simplify_mesh and untangle_mesh (the mesh is then unchanged, or as the
// failing step left it on cancellation).
struct SimplifyUntangleStats {
  SimplifyStats simplify;              // of the result kept
  UntangleMeshStats untangle;          // its last untangling
  bool retried = false;                // the first way left pairs
  bool retry_used = false;             // the second way left fewer: its result is kept
  size_t first_pairs_after = 0;        // pairs the first way left
  UntangleMeshStats uniform_untangle;  // the second way's first step (when retried)
  double simplify_seconds = 0.0;       // all simplify_mesh calls
  double untangle_seconds = 0.0;       // all untangle_mesh calls
};
Result<SimplifyUntangleStats> simplify_and_untangle(ContourMesh& mesh, const SimplifyOptions& simplify,
                                                    const UntangleMeshOptions& untangle, Context* ctx = nullptr);

}  // namespace ldc
