// The snapped triangle mesh and the rasterizer that turns it into span lists.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/build.h"
#include "ldc/detail/exact.h"
#include "ldc/world.h"

namespace ldc::detail {

using Vec3i = std::array<int64_t, 3>;

// Vertices in fixed-point lattice coordinates, welded; non-degenerate triangles only.
struct SnappedMesh {
  std::vector<Vec3i> vertices;
  // The input positions of the welded vertices in the same fixed-point units,
  // before rounding: depths are computed from these (snapping moves a crossing
  // far along a ray that grazes the surface), decisions from `vertices`.
  std::vector<glm::dvec3> unsnapped;
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<uint16_t> material;
  std::vector<uint32_t> normal_code;   // outward (as wound) normal, octahedral
  std::vector<uint8_t> normal_positive;  // bit a: normal component a > 0
  std::vector<std::array<int64_t, 6>> box;  // min x, y, z, max x, y, z of each triangle

  void resize(size_t n);
  // Sets triangle i; safe to call for different i from several threads.
  void set_triangle(size_t i, const std::array<uint32_t, 3>& t, const std::array<i128, 3>& n,
                    uint16_t mat);
};

// Stage 1 of build_from_mesh: vertices to the lattice's fixed point, welded
// where equal; welded_id maps input vertices to welded ones. Fills
// `vertices` and `unsnapped` of `out`. Positions no triangle uses are
// skipped (welded id 0, never read): a stray far vertex is no error.
Status snap_vertices(const TriangleMesh& mesh, const Lattice& lat, SnappedMesh& out,
                     std::vector<uint32_t>& welded_id);

// Calls fn(a, b, balance, uses) once per undirected edge {a < b} of the
// triangles (vertex ids < `vertices`; repeated ids make no edge): `uses` is
// how many triangle sides lie on it, `balance` those running a -> b minus
// those running b -> a. Edges are bucketed by their smaller vertex (a
// counting sort), so this is linear in the triangle count.
template <class Fn>
void for_each_undirected_edge(const std::vector<std::array<uint32_t, 3>>& tris, size_t vertices, Fn fn) {
  std::vector<uint32_t> first(vertices + 1, 0);
  for (const auto& t : tris)
    for (int e = 0; e < 3; ++e)
      if (t[e] != t[(e + 1) % 3]) ++first[std::min(t[e], t[(e + 1) % 3]) + 1];
  for (size_t v = 0; v < vertices; ++v) first[v + 1] += first[v];
  std::vector<std::pair<uint32_t, int>> other(first[vertices]);  // (larger vertex, +-1)
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (const auto& t : tris) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = t[e], b = t[(e + 1) % 3];
      if (a != b) other[fill[std::min(a, b)]++] = {std::max(a, b), a < b ? 1 : -1};
    }
  }
  for (size_t v = 0; v < vertices; ++v) {
    auto begin = other.begin() + first[v], end = other.begin() + first[v + 1];
    std::sort(begin, end);
    for (auto i = begin; i != end;) {
      auto j = i;
      int balance = 0;
      while (j != end && j->first == i->first) balance += (j++)->second;
      fn(uint32_t(v), i->first, balance, size_t(j - i));
      i = j;
    }
  }
}

// (B - A) x (C - A), exact.
std::array<i128, 3> triangle_normal(const std::vector<Vec3i>& v, const std::array<uint32_t, 3>& t);

// Stages 2-4 of build_from_mesh: fills every chunk of `world` (whose lattice the
// mesh was snapped to). Updates the report's crossing and repair counts.
Status rasterize_mesh_into(const SnappedMesh& mesh, World& world, Context* ctx,
                           BuildReport& report);

}  // namespace ldc::detail
