// The path-traced reference for gi_bridge: Monte Carlo irradiance at points
// with normals on the contoured mesh (Embree 3), with the same materials
// (albedo, emission by triangle material), sky (SkyLight::radiance) and
// point lights as the cone tracer. Lambertian surfaces, cosine-weighted
// sampling, point lights by next-event estimation with a shadow ray (from
// the point lifted by ray_offset; distance and cosine from the point).
// tests/gi/test_path_trace.cpp checks it on scenes with exact answers.
//
// Bounces are counted as in GiEngine::irradiance: with `bounces` = b, sky
// and point light reach the point after at most b reflections, emission
// after at most b - 1 (the cone tracer's D holds emission and once-reflected
// light).
//
// Target ldc::gi_reference (built when Embree 3 is found); Embree's headers
// stay in path_trace.cpp.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include <glm/glm.hpp>

#include "contour/contour.h"
#include "gi_bridge/gi.h"
#include "ldc/query.h"

namespace ldc {

struct PathTraceConfig {
  int samples = 256;       // cosine-weighted paths per point [Limit: 1 .. 1<<20]
  uint32_t seed = 1;       // the same seed gives the same result for any thread count
  double ray_offset = 1e-3;  // start of secondary rays off the surface [Units: m] [Limit: >= 0]
};

class PathTracer {
 public:
  // Builds the Embree scene of the mesh (copied). Fails naming the reason.
  static Result<std::unique_ptr<PathTracer>> create(const ContourMesh& mesh, const MaterialTable& materials,
                                                    const GiLights& lights);
  ~PathTracer();

  Status irradiance(std::span<const glm::dvec3> points, std::span<const glm::vec3> normals, int bounces,
                    std::span<glm::vec3> out, const PathTraceConfig& config = {}) const;

  // The first hit along a ray (for images): distance (infinity on a miss),
  // unit normal facing the ray's origin and material.
  struct Hit {
    double distance;
    glm::vec3 normal;
    uint16_t material;
  };
  Hit intersect(const glm::dvec3& origin, const glm::vec3& direction) const;

  // What a camera sees along each ray (one per pixel, say): the sky's
  // radiance where it misses; albedo / pi * irradiance + emission of the
  // first surface it hits, the irradiance path-traced as irradiance() does.
  // `hit` (optional) receives 1 where the ray hit a surface, 0 where not.
  Status radiance_along(std::span<const Ray> rays, int bounces, std::span<glm::vec3> out,
                        const PathTraceConfig& config = {}, std::span<uint8_t> hit = {}) const;

  struct Impl;

 private:
  explicit PathTracer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace ldc
