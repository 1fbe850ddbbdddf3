// Analytic primitives under an affine transform: signed values, exact segment
// roots (line/convex-shape intervals in local space; an affine map keeps the
// segment parameter) and exact normals (inverse-transpose of the local normal).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "ldc/build.h"
#include "ldc/internal/build_common.h"
#include "ldc/internal/lattice_range.h"

namespace ldc {

const char* primitive_shape_name(Primitive::Shape shape) {
  switch (shape) {
    case Primitive::Shape::kSphere: return "sphere";
    case Primitive::Shape::kBox: return "box";
    case Primitive::Shape::kCapsule: return "capsule";
    case Primitive::Shape::kCylinder: return "cylinder";
  }
  return "?";
}

namespace {

using Interval = std::pair<double, double>;  // empty when first > second
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Interval kNoHit{kInf, -kInf};

// t where |o + t d|^2 = r^2 (in the given two or three components).
Interval quadratic_interval(double a, double b, double c) {
  if (a == 0.0) return c <= 0.0 ? Interval{-kInf, kInf} : kNoHit;
  double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return kNoHit;
  double s = std::sqrt(disc);
  // Numerically stable pair of roots.
  double qq = -0.5 * (b + (b >= 0.0 ? s : -s));
  double t0 = qq / a, t1 = qq != 0.0 ? c / qq : t0;
  return {std::min(t0, t1), std::max(t0, t1)};
}

Interval sphere_interval(const glm::dvec3& o, const glm::dvec3& d, double r) {
  return quadratic_interval(glm::dot(d, d), 2.0 * glm::dot(o, d), glm::dot(o, o) - r * r);
}

Interval slab_interval(double o, double d, double lo, double hi) {
  if (d == 0.0) return (o >= lo && o <= hi) ? Interval{-kInf, kInf} : kNoHit;
  double t0 = (lo - o) / d, t1 = (hi - o) / d;
  return {std::min(t0, t1), std::max(t0, t1)};
}

Interval intersect(Interval a, Interval b) {
  return {std::max(a.first, b.first), std::min(a.second, b.second)};
}

Interval hull(Interval a, Interval b) {
  if (a.first > a.second) return b;
  if (b.first > b.second) return a;
  return {std::min(a.first, b.first), std::max(a.second, b.second)};
}

Interval cylinder_interval(const glm::dvec3& o, const glm::dvec3& d, double r, double hh) {
  Interval side = quadratic_interval(d.x * d.x + d.y * d.y, 2.0 * (o.x * d.x + o.y * d.y),
                                     o.x * o.x + o.y * o.y - r * r);
  return intersect(side, slab_interval(o.z, d.z, -hh, hh));
}

class PrimitiveSolid final : public ImplicitSolid {
 public:
  explicit PrimitiveSolid(const Primitive& p)
      : p_(p), inverse_(glm::inverse(p.transform)),
        normal_matrix_(glm::transpose(glm::inverse(glm::dmat3(p.transform)))) {}

  double value(const glm::dvec3& world) const override { return local_value(to_local(world)); }

  glm::dvec3 normal(const glm::dvec3& world, double) const override {
    glm::dvec3 n = normal_matrix_ * local_normal(to_local(world));
    double len = glm::length(n);
    return len > 0.0 ? n / len : glm::dvec3(0.0);
  }

  uint16_t material(const glm::dvec3&) const override { return p_.material; }

  WorldBox bounds() const override { return detail::transformed_box_bounds(p_.transform, local_half_extent()); }

