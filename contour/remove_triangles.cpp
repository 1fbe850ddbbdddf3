#include "contour/detail/remove_triangles.h"

namespace ldc::detail {

void remove_triangles(ContourMesh& mesh, const std::vector<uint8_t>& gone) {
  const bool per_triangle_material = mesh.triangle_material.size() == mesh.triangle_count();
  std::vector<uint8_t> used(mesh.vertex_count(), 0);
  size_t kept = 0;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (gone[t]) continue;
    for (int k = 0; k < 3; ++k) used[mesh.triangles[t][k]] = 1;
    mesh.triangles[kept] = mesh.triangles[t];
    if (per_triangle_material) mesh.triangle_material[kept] = mesh.triangle_material[t];
    ++kept;
  }
  mesh.triangles.resize(kept);
  if (per_triangle_material) mesh.triangle_material.resize(kept);
  const bool normals = mesh.normals.size() == mesh.vertex_count();
  const bool materials = mesh.vertex_material.size() == mesh.vertex_count();
  std::vector<uint32_t> remap(mesh.vertex_count());
  uint32_t next = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    remap[v] = next;
    if (!used[v]) continue;
    mesh.positions[next] = mesh.positions[v];
    if (normals) mesh.normals[next] = mesh.normals[v];
    if (materials) mesh.vertex_material[next] = mesh.vertex_material[v];
    ++next;
  }
  mesh.positions.resize(next);
  if (normals) mesh.normals.resize(next);
  if (materials) mesh.vertex_material.resize(next);
  for (glm::uvec3& t : mesh.triangles) t = glm::uvec3(remap[t.x], remap[t.y], remap[t.z]);
}

}  // namespace ldc::detail
