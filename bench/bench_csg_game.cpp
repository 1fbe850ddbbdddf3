// Per-frame edits on the default landscape (h = 0.2 m): a sphere dig of radius
// 2 m, a box build and a paint stroke, timed alone and with the re-mesh of the
// chunks they dirtied (ChunkedMesh::update), at 1 and 2 threads and chunk sizes
// 16 and 32; then 1,000 random digs with time per edit and memory; then the
// self-intersecting pairs of the chunk meshes per contour config.
//
// Usage: bench_csg_game [--quick | --dig [runs] [untangle] | --validity]
//   --dig: only the 2 m sphere dig + re-mesh (C = 32, LiveConfig's contour
//   config, or with ContourConfig::untangle on when `untangle` follows), median
//   and p95 over `runs` (default 101) at 1 and 2 threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "bench_common.h"
#include "contour/contour.h"
#include "csg/csg.h"
#include "ldc/terrain.h"

namespace {

using ldc::bench::median_ms;

// The top surface height at (x, y): the last exit of the vertical ray nearest to it.
double ground_height(const ldc::World& w, double x, double y) {
  glm::dvec3 q = w.lattice().to_lattice({x, y, 0.0});
  auto points = w.ray_points(2, {int(std::lround(q.x)), int(std::lround(q.y))});
  for (auto it = points.rbegin(); it != points.rend(); ++it) {
    if (!it->enter) return w.lattice().origin.z + it->depth * w.lattice().cell_size;
  }
  return w.lattice().origin.z;
}

struct GameEdit {
  const char* name;
  ldc::Brush brush;
  ldc::EditOp op;
};

std::vector<GameEdit> game_edits(const ldc::World& w) {
  const double x = 20.3, y = 22.7, z = ground_height(w, x, y);
  return {
      {"sphere dig r=2m", ldc::Brush::sphere({x, y, z}, 2.0), ldc::EditOp::kSubtract},
      {"box build 2x2x2m", ldc::Brush::box({x + 6.0, y, ground_height(w, x + 6.0, y) + 0.9}, glm::dvec3(1.0), 2),
       ldc::EditOp::kUnion},
      {"paint stroke r=1m, 4m", ldc::Brush::capsule({x - 2, y - 6, z}, {x + 2, y - 6, z}, 1.0, 3), ldc::EditOp::kPaint},
      {"noise dig r=2m", ldc::Brush::noisy_sphere({x - 6, y, ground_height(w, x - 6, y)}, {.radius = 2.0}),
       ldc::EditOp::kSubtract},
  };
}

// Median over reps of one edit (then undone, untimed), alone and with the re-mesh.
void time_edit(ldc::WorldEditor& ed, ldc::ChunkedMesh& meshes, const GameEdit& e, int reps, double* edit_ms,
               double* total_ms, size_t* chunks, size_t* remeshed) {
  std::vector<double> alone, both;
  for (int r = 0; r < reps; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    ldc::EditReceipt receipt = ed.apply(e.brush, e.op).value();
    auto t1 = std::chrono::steady_clock::now();
    *remeshed = meshes.update(ed.world(), ed.take_dirty()).value().chunks_remeshed;
    auto t2 = std::chrono::steady_clock::now();
    alone.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    both.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
    *chunks = receipt.changed_chunks.size();
    if (!ed.undo(receipt).ok()) std::abort();
    (void)meshes.update(ed.world(), ed.take_dirty()).value();
  }
  std::sort(alone.begin(), alone.end());
  std::sort(both.begin(), both.end());
  *edit_ms = alone[alone.size() / 2];
  *total_ms = both[both.size() / 2];
}

void game_table(bool quick) {
  std::printf("\n## Game edits on the default landscape (h = 0.2 m)\n\n");
  std::printf("Median of %d runs; each edit is undone (untimed) before the next run. "
              "`edit` = WorldEditor::apply; `edit + re-mesh` adds ChunkedMesh::update on the dirty list, "
              "with ContourConfig::untangle off (LiveConfig's default) and on.\n\n",
              quick ? 5 : 21);
  std::printf("| edit | C | threads | untangle | chunks changed | chunks re-meshed | edit ms | edit + re-mesh ms |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int c : {16, 32}) {
    ldc::World w = ldc::build_terrain({}, 0.2, c).value();
    for (int threads : {1, 2}) {
      tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
      for (bool untangle : {false, true}) {
        ldc::WorldEditor ed(w);
        ldc::ChunkedMesh meshes({.untangle = untangle});
        if (!meshes.build(ed.world()).ok()) std::abort();
        for (const GameEdit& e : game_edits(w)) {
          double edit_ms = 0, total_ms = 0;
          size_t chunks = 0, remeshed = 0;
          time_edit(ed, meshes, e, quick ? 5 : 21, &edit_ms, &total_ms, &chunks, &remeshed);
          std::printf("| %s | %d | %d | %s | %zu | %zu | %.2f | %.2f |\n", e.name, c, threads, untangle ? "on" : "off",
                      chunks, remeshed, edit_ms, total_ms);
        }
      }
    }
  }
}

void stress_table(bool quick) {
  const int n = quick ? 200 : 1000;
  std::printf("\n## %d random digs on the default landscape (h = 0.2 m, C = 32, 2 threads)\n\n", n);
  ldc::World w = ldc::build_terrain({}, 0.2, 32).value();
  ldc::WorldEditor ed(w);
  ldc::ChunkedMesh meshes({.untangle = false});  // LiveConfig's default
  if (!meshes.build(ed.world()).ok()) std::abort();
  ldc::WorldStats before = ed.world().stats();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> xy(2.0, 46.0), radius(0.5, 2.0), depth(-1.5, 0.5);
  std::vector<double> edit, total;
  for (int i = 0; i < n; ++i) {
    double x = xy(rng), y = xy(rng);
    ldc::Brush b = ldc::Brush::sphere({x, y, ground_height(ed.world(), x, y) + depth(rng)}, radius(rng));
    auto t0 = std::chrono::steady_clock::now();
    if (!ed.apply(b, ldc::EditOp::kSubtract).ok()) std::abort();
    auto t1 = std::chrono::steady_clock::now();
    if (!meshes.update(ed.world(), ed.take_dirty()).ok()) std::abort();
    auto t2 = std::chrono::steady_clock::now();
    edit.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    total.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
  }
  ldc::WorldStats after = ed.world().stats();
  auto pct = [](std::vector<double> v, double p) {
    std::sort(v.begin(), v.end());
    return v[size_t(p * double(v.size() - 1))];
  };
  double mean_edit = 0, mean_total = 0;
  for (size_t i = 0; i < edit.size(); ++i) mean_edit += edit[i] / double(n), mean_total += total[i] / double(n);
  bool valid = ldc::validate(ed.world()).ok;
  std::printf("| | mean ms | median ms | p95 ms | max ms |\n|---|---|---|---|---|\n");
  std::printf("| edit | %.2f | %.2f | %.2f | %.2f |\n", mean_edit, pct(edit, 0.5), pct(edit, 0.95), pct(edit, 1.0));
  std::printf("| edit + re-mesh | %.2f | %.2f | %.2f | %.2f |\n\n", mean_total, pct(total, 0.5), pct(total, 0.95),
              pct(total, 1.0));
  std::printf("| | points | mixed chunks | memory MiB | bytes/point |\n|---|---|---|---|---|\n");
  for (auto [label, s] : {std::pair{"before", before}, std::pair{"after", after}}) {
    std::printf("| %s | %zu | %zu | %.2f | %.2f |\n", label, s.points, s.chunks_mixed,
                double(s.memory_bytes) / (1024.0 * 1024.0), s.bytes_per_point());
  }
  std::printf("\nvalidate() after the digs: %s\n", valid ? "ok" : "FAILED");
}

// The budget row alone, with its spread: median and p95 of edit + re-mesh.
void dig_table(int runs, bool untangle) {
  std::printf("\n## 2 m sphere dig + re-mesh (h = 0.2 m, C = 32, untangle %s), %d runs\n\n", untangle ? "on" : "off",
              runs);
  std::printf("| threads | edit ms median | edit + re-mesh ms median | p95 | min |\n|---|---|---|---|---|\n");
  ldc::World w = ldc::build_terrain({}, 0.2, 32).value();
  for (int threads : {1, 2}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, size_t(threads));
    ldc::WorldEditor ed(w);
    ldc::ChunkedMesh meshes({.untangle = untangle});
    if (!meshes.build(ed.world()).ok()) std::abort();
    const GameEdit dig = game_edits(w).front();
    std::vector<double> edit, total;
    for (int r = 0; r < runs; ++r) {
      auto t0 = std::chrono::steady_clock::now();
      ldc::EditReceipt receipt = ed.apply(dig.brush, dig.op).value();
      auto t1 = std::chrono::steady_clock::now();
      (void)meshes.update(ed.world(), ed.take_dirty()).value();
      auto t2 = std::chrono::steady_clock::now();
      edit.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      total.push_back(std::chrono::duration<double, std::milli>(t2 - t0).count());
      if (!ed.undo(receipt).ok()) std::abort();
      (void)meshes.update(ed.world(), ed.take_dirty()).value();
    }
    std::sort(edit.begin(), edit.end());
    std::sort(total.begin(), total.end());
    std::printf("| %d | %.2f | %.2f | %.2f | %.2f |\n", threads, edit[edit.size() / 2], total[total.size() / 2],
                total[size_t(0.95 * double(total.size() - 1))], total.front());
  }
}

