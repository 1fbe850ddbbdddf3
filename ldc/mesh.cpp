// TriangleMesh measures, checks and topology.
#include "ldc/mesh.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numeric>

#include "ldc/internal/vec_text.h"

namespace ldc {
namespace {

using detail::is_finite;

bool indices_valid(const TriangleMesh& mesh, const glm::uvec3& triangle) {
  const size_t count = mesh.positions.size();
  return triangle.x < count && triangle.y < count && triangle.z < count;
}

// Welded vertex id per position: positions with equal coordinates share one.
// Sorting bit patterns (with -0.0 folded into +0.0) groups exactly the equal
// positions and is a strict order even if a NaN slipped in.
std::vector<uint32_t> weld_by_position(const std::vector<glm::dvec3>& positions) {
  using Key = std::array<uint64_t, 3>;
  std::vector<Key> keys(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const glm::dvec3 p = positions[i] + glm::dvec3(0.0);
    keys[i] = {std::bit_cast<uint64_t>(p.x), std::bit_cast<uint64_t>(p.y),
               std::bit_cast<uint64_t>(p.z)};
  }
  std::vector<uint32_t> order(positions.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
  std::vector<uint32_t> welded(positions.size());
  uint32_t id = 0;
  for (size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && keys[order[k]] != keys[order[k - 1]]) ++id;
    welded[order[k]] = id;
  }
  return welded;
}

// One use of an undirected edge: key = (min << 32) | max, direction +1 when
// the triangle walks min -> max.
struct EdgeUse {
  uint64_t key;
  int32_t direction;
};

void count_edges(std::vector<EdgeUse>& uses, MeshTopology& topology) {
  std::sort(uses.begin(), uses.end(),
            [](const EdgeUse& a, const EdgeUse& b) { return a.key < b.key; });
  for (size_t begin = 0; begin < uses.size();) {
    size_t end = begin;
    int64_t balance = 0;
    for (; end < uses.size() && uses[end].key == uses[begin].key; ++end)
      balance += uses[end].direction;
    const size_t count = end - begin;
    if (count == 1) ++topology.boundary_edges;
    if (count > 2) ++topology.nonmanifold_edges;
    if (balance != 0) ++topology.unbalanced_edges;
    begin = end;
  }
}

}  // namespace

double MeshBounds::diagonal() const { return glm::length(extent()); }

MeshBounds mesh_bounds(const TriangleMesh& mesh) {
  MeshBounds bounds;
  bool first = true;
  auto include = [&](const glm::dvec3& p) {
    bounds.min = first ? p : glm::min(bounds.min, p);
    bounds.max = first ? p : glm::max(bounds.max, p);
    first = false;
  };
  for (const glm::uvec3& triangle : mesh.triangles) {
    if (!indices_valid(mesh, triangle)) continue;
    for (int corner = 0; corner < 3; ++corner) include(mesh.positions[triangle[corner]]);
  }
  if (first) {  // no usable triangle: fall back to every position
    for (const glm::dvec3& p : mesh.positions) include(p);
  }
  return bounds;
}

double mesh_signed_volume(const TriangleMesh& mesh) {
  if (mesh.positions.empty()) return 0.0;
  // Tetrahedra against a point on the mesh rather than the origin: far from
  // the origin the per-triangle terms would be huge and cancel badly.
  const glm::dvec3 origin = mesh.positions.front();
  double six_volume = 0.0;
  for (const glm::uvec3& triangle : mesh.triangles) {
    if (!indices_valid(mesh, triangle)) continue;
    const glm::dvec3 a = mesh.positions[triangle.x] - origin;
    const glm::dvec3 b = mesh.positions[triangle.y] - origin;
    const glm::dvec3 c = mesh.positions[triangle.z] - origin;
    six_volume += glm::dot(a, glm::cross(b, c));
  }
  return six_volume / 6.0;
}

Status check_mesh(const TriangleMesh& mesh, std::string_view name) {
  const std::string prefix = std::string(name) + ": ";
  if (!mesh.triangle_material.empty() && mesh.triangle_material.size() != mesh.triangles.size()) {
    return {ErrorCode::kInvalidArgument,
            prefix + "triangle_material has " + std::to_string(mesh.triangle_material.size()) +
                " entries for " + std::to_string(mesh.triangles.size()) + " triangles"};
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int corner = 0; corner < 3; ++corner) {
      const uint32_t index = mesh.triangles[t][corner];
      if (index >= mesh.positions.size()) {
        return {ErrorCode::kInvalidArgument,
                prefix + "triangle " + std::to_string(t) + " vertex index " +
                    std::to_string(index) + " out of range (" +
                    std::to_string(mesh.positions.size()) + " positions)"};
      }
      if (!is_finite(mesh.positions[index])) {
        return {ErrorCode::kInvalidArgument, prefix + "vertex " + std::to_string(index) +
                                                 " (used by triangle " + std::to_string(t) +
                                                 ") has a non-finite coordinate"};
      }
    }
    if (!mesh.material_names.empty() && mesh.material_of(t) >= mesh.material_names.size()) {
      return {ErrorCode::kInvalidArgument,
              prefix + "triangle " + std::to_string(t) + " has material id " +
                  std::to_string(mesh.material_of(t)) + " but there are only " +
                  std::to_string(mesh.material_names.size()) + " material names"};
    }
  }
  return {};
}

MeshTopology mesh_topology(const TriangleMesh& mesh) {
  MeshTopology topology;
  const std::vector<uint32_t> welded = weld_by_position(mesh.positions);
  std::vector<EdgeUse> uses;
  uses.reserve(mesh.triangles.size() * 3);
  for (const glm::uvec3& triangle : mesh.triangles) {
    if (!indices_valid(mesh, triangle)) continue;
    const std::array<uint32_t, 3> v = {welded[triangle.x], welded[triangle.y], welded[triangle.z]};
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
      // Collapsed to a segment: its edges would cancel each other, and
      // counting them would make a clean neighbour edge look non-manifold.
      ++topology.degenerate_triangles;
      continue;
    }
    const glm::dvec3& a = mesh.positions[triangle.x];
    if (glm::cross(mesh.positions[triangle.y] - a, mesh.positions[triangle.z] - a) ==
        glm::dvec3(0.0)) {
      ++topology.degenerate_triangles;  // zero area but three corners: its edges still close the
                                        // surface
    }
    for (int k = 0; k < 3; ++k) {
      const uint32_t from = v[k];
      const uint32_t to = v[(k + 1) % 3];
      const uint64_t low = std::min(from, to);
      const uint64_t high = std::max(from, to);
      uses.push_back({(low << 32) | high, from < to ? 1 : -1});
    }
  }
  count_edges(uses, topology);
  return topology;
}

}  // namespace ldc
