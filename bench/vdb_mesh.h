// The OpenVDB peer's mesh <-> level-set conversions, shared by bench_contour
// and bench_csg so that both measure the same pipeline: meshToLevelSet (half
// width 3 voxels) and volumeToMesh (isovalue 0, adaptivity 0 unless given:
// bench_contour's adaptive table sweeps it).
#pragma once

#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include "ldc/mesh.h"

namespace ldc::bench {

inline openvdb::FloatGrid::Ptr vdb_level_set(const TriangleMesh& m, const openvdb::math::Transform& xform) {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> tris;
  points.reserve(m.positions.size());
  tris.reserve(m.triangles.size());
  for (const auto& p : m.positions) points.emplace_back(float(p.x), float(p.y), float(p.z));
  for (const auto& t : m.triangles) tris.emplace_back(t[0], t[1], t[2]);
  std::vector<openvdb::Vec4I> no_quads;
  return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(xform, points, tris, no_quads, 3.0f);
}

inline TriangleMesh vdb_to_mesh(const openvdb::FloatGrid& grid, double adaptivity = 0.0) {
  std::vector<openvdb::Vec3s> out_points;
  std::vector<openvdb::Vec3I> out_tris;
  std::vector<openvdb::Vec4I> out_quads;
  openvdb::tools::volumeToMesh(grid, out_points, out_tris, out_quads, 0.0, adaptivity);
  TriangleMesh out;
  out.positions.reserve(out_points.size());
  out.triangles.reserve(out_tris.size() + 2 * out_quads.size());
  for (const auto& p : out_points) out.positions.push_back({p.x(), p.y(), p.z()});
  // volumeToMesh winds polygons inward: reverse them.
  for (const auto& t : out_tris) out.triangles.push_back({t.z(), t.y(), t.x()});
  for (const auto& q : out_quads) {
    out.triangles.push_back({q.w(), q.z(), q.y()});
    out.triangles.push_back({q.w(), q.y(), q.x()});
  }
  return out;
}

}  // namespace ldc::bench
