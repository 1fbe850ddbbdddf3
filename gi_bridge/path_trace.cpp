// Path-traced reference irradiance with Embree 3 (see path_trace.h).
#include "gi_bridge/path_trace.h"

#include <cmath>
#include <numbers>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include "ldc/internal/vec_text.h"

namespace ldc {

struct PathTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<uint16_t> material;  // per triangle
  MaterialTable materials;
  GiLights lights;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

PathTracer::PathTracer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PathTracer::~PathTracer() = default;

Result<std::unique_ptr<PathTracer>> PathTracer::create(const ContourMesh& mesh, const MaterialTable& materials,
                                                       const GiLights& lights) {
  // Each light is one shadow ray per vertex: take as many as either GI mode.
  GiConfig any_lights;
  any_lights.light_volume = true;
  if (Status s = check_gi_lights(lights, any_lights); !s.ok()) return s;
  if (mesh.triangles.empty()) return Status(ErrorCode::kInvalidArgument, "path tracer: the mesh has no triangles");
  auto impl = std::make_unique<Impl>();
  impl->device = rtcNewDevice(nullptr);
  if (!impl->device) return Status(ErrorCode::kIoError, "path tracer: rtcNewDevice failed");
  impl->scene = rtcNewScene(impl->device);
  RTCGeometry geom = rtcNewGeometry(impl->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.positions.size()));
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) v[3 * i + size_t(k)] = float(mesh.positions[i][k]);
  }
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), mesh.triangles.size()));
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) idx[3 * i + size_t(k)] = mesh.triangles[i][k];
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl->scene);
  impl->material = mesh.triangle_material;
  impl->material.resize(mesh.triangles.size(), 0);
  impl->materials = materials;
  impl->lights = lights;
  return std::unique_ptr<PathTracer>(new PathTracer(std::move(impl)));
}

namespace {

RTCRayHit make_ray(const glm::dvec3& o, const glm::vec3& d, float tfar) {
  RTCRayHit rh{};
  rh.ray.org_x = float(o.x);
  rh.ray.org_y = float(o.y);
  rh.ray.org_z = float(o.z);
  rh.ray.dir_x = d.x;
  rh.ray.dir_y = d.y;
  rh.ray.dir_z = d.z;
  rh.ray.tnear = 0.0f;
  rh.ray.tfar = tfar;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// A cosine-weighted direction around n.
glm::vec3 cosine_sample(const glm::vec3& n, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float r1 = u(rng), r2 = u(rng);
  const float phi = 6.2831853f * r1, r = std::sqrt(r2);
  const glm::vec3 t = std::abs(n.x) > 0.5f ? glm::normalize(glm::cross(n, glm::vec3(0, 1, 0)))
                                           : glm::normalize(glm::cross(n, glm::vec3(1, 0, 0)));
  const glm::vec3 b = glm::cross(n, t);
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - r2)) * n);
}

}  // namespace

PathTracer::Hit PathTracer::intersect(const glm::dvec3& origin, const glm::vec3& direction) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh = make_ray(origin, direction, std::numeric_limits<float>::infinity());
  rtcIntersect1(impl_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return {std::numeric_limits<double>::infinity(), glm::vec3(0.0f), 0};
  glm::vec3 n = glm::normalize(glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z));
  if (glm::dot(n, direction) > 0.0f) n = -n;
  return {double(rh.ray.tfar), n, impl_->material[rh.hit.primID]};
}

namespace {

// Irradiance from the point lights at surface point x (normal n): distance
// and cosine from x itself, shadow rays from `origin` (x lifted off the
// surface by the ray offset, which would otherwise bias 1 / r^2).
glm::vec3 point_light_irradiance(const PathTracer::Impl& im, const glm::dvec3& x, const glm::dvec3& origin,
                                 const glm::vec3& n) {
  glm::vec3 e(0.0f);
  for (const PointLight& l : im.lights.points) {
    const glm::dvec3 to = l.position - x;
    const double r = glm::length(to);
    if (r <= 0.0) continue;
    const glm::vec3 w = glm::vec3(to / r);
    const float c = glm::dot(n, w);
    if (c <= 0.0f) continue;
    const glm::dvec3 from_origin = l.position - origin;
    const double r_origin = glm::length(from_origin);
    if (r_origin <= 0.0) continue;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay ray = make_ray(origin, glm::vec3(from_origin / r_origin), float(r_origin)).ray;
    rtcOccluded1(im.scene, &ctx, &ray);
    if (ray.tfar < 0.0f) continue;  // occluded
    e += l.intensity * (c / float(r * r));
  }
  return e;
}

}  // namespace

