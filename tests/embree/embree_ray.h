// One Embree 3 ray query, set up the same way by the agreement test and by
// bench/bench_query.cpp: origin, direction, tnear 0, tfar infinite.
#pragma once

#include <limits>

#include <embree3/rtcore.h>
#include <glm/glm.hpp>

namespace ldc::test {

inline RTCRayHit embree_ray(const glm::dvec3& origin, const glm::dvec3& direction) {
  RTCRayHit rh;
  rh.ray.org_x = float(origin.x);
  rh.ray.org_y = float(origin.y);
  rh.ray.org_z = float(origin.z);
  rh.ray.dir_x = float(direction.x);
  rh.ray.dir_y = float(direction.y);
  rh.ray.dir_z = float(direction.z);
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = std::numeric_limits<float>::infinity();
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

}  // namespace ldc::test
