#include "voxel_peers.h"

#include <chrono>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/LevelSetUtil.h>

#include "vdb_mesh.h"

namespace ldc::bench {
namespace {
double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}
}  // namespace

VdbSolidResult vdb_solid_occupancy(const TriangleMesh& mesh, double s, const glm::dvec3& lo, const glm::ivec3& dims) {
  openvdb::initialize();
  VdbSolidResult r;
  openvdb::math::Transform::Ptr xform = openvdb::math::Transform::createLinearTransform(s);
  xform->postTranslate(openvdb::Vec3d(lo.x + 0.5 * s, lo.y + 0.5 * s, lo.z + 0.5 * s));
  auto t = std::chrono::steady_clock::now();
  openvdb::FloatGrid::Ptr ls = vdb_level_set(mesh, *xform);
  r.level_set_ms = ms_since(t);
  r.level_set_voxels = ls->activeVoxelCount();
  t = std::chrono::steady_clock::now();
  openvdb::BoolGrid::Ptr mask = openvdb::tools::sdfInteriorMask(*ls);
  r.mask_ms = ms_since(t);
  t = std::chrono::steady_clock::now();
  openvdb::tools::Dense<uint8_t, openvdb::tools::LayoutXYZ> dense(
      openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(dims.x - 1, dims.y - 1, dims.z - 1)));
  openvdb::tools::copyToDense(*mask, dense);
  r.dense_ms = ms_since(t);
  const uint8_t* d = dense.data();
  for (size_t i = 0; i < dense.valueCount(); ++i) r.occupied += d[i] != 0;
  return r;
}

}  // namespace ldc::bench
