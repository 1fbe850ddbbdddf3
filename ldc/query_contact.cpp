// Queries: closest points, overlaps and sphere casts.
#include "ldc/query.h"

namespace ldc {

Result<RayHit> Queries::sphere_cast(const Ray&, double) const {
  return Status(ErrorCode::kUnsupported, "sphere_cast: not written yet");
}
Result<Overlap> Queries::overlap(const glm::dvec3&, double) const {
  return Status(ErrorCode::kUnsupported, "overlap: not written yet");
}
Result<Overlap> Queries::overlap(const OrientedBox&) const {
  return Status(ErrorCode::kUnsupported, "overlap: not written yet");
}
Result<Overlap> Queries::overlap(const Capsule&) const {
  return Status(ErrorCode::kUnsupported, "overlap: not written yet");
}
Result<ClosestPoint> Queries::closest_point(const glm::dvec3&, double) const {
  return Status(ErrorCode::kUnsupported, "closest_point: not written yet");
}

}  // namespace ldc
