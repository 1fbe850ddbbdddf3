// The procedural landscape (see terrain.h).
//
// value(p) = max(box walls, min(arches, max(ground, -caves))), where
//   ground: z - H(q) scaled to be distance-like. H is a 4-octave gradient-noise
//     height, terraced in places into steps (the cliffs). q is (x, y) pushed
//     sideways by a 3D noise that changes with height, so steep steps lean out
//     into overhangs.
//   caves: horizontal tunnels along the zero lines of a 2D noise, centred a
//     varying depth below a smoothed ground; where they rise close to the
//     surface they break through it (cave mouths).
//   arches: half-tori standing on vertical legs at seeded positions.
//   box walls: the block [0, size_x] x [0, size_y] x [floor_z, inf).
//
// Every random number comes from an integer hash of lattice coordinates and
// the seed, and only +, -, *, /, sqrt and floor touch doubles, so the values
// are the same on every IEEE machine as long as the compiler does not fuse
// multiply-adds (GCC does not in ISO mode, -std=c++20; clang is told below).
#include "ldc/terrain.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#ifdef __clang__
#pragma STDC FP_CONTRACT OFF
#endif

namespace ldc {
namespace {

// ---------------------------------------------------------------------------
// Hashing and noise

// lowbias32 finaliser (Wellons): full avalanche for a few multiplies.
inline uint32_t mix32(uint32_t h) {
  h ^= h >> 16;
  h *= 0x7feb352dU;
  h ^= h >> 15;
  h *= 0x846ca68bU;
  h ^= h >> 16;
  return h;
}

inline uint32_t hash2(uint32_t x, uint32_t y, uint32_t seed) {
  return mix32(seed + x * 0x9E3779B1U + y * 0x85EBCA77U);
}

inline uint32_t hash3(uint32_t x, uint32_t y, uint32_t z, uint32_t seed) {
  return mix32(seed + x * 0x9E3779B1U + y * 0x85EBCA77U + z * 0xC2B2AE3DU);
}

// A uniform double in [0, 1) from the top 24 bits (exact, machine independent).
inline double unit_from_hash(uint32_t h) { return double(h >> 8) * (1.0 / 16777216.0); }

// Lattice cell of x and the offset in it. Out-of-range or NaN coordinates map
// to cell 0 rather than overflowing the integer conversion.
inline uint32_t lattice_cell(double x, double* frac) {
  double f = std::floor(x);
  *frac = x - f;
  if (!(f > -1e15 && f < 1e15)) return 0;
  return uint32_t(int64_t(f));
}

// Quintic fade 6t^5 - 15t^4 + 10t^3 and its derivative: C2 noise.
inline double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }
inline double fade_slope(double t) { return 30.0 * t * t * (t * (t - 2.0) + 1.0); }

// 16 unit gradients, 22.5 degrees apart (literals, not std::cos, for determinism).
constexpr double kC1 = 0.9238795325112867, kS1 = 0.3826834323650898, kR2 = 0.7071067811865476;
constexpr std::array<std::array<double, 2>, 16> kGrad2 = {{
    {1, 0}, {kC1, kS1}, {kR2, kR2}, {kS1, kC1}, {0, 1}, {-kS1, kC1}, {-kR2, kR2}, {-kC1, kS1},
    {-1, 0}, {-kC1, -kS1}, {-kR2, -kR2}, {-kS1, -kC1}, {0, -1}, {kS1, -kC1}, {kR2, -kR2},
    {kC1, -kS1}}};

// Perlin's 12 cube-edge gradients padded to 16.
constexpr std::array<std::array<double, 3>, 16> kGrad3 = {{
    {1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1}, {1, 0, -1},
    {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}, {1, 1, 0}, {-1, 1, 0},
    {0, -1, 1}, {0, -1, -1}}};

struct Noise2 {
  double v = 0.0, dx = 0.0, dy = 0.0;  // value in about [-1, 1] and its gradient
};

// 2D gradient noise with analytic derivatives, scaled by sqrt(2) so that its
// range is about [-1, 1].
Noise2 gradient_noise2(double x, double y, uint32_t seed) {
  double tx, ty;
  const uint32_t ix = lattice_cell(x, &tx), iy = lattice_cell(y, &ty);
  const auto& g00 = kGrad2[hash2(ix, iy, seed) >> 28];
  const auto& g10 = kGrad2[hash2(ix + 1, iy, seed) >> 28];
  const auto& g01 = kGrad2[hash2(ix, iy + 1, seed) >> 28];
  const auto& g11 = kGrad2[hash2(ix + 1, iy + 1, seed) >> 28];
  const double d00 = g00[0] * tx + g00[1] * ty;
  const double d10 = g10[0] * (tx - 1.0) + g10[1] * ty;
  const double d01 = g01[0] * tx + g01[1] * (ty - 1.0);
  const double d11 = g11[0] * (tx - 1.0) + g11[1] * (ty - 1.0);
  const double u = fade(tx), v = fade(ty);
  const double k1 = d10 - d00, k2 = d01 - d00, k3 = d00 - d10 - d01 + d11;
  Noise2 n;
  n.v = d00 + u * k1 + v * k2 + u * v * k3;
  n.dx = g00[0] + u * (g10[0] - g00[0]) + v * (g01[0] - g00[0]) +
         u * v * (g00[0] - g10[0] - g01[0] + g11[0]) + fade_slope(tx) * (k1 + v * k3);
  n.dy = g00[1] + u * (g10[1] - g00[1]) + v * (g01[1] - g00[1]) +
         u * v * (g00[1] - g10[1] - g01[1] + g11[1]) + fade_slope(ty) * (k2 + u * k3);
  constexpr double kScale = 1.4142135623730951;
  n.v *= kScale;
  n.dx *= kScale;
  n.dy *= kScale;
  return n;
}

// Two independent 3D gradient noises (values only, about [-1, 1]) sharing one
// lattice walk: the two gradients come from different bits of one hash.
glm::dvec2 gradient_noise3_pair(double x, double y, double z, uint32_t seed) {
  double t[3];
  const uint32_t ix = lattice_cell(x, &t[0]), iy = lattice_cell(y, &t[1]),
                 iz = lattice_cell(z, &t[2]);
  glm::dvec2 corner[8];
  for (int c = 0; c < 8; ++c) {
    const int cx = c & 1, cy = (c >> 1) & 1, cz = c >> 2;
    const uint32_t h = hash3(ix + uint32_t(cx), iy + uint32_t(cy), iz + uint32_t(cz), seed);
    const double dx = t[0] - cx, dy = t[1] - cy, dz = t[2] - cz;
    const auto& a = kGrad3[h >> 28];
    const auto& b = kGrad3[(h >> 24) & 15u];
    corner[c] = {a[0] * dx + a[1] * dy + a[2] * dz, b[0] * dx + b[1] * dy + b[2] * dz};
  }
  const double u = fade(t[0]), v = fade(t[1]), w = fade(t[2]);
  glm::dvec2 x0[4];
  for (int i = 0; i < 4; ++i) x0[i] = corner[2 * i] + u * (corner[2 * i + 1] - corner[2 * i]);
  const glm::dvec2 y0 = x0[0] + v * (x0[1] - x0[0]);
  const glm::dvec2 y1 = x0[2] + v * (x0[3] - x0[2]);
  return y0 + w * (y1 - y0);
}

// Cubic smoothstep of t on [lo, hi] and its derivative with respect to t.
inline double smoothstep(double lo, double hi, double t, double* slope = nullptr) {
  const double a = std::clamp((t - lo) / (hi - lo), 0.0, 1.0);
  if (slope) *slope = 6.0 * a * (1.0 - a) / (hi - lo);
  return a * a * (3.0 - 2.0 * a);
}

// ---------------------------------------------------------------------------
// Tuning. Lengths in metres. Chosen by eye on renders of the default scene.

constexpr int kHeightOctaves = 4;
constexpr double kHeightFrequency = 1.0 / 16.0;  // largest hills ~16 m across
constexpr double kHeightGain = 2.0;              // fbm value -> [-1, 1] before saturation
constexpr int kTerraceSteps = 2;                 // cliffs at a quarter and three quarters up
constexpr double kTerraceHalfWidth = 0.1;        // cliff width, fraction of a step
constexpr double kTerraceMix = 0.85;             // how flat terraces get where they are on
constexpr double kWarpFrequencyXY = 1.0 / 6.0;
constexpr double kWarpFrequencyZ = 1.0 / 3.0;    // warp turns with height: cliffs lean
constexpr double kCaveMaskFrequency = 1.0 / 14.0;
constexpr double kTunnelFrequency = 1.0 / 11.0;
constexpr double kCaveSquash = 0.8;              // tunnels this much lower than wide
constexpr double kCaveDepthMax = 3.2;            // tunnel centre below the smoothed ground
constexpr double kCaveDepthMin = 0.2;            // ... where the tunnel is widest: mouths
constexpr double kCaveFloorClearance = 0.3;      // rock kept under the lowest tunnel
constexpr double kCaveExactBand = 1.0;           // tunnel noise evaluated within this of it
constexpr double kArchExactBand = 1.0;           // arch evaluated within this of its box
constexpr double kEarlyOutMargin = 0.5;          // skip noise this far from the surfaces
constexpr double kFarOutside = 2.0;              // skip everything this far outside the box
constexpr double kGrassMinNormalZ = 0.75;
constexpr double kSandLevel = 0.2;               // fraction of relief above the lowest ground
constexpr double kWallSoilDepth = 1.0;

enum class Feature : uint8_t { kGround, kCave, kArch, kWall, kFloor };

struct Sample {
  double value = 0.0;
  Feature feature = Feature::kGround;
};

struct Height {
  double height = 0.0;   // terraced ground height at q [m]
  double dx = 0.0, dy = 0.0;
  double smooth = 0.0;   // the same before terracing (caves follow this)
};

struct Arch {
  glm::dvec3 centre{0.0};   // centre of the torus, on the ground line of its feet
  glm::dvec2 dir{1.0, 0.0};  // horizontal direction of the span
  double radius = 3.0;      // half the span [m]
  double thickness = 1.2;   // tube radius at mid height [m]
  WorldBox box;             // holds every point where the arch value <= 0
};

// ---------------------------------------------------------------------------

class TerrainSolid final : public ImplicitSolid {
 public:
  explicit TerrainSolid(const TerrainConfig& config);