  // Outside when the box misses the bounds; inside when all eight corners are
  // inside (the shapes are convex, and so are their affine images).
  BoxClass classify(const WorldBox& box) const override {
    if (detail::boxes_disjoint(box, bounds())) return BoxClass::kOutside;
    for (int i = 0; i < 8; ++i) {
      glm::dvec3 c((i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                   (i & 4) ? box.max.z : box.min.z);
      if (!(value(c) < 0.0)) return BoxClass::kUnknown;
    }
    return BoxClass::kInside;
  }

  bool segment_root(const glm::dvec3& a, const glm::dvec3& b, double* t) const override {
    glm::dvec3 o = to_local(a), d = to_local(b) - o;
    Interval iv = local_interval(o, d);
    if (iv.first > iv.second) return false;
    *t = local_value(o) < 0.0 ? iv.second : iv.first;  // leaving or entering the shape
    return *t >= 0.0 && *t <= 1.0;
  }

 private:
  glm::dvec3 to_local(const glm::dvec3& w) const {
    return glm::dvec3(inverse_ * glm::dvec4(w, 1.0));
  }

  glm::dvec3 local_half_extent() const {
    switch (p_.shape) {
      case Primitive::Shape::kSphere: return glm::dvec3(p_.radius);
      case Primitive::Shape::kBox: return p_.half_extents;
      case Primitive::Shape::kCapsule: return {p_.radius, p_.radius, p_.half_height + p_.radius};
      case Primitive::Shape::kCylinder: return {p_.radius, p_.radius, p_.half_height};
    }
    return glm::dvec3(0.0);
  }

  double local_value(const glm::dvec3& q) const {
    switch (p_.shape) {
      case Primitive::Shape::kSphere: return glm::length(q) - p_.radius;
      case Primitive::Shape::kBox: {
        glm::dvec3 d = glm::abs(q) - p_.half_extents;
        return glm::length(glm::max(d, 0.0)) + std::min(std::max(d.x, std::max(d.y, d.z)), 0.0);
      }
      case Primitive::Shape::kCapsule: {
        glm::dvec3 axis_point(0.0, 0.0, std::clamp(q.z, -p_.half_height, p_.half_height));
        return glm::length(q - axis_point) - p_.radius;
      }
      case Primitive::Shape::kCylinder: {
        glm::dvec2 d(std::hypot(q.x, q.y) - p_.radius, std::abs(q.z) - p_.half_height);
        return std::min(std::max(d.x, d.y), 0.0) + glm::length(glm::max(d, 0.0));
      }
    }
    return 1.0;
  }

  glm::dvec3 local_normal(const glm::dvec3& q) const {
    switch (p_.shape) {
      case Primitive::Shape::kSphere: return q;
      case Primitive::Shape::kBox: {
        glm::dvec3 d = glm::abs(q) - p_.half_extents;
        int a = (d.x >= d.y && d.x >= d.z) ? 0 : (d.y >= d.z ? 1 : 2);
        glm::dvec3 n(0.0);
        n[a] = q[a] >= 0.0 ? 1.0 : -1.0;
        return n;
      }
      case Primitive::Shape::kCapsule:
        return q - glm::dvec3(0.0, 0.0, std::clamp(q.z, -p_.half_height, p_.half_height));
      case Primitive::Shape::kCylinder: {
        double side = std::hypot(q.x, q.y) - p_.radius;
        double cap = std::abs(q.z) - p_.half_height;
        if (side >= cap) return {q.x, q.y, 0.0};
        return {0.0, 0.0, q.z >= 0.0 ? 1.0 : -1.0};
      }
    }
    return glm::dvec3(0.0, 0.0, 1.0);
  }

  Interval local_interval(const glm::dvec3& o, const glm::dvec3& d) const {
    switch (p_.shape) {
      case Primitive::Shape::kSphere: return sphere_interval(o, d, p_.radius);
      case Primitive::Shape::kBox: {
        Interval iv{-kInf, kInf};
        for (int a = 0; a < 3; ++a) {
          iv = intersect(iv, slab_interval(o[a], d[a], -p_.half_extents[a], p_.half_extents[a]));
        }
        return iv;
      }
      case Primitive::Shape::kCapsule: {
        glm::dvec3 cap(0.0, 0.0, p_.half_height);
        Interval iv = cylinder_interval(o, d, p_.radius, p_.half_height);
        iv = hull(iv, sphere_interval(o - cap, d, p_.radius));
        return hull(iv, sphere_interval(o + cap, d, p_.radius));
      }
      case Primitive::Shape::kCylinder: return cylinder_interval(o, d, p_.radius, p_.half_height);
    }
    return kNoHit;
  }

  Primitive p_;
  glm::dmat4 inverse_;
  glm::dmat3 normal_matrix_;
};

bool finite_positive(double v) { return v > 0.0 && std::isfinite(v); }

// The primitive's smallest half size in local units (a capsule's segment may be short).
double smallest_local_size(const Primitive& p) {
  switch (p.shape) {
    case Primitive::Shape::kSphere:
    case Primitive::Shape::kCapsule: return p.radius;
    case Primitive::Shape::kCylinder: return std::min(p.radius, p.half_height);
    case Primitive::Shape::kBox: return std::min({p.half_extents.x, p.half_extents.y, p.half_extents.z});
  }
  return p.radius;
}

// Refuses a primitive so small in world units that squares of its sizes
// underflow: its classification then broke (a 1e-170 sphere built every chunk solid).
Status check_world_size(const Primitive& p, const glm::dmat3& m) {
  const double scale = std::min({glm::length(m[0]), glm::length(m[1]), glm::length(m[2])});
  const double size = smallest_local_size(p) * scale;
  if (size >= detail::kMinLatticeCellSize) return {};
  char text[160];
  std::snprintf(text, sizeof(text), "%s: smallest half size %g m (after the transform) is below the limit of %g m",
                primitive_shape_name(p.shape), size, detail::kMinLatticeCellSize);
  return {ErrorCode::kInvalidArgument, text};
}

}  // namespace

Status check_primitive(const Primitive& p) {
  std::string name = primitive_shape_name(p.shape);
  if ((p.shape != Primitive::Shape::kBox) && !finite_positive(p.radius)) {
    return {ErrorCode::kInvalidArgument,
            name + ": radius = " + std::to_string(p.radius) + " must be finite and > 0"};
  }
  if ((p.shape == Primitive::Shape::kCapsule || p.shape == Primitive::Shape::kCylinder) &&
      !finite_positive(p.half_height)) {
    return {ErrorCode::kInvalidArgument,
            name + ": half_height = " + std::to_string(p.half_height) + " must be finite and > 0"};
  }
  if (p.shape == Primitive::Shape::kBox) {
    for (int a = 0; a < 3; ++a) {
      if (!finite_positive(p.half_extents[a])) {
        return {ErrorCode::kInvalidArgument, name + ": half_extents must be finite and > 0"};
      }
    }
  }
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(p.transform[i][j])) {
        return {ErrorCode::kInvalidArgument, name + ": transform is not finite"};
      }
  // Relative to the column lengths, so uniformly tiny or huge scales are fine.
  glm::dmat3 m(p.transform);
  double det = glm::determinant(m);
  double scale = glm::length(m[0]) * glm::length(m[1]) * glm::length(m[2]);
  if (!(std::abs(det) > 1e-12 * scale)) {
    return {ErrorCode::kInvalidArgument, name + ": transform is not invertible (det " +
                                             std::to_string(det) + ")"};
  }
  return check_world_size(p, m);
}

std::unique_ptr<ImplicitSolid> make_primitive_solid(const Primitive& primitive) {
  return std::make_unique<PrimitiveSolid>(primitive);
}

Result<World> build_from_primitive(const Primitive& primitive, const GridConfig& grid,
                                   Context* ctx, BuildReport* report) {
  Status s = check_primitive(primitive);
  if (!s.ok()) return s;
  return detail::build_implicit_as(*make_primitive_solid(primitive), grid, ctx, report,
                                   std::string("primitive ") + primitive_shape_name(primitive.shape));
}

}  // namespace ldc