// Self-intersections of the engine's chunk meshes (mesh_quality of the
// assembled ChunkedMesh, exact predicates) per contour config: on the
// landscape as built, after `edits` random digs and builds (the same sequence
// for every config), and the 2 m dig + re-mesh's median time at 2 threads.
struct EngineConfig {
  const char* name;
  ldc::ContourConfig config;
};

// The 2 m sphere dig + re-mesh's median ms (time_edit) on 2 threads.
double dig_median_ms(const ldc::World& w, const ldc::ContourConfig& config, int runs) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
  ldc::WorldEditor ed(w);
  ldc::ChunkedMesh meshes(config);
  if (!meshes.build(ed.world()).ok()) std::abort();
  double edit_ms = 0.0, total_ms = 0.0;
  size_t chunks = 0, remeshed = 0;
  time_edit(ed, meshes, game_edits(w).front(), runs, &edit_ms, &total_ms, &chunks, &remeshed);
  return total_ms;
}

void validity_table(bool quick) {
  const int edits = quick ? 60 : 300, runs = quick ? 11 : 31;
  std::printf("\n## Self-intersections of engine chunk meshes (h = 0.2 m, C = 32)\n\n");
  std::printf("mesh_quality of ChunkedMesh::assemble() (exact predicates; the tools' `closed` = no pair, no "
              "non-manifold edge or vertex, watertight): the default landscape as built, then after %d random edits "
              "(spheres, noisy spheres and boxes in turn, radius or half-size 0.35 to 2 m, every 4th a build, the "
              "rest digs; same sequence for every config), each followed by ChunkedMesh::update; `dig ms` = the 2 m "
              "sphere dig + re-mesh, median of %d, 2 threads.\n\n",
              edits, runs);
  const std::vector<EngineConfig> configs = {
      {"iterative, relax 4, untangle off (LiveConfig's default)", {.untangle = false}},
      {"iterative, relax 4, untangle on", {.untangle = true}},
      {"iterative, relax 0, untangle on", {.relax_iterations = 0, .untangle = true}},
      {"mass points, relax 0", {.placement = ldc::Placement::kMassPoint, .relax_iterations = 0}},
      {"mass points, relax 4", {.placement = ldc::Placement::kMassPoint}},
      {"mass points, relax 4 without the pull back to the planes",
       {.placement = ldc::Placement::kMassPoint, .relax_plane_pull = 0.0}},
  };
  std::printf("| config | triangles | pairs | non-manifold edges + vertices | closed | triangles after | pairs after | "
              "closed after | dig ms |\n|---|---|---|---|---|---|---|---|---|\n");
  const ldc::World w = ldc::build_terrain({}, 0.2, 32).value();
  for (const EngineConfig& c : configs) {
    ldc::WorldEditor ed(w);
    ldc::ChunkedMesh meshes(c.config);
    if (!meshes.build(ed.world()).ok()) std::abort();
    const ldc::ContourMesh m0 = meshes.assemble();
    const ldc::MeshQuality q0 = ldc::mesh_quality(m0);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> xy(2.0, 46.0), radius(0.5, 2.0), dz(-1.5, 1.0);
    for (int i = 0; i < edits; ++i) {
      const double x = xy(rng), y = xy(rng);
      const glm::dvec3 at(x, y, ground_height(ed.world(), x, y) + dz(rng));
      const double r = radius(rng);
      // Spheres, noisy spheres and boxes (sharp edges); every 4th edit builds, the rest dig.
      const ldc::Brush b = i % 3 == 0   ? ldc::Brush::sphere(at, r)
                           : i % 3 == 1 ? ldc::Brush::noisy_sphere(at, {.radius = r})
                                        : ldc::Brush::box(at, glm::dvec3(0.7 * r), uint16_t(1 + i % 3));
      if (!ed.apply(b, i % 4 == 3 ? ldc::EditOp::kUnion : ldc::EditOp::kSubtract).ok()) std::abort();
      if (!meshes.update(ed.world(), ed.take_dirty()).ok()) std::abort();
    }
    const ldc::ContourMesh m1 = meshes.assemble();
    const ldc::MeshQuality q1 = ldc::mesh_quality(m1);
    std::printf("| %s | %zu | %zu | %zu | %s | %zu | %zu | %s | %.2f |\n", c.name, m0.triangles.size(),
                q0.self_intersecting_pairs, q0.nonmanifold_edges + q0.nonmanifold_vertices, q0.closed() ? "yes" : "no",
                m1.triangles.size(), q1.self_intersecting_pairs, q1.closed() ? "yes" : "no",
                dig_median_ms(w, c.config, runs));
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "--validity") == 0) {
    validity_table(false);
    return 0;
  }
  if (argc > 1 && std::strcmp(argv[1], "--dig") == 0) {
    const bool untangle = argc > 3 && std::strcmp(argv[3], "untangle") == 0;
    dig_table(argc > 2 ? std::max(1, std::atoi(argv[2])) : 101, untangle);
    return 0;
  }
  bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::printf("# Brush edits\n\n");
  ldc::bench::print_machine();
  game_table(quick);
  stress_table(quick);
  validity_table(quick);
  return 0;
}
