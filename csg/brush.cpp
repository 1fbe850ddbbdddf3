// Brushes and their rasterization on a world's lattice and chunk grid.
#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "csg/csg.h"
#include "csg/detail/brush_raster.h"

namespace ldc {
namespace {

Brush primitive_brush(Primitive::Shape shape, const glm::dmat4& transform, uint16_t material) {
  Brush b;
  b.shape = Brush::Shape::kPrimitive;
  b.primitive.shape = shape;
  b.primitive.transform = transform;
  b.primitive.material = material;
  b.material = material;
  return b;
}

// A frame whose z axis runs from a to b, centred between them.
glm::dmat4 segment_frame(const glm::dvec3& a, const glm::dvec3& b) {
  glm::dvec3 z = b - a;
  double len = glm::length(z);
  z = len > 0.0 ? z / len : glm::dvec3(0, 0, 1);
  glm::dvec3 x = glm::normalize(glm::cross(std::abs(z.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0), z));
  glm::dvec3 y = glm::cross(z, x);
  glm::dmat4 m(1.0);
  m[0] = glm::dvec4(x, 0.0);
  m[1] = glm::dvec4(y, 0.0);
  m[2] = glm::dvec4(z, 0.0);
  m[3] = glm::dvec4(0.5 * (a + b), 1.0);
  return m;
}

bool finite_matrix(const glm::dmat4& m) {
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(m[i][j])) return false;
  return true;
}

}  // namespace

Brush Brush::sphere(const glm::dvec3& centre, double radius, uint16_t material) {
  Brush b = primitive_brush(Primitive::Shape::kSphere, glm::translate(glm::dmat4(1.0), centre), material);
  b.primitive.radius = radius;
  return b;
}

Brush Brush::box(const glm::dvec3& centre, const glm::dvec3& half_extents, uint16_t material) {
  Brush b = primitive_brush(Primitive::Shape::kBox, glm::translate(glm::dmat4(1.0), centre), material);
  b.primitive.half_extents = half_extents;
  return b;
}

Brush Brush::capsule(const glm::dvec3& a, const glm::dvec3& c, double radius, uint16_t material) {
  Brush b = primitive_brush(Primitive::Shape::kCapsule, segment_frame(a, c), material);
  b.primitive.radius = radius;
  b.primitive.half_height = std::max(0.5 * glm::length(c - a), 1e-9);
  return b;
}

Brush Brush::cylinder(const glm::dvec3& a, const glm::dvec3& c, double radius, uint16_t material) {
  Brush b = primitive_brush(Primitive::Shape::kCylinder, segment_frame(a, c), material);
  b.primitive.radius = radius;
  b.primitive.half_height = 0.5 * glm::length(c - a);
  return b;
}

Brush Brush::noisy_sphere(const glm::dvec3& centre, const NoiseSphere& noise, uint16_t material) {
  Brush b;
  b.shape = Shape::kNoise;
  b.noise = noise;
  b.transform = glm::translate(glm::dmat4(1.0), centre);
  b.material = material;
  return b;
}

Brush Brush::from_mesh(std::shared_ptr<const TriangleMesh> mesh, const glm::dmat4& transform, uint16_t material) {
  Brush b;
  b.shape = Shape::kMesh;
  b.mesh = std::move(mesh);
  b.transform = transform;
  b.material = material;
  return b;
}

Status check_brush(const Brush& b) {
  switch (b.shape) {
    case Brush::Shape::kPrimitive: return check_primitive(b.primitive);
    case Brush::Shape::kMesh:
      if (!b.mesh) return {ErrorCode::kInvalidArgument, "brush: mesh brush without a mesh"};
      if (!finite_matrix(b.transform) || glm::determinant(glm::dmat3(b.transform)) == 0.0) {
        return {ErrorCode::kInvalidArgument, "brush: mesh transform is not finite and invertible"};
      }
      return check_mesh(*b.mesh, "brush mesh");
    case Brush::Shape::kNoise: {
      const NoiseSphere& n = b.noise;
      if (!(n.radius > 0.0) || !std::isfinite(n.radius)) {
        return {ErrorCode::kInvalidArgument, "brush: noise radius = " + std::to_string(n.radius) + " must be > 0"};
      }
      if (!(n.amplitude >= 0.0 && n.amplitude <= 0.9)) {
        return {ErrorCode::kInvalidArgument, "brush: noise amplitude = " + std::to_string(n.amplitude) + " must be in 0 .. 0.9"};
      }
      if (!(n.frequency > 0.0 && n.frequency <= 64.0)) {
        return {ErrorCode::kInvalidArgument, "brush: noise frequency = " + std::to_string(n.frequency) + " must be in (0, 64]"};
      }
      if (!finite_matrix(b.transform)) return {ErrorCode::kInvalidArgument, "brush: transform is not finite"};
      return {};
    }
  }
  return {ErrorCode::kInvalidArgument, "brush: unknown shape"};
}

Result<World> rasterize_brush(const Brush& brush, const Lattice& lattice, int chunk_size) {
  Status s = check_brush(brush);
  if (!s.ok()) return s;
  switch (brush.shape) {
    case Brush::Shape::kPrimitive: return detail::rasterize_primitive(brush.primitive, lattice, chunk_size);
    case Brush::Shape::kNoise: return detail::rasterize_noise_sphere(brush, lattice, chunk_size);
    case Brush::Shape::kMesh: return detail::rasterize_mesh_brush(brush, lattice, chunk_size);
  }
  return Status(ErrorCode::kInvalidArgument, "brush: unknown shape");
}

}  // namespace ldc