  double value(const glm::dvec3& p) const override { return evaluate(p).value; }
  glm::dvec3 normal(const glm::dvec3& p, double step) const override;
  uint16_t material(const glm::dvec3& p) const override;
  WorldBox bounds() const override;
  BoxClass classify(const WorldBox& box) const override;

 private:
  Sample evaluate(const glm::dvec3& p) const;
  Sample wall_distance(const glm::dvec3& p) const;
  Sample ground_and_caves(const glm::dvec3& p) const;
  Height terrain_height(double x, double y) const;
  glm::dvec2 warped(const glm::dvec3& p) const;
  double cave_distance(const glm::dvec2& q, double z, double smooth_height) const;
  double arch_distance(const Arch& arch, const glm::dvec3& p) const;
  bool box_touches_arch(const WorldBox& box) const;
  void place_arches(int count);

  TerrainConfig config_;
  uint32_t seed_height_, seed_warp_, seed_cave_mask_, seed_tunnel_;
  std::array<glm::dvec2, kHeightOctaves> octave_offset_;
  double ground_mid_;   // floor + base: H when the noise is 0
  double height_min_;   // no ground lower than this (caves aside)
  double height_max_;   // no ground higher than this
  // z range caves can carve; empty (+inf, -inf) without caves.
  double cave_air_min_ = std::numeric_limits<double>::infinity();
  double cave_air_max_ = -std::numeric_limits<double>::infinity();
  double sand_level_;
  double top_;          // highest solid point, arches included
  std::vector<Arch> arches_;
};

uint32_t layer_seed(uint32_t seed, uint32_t layer) { return mix32(mix32(seed) + layer * 0x632BE5ABU); }

TerrainSolid::TerrainSolid(const TerrainConfig& config) : config_(config) {
  seed_height_ = layer_seed(config.seed, 1);
  seed_warp_ = layer_seed(config.seed, 2);
  seed_cave_mask_ = layer_seed(config.seed, 3);
  seed_tunnel_ = layer_seed(config.seed, 4);
  for (int o = 0; o < kHeightOctaves; ++o) {
    // Offsets keep the lattice corners of all octaves from lining up at the origin.
    const uint32_t h = layer_seed(seed_height_, uint32_t(o));
    octave_offset_[size_t(o)] = {256.0 * unit_from_hash(h), 256.0 * unit_from_hash(mix32(h))};
  }
  ground_mid_ = config.floor_z + config.base_height;
  height_min_ = ground_mid_ + config.relief * (0.0 - 0.5);
  height_max_ = ground_mid_ + config.relief * (1.0 - 0.5);
  sand_level_ = height_min_ + kSandLevel * config.relief;
  if (config.cave_radius > 0.0) {
    const double clear = config.floor_z + kCaveSquash * config.cave_radius + kCaveFloorClearance;
    const double centre_min = std::max(height_min_ - kCaveDepthMax, clear);
    const double centre_max = std::max(height_max_ - kCaveDepthMin, clear);
    const double eps = 1e-9 * (1.0 + std::abs(centre_max) + std::abs(centre_min));
    cave_air_min_ = centre_min - kCaveSquash * config.cave_radius - eps;
    cave_air_max_ = centre_max + kCaveSquash * config.cave_radius + eps;
  }
  place_arches(config.arches);
  top_ = height_max_;
  for (const Arch& a : arches_) top_ = std::max(top_, a.box.max.z);
}

// --- Ground ------------------------------------------------------------------

// Height of the ground at (x, y): fbm, saturated into [0, 1], then terraced
// where the second octave says so (cliff zones next to rolling ones).
Height TerrainSolid::terrain_height(double x, double y) const {
  double sum = 0.0, sdx = 0.0, sdy = 0.0, amplitude = 1.0, frequency = kHeightFrequency;
  double mask = 0.0, mdx = 0.0, mdy = 0.0;
  // Octave o is rotated by o * atan(0.6 / 0.8) so lattice axes do not line up.
  double c = 1.0, s = 0.0;
  for (int o = 0; o < kHeightOctaves; ++o) {
    const glm::dvec2& off = octave_offset_[size_t(o)];
    const double px = frequency * (c * x - s * y) + off.x;
    const double py = frequency * (s * x + c * y) + off.y;
    const Noise2 n = gradient_noise2(px, py, seed_height_ + uint32_t(o));
    const double gx = frequency * (c * n.dx + s * n.dy), gy = frequency * (-s * n.dx + c * n.dy);
    sum += amplitude * n.v;
    sdx += amplitude * gx;
    sdy += amplitude * gy;
    if (o == 1) mask = n.v, mdx = gx, mdy = gy;
    amplitude *= 0.5;
    frequency *= 2.0;
    const double c2 = 0.8 * c - 0.6 * s;
    s = 0.6 * c + 0.8 * s;
    c = c2;
  }
  constexpr double kNorm = kHeightGain / 1.875;  // 1.875 = sum of the amplitudes
  // sat(x) = 1.5x - 0.5x^3 on [-1, 1]: a C1 saturation keeps H in its bounds.
  const double f = std::clamp(kNorm * sum, -1.0, 1.0);
  const double u = 0.5 + 0.5 * (1.5 * f - 0.5 * f * f * f);
  const double du = 0.5 * 1.5 * (1.0 - f * f) * kNorm;  // d u / d sum

  double mix_slope;
  const double mix = kTerraceMix * smoothstep(-0.2, 0.3, mask, &mix_slope);
  mix_slope *= kTerraceMix;
  const double t = u * kTerraceSteps;
  const double step = std::floor(t);
  double step_slope;
  const double riser = smoothstep(0.5 - kTerraceHalfWidth, 0.5 + kTerraceHalfWidth, t - step,
                                  &step_slope);
  const double terrace = (step + riser) / kTerraceSteps;
  const double shape = std::clamp(u + mix * (terrace - u), 0.0, 1.0);
  const double dshape_du = 1.0 + mix * (step_slope - 1.0);

  Height h;
  h.height = ground_mid_ + config_.relief * (shape - 0.5);
  h.smooth = ground_mid_ + config_.relief * (u - 0.5);
  h.dx = config_.relief * (dshape_du * du * sdx + mix_slope * mdx * (terrace - u));
  h.dy = config_.relief * (dshape_du * du * sdy + mix_slope * mdy * (terrace - u));
  return h;
}

// (x, y) pushed sideways by up to about `overhang` metres, differently at each
// height: where the ground is steep this makes the cliff lean in or out.
glm::dvec2 TerrainSolid::warped(const glm::dvec3& p) const {
  if (config_.overhang <= 0.0) return {p.x, p.y};
  const glm::dvec2 w = gradient_noise3_pair(p.x * kWarpFrequencyXY, p.y * kWarpFrequencyXY,
                                            p.z * kWarpFrequencyZ, seed_warp_);
  return glm::dvec2(p.x, p.y) + config_.overhang * w;
}

// Distance-like value of the tunnels at height z (negative in the air of a
// tunnel). Tunnels follow the zero lines of a 2D noise, centred at a depth
// below the smoothed ground that shrinks where a mask noise is high; the same
// mask tapers the radius to zero, so tunnels end in dead ends.
double TerrainSolid::cave_distance(const glm::dvec2& q, double z, double smooth_height) const {
  constexpr double kNoCave = 1e9;
  const double m = gradient_noise2(q.x * kCaveMaskFrequency, q.y * kCaveMaskFrequency,
                                   seed_cave_mask_).v;
  const double radius = config_.cave_radius * smoothstep(-0.3, 0.1, m);
  if (radius <= 0.0) return kNoCave;
  const double depth =
      kCaveDepthMax - (kCaveDepthMax - kCaveDepthMin) * smoothstep(0.15, 0.75, m);
  const double clear = config_.floor_z + kCaveSquash * config_.cave_radius + kCaveFloorClearance;
  const double centre = std::max(smooth_height - depth, clear);
  const double dz = std::abs(z - centre) / kCaveSquash;
  // Far above or below the tunnel's centre line: a lower bound is enough.
  if (dz >= radius + kCaveExactBand) return dz - radius;
  const Noise2 n = gradient_noise2(q.x * kTunnelFrequency, q.y * kTunnelFrequency, seed_tunnel_);
  // |n| / |grad n| is the first-order distance to the zero line; the floor on
  // the gradient keeps it finite where the noise is flat.
  const double slope = kTunnelFrequency * std::max(std::sqrt(n.dx * n.dx + n.dy * n.dy), 0.5);
  const double lateral = std::abs(n.v) / slope;
  return std::sqrt(lateral * lateral + dz * dz) - radius;
}

// Ground minus caves. The ground value (z - H) / sqrt(1 + |grad H|^2) is the
// first-order distance to a height field: gradient magnitude about 1 near the
// surface (more where the warp makes overhangs, less nowhere).
Sample TerrainSolid::ground_and_caves(const glm::dvec3& p) const {
  const double z = p.z;
  if (z > height_max_ + kEarlyOutMargin) return {z - height_max_, Feature::kGround};
  const bool clear_of_caves = z < cave_air_min_ - kEarlyOutMargin || z > cave_air_max_;
  if (z < height_min_ - kEarlyOutMargin && clear_of_caves) {
    return {z - height_min_, Feature::kGround};
  }

  const glm::dvec2 q = warped(p);
  const Height h = terrain_height(q.x, q.y);
  Sample s{(z - h.height) / std::sqrt(1.0 + h.dx * h.dx + h.dy * h.dy), Feature::kGround};
  if (config_.cave_radius > 0.0 && z > cave_air_min_ - kCaveExactBand &&
      z < cave_air_max_ + kCaveExactBand) {
    const double cave = -cave_distance(q, z, h.smooth);
    if (cave > s.value) s = {cave, Feature::kCave};
  }
  return s;
}

// --- Arches ------------------------------------------------------------------

// A half-torus in the vertical plane through the centre along `dir`, thicker at
// the feet, continued straight down below the centre (legs), so its feet always
// reach the ground.
double TerrainSolid::arch_distance(const Arch& arch, const glm::dvec3& p) const {
  const double dx = p.x - arch.centre.x, dy = p.y - arch.centre.y;
  const double along = dx * arch.dir.x + dy * arch.dir.y;
  const double across = -dx * arch.dir.y + dy * arch.dir.x;
  const double up = std::max(p.z - arch.centre.z, 0.0);
  const double rho = std::sqrt(along * along + up * up);
  const double elevation = rho > 1e-9 ? up / rho : 0.0;  // sine of the angle above the feet
  const double tube = arch.thickness * (1.2 - 0.35 * elevation);
  const double ring = rho - arch.radius;
  return std::sqrt(ring * ring + across * across) - tube;
}

bool boxes_overlap(const WorldBox& a, const WorldBox& b) {
  return a.min.x <= b.max.x && b.min.x <= a.max.x && a.min.y <= b.max.y && b.min.y <= a.max.y &&
         a.min.z <= b.max.z && b.min.z <= a.max.z;
}

bool TerrainSolid::box_touches_arch(const WorldBox& box) const {
  for (const Arch& a : arches_) {
    if (boxes_overlap(a.box, box)) return true;
  }
  return false;
}

// An arch with seeded span, thickness and direction at a seeded position.
Arch random_arch(uint32_t h, const TerrainConfig& config) {
  auto next = [&h] { return unit_from_hash(h = mix32(h)); };
  Arch a;
  a.radius = 3.0 + 1.0 * next();
  a.thickness = 1.0 + 0.4 * next();
  const double dx = 2.0 * next() - 1.0;
  const double dy = 2.0 * next() - 1.0;
  const double len = std::sqrt(dx * dx + dy * dy);
  a.dir = len > 0.1 ? glm::dvec2(dx, dy) / len : glm::dvec2(1.0, 0.0);
  const double reach = a.radius + 1.2 * a.thickness + 0.5;  // stay clear of the walls
  a.centre.x = reach + (config.size_x - 2.0 * reach) * next();
  a.centre.y = reach + (config.size_y - 2.0 * reach) * next();
  return a;
}

// Tries seeded spots for each arch and keeps the first (else the best) with
// clear space under it and no other arch nearby. Arches that find no spot
// (small domains) are left out.
void TerrainSolid::place_arches(int count) {
  constexpr int kAttempts = 32;
  constexpr double kWantedOpening = 1.5, kLeastOpening = 0.5;
  const uint32_t seed = layer_seed(config_.seed, 5);
  for (int i = 0; i < count; ++i) {
    Arch best;
    double best_opening = -1e300;
    for (int attempt = 0; attempt < kAttempts && best_opening < kWantedOpening; ++attempt) {
      Arch a = random_arch(hash2(uint32_t(i), uint32_t(attempt), seed), config_);
      const double reach = a.radius + 1.2 * a.thickness + 0.5;
      if (config_.size_x < 2.0 * reach || config_.size_y < 2.0 * reach) continue;
      bool crowded = false;
      for (const Arch& other : arches_) {
        const glm::dvec2 d = glm::dvec2(a.centre) - glm::dvec2(other.centre);
        crowded |= std::sqrt(d.x * d.x + d.y * d.y) < a.radius + other.radius + 2.0;
      }
      if (crowded) continue;
      const glm::dvec2 c(a.centre), foot = a.radius * a.dir;
      const double ground_a = terrain_height(c.x + foot.x, c.y + foot.y).height;
      const double ground_b = terrain_height(c.x - foot.x, c.y - foot.y).height;
      a.centre.z = std::max(ground_a, ground_b) - 0.3;
      const double underside = a.centre.z + a.radius - 0.85 * a.thickness;
      const double opening = underside - terrain_height(c.x, c.y).height;
      if (opening > best_opening) best = a, best_opening = opening;
    }
    if (best_opening < kLeastOpening) continue;
    // Box of every point with |ring| and |across| <= the thickest tube (1.2 t).
    const double t = 1.2 * best.thickness, reach = best.radius + t, eps = 1e-6;
    const double ex = std::abs(best.dir.x) * reach + std::abs(best.dir.y) * t + eps;
    const double ey = std::abs(best.dir.y) * reach + std::abs(best.dir.x) * t + eps;
    best.box.min = {best.centre.x - ex, best.centre.y - ey, -std::numeric_limits<double>::max()};
    best.box.max = {best.centre.x + ex, best.centre.y + ey, best.centre.z + reach + eps};
    arches_.push_back(best);
  }
}

// --- The solid ---------------------------------------------------------------

// Signed distance to the block [0, sx] x [0, sy] x [floor, inf): max of planes.
Sample TerrainSolid::wall_distance(const glm::dvec3& p) const {
  const double wx = std::max(-p.x, p.x - config_.size_x);
  const double wy = std::max(-p.y, p.y - config_.size_y);
  const double wz = config_.floor_z - p.z;
  if (wz > wx && wz > wy) return {wz, Feature::kFloor};
  return {std::max(wx, wy), Feature::kWall};
}

Sample TerrainSolid::evaluate(const glm::dvec3& p) const {
  const Sample wall = wall_distance(p);
  if (wall.value > kFarOutside || std::isnan(wall.value)) return wall;
  Sample s = ground_and_caves(p);
  for (const Arch& a : arches_) {
    const WorldBox& b = a.box;
    if (p.x < b.min.x - kArchExactBand || p.x > b.max.x + kArchExactBand ||
        p.y < b.min.y - kArchExactBand || p.y > b.max.y + kArchExactBand ||
        p.z > b.max.z + kArchExactBand) {
      continue;
    }
    const double d = arch_distance(a, p);
    if (d < s.value) s = {d, Feature::kArch};
  }
  return wall.value > s.value ? wall : s;
}

glm::dvec3 TerrainSolid::normal(const glm::dvec3& p, double step) const {
  // Small enough to stay on one side of the early-out thresholds.
  const double h = step > 1e-7 ? std::min(step, 0.05) : 1e-3;
  const glm::dvec3 g{value({p.x + h, p.y, p.z}) - value({p.x - h, p.y, p.z}),
                     value({p.x, p.y + h, p.z}) - value({p.x, p.y - h, p.z}),
                     value({p.x, p.y, p.z + h}) - value({p.x, p.y, p.z - h})};
  const double len = std::sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
  if (!(len > 0.0) || !std::isfinite(len)) return {0.0, 0.0, 1.0};
  return g / len;
}

uint16_t TerrainSolid::material(const glm::dvec3& p) const {
  switch (evaluate(p).feature) {
    case Feature::kArch:
    case Feature::kFloor:
      return kMaterialRock;
    case Feature::kCave:
      return kMaterialDirt;
    case Feature::kWall: {
      // The cut through the block: a soil layer over rock.
      const glm::dvec2 q = warped(p);
      return terrain_height(q.x, q.y).height - p.z < kWallSoilDepth ? kMaterialDirt
                                                                    : kMaterialRock;
    }
    case Feature::kGround:
      break;
  }
  if (normal(p, 1e-3).z < kGrassMinNormalZ) return kMaterialRock;
  return p.z < sand_level_ ? kMaterialSand : kMaterialGrass;
}

WorldBox TerrainSolid::bounds() const {
  WorldBox b;
  b.min = {0.0, 0.0, config_.floor_z};
  b.max = {config_.size_x, config_.size_y, top_};
  return b;
}

// Conservative: every answer other than kUnknown holds for every point of the
// box (value > 0 for kOutside, < 0 for kInside), boundaries included.
ImplicitSolid::BoxClass TerrainSolid::classify(const WorldBox& box) const {
  if (box.max.x < 0.0 || box.min.x > config_.size_x || box.max.y < 0.0 ||
      box.min.y > config_.size_y || box.max.z < config_.floor_z) {
    return BoxClass::kOutside;
  }
  const double eps = 1e-9 * (1.0 + std::abs(height_max_) + std::abs(height_min_));
  if (box.min.z > height_max_ + eps && !box_touches_arch(box)) return BoxClass::kOutside;
  const bool in_block = box.min.x > 0.0 && box.max.x < config_.size_x && box.min.y > 0.0 &&
                        box.max.y < config_.size_y && box.min.z > config_.floor_z;
  const bool clear_of_caves = box.max.z < cave_air_min_ || box.min.z > cave_air_max_;
  if (in_block && box.max.z < height_min_ - eps && clear_of_caves) return BoxClass::kInside;
  return BoxClass::kUnknown;
}

// --- Config --------------------------------------------------------------------

// Shortest text that reads back as the same double.
std::string number_text(double x) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), x);
  return std::string(buf, r.ptr);
}

