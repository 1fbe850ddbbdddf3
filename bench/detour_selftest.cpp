// Self test of the Recast/Detour peer (not part of ctest): builds
// tests/data/nav_test.obj as a solo mesh, runs 1000 random path queries and
// prints the figures shared/PEERS.md lists for it, then builds a tiled
// navmesh (tile size 32) and times rebuilding the tile at the mesh centre.
//
//   detour_selftest [mesh.obj] [pairs] [seed]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "detour_peer.h"
#include "ldc/mesh.h"
#include "meshio/meshio.h"

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}
double percentile(std::vector<double> v, double p) {  // nearest rank
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  rank = std::clamp<size_t>(rank, 1, v.size());
  return v[rank - 1];
}

// RecastDemo's rcMeshLoaderObj: polygons fanned from their first corner.
bool load_obj_fan(const std::string& path, std::vector<float>* verts, std::vector<int>* tris) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      float x = 0, y = 0, z = 0;
      ls >> x >> y >> z;
      verts->insert(verts->end(), {x, y, z});
    } else if (tag == "f") {
      std::vector<int> face;
      std::string corner;
      const int nv = static_cast<int>(verts->size() / 3);
      while (ls >> corner) {
        int i = std::atoi(corner.c_str());
        face.push_back(i < 0 ? nv + i : i - 1);
      }
      for (size_t i = 2; i < face.size(); ++i) tris->insert(tris->end(), {face[0], face[i - 1], face[i]});
    }
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace ldc::bench;
  const std::string path = argc > 1 ? argv[1] : std::string(LDC_BENCH_DATA_DIR) + "/nav_test.obj";
  const int npairs = argc > 2 ? std::atoi(argv[2]) : 1000;
  const uint32_t seed = argc > 3 ? static_cast<uint32_t>(std::strtoul(argv[3], nullptr, 10)) : 1u;

  // The triangles as RecastDemo's OBJ loader makes them (polygons fanned),
  // which is what the PEERS.md figures were measured on.
  std::vector<float> verts;
  std::vector<int> tris;
  if (!load_obj_fan(path, &verts, &tris) || tris.empty()) {
    std::fprintf(stderr, "cannot read %s\n", path.c_str());
    return 1;
  }
  std::printf("%s: %zu verts, %zu tris (polygons fanned, as RecastDemo)\n", path.c_str(), verts.size() / 3,
              tris.size() / 3);

  // Solo mesh: build 7 times, report the median and range.
  DetourParams params;
  std::unique_ptr<DetourNav> nav;
  DetourBuildStats stats;
  std::vector<double> build_ms;
  for (int rep = 0; rep < 7; ++rep) {
    std::string error;
    nav = detour_build(verts, tris, params, &stats, &error);
    if (!nav) {
      std::fprintf(stderr, "build failed: %s\n", error.c_str());
      return 1;
    }
    build_ms.push_back(stats.build_ms);
  }
  std::printf("solo build: %.2f ms [%.2f-%.2f], %d polys, grid %dx%d\n", median(build_ms),
              *std::min_element(build_ms.begin(), build_ms.end()),
              *std::max_element(build_ms.begin(), build_ms.end()), stats.polys, stats.grid_w, stats.grid_h);
  std::printf("  PEERS.md: 23.0 ms [23.0-23.8], 153 polys, grid 305x258\n");

  // The same file through ldc::load_mesh (polygons ear-clipped: other diagonals).
  ldc::Result<ldc::TriangleMesh> loaded = ldc::load_mesh(path);
  if (!loaded.ok()) {
    std::fprintf(stderr, "%s\n", loaded.status().message().c_str());
    return 1;
  }
  const ldc::TriangleMesh& mesh = loaded.value();
  {
    std::vector<float> lverts;
    std::vector<int> ltris;
    for (const glm::dvec3& p : mesh.positions) {
      lverts.insert(lverts.end(), {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
    }
    for (const glm::uvec3& t : mesh.triangles) {
      ltris.insert(ltris.end(), {static_cast<int>(t.x), static_cast<int>(t.y), static_cast<int>(t.z)});
    }
    DetourBuildStats lstats;
    std::string error;
    if (!detour_build(lverts, ltris, params, &lstats, &error)) {
      std::fprintf(stderr, "build (ldc loader) failed: %s\n", error.c_str());
      return 1;
    }
    std::printf("  with ldc::load_mesh's triangles (%zu): %.2f ms, %d polys, grid %dx%d\n", mesh.triangles.size(),
                lstats.build_ms, lstats.polys, lstats.grid_w, lstats.grid_h);
  }

  const std::vector<DetourPair> pairs = detour_random_pairs(*nav, npairs, seed);
  constexpr int kReps = 5;
  std::vector<double> query_us;
  int found = 0, out_of_nodes = 0;
  double length_sum = 0;
  for (const DetourPair& pair : pairs) {
    std::vector<double> reps;
    DetourPath result;
    for (int r = 0; r < kReps; ++r) {
      const auto t0 = Clock::now();
      result = detour_find_path(*nav, pair.start, pair.goal);
      reps.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
    }
    query_us.push_back(median(reps));
    if (result.found) {
      ++found;
      length_sum += result.length;
    }
    if (result.out_of_nodes) ++out_of_nodes;
  }
  double total_us = 0;
  for (double q : query_us) total_us += q;
  std::printf("%zu queries (seed %u): median %.2f us, p99 %.2f us, sum %.2f ms, found %.1f%%, "
              "mean length (found) %.2f, out-of-nodes %d\n",
              pairs.size(), seed, median(query_us), percentile(query_us, 99), total_us / 1000.0,
              pairs.empty() ? 0.0 : 100.0 * found / static_cast<double>(pairs.size()),
              found ? length_sum / found : 0.0, out_of_nodes);
  std::printf("  PEERS.md: median 1.69 us, p99 7.82 us, 2.84 ms, found 28.6%%, length 24.95, 0\n");

  // Tiled navmesh and one tile rebuild at the centre of the mesh.
  DetourParams tiled = params;
  tiled.tile_size = 32;
  DetourBuildStats tstats;
  std::string error;
  std::unique_ptr<DetourNav> tnav = detour_build(verts, tris, tiled, &tstats, &error);
  if (!tnav) {
    std::fprintf(stderr, "tiled build failed: %s\n", error.c_str());
    return 1;
  }
  std::printf("tiled build (tile 32): %.2f ms, %d tiles, %d polys\n", tstats.build_ms, tstats.tiles, tstats.polys);
  const ldc::MeshBounds bounds = ldc::mesh_bounds(mesh);
  const glm::vec3 centre = glm::vec3(0.5 * (bounds.min + bounds.max));
  std::vector<double> rebuild_ms;
  for (int rep = 0; rep < 9; ++rep) {
    const double ms = detour_rebuild_tile(*tnav, verts, tris, centre, &error);
    if (ms < 0) {
      std::fprintf(stderr, "tile rebuild failed: %s\n", error.c_str());
      return 1;
    }
    rebuild_ms.push_back(ms);
  }
  std::printf("tile rebuild at centre: median %.3f ms [%.3f-%.3f] over %zu\n", median(rebuild_ms),
              *std::min_element(rebuild_ms.begin(), rebuild_ms.end()),
              *std::max_element(rebuild_ms.begin(), rebuild_ms.end()), rebuild_ms.size());
  // A "dig": drop the triangles with a corner within 4 m (x/z) of the centre, rebuild that tile.
  std::vector<int> dug;
  for (size_t t = 0; t + 2 < tris.size(); t += 3) {
    bool near = false;
    for (int k = 0; k < 3; ++k) {
      const float* v = &verts[3 * static_cast<size_t>(tris[t + k])];
      near = near || (std::hypot(v[0] - centre.x, v[2] - centre.z) < 4.0f);
    }
    if (!near) dug.insert(dug.end(), {tris[t], tris[t + 1], tris[t + 2]});
  }
  const double dig_ms = detour_rebuild_tile(*tnav, verts, dug, centre, &error);
  if (dig_ms < 0) {
    std::fprintf(stderr, "dig rebuild failed: %s\n", error.c_str());
    return 1;
  }
  int dfound = 0;
  for (const DetourPair& pair : pairs) dfound += detour_find_path(*tnav, pair.start, pair.goal).found ? 1 : 0;
  std::printf("dig (%zu of %zu tris removed): tile rebuild %.3f ms, solo pairs found %.1f%%\n",
              (tris.size() - dug.size()) / 3, tris.size() / 3, dig_ms,
              pairs.empty() ? 0.0 : 100.0 * dfound / static_cast<double>(pairs.size()));
  detour_rebuild_tile(*tnav, verts, tris, centre, &error);  // back to the original

  // The tiled navmesh answers the same pairs (sanity: found share near the solo one).
  int tfound = 0;
  for (const DetourPair& pair : pairs) tfound += detour_find_path(*tnav, pair.start, pair.goal).found ? 1 : 0;
  std::printf("tiled: solo pairs found %.1f%%\n", pairs.empty() ? 0.0 : 100.0 * tfound / static_cast<double>(pairs.size()));
  return 0;
}