Status PathTracer::irradiance(std::span<const glm::dvec3> points, std::span<const glm::vec3> normals, int bounces,
                              std::span<glm::vec3> out, const PathTraceConfig& config) const {
  if (normals.size() != points.size() || out.size() != points.size())
    return Status(ErrorCode::kInvalidArgument, "path tracer: points, normals and outputs differ in size (" +
                                                   std::to_string(points.size()) + ", " + std::to_string(normals.size()) +
                                                   ", " + std::to_string(out.size()) + ")");
  if (bounces < 1 || bounces > 16) return Status(ErrorCode::kInvalidArgument, "path tracer: bounces " + std::to_string(bounces) + " must be 1 .. 16");
  if (config.samples < 1 || config.samples > (1 << 20))
    return Status(ErrorCode::kInvalidArgument, "path tracer: samples " + std::to_string(config.samples) + " must be 1 .. 2^20");
  if (!(config.ray_offset >= 0.0 && std::isfinite(config.ray_offset)))
    return Status(ErrorCode::kInvalidArgument,
                  "path tracer: ray_offset " + std::to_string(config.ray_offset) + " must be finite and >= 0");
  for (size_t i = 0; i < points.size(); ++i) {
    if (!detail::is_finite(points[i]))
      return Status(ErrorCode::kInvalidArgument,
                    "path tracer: point " + std::to_string(i) + " " + detail::vec_text(points[i]) + " is not finite");
    const float len = glm::length(normals[i]);
    if (!(len > 0.0f && std::isfinite(len)))
      return Status(ErrorCode::kInvalidArgument, "path tracer: normal " + std::to_string(i) + " is zero or not finite");
  }
  const Impl& im = *impl_;
  tbb::parallel_for(size_t(0), points.size(), [&](size_t q) {
    std::mt19937 rng(config.seed * 2654435761u + uint32_t(q));
    const glm::vec3 n0 = glm::normalize(normals[q]);
    const glm::dvec3 p0 = points[q] + config.ray_offset * glm::dvec3(n0);
    glm::vec3 sum(0.0f);
    for (int s = 0; s < config.samples; ++s) {
      glm::dvec3 p = p0;
      glm::vec3 n = n0, beta(1.0f), l(0.0f);
      for (int k = 0;; ++k) {  // k: reflections so far
        const glm::vec3 w = cosine_sample(n, rng);
        const Hit h = intersect(p, w);
        if (!std::isfinite(h.distance)) {
          l += beta * im.lights.sky.radiance(w);
          break;
        }
        const VoxelMaterial& m = im.materials[h.material];
        if (k <= bounces - 1) l += beta * m.emission;
        if (k + 1 > bounces) break;
        beta *= m.albedo;
        const glm::dvec3 hit = p + h.distance * glm::dvec3(w);
        p = hit + config.ray_offset * glm::dvec3(h.normal);
        n = h.normal;
        l += beta * point_light_irradiance(im, hit, p, n) * (1.0f / std::numbers::pi_v<float>);
        if (beta.x + beta.y + beta.z <= 0.0f) break;
      }
      sum += l;
    }
    out[q] = sum * (std::numbers::pi_v<float> / float(config.samples)) + point_light_irradiance(im, points[q], p0, n0);
  });
  return {};
}

}  // namespace ldc

namespace ldc {

Status PathTracer::radiance_along(std::span<const Ray> rays, int bounces, std::span<glm::vec3> out,
                                  const PathTraceConfig& config, std::span<uint8_t> hit) const {
  if (out.size() != rays.size() || (!hit.empty() && hit.size() != rays.size()))
    return Status(ErrorCode::kInvalidArgument, "path tracer: " + std::to_string(rays.size()) + " rays but " +
                                                   std::to_string(out.size()) + " outputs");
  const Impl& im = *impl_;
  std::vector<glm::dvec3> points;
  std::vector<glm::vec3> normals;
  std::vector<size_t> pixel;
  std::vector<uint16_t> material;
  for (size_t i = 0; i < rays.size(); ++i) {
    const glm::vec3 d = glm::normalize(glm::vec3(rays[i].direction));
    const Hit h = intersect(rays[i].origin, d);
    if (!hit.empty()) hit[i] = std::isfinite(h.distance) ? 1 : 0;
    if (!std::isfinite(h.distance)) {
      out[i] = im.lights.sky.radiance(d);
      continue;
    }
    points.push_back(rays[i].origin + h.distance * glm::dvec3(d));
    normals.push_back(h.normal);
    pixel.push_back(i);
    material.push_back(h.material);
  }
  std::vector<glm::vec3> e(points.size());
  if (Status s = irradiance(points, normals, bounces, e, config); !s.ok()) return s;
  for (size_t k = 0; k < pixel.size(); ++k) {
    const VoxelMaterial& m = im.materials[material[k]];
    out[pixel[k]] = m.albedo * e[k] * (1.0f / std::numbers::pi_v<float>) + m.emission;
  }
  return {};
}

}  // namespace ldc