Status bad_field(const char* field, double value, const char* rule) {
  return {ErrorCode::kInvalidArgument,
          std::string("terrain: ") + field + " = " + number_text(value) + " must be " + rule};
}

}  // namespace

const char* terrain_material_name(uint16_t id) {
  switch (id) {
    case kMaterialRock: return "rock";
    case kMaterialGrass: return "grass";
    case kMaterialDirt: return "dirt";
    case kMaterialSand: return "sand";
    default: return "unknown";
  }
}

Status check_terrain(const TerrainConfig& c) {
  struct Rule {
    const char* field;
    double value;
    bool positive;  // > 0, else >= 0 (floor_z: any finite value)
  };
  const Rule rules[] = {{"size_x", c.size_x, true},           {"size_y", c.size_y, true},
                        {"base_height", c.base_height, true}, {"relief", c.relief, false},
                        {"overhang", c.overhang, false},      {"cave_radius", c.cave_radius, false}};
  for (const Rule& r : rules) {
    if (!std::isfinite(r.value)) return bad_field(r.field, r.value, "finite");
    if (r.positive && !(r.value > 0.0)) return bad_field(r.field, r.value, "> 0");
    if (!r.positive && !(r.value >= 0.0)) return bad_field(r.field, r.value, ">= 0");
  }
  if (!std::isfinite(c.floor_z)) return bad_field("floor_z", c.floor_z, "finite");
  if (c.arches < 0 || c.arches > 64) {
    return {ErrorCode::kInvalidArgument,
            "terrain: arches = " + std::to_string(c.arches) + " must be in 0 .. 64"};
  }
  return Status::ok_status();
}

