// Static polygon objects: transformed, built at s / 16, sampled with m = 16.
#include <cmath>
#include <limits>
#include <string>

#include "ldc/build.h"
#include "ldc/internal/vec_text.h"
#include "voxelize/detail/objects.h"

namespace ldc {

Status check_static_object(const StaticObject& object) {
  if (!object.mesh) return {ErrorCode::kInvalidArgument, "static object: no mesh"};
  if (object.mesh->triangles.empty()) return {ErrorCode::kInvalidArgument, "static object: the mesh has no triangles"};
  Status s = check_mesh(*object.mesh, "static object mesh");
  if (!s.ok()) return s;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(object.transform[c][r])) {
        return {ErrorCode::kInvalidArgument, "static object: transform holds a non-finite number"};
      }
    }
  }
  const double det = glm::determinant(glm::dmat3(object.transform));
  if (!(std::abs(det) > 1e-12)) {
    return {ErrorCode::kInvalidArgument, "static object: transform is not invertible (determinant " +
                                             std::to_string(det) + ")"};
  }
  return {};
}

namespace detail {

WorldBox object_bounds(const StaticObject& object) {
  WorldBox b{glm::dvec3(std::numeric_limits<double>::infinity()), glm::dvec3(-std::numeric_limits<double>::infinity())};
  for (const glm::dvec3& p : object.mesh->positions) {
    const glm::dvec3 q = glm::dvec3(object.transform * glm::dvec4(p, 1.0));
    b.min = glm::min(b.min, q);
    b.max = glm::max(b.max, q);
  }
  return b;
}

VoxelBox voxels_of_box(const WorldBox& box, const glm::dvec3& origin, double s) {
  const glm::ivec3 lo(glm::floor((box.min - origin) / s));
  const glm::ivec3 hi(glm::floor((box.max - origin) / s));
  return {lo, hi - lo + 1};
}

Result<ObjectWorld> build_object_world(const StaticObject& object, const glm::dvec3& origin, double voxel_size,
                                       Context* ctx) {
  Status s = check_static_object(object);
  if (!s.ok()) return s;
  TriangleMesh mesh = *object.mesh;
  for (glm::dvec3& p : mesh.positions) p = glm::dvec3(object.transform * glm::dvec4(p, 1.0));
  if (glm::determinant(glm::dmat3(object.transform)) < 0.0) {
    for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);  // mirrored: keep the winding outward
  }
  // The mesh keeps its own ids (and names, which its checks match them
  // against); material_base is added when the voxels read them.
  const bool own_ids = !mesh.triangle_material.empty();
  if (!own_ids) mesh.triangle_material.assign(mesh.triangles.size(), object.material);
  GridConfig grid;
  grid.cell_size = voxel_size / kObjectSupersampling;
  grid.use_origin = true;
  grid.origin = origin;
  Result<World> world = build_from_mesh(mesh, grid, ctx);
  if (!world.ok()) return Status(world.status().code(), "static object: " + world.status().message());
  ObjectWorld out{std::move(world).value(), voxels_of_box(object_bounds(object), origin, voxel_size),
                  own_ids ? int(object.material_base) : 0};
  return out;
}

VoxelSource object_source(const ObjectWorld& object, const MaterialTable& materials, int occ_axis) {
  VoxelSource src;
  src.world = &object.world;
  src.m = kObjectSupersampling;
  src.stride = 1;
  src.occ_axis = occ_axis;
  src.materials = &materials;
  src.material_offset = object.material_offset;
  return src;
}

}  // namespace detail
}  // namespace ldc
