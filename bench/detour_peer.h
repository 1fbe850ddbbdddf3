// Recast/Detour peer for the pathfinding benchmark: the standard Recast build
// pipeline (as RecastDemo's Sample_SoloMesh / Sample_TileMesh) and Detour
// queries (findNearestPoly + findPath + findStraightPath), with the parameters
// shared/PEERS.md measured the reference figures with. Recast/Detour headers
// stay in detour_peer.cpp: DetourNav is opaque here.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace ldc::bench {

struct DetourParams {  // RecastDemo defaults, as PEERS.md
  float cell_size = 0.3f, cell_height = 0.2f;
  float agent_height = 2.0f, agent_radius = 0.6f, agent_max_climb = 0.9f, agent_max_slope = 45.0f;
  int region_min_size = 8, region_merge_size = 20;
  float edge_max_len = 12.0f, edge_max_error = 1.3f;
  int verts_per_poly = 6;
  float detail_sample_dist = 6.0f, detail_sample_max_error = 1.0f;
  int tile_size = 0;  // cells per tile side; 0 = one solo mesh; >0 = tiled navmesh (for tile rebuilds)
  int max_nodes = 2048;
};

struct DetourBuildStats {
  double build_ms = 0;  // triangles in memory -> ready dtNavMeshQuery
  int polys = 0;        // all tiles together
  int grid_w = 0, grid_h = 0;  // cells of the whole bounds (rcCalcGridSize)
  int tiles = 0;        // tiles holding data (1 for a solo mesh)
};

// Owns dtNavMesh, dtNavMeshQuery and the input triangles; opaque (the
// Recast/Detour side lives in detour_peer.cpp).
class DetourNav {
 public:
  struct Impl;
  explicit DetourNav(std::unique_ptr<Impl> impl);
  ~DetourNav();
  DetourNav(const DetourNav&) = delete;
  DetourNav& operator=(const DetourNav&) = delete;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// verts: xyz floats, Y up (Detour's convention); tris: index triples.
// Returns null (and the reason in *error) when the build fails.
std::unique_ptr<DetourNav> detour_build(const std::vector<float>& verts, const std::vector<int>& tris,
                                        const DetourParams& params, DetourBuildStats* stats, std::string* error);

struct DetourPair {
  glm::vec3 start{0}, goal{0};
};

// count pairs from dtNavMeshQuery::findRandomPoint with a fixed seeded RNG
// (same seed -> same pairs).
std::vector<DetourPair> detour_random_pairs(DetourNav& nav, int count, uint32_t seed);

struct DetourPath {
  bool found = false;         // complete: last poly is the goal's poly
  bool out_of_nodes = false;  // DT_OUT_OF_NODES
  std::vector<glm::vec3> straight;  // findStraightPath points
  double length = 0;          // sum of 3D segment lengths of `straight`
};

// findNearestPoly (half extents 2,4,2) + findPath (max 2048 polys) +
// findStraightPath; a partial path's straight path ends at the point of its
// last poly nearest the goal (as RecastDemo's NavMeshTesterTool).
DetourPath detour_find_path(DetourNav& nav, const glm::vec3& start, const glm::vec3& goal);

// The nearest point of the navmesh within half_extents of p (Detour's frame); false when none.
bool detour_nearest_point(DetourNav& nav, const glm::vec3& p, const glm::vec3& half_extents,
                          glm::vec3* nearest);

// Tiled navmesh only: replaces the triangles (e.g. after a dig), rebuilds the
// one tile containing `at` (Recast build of that tile from the triangles
// overlapping it + removeTile/addTile) and returns the milliseconds it took
// (triangle gathering for the tile included; copying the triangle list in
// excluded). Returns a negative value (and the reason in *error) on failure.
double detour_rebuild_tile(DetourNav& nav, const std::vector<float>& verts,
                           const std::vector<int>& tris, const glm::vec3& at, std::string* error);

}  // namespace ldc::bench