std::unique_ptr<ImplicitSolid> make_terrain_solid(const TerrainConfig& config) {
  return std::make_unique<TerrainSolid>(config);
}

Result<World> build_terrain(const TerrainConfig& config, double cell_size, int chunk_size,
                            Context* ctx, BuildReport* report) {
  if (Status s = check_terrain(config); !s.ok()) return s;
  if (!std::isfinite(cell_size) || !(cell_size > 0.0)) {
    return bad_field("cell_size", cell_size, "> 0 and finite");
  }
  const std::unique_ptr<ImplicitSolid> solid = make_terrain_solid(config);
  GridConfig grid;
  grid.cell_size = cell_size;
  grid.chunk_size = chunk_size;
  grid.padding = 2;
  Result<World> built = build_from_implicit(*solid, grid, ctx, report);
  if (!built.ok()) return built;
  World world = std::move(built).value();
  world.set_metadata("source", "terrain");
  world.set_metadata("terrain.seed", std::to_string(config.seed));
  world.set_metadata("terrain.size_x", number_text(config.size_x));
  world.set_metadata("terrain.size_y", number_text(config.size_y));
  world.set_metadata("terrain.floor_z", number_text(config.floor_z));
  world.set_metadata("terrain.base_height", number_text(config.base_height));
  world.set_metadata("terrain.relief", number_text(config.relief));
  world.set_metadata("terrain.overhang", number_text(config.overhang));
  world.set_metadata("terrain.cave_radius", number_text(config.cave_radius));
  world.set_metadata("terrain.arches", std::to_string(config.arches));
  for (uint16_t id : {kMaterialRock, kMaterialGrass, kMaterialDirt, kMaterialSand}) {
    world.set_metadata("material." + std::to_string(id), terrain_material_name(id));
  }
  return world;
}

}  // namespace ldc
