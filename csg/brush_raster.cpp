// Brush rasterizers. Primitives and noise spheres go through the implicit
// builder (node signs sampled, exact or root-searched crossings), meshes
// through the watertight mesh builder, all on the world's own lattice so the
// result's chunks line up with the world's.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "csg/detail/brush_raster.h"
#include "ldc/internal/build_common.h"

namespace ldc::detail {
namespace {

uint32_t hash3(int x, int y, int z, uint32_t seed) {
  uint32_t h = seed * 0x9E3779B1u;
  h ^= uint32_t(x) * 0x85EBCA6Bu;
  h = (h << 13) | (h >> 19);
  h ^= uint32_t(y) * 0xC2B2AE35u;
  h = (h << 17) | (h >> 15);
  h ^= uint32_t(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x7FEB352Du;
  h ^= h >> 15;
  h *= 0x846CA68Bu;
  return h ^ (h >> 16);
}

// One of the 12 cube-edge directions (Perlin's improved-noise gradients).
double corner_dot(uint32_t h, double x, double y, double z) {
  switch (h % 12) {
    case 0: return x + y;
    case 1: return -x + y;
    case 2: return x - y;
    case 3: return -x - y;
    case 4: return x + z;
    case 5: return -x + z;
    case 6: return x - z;
    case 7: return -x - z;
    case 8: return y + z;
    case 9: return -y + z;
    case 10: return y - z;
    default: return -y - z;
  }
}

double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// 3D gradient noise, about [-1, 1].
double gradient_noise(const glm::dvec3& p, uint32_t seed) {
  glm::dvec3 f = glm::floor(p);
  glm::ivec3 i(f);
  glm::dvec3 t = p - f;
  double corner[8];
  for (int k = 0; k < 8; ++k) {
    glm::ivec3 o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    glm::dvec3 d = t - glm::dvec3(o);
    corner[k] = corner_dot(hash3(i.x + o.x, i.y + o.y, i.z + o.z, seed), d.x, d.y, d.z);
  }
  double u = fade(t.x), v = fade(t.y), w = fade(t.z);
  auto lerp = [](double a, double b, double s) { return a + s * (b - a); };
  double x00 = lerp(corner[0], corner[1], u), x10 = lerp(corner[2], corner[3], u);
  double x01 = lerp(corner[4], corner[5], u), x11 = lerp(corner[6], corner[7], u);
  return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

// Three octaves, normalized to about [-1, 1].
double fractal_noise(const glm::dvec3& p, uint32_t seed) {
  return (gradient_noise(p, seed) + 0.5 * gradient_noise(2.0 * p, seed + 1) +
          0.25 * gradient_noise(4.0 * p, seed + 2)) /
         1.75;
}

// fractal_noise over the unit sphere, tabulated on a cube map: every brush
// with the same frequency and seed shares one table, so a dig evaluates a
// bilinear lookup per sample instead of three octaves of gradient noise (the
// noise dominated the edit, 10 ms of a 2 m dig). Grid vertices on a face's
// border are computed from the same cube point as the neighbour face's, and
// the lookup on a border reads that border only, so the tabulated noise is
// continuous over the sphere and the brush stays a star-shaped solid.
class NoiseTable {
 public:
  NoiseTable(double frequency, uint32_t seed)
      : n_(std::clamp(int(std::ceil(32.0 * frequency)), 32, 256)), values_(6 * size_t(n_ + 1) * size_t(n_ + 1)) {
    for (int face = 0; face < 6; ++face) {
      for (int j = 0; j <= n_; ++j) {
        for (int i = 0; i <= n_; ++i) {
          glm::dvec3 p = cube_point(face, -1.0 + 2.0 * i / n_, -1.0 + 2.0 * j / n_);
          values_[index(face, i, j)] = float(fractal_noise(glm::normalize(p) * frequency, seed));
        }
      }
    }
  }

  // The noise in unit direction d.
  double at(const glm::dvec3& d) const {
    glm::dvec3 m = glm::abs(d);
    int axis = m.x >= m.y && m.x >= m.z ? 0 : (m.y >= m.z ? 1 : 2);
    int face = 2 * axis + (d[axis] < 0.0);
    double x = (d[(axis + 1) % 3] / m[axis] + 1.0) * 0.5 * n_;
    double y = (d[(axis + 2) % 3] / m[axis] + 1.0) * 0.5 * n_;
    int i = std::clamp(int(x), 0, n_ - 1), j = std::clamp(int(y), 0, n_ - 1);
    double u = std::clamp(x - i, 0.0, 1.0), v = std::clamp(y - j, 0.0, 1.0);
    double a = values_[index(face, i, j)], b = values_[index(face, i + 1, j)];
    double c = values_[index(face, i, j + 1)], e = values_[index(face, i + 1, j + 1)];
    return (1.0 - v) * ((1.0 - u) * a + u * b) + v * ((1.0 - u) * c + u * e);
  }

 private:
  // Face 2a (+a) or 2a + 1 (-a); s, t along axes a + 1 and a + 2 (mod 3).
  static glm::dvec3 cube_point(int face, double s, double t) {
    int axis = face / 2;
    glm::dvec3 p;
    p[axis] = face % 2 ? -1.0 : 1.0;
    p[(axis + 1) % 3] = s;
    p[(axis + 2) % 3] = t;
    return p;
  }
  size_t index(int face, int i, int j) const { return (size_t(face) * (n_ + 1) + size_t(j)) * (n_ + 1) + size_t(i); }

  int n_;
  std::vector<float> values_;
};

// Tables by (frequency, seed), built on first use and kept (at most
// kMaxTables; then the cache starts over). Safe from concurrent rasterizers.
std::shared_ptr<const NoiseTable> noise_table(double frequency, uint32_t seed) {
  constexpr size_t kMaxTables = 32;
  static std::mutex mutex;
  static std::map<std::pair<double, uint32_t>, std::shared_ptr<const NoiseTable>> tables;
  const auto key = std::make_pair(frequency, seed);
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = tables.find(key);
    if (it != tables.end()) return it->second;
  }
  auto table = std::make_shared<const NoiseTable>(frequency, seed);  // built outside the lock
  std::lock_guard<std::mutex> lock(mutex);
  if (tables.size() >= kMaxTables) tables.clear();
  return tables.try_emplace(key, table).first->second;
}

// |x| - R (1 + amplitude * noise(direction)) in the brush's local frame: a
// star-shaped solid, so every radial line crosses its surface once.
class NoiseSphereSolid final : public ImplicitSolid {
 public:
  NoiseSphereSolid(const NoiseShape& s, uint16_t material)
      : n_(s.noise),
        table_(noise_table(s.noise.frequency, s.noise.seed)),
        transform_(s.transform),
        inverse_(glm::inverse(s.transform)),
        material_(material) {}

  double value(const glm::dvec3& world) const override {
    glm::dvec3 l(inverse_ * glm::dvec4(world, 1.0));
    double r = glm::length(l);
    if (r == 0.0) return -n_.radius;
    return r - local_radius(l / r);
  }
  uint16_t material(const glm::dvec3&) const override { return material_; }

  WorldBox bounds() const override {
    return transformed_box_bounds(transform_, glm::dvec3(n_.radius * (1.0 + n_.amplitude)));
  }

  // Inside when all corners lie in the inner ball (its affine image is convex).
  BoxClass classify(const WorldBox& box) const override {
    if (boxes_disjoint(box, bounds())) return BoxClass::kOutside;
    const double inner = n_.radius * (1.0 - n_.amplitude);
    for (int i = 0; i < 8; ++i) {
      glm::dvec3 c((i & 1) ? box.max.x : box.min.x, (i & 2) ? box.max.y : box.min.y,
                   (i & 4) ? box.max.z : box.min.z);
      if (!(glm::length(glm::dvec3(inverse_ * glm::dvec4(c, 1.0))) < inner)) return BoxClass::kUnknown;
    }
    return BoxClass::kInside;
  }

 private:
  double local_radius(const glm::dvec3& direction) const {
    return n_.radius * (1.0 + n_.amplitude * table_->at(direction));
  }

  NoiseSphere n_;
  std::shared_ptr<const NoiseTable> table_;
  glm::dmat4 transform_, inverse_;
  uint16_t material_;
};

}  // namespace

GridConfig aligned_grid(const Lattice& lattice, int chunk_size) {
  GridConfig g;
  g.cell_size = lattice.cell_size;
  g.use_origin = true;
  g.origin = lattice.origin;
  g.chunk_size = chunk_size;
  g.padding = 1;
  return g;
}

std::unique_ptr<ImplicitSolid> make_noise_sphere_solid(const NoiseShape& shape, uint16_t material) {
  return std::make_unique<NoiseSphereSolid>(shape, material);
}

Result<World> rasterize_primitive(const Primitive& primitive, const Lattice& lattice, int chunk_size, Context* ctx) {
  return build_from_implicit(*make_primitive_solid(primitive), aligned_grid(lattice, chunk_size), ctx);
}

Result<World> rasterize_noise_sphere(const NoiseShape& shape, uint16_t material, const Lattice& lattice,
                                    int chunk_size, Context* ctx) {
  return build_from_implicit(NoiseSphereSolid(shape, material), aligned_grid(lattice, chunk_size), ctx);
}

Result<World> rasterize_mesh_brush(const MeshShape& shape, uint16_t material, const Lattice& lattice, int chunk_size,
                                  Context* ctx) {
  TriangleMesh placed;
  placed.positions.reserve(shape.mesh->positions.size());
  for (const glm::dvec3& p : shape.mesh->positions) {
    placed.positions.emplace_back(shape.transform * glm::dvec4(p, 1.0));
  }
  placed.triangles = shape.mesh->triangles;
  if (glm::determinant(glm::dmat3(shape.transform)) < 0.0) {  // a mirror turns the faces inside out
    for (glm::uvec3& t : placed.triangles) std::swap(t.y, t.z);
  }
  placed.triangle_material.assign(placed.triangles.size(), material);
  return build_from_mesh(placed, aligned_grid(lattice, chunk_size), ctx);
}

}  // namespace ldc::detail
