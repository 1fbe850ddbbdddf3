// Brushes and their rasterization on a world's lattice and chunk grid.
#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "csg/csg.h"
#include "csg/detail/brush_raster.h"

namespace ldc {
namespace {

Primitive placed_primitive(Primitive::Shape shape, const glm::dmat4& transform) {
  Primitive p;
  p.shape = shape;
  p.transform = transform;
  return p;
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

glm::dmat4& Brush::transform() {
  return std::visit([](auto& s) -> glm::dmat4& { return s.transform; }, shape);
}

const glm::dmat4& Brush::transform() const {
  return std::visit([](const auto& s) -> const glm::dmat4& { return s.transform; }, shape);
}

Brush Brush::sphere(const glm::dvec3& centre, double radius, uint16_t material) {
  Primitive p = placed_primitive(Primitive::Shape::kSphere, glm::translate(glm::dmat4(1.0), centre));
  p.radius = radius;
  return {p, material};
}

Brush Brush::box(const glm::dvec3& centre, const glm::dvec3& half_extents, uint16_t material) {
  Primitive p = placed_primitive(Primitive::Shape::kBox, glm::translate(glm::dmat4(1.0), centre));
  p.half_extents = half_extents;
  return {p, material};
}

Brush Brush::capsule(const glm::dvec3& a, const glm::dvec3& c, double radius, uint16_t material) {
  Primitive p = placed_primitive(Primitive::Shape::kCapsule, segment_frame(a, c));
  p.radius = radius;
  p.half_height = std::max(0.5 * glm::length(c - a), 1e-9);
  return {p, material};
}

Brush Brush::cylinder(const glm::dvec3& a, const glm::dvec3& c, double radius, uint16_t material) {
  Primitive p = placed_primitive(Primitive::Shape::kCylinder, segment_frame(a, c));
  p.radius = radius;
  p.half_height = 0.5 * glm::length(c - a);
  return {p, material};
}

Brush Brush::noisy_sphere(const glm::dvec3& centre, const NoiseSphere& noise, uint16_t material) {
  return {NoiseShape{noise, glm::translate(glm::dmat4(1.0), centre)}, material};
}

Brush Brush::from_mesh(std::shared_ptr<const TriangleMesh> mesh, const glm::dmat4& transform, uint16_t material) {
  return {MeshShape{std::move(mesh), transform}, material};
}

namespace {

Status check_shape(const Primitive& p) { return check_primitive(p); }

Status check_shape(const MeshShape& m) {
  if (!m.mesh) return {ErrorCode::kInvalidArgument, "brush: mesh brush without a mesh"};
  if (!finite_matrix(m.transform) || glm::determinant(glm::dmat3(m.transform)) == 0.0) {
    return {ErrorCode::kInvalidArgument, "brush: mesh transform is not finite and invertible"};
  }
  return check_mesh(*m.mesh, "brush mesh");
}

Status check_shape(const NoiseShape& s) {
  const NoiseSphere& n = s.noise;
  if (!(n.radius > 0.0) || !std::isfinite(n.radius)) {
    return {ErrorCode::kInvalidArgument, "brush: noise radius = " + std::to_string(n.radius) + " must be > 0"};
  }
  if (!(n.amplitude >= 0.0 && n.amplitude <= 0.9)) {
    return {ErrorCode::kInvalidArgument, "brush: noise amplitude = " + std::to_string(n.amplitude) + " must be in 0 .. 0.9"};
  }
  if (!(n.frequency > 0.0 && n.frequency <= 64.0)) {
    return {ErrorCode::kInvalidArgument, "brush: noise frequency = " + std::to_string(n.frequency) + " must be in (0, 64]"};
  }
  if (!finite_matrix(s.transform)) return {ErrorCode::kInvalidArgument, "brush: transform is not finite"};
  return {};
}

}  // namespace

Status check_brush(const Brush& b) {
  return std::visit([](const auto& shape) { return check_shape(shape); }, b.shape);
}

namespace {

// The builders' own stages as the one stage "rasterize": an implicit build's
// "sample", a mesh build's "rasterize" (first half) and "emit" (second half).
// Their timers stay here; the caller's cancel reaches the build at its next report.
class BrushProgress {
 public:
  explicit BrushProgress(Context* outer) : outer_(outer) {
    inner_.set_progress([this](std::string_view stage, double fraction) {
      if (outer_->cancelled()) inner_.cancel();
      const double f = stage == "sample" ? fraction : stage == "rasterize" ? 0.5 * fraction
                       : stage == "emit" ? 0.5 + 0.5 * fraction : -1.0;
      if (f >= 0.0) outer_->report_progress("rasterize", f);
    });
  }
  Context* context() { return outer_ ? &inner_ : nullptr; }

 private:
  Context* outer_;
  Context inner_;
};

}  // namespace

Result<World> rasterize_brush(const Brush& brush, const Lattice& lattice, int chunk_size, Context* ctx) {
  Status s = check_brush(brush);
  if (!s.ok()) return s;
  BrushProgress progress(ctx);
  if (const Primitive* p = std::get_if<Primitive>(&brush.shape)) {
    Primitive with_material = *p;
    with_material.material = brush.material;
    return detail::rasterize_primitive(with_material, lattice, chunk_size, progress.context());
  }
  if (const NoiseShape* n = std::get_if<NoiseShape>(&brush.shape)) {
    return detail::rasterize_noise_sphere(*n, brush.material, lattice, chunk_size, progress.context());
  }
  return detail::rasterize_mesh_brush(std::get<MeshShape>(brush.shape), brush.material, lattice, chunk_size,
                                      progress.context());
}

}  // namespace ldc
