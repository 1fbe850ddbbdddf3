// The peers of bench_csg: CGAL corefinement booleans (Epick and Epeck kernels)
// and the OpenVDB level-set boolean pipeline. Their heavy headers stay in
// csg_peers.cpp, which is compiled with NDEBUG (as the peers were measured in
// shared/PEERS.md: Release, -DNDEBUG), while the ldc side keeps its asserts.
#pragma once

#include <string>

#include "csg/csg.h"
#include "ldc/mesh.h"

namespace ldc::bench {

enum class CgalKernel { kEpick, kEpeck };
const char* cgal_kernel_name(CgalKernel kernel);

struct CgalBooleanResult {
  bool ok = false;
  // "ok", or why there is no result: the failed preconditions and what the
  // call did anyway ("returned false", "threw: ...").
  std::string status;
  double ms = 0;           // median time of corefine_and_compute_* alone (ok only)
  TriangleMesh mesh;       // the result, coordinates rounded to double
};

// a op b by PMP::corefine_and_compute_union / difference / intersection on
// CGAL::Surface_mesh. Fresh input copies are built before every repetition,
// outside the timer; the timer covers the corefine call only. Single thread
// (CGAL's corefinement is sequential). Preconditions (closed, no
// self-intersection, bounds a volume) are checked first and reported; the
// call is tried anyway, and a false return or an exception is reported, not
// fatal.
CgalBooleanResult cgal_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, CgalKernel kernel,
                               int reps);

// OpenVDB: meshToLevelSet of a and b (half width 3, voxel size h), csgUnion /
// csgDifference / csgIntersection, volumeToMesh (isovalue 0, adaptivity 0),
// polygons re-wound outward. The whole pipeline from the two meshes in memory
// to the output mesh; threads as the caller's tbb::global_control allows.
TriangleMesh vdb_boolean(const TriangleMesh& a, const TriangleMesh& b, BooleanOp op, double h);
void vdb_initialize();

}  // namespace ldc::bench
