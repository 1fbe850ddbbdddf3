// The surface reading of build_from_mesh: components, and prisms for sheets.
#include "ldc/detail/mesh_shells.h"

#include <algorithm>
#include <numeric>

#include "ldc/detail/mesh_raster.h"

namespace ldc::detail {
namespace {

// Union-find over welded vertices, with path halving.
struct DisjointSets {
  std::vector<uint32_t> parent;
  explicit DisjointSets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  uint32_t find(uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  }
  void join(uint32_t a, uint32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

std::array<uint32_t, 3> welded_triangle(const TriangleMesh& mesh, size_t t,
                                        const std::vector<uint32_t>& welded_id) {
  const glm::uvec3& tri = mesh.triangles[t];
  return {welded_id[tri[0]], welded_id[tri[1]], welded_id[tri[2]]};
}

bool degenerate(const TriangleMesh& mesh, size_t t, const std::array<uint32_t, 3>& w) {
  if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) return true;
  const glm::uvec3& tri = mesh.triangles[t];
  const glm::dvec3 n = glm::cross(mesh.positions[tri[1]] - mesh.positions[tri[0]],
                                  mesh.positions[tri[2]] - mesh.positions[tri[0]]);
  return glm::dot(n, n) == 0.0;
}

// Marks components with an unbalanced edge open and counts edges used once.
void find_open_edges(const TriangleMesh& mesh, const std::vector<uint32_t>& welded_id, size_t welded_count,
                     DisjointSets& sets, const std::vector<uint32_t>& component_of_root, MeshComponents& out) {
  std::vector<std::array<uint32_t, 3>> tris;
  tris.reserve(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (out.of_triangle[t] != MeshComponents::kNone) tris.push_back(welded_triangle(mesh, t, welded_id));
  }
  for_each_undirected_edge(tris, welded_count, [&](uint32_t a, uint32_t, int balance, size_t uses) {
    out.boundary_edges += uses == 1;
    if (balance != 0) out.closed[component_of_root[sets.find(a)]] = 0;
  });
}

}  // namespace

MeshComponents mesh_components(const TriangleMesh& mesh, const std::vector<uint32_t>& welded_id,
                               size_t welded_count) {
  MeshComponents out;
  const size_t n = mesh.triangles.size();
  out.of_triangle.assign(n, MeshComponents::kNone);
  DisjointSets sets(welded_count);
  std::vector<uint8_t> usable(n, 0);
  for (size_t t = 0; t < n; ++t) {
    const auto w = welded_triangle(mesh, t, welded_id);
    if (degenerate(mesh, t, w)) continue;
    usable[t] = 1;
    sets.join(w[0], w[1]);
    sets.join(w[1], w[2]);
  }
  std::vector<uint32_t> component_of_root(welded_count, MeshComponents::kNone);
  const MeshBounds bounds = mesh_bounds(mesh);
  const glm::dvec3 centre = 0.5 * (bounds.min + bounds.max);  // volumes about it: less cancellation
  for (size_t t = 0; t < n; ++t) {
    if (!usable[t]) continue;
    const uint32_t root = sets.find(welded_id[mesh.triangles[t][0]]);
    if (component_of_root[root] == MeshComponents::kNone) {
      component_of_root[root] = uint32_t(out.closed.size());
      out.closed.push_back(1);
      out.volume.push_back(0.0);
      out.area.push_back(0.0);
    }
    const uint32_t c = component_of_root[root];
    out.of_triangle[t] = c;
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::dvec3 a = mesh.positions[tri[0]] - centre, b = mesh.positions[tri[1]] - centre,
                     d = mesh.positions[tri[2]] - centre;
    out.volume[c] += glm::dot(a, glm::cross(b, d)) / 6.0;
    out.area[c] += 0.5 * glm::length(glm::cross(b - a, d - a));
  }
  find_open_edges(mesh, welded_id, welded_count, sets, component_of_root, out);
  return out;
}

bool reads_as_solid(const MeshComponents& components, size_t c, BuildMode mode, double thickness) {
  switch (mode) {
    case BuildMode::kSolid: return true;
    case BuildMode::kSurface: return false;
    case BuildMode::kAuto:
      return components.closed[c] && components.volume[c] > 0.25 * components.area[c] * thickness;
  }
  return true;
}

namespace {

// Appends the closed prism under triangle t: its top face is the triangle
// (turned to face up when it faces down), its bottom the triangle moved
// `thickness` down (or behind a wall), and three quads join them.
void append_prism(const TriangleMesh& mesh, size_t t, double thickness, int up_axis,
                  TriangleMesh& out) {
  glm::uvec3 top = mesh.triangles[t];
  const glm::dvec3 n = glm::normalize(glm::cross(mesh.positions[top[1]] - mesh.positions[top[0]],
                                                 mesh.positions[top[2]] - mesh.positions[top[0]]));
  glm::dvec3 down = -n;
  if (n[up_axis] < 0.0) {  // wound facing down: the top is the other side
    std::swap(top[1], top[2]);
    down = n;
  }
  const uint32_t base = uint32_t(out.positions.size());
  for (int k = 0; k < 3; ++k) out.positions.push_back(mesh.positions[top[k]] + thickness * down);
  const glm::uvec3 bottom(base, base + 1, base + 2);
  out.triangles.push_back(top);
  out.triangles.emplace_back(bottom[0], bottom[2], bottom[1]);
  for (int e = 0; e < 3; ++e) {
    const int f = (e + 1) % 3;
    out.triangles.emplace_back(top[e], bottom[e], bottom[f]);
    out.triangles.emplace_back(top[e], bottom[f], top[f]);
  }
  if (!mesh.triangle_material.empty()) {
    out.triangle_material.insert(out.triangle_material.end(), 8, mesh.material_of(t));
  }
}

}  // namespace

TriangleMesh shelled_mesh(const TriangleMesh& mesh, const MeshComponents& components,
                          BuildMode mode, double thickness, int up_axis, BuildReport& report) {
  TriangleMesh out;
  out.positions = mesh.positions;
  out.material_names = mesh.material_names;
  std::vector<uint8_t> solid(components.count());
  for (size_t c = 0; c < components.count(); ++c) {
    solid[c] = reads_as_solid(components, c, mode, thickness);
    ++(solid[c] ? report.solid_components : report.surface_components);
  }
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const uint32_t c = components.of_triangle[t];
    if (c == MeshComponents::kNone) continue;  // degenerate: the build skips it too
    if (solid[c]) {
      out.triangles.push_back(mesh.triangles[t]);
      if (!mesh.triangle_material.empty()) out.triangle_material.push_back(mesh.material_of(t));
    } else {
      append_prism(mesh, t, thickness, up_axis, out);
      ++report.shell_triangles;
    }
  }
  return out;
}

}  // namespace ldc::detail
