// Surface error of a triangle mesh against a reference mesh, by sampling.
//
// The same measure as the independent harness behind shared/PEERS.md
// ("meshdist(A = reference, B = test)"), so that the benchmarks' own figures
// and the peer figures can sit in one table:
//   - both surfaces are sampled area-weighted and uniformly, `samples` points
//     each, from a fixed seed (stratified along the area CDF: the same
//     distribution as independent draws, with less variance);
//   - distances are point-to-surface (AABB tree, exact closest point);
//   - `rel` figures are divided by the bounding-box diagonal of the reference;
//   - the normal error of a test sample is the angle between its test face's
//     normal and the normal of the closest reference face. Where the closest
//     point lies on a reference edge, either adjacent face may be taken, so
//     near sharp edges a few % of samples over 10 degrees are measurement
//     noise, not geometry (PEERS.md notes the same of the harness).
//
// Results are identical for any thread count (per-sample RNG, block sums
// combined in order). CGAL stays inside meshdist.cpp.
#pragma once

#include <cstddef>
#include <cstdint>

#include "ldc/mesh.h"
#include "ldc/status.h"

namespace ldc::bench {

struct MeshDistOptions {
  // Points sampled on each surface [Limit: >= 1] [Units: points].
  size_t samples = 200000;
  // Seed of the sample positions; the same seed gives the same samples.
  uint32_t seed = 1;
  // A reference edge is sharp where the angle between the normals of its two
  // faces exceeds this [Limit: 0..180] [Units: degrees].
  double sharp_angle_deg = 30.0;
  // Test samples within this distance of a sharp reference edge count as
  // "near sharp" (the benches pass 2h). 0 disables the near/away split.
  // [Limit: >= 0, finite] [Units: mesh units, absolute]
  double near_sharp_distance = 0.0;
};

struct MeshDistResult {
  Status status;                 // not ok: bad options or an empty/invalid mesh; figures are 0
  double diagonal = 0;           // bounding-box diagonal of the reference
  // (mean over test samples of the distance to the reference + mean over
  // reference samples of the distance to the test) / 2, over the diagonal.
  double mean_rel = 0;
  // Largest sampled distance over both sides / diagonal: a lower bound of the
  // true Hausdorff distance.
  double hausdorff_rel = 0;
  double normal_mean_deg = 0;    // mean normal error over test samples, in [0, 180]
  double normal_over10 = 0;      // fraction of test samples with normal error > 10 degrees
  size_t sharp_edges = 0;        // reference edges (vertices welded by position) with dihedral > sharp_angle_deg
  // Near/away split; when disabled (distance 0) or without sharp edges:
  // near_* are 0 and away_normal_deg equals normal_mean_deg.
  double near_fraction = 0;      // fraction of test samples near a sharp edge
  double near_normal_deg = 0;    // mean normal error of the near-sharp samples
  double near_over10 = 0;        // fraction of near-sharp samples over 10 degrees
  double away_normal_deg = 0;    // mean normal error of the other samples
  double volume_ratio = 0;       // signed volume test / reference (0 if the reference has none)
};

MeshDistResult mesh_distance(const TriangleMesh& test, const TriangleMesh& reference,
                             const MeshDistOptions& options = {});

}  // namespace ldc::bench
