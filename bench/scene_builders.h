// Scenes the GI benchmark and its tests share (header-only: bench_gi and
// ldc_gi_reference_tests include it).
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "csg/csg.h"
#include "ldc/build.h"
#include "ldc/mesh.h"
#include "ldc/terrain.h"

namespace ldc::bench {

// Appends an axis-aligned box of material `mat` (12 triangles, outward).
inline void add_box(TriangleMesh& m, glm::dvec3 lo, glm::dvec3 hi, uint16_t mat) {
  const uint32_t b = uint32_t(m.positions.size());
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  const uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) {
    m.triangles.emplace_back(b + f[0], b + f[1], b + f[2]);
    m.triangles.emplace_back(b + f[0], b + f[2], b + f[3]);
    m.triangle_material.insert(m.triangle_material.end(), {mat, mat});
  }
}

// The mesh built onto a lattice of cell size h with its origin at 0 (box
// faces on multiples of h stay on lattice planes); exits naming the error.
inline World build_on_origin(const TriangleMesh& m, double h) {
  GridConfig g;
  g.cell_size = h;
  g.use_origin = true;
  Result<World> w = build_from_mesh(m, g);
  if (!w.ok()) {
    std::fprintf(stderr, "build: %s\n", w.status().message().c_str());
    std::exit(1);
  }
  return std::move(w).value();
}

// scripts/default-tunnel.json's edits, as the main job applies them to the
// default landscape: a tunnel 3 m wide under 3 to 8 m of ground, a chamber
// with a pillar, a sand floor.
inline std::vector<std::pair<Brush, EditOp>> main_job_tunnel_edits() {
  NoiseSphere chamber;
  chamber.radius = 2.8;
  chamber.amplitude = 0.35;
  chamber.frequency = 1.5;
  chamber.seed = 3;
  return {{Brush::capsule({-1, 9, 3.2}, {12, 10, 3.6}, 1.5), EditOp::kSubtract},
          {Brush::capsule({12, 10, 3.6}, {24, 9, 3.8}, 1.5), EditOp::kSubtract},
          {Brush::noisy_sphere({24, 9, 4.2}, chamber), EditOp::kSubtract},
          {Brush::capsule({24, 9, 3.8}, {36, 11, 3.6}, 1.5), EditOp::kSubtract},
          {Brush::capsule({36, 11, 3.6}, {49, 10, 3.0}, 1.5), EditOp::kSubtract},
          {Brush::cylinder({24, 9, 1}, {24, 9, 7.5}, 0.45, 2), EditOp::kUnion},
          {Brush::capsule({-1, 9.5, 2.0}, {49, 10, 2.0}, 1.4, 3), EditOp::kPaint}};
}

// The default landscape (h = 0.2 m) with those edits; fails on any error.
inline Result<World> main_job_tunnel() {
  Result<World> w = build_terrain(TerrainConfig{}, 0.2);
  if (!w.ok()) return w.status();
  WorldEditor ed(std::move(w).value());
  for (const auto& [brush, op] : main_job_tunnel_edits()) {
    Result<EditReceipt> r = ed.apply(brush, op);
    if (!r.ok()) return r.status();
  }
  return ed.world();
}

}  // namespace ldc::bench
