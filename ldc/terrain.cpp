// The procedural landscape (see terrain.h).
//
// value(p) = max(box walls, min(arches, max(ground, -caves))), where
//   ground: z - H(q) scaled to be distance-like. H is a 3-octave gradient-noise
//     height, terraced in places into steps (the cliffs). q is (x, y) pushed
//     sideways by a noise that changes with height, so steep steps lean out
//     into overhangs.
//   caves: level tunnels along the zero lines of a 2D noise, some deep, some
//     high enough to run out of the hills into the valleys (cave mouths).
//   arches: lumpy half-tori standing on vertical legs at seeded positions.
//   box walls: the block [0, size_x] x [0, size_y] x [floor_z, inf).
//
// Cost: a value() inside the ground band is 4-5 noise samples (about 95 ns on
// a 2.6 GHz EPYC VM); far above or below the ground, 0-2 samples.
//
// Every random number comes from an integer hash of lattice coordinates and
// the seed, and only +, -, *, /, sqrt and comparisons touch doubles, so the
// values are the same on every IEEE machine as long as the compiler does not
// fuse a * b + c into one FMA (one rounding instead of two). GCC does so for
// C++ even with -std=c++20 wherever the target has FMA (aarch64, -march=
// haswell), and clang within expressions, so both are told not to here,
// before any include so that inlined header code agrees.
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#include "ldc/terrain.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

// The noise samples are inlined into their callers so the out-of-order core
// can overlap independent octaves (value() about 8% faster than with calls).
#if defined(__GNUC__)
#define LDC_TERRAIN_INLINE inline __attribute__((always_inline))
#else
#define LDC_TERRAIN_INLINE inline
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

// A uniform double in [0, 1) from the top 24 bits (exact, machine independent).
inline double unit_from_hash(uint32_t h) { return double(h >> 8) * (1.0 / 16777216.0); }

// floor(x) for |x| < 2^50 by cast and compare: exact, and much cheaper than
// std::floor on baseline x86-64 (no SSE4.1 round instruction).
inline int64_t floor_to_int(double x) {
  const int64_t i = int64_t(x);
  return x < double(i) ? i - 1 : i;
}

// Lattice cell of x and the offset in it. Coordinates are first clamped to
// +-2^50 (NaN to 2^50) so the integer conversion cannot overflow.
inline uint32_t lattice_cell(double x, double* frac) {
  constexpr double kLimit = 1125899906842624.0;  // 2^50
  x = std::max(-kLimit, std::min(kLimit, x));
  const int64_t i = floor_to_int(x);
  *frac = x - double(i);
  return uint32_t(i);
}

// Quintic fade 6t^5 - 15t^4 + 10t^3 and its derivative: C2 noise.
inline double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }
inline double fade_slope(double t) { return 30.0 * t * t * (t * (t - 2.0) + 1.0); }

// 16 gradients of length sqrt(2), 22.5 degrees apart, written as literals (not
// std::cos) for determinism. The length scales the noise range to about [-1, 1].
constexpr double kC1 = 0.9238795325112867, kS1 = 0.3826834323650898, kR2 = 0.7071067811865476;
constexpr double kSqrt2 = 1.4142135623730951;
constexpr std::array<std::array<double, 2>, 16> kGrad2 = [] {
  const std::array<std::array<double, 2>, 16> unit = {{
      {1, 0}, {kC1, kS1}, {kR2, kR2}, {kS1, kC1}, {0, 1}, {-kS1, kC1}, {-kR2, kR2},
      {-kC1, kS1}, {-1, 0}, {-kC1, -kS1}, {-kR2, -kR2}, {-kS1, -kC1}, {0, -1}, {kS1, -kC1},
      {kR2, -kR2}, {kC1, -kS1}}};
  std::array<std::array<double, 2>, 16> g{};
  for (size_t i = 0; i < 16; ++i) g[i] = {kSqrt2 * unit[i][0], kSqrt2 * unit[i][1]};
  return g;
}();

struct Noise2 {
  double v = 0.0, dx = 0.0, dy = 0.0;  // value in about [-1, 1] and its gradient
};

// 2D gradient noise (Perlin's, quintic fade) with analytic derivatives. Corner
// gradients come from a seeded permutation table: two byte loads per corner
// instead of a full integer hash, the bulk of the cost of a sample. The
// pattern repeats every 256 cells.
class NoiseLayer {
 public:
  explicit NoiseLayer(uint32_t seed) {
    for (int i = 0; i < 256; ++i) perm_[size_t(i)] = uint8_t(i);
    for (uint32_t i = 255; i > 0; --i) {  // Fisher-Yates with the integer hash
      std::swap(perm_[i], perm_[hash2(i, 0, seed) % (i + 1)]);
    }
    for (size_t i = 0; i < 256; ++i) perm_[256 + i] = perm_[i];
  }

  // The first noise with its gradient.
  LDC_TERRAIN_INLINE Noise2 sample(double x, double y) const { return blend(locate(x, y)); }
  // The value alone.
  LDC_TERRAIN_INLINE double value(double x, double y) const { return blend_value(locate(x, y)); }

 private:
  struct Cell {
    std::array<uint32_t, 4> h;  // corner bytes: (0,0), (1,0), (0,1), (1,1)
    double tx, ty;              // position in the cell
  };

  LDC_TERRAIN_INLINE Cell locate(double x, double y) const {
    Cell c;
    const uint32_t ix = lattice_cell(x, &c.tx) & 255u, iy = lattice_cell(y, &c.ty) & 255u;
    const uint32_t row0 = perm_[ix], row1 = perm_[ix + 1];
    c.h = {perm_[row0 + iy], perm_[row1 + iy], perm_[row0 + iy + 1], perm_[row1 + iy + 1]};
    return c;
  }

  // The corner gradients of a cell and their dot products with the offsets
  // from the corners: what both blends start from.
  struct Corners {
    const std::array<double, 2>&g00, &g10, &g01, &g11;
    double d00, d10, d01, d11;
  };
  LDC_TERRAIN_INLINE static Corners corners(const Cell& c) {
    const auto& g00 = kGrad2[c.h[0] & 15u];
    const auto& g10 = kGrad2[c.h[1] & 15u];
    const auto& g01 = kGrad2[c.h[2] & 15u];
    const auto& g11 = kGrad2[c.h[3] & 15u];
    const double tx = c.tx, ty = c.ty;
    return {g00, g10, g01, g11,
            g00[0] * tx + g00[1] * ty, g10[0] * (tx - 1.0) + g10[1] * ty,
            g01[0] * tx + g01[1] * (ty - 1.0), g11[0] * (tx - 1.0) + g11[1] * (ty - 1.0)};
  }

  LDC_TERRAIN_INLINE static double blend_value(const Cell& c) {
    const auto [g00, g10, g01, g11, d00, d10, d01, d11] = corners(c);
    const double u = fade(c.tx), v = fade(c.ty);
    const double a = d00 + u * (d10 - d00), b = d01 + u * (d11 - d01);
    return a + v * (b - a);
  }

  LDC_TERRAIN_INLINE static Noise2 blend(const Cell& c) {
    const auto [g00, g10, g01, g11, d00, d10, d01, d11] = corners(c);
    const double tx = c.tx, ty = c.ty;
    const double u = fade(tx), v = fade(ty);
    const double k1 = d10 - d00, k2 = d01 - d00, k3 = d00 - d10 - d01 + d11;
    Noise2 n;
    n.v = d00 + u * k1 + v * k2 + u * v * k3;
    n.dx = g00[0] + u * (g10[0] - g00[0]) + v * (g01[0] - g00[0]) +
           u * v * (g00[0] - g10[0] - g01[0] + g11[0]) + fade_slope(tx) * (k1 + v * k3);
    n.dy = g00[1] + u * (g10[1] - g00[1]) + v * (g01[1] - g00[1]) +
           u * v * (g00[1] - g10[1] - g01[1] + g11[1]) + fade_slope(ty) * (k2 + u * k3);
    return n;
  }

  std::array<uint8_t, 512> perm_;
};

// Cubic smoothstep of t on [lo, hi] and its derivative with respect to t.
inline double smoothstep(double lo, double hi, double t, double* slope = nullptr) {
  const double inv = 1.0 / (hi - lo);  // folded: callers pass constants
  const double a = std::clamp((t - lo) * inv, 0.0, 1.0);
  if (slope) *slope = 6.0 * a * (1.0 - a) * inv;
  return a * a * (3.0 - 2.0 * a);
}

// ---------------------------------------------------------------------------
// Tuning. Lengths in metres. Chosen by eye on renders of the default scene.

constexpr size_t kHeightOctaves = 3;
constexpr double kHeightFrequency = 1.0 / 16.0;  // largest hills ~16 m across
constexpr double kHeightGain = 2.0;              // fbm value -> [-1, 1] before saturation
constexpr int kTerraceSteps = 2;                 // cliffs at a quarter and three quarters up
constexpr double kTerraceHalfWidth = 0.1;        // cliff width, fraction of a step
constexpr double kTerraceMix = 0.85;             // how flat terraces get where they are on
constexpr double kWarpFrequencyXY = 1.0 / 6.0;
constexpr glm::dvec2 kWarpSlide{0.8 / 3.0, 0.6 / 3.0};  // pattern shift per metre up
constexpr double kWarpGain = 0.5;                // noise gradient -> about [-1, 1]
constexpr double kCaveMaskFrequency = 1.0 / 14.0;
constexpr double kTunnelFrequency = 1.0 / 11.0;
constexpr double kCaveSquash = 0.8;              // tunnels this much lower than wide
constexpr double kCaveDeepLevel = -1.5;         // deep tunnels: below the lowest ground by this
constexpr double kCaveHighLevel = 0.3;           // high tunnels: this fraction of relief up,
                                                 // so they run out of hills into valleys
constexpr double kCaveFloorClearance = 0.3;      // rock kept under the lowest tunnel
constexpr double kCaveExactBand = 0.4;           // tunnel noise evaluated within this of it
constexpr double kArchExactBand = 1.0;           // arch evaluated within this of its box
constexpr double kEarlyOutMargin = 0.5;          // skip noise this far from the surfaces
constexpr double kFarOutside = 2.0;              // skip everything this far outside the box
constexpr double kGrassMinNormalZ = 0.75;
constexpr double kSandLevel = 0.2;               // fraction of relief above the lowest ground
constexpr double kWallSoilDepth = 1.0;

// Largest tube radius over thickness: 1.2 at the feet + lumps of at most 0.15.
constexpr double kArchTubeMax = 1.35;

enum class Feature : uint8_t { kGround, kCave, kArch, kWall, kFloor };

struct Sample {
  double value = 0.0;
  Feature feature = Feature::kGround;
};

struct Height {
  double height = 0.0;   // terraced ground height at q [m]
  double dx = 0.0, dy = 0.0;
};

struct Arch {
  glm::dvec3 centre{0.0};   // centre of the torus, on the ground line of its feet
  glm::dvec2 dir{1.0, 0.0};  // horizontal direction of the span
  double radius = 3.0;      // half the span [m]
  double thickness = 1.2;   // tube radius at mid height [m]
  uint32_t seed = 0;        // for the bumps along the arch
  WorldBox box;             // holds every point where the arch value <= 0
};

// 1D gradient noise in [-0.5, 0.5] (slopes from the hash, quintic blend).
double gradient_noise1(double x, uint32_t seed) {
  double t;
  const uint32_t i = lattice_cell(x, &t);
  const double g0 = 2.0 * unit_from_hash(hash2(i, 0, seed)) - 1.0;
  const double g1 = 2.0 * unit_from_hash(hash2(i + 1, 0, seed)) - 1.0;
  const double a = g0 * t, b = g1 * (t - 1.0);
  return a + fade(t) * (b - a);
}

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
  double cave_distance(const glm::dvec3& p) const;
  double arch_distance(const Arch& arch, const glm::dvec3& p) const;
  bool box_touches_arch(const WorldBox& box) const;
  void place_arches(int count);

  TerrainConfig config_;
  std::vector<NoiseLayer> height_noise_;  // one layer per octave
  NoiseLayer warp_noise_, cave_mask_noise_, tunnel_noise_;
  // Lattice coordinates of octave o: (xx x + xy y, yx x + yy y) + offset.
  struct Octave {
    double xx, xy, yx, yy;
    glm::dvec2 offset;
    double amplitude;
  };
  std::array<Octave, kHeightOctaves> octaves_;
  double ground_mid_;   // floor + base: H when the noise is 0
  double height_min_;   // no ground lower than this (caves aside)
  double height_max_;   // no ground higher than this
  // z range caves can carve; empty (+inf, -inf) without caves.
  double cave_air_min_ = std::numeric_limits<double>::infinity();
  double cave_air_max_ = -std::numeric_limits<double>::infinity();
  double cave_deep_ = 0.0, cave_high_ = 0.0;  // lowest and highest tunnel centre
  double sand_level_;
  double top_;          // highest solid point, arches included
  std::vector<Arch> arches_;
};

uint32_t layer_seed(uint32_t seed, uint32_t layer) { return mix32(mix32(seed) + layer * 0x632BE5ABU); }

TerrainSolid::TerrainSolid(const TerrainConfig& config)
    : config_(config),
      warp_noise_(layer_seed(config.seed, 2)),
      cave_mask_noise_(layer_seed(config.seed, 3)),
      tunnel_noise_(layer_seed(config.seed, 4)) {
  // Octave o: frequency and rotation doubling and turning by atan(0.6 / 0.8)
  // each time, so lattice axes do not line up; offsets keep the lattice
  // corners (where gradient noise is 0) of all octaves apart.
  double c = 1.0, s = 0.0, frequency = kHeightFrequency, amplitude = 1.0;
  for (size_t o = 0; o < kHeightOctaves; ++o) {
    const uint32_t h = layer_seed(config.seed, 16 + uint32_t(o));
    height_noise_.emplace_back(h);
    octaves_[o] = {frequency * c, -frequency * s, frequency * s, frequency * c,
                   {256.0 * unit_from_hash(h), 256.0 * unit_from_hash(mix32(h))}, amplitude};
    const double c2 = 0.8 * c - 0.6 * s;
    s = 0.6 * c + 0.8 * s;
    c = c2;
    frequency *= 2.0;
    amplitude *= 0.5;
  }
  ground_mid_ = config.floor_z + config.base_height;
  height_min_ = ground_mid_ + config.relief * (0.0 - 0.5);
  height_max_ = ground_mid_ + config.relief * (1.0 - 0.5);
  sand_level_ = height_min_ + kSandLevel * config.relief;
  if (config.cave_radius > 0.0) {
    const double lowest = config.floor_z + kCaveSquash * config.cave_radius + kCaveFloorClearance;
    cave_deep_ = std::max(height_min_ + kCaveDeepLevel, lowest);
    cave_high_ = std::max(height_min_ + kCaveHighLevel * config.relief, lowest);
    const double eps = 1e-9 * (1.0 + std::abs(cave_deep_) + std::abs(cave_high_));
    cave_air_min_ = cave_deep_ - kCaveSquash * config.cave_radius - eps;
    cave_air_max_ = cave_high_ + kCaveSquash * config.cave_radius + eps;
  }
  place_arches(config.arches);
  top_ = height_max_;
  for (const Arch& a : arches_) top_ = std::max(top_, a.box.max.z);
}

// --- Ground ------------------------------------------------------------------

// Height of the ground at (x, y): fbm, saturated into [0, 1], then terraced
// where the second octave says so (cliff zones next to rolling ones).
Height TerrainSolid::terrain_height(double x, double y) const {
  double sum = 0.0, sdx = 0.0, sdy = 0.0;
  double mask = 0.0, mdx = 0.0, mdy = 0.0;
  for (size_t o = 0; o < kHeightOctaves; ++o) {
    const Octave& k = octaves_[o];
    const Noise2 n = height_noise_[o].sample(k.xx * x + k.xy * y + k.offset.x,
                                             k.yx * x + k.yy * y + k.offset.y);
    const double gx = k.xx * n.dx + k.yx * n.dy, gy = k.xy * n.dx + k.yy * n.dy;
    sum += k.amplitude * n.v;
    sdx += k.amplitude * gx;
    sdy += k.amplitude * gy;
    if (o == 1) mask = n.v, mdx = gx, mdy = gy;
  }
  constexpr double kAmplitudes = 2.0 - 2.0 / (1 << (kHeightOctaves - 1));  // 1 + 1/2 + ...
  constexpr double kNorm = kHeightGain / kAmplitudes;
  // sat(x) = 1.5x - 0.5x^3 on [-1, 1]: a C1 saturation keeps H in its bounds.
  const double f = std::clamp(kNorm * sum, -1.0, 1.0);
  const double u = 0.5 + 0.5 * (1.5 * f - 0.5 * f * f * f);
  const double du = 0.5 * 1.5 * (1.0 - f * f) * kNorm;  // d u / d sum

  double mix_slope;
  const double mix = kTerraceMix * smoothstep(-0.2, 0.3, mask, &mix_slope);
  mix_slope *= kTerraceMix;
  const double t = u * kTerraceSteps;
  const double step = double(floor_to_int(t));  // u is in [0, 1]
  double step_slope;
  const double riser = smoothstep(0.5 - kTerraceHalfWidth, 0.5 + kTerraceHalfWidth, t - step,
                                  &step_slope);
  const double terrace = (step + riser) / kTerraceSteps;
  const double shape = std::clamp(u + mix * (terrace - u), 0.0, 1.0);
  const double dshape_du = 1.0 + mix * (step_slope - 1.0);

  Height h;
  h.height = ground_mid_ + config_.relief * (shape - 0.5);
  h.dx = config_.relief * (dshape_du * du * sdx + mix_slope * mdx * (terrace - u));
  h.dy = config_.relief * (dshape_du * du * sdy + mix_slope * mdy * (terrace - u));
  return h;
}

// (x, y) pushed sideways by up to about `overhang` metres along the gradient
// of a 2D noise whose pattern slides sideways as z grows, so the push turns
// with height: where the ground is steep the cliff leans in or out. (A slid 2D
// noise costs a quarter of a 3D one and looks the same here.)
glm::dvec2 TerrainSolid::warped(const glm::dvec3& p) const {
  if (config_.overhang <= 0.0) return {p.x, p.y};
  const Noise2 n = warp_noise_.sample(p.x * kWarpFrequencyXY + p.z * kWarpSlide.x,
                                      p.y * kWarpFrequencyXY + p.z * kWarpSlide.y);
  return {p.x + config_.overhang * kWarpGain * n.dx, p.y + config_.overhang * kWarpGain * n.dy};
}

// Distance-like value of the tunnels (negative in their air). Tunnels follow
// the zero lines of a 2D noise, level, at a height between cave_deep_ and
// cave_high_ set by a second (mask) noise; the mask also tapers the radius to
// zero, so tunnels end in dead ends, and the level ramps between the two.
// High tunnels run out of the hills into the valleys: the cave mouths.
// Independent of the ground, so below it no height noise is needed.
double TerrainSolid::cave_distance(const glm::dvec3& p) const {
  constexpr double kNoCave = 1e9;
  const double m = cave_mask_noise_.value(p.x * kCaveMaskFrequency, p.y * kCaveMaskFrequency);
  const double radius = config_.cave_radius * smoothstep(-0.3, 0.1, m);
  if (radius <= 0.0) return kNoCave;
  const double centre = cave_deep_ + (cave_high_ - cave_deep_) * smoothstep(0.2, 0.6, m);
  const double dz = std::abs(p.z - centre) * (1.0 / kCaveSquash);
  // Well above or below this tunnel: the vertical distance is a lower bound.
  if (dz > radius + kCaveExactBand) return dz - radius;
  const Noise2 n = tunnel_noise_.sample(p.x * kTunnelFrequency, p.y * kTunnelFrequency);
  // |n| / |grad n| is the first-order distance to the zero line; the floor on
  // the gradient keeps it finite where the noise is flat.
  const double slope = kTunnelFrequency * std::max(std::sqrt(n.dx * n.dx + n.dy * n.dy), 0.5);
  const double lateral = std::abs(n.v) / slope;
  return std::sqrt(lateral * lateral + dz * dz) - radius;
}

// Ground minus caves. The ground value (z - H) / sqrt(1 + |grad H|^2) is the
// first-order distance to a height field: gradient magnitude about 1 near the
// surface (more where the warp makes overhangs). Far above or below the
// ground's range a bound stands in for it (sign right, no noise).
Sample TerrainSolid::ground_and_caves(const glm::dvec3& p) const {
  const double z = p.z;
  Sample s;
  if (z > height_max_ + kEarlyOutMargin) {
    s = {z - height_max_, Feature::kGround};
  } else if (z < height_min_ - kEarlyOutMargin) {
    s = {z - height_min_, Feature::kGround};
  } else {
    const glm::dvec2 q = warped(p);
    const Height h = terrain_height(q.x, q.y);
    s = {(z - h.height) / std::sqrt(1.0 + h.dx * h.dx + h.dy * h.dy), Feature::kGround};
  }
  if (z > cave_air_min_ - kCaveExactBand && z < cave_air_max_ + kCaveExactBand) {
    const double cave = -cave_distance(p);
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
  const double side = rho > 1e-9 ? along / rho : 1.0;     // -1 .. 1 from foot to foot
  // Thicker at the feet, with lumps along the arch so it reads as rock.
  const double lumps = 0.3 * gradient_noise1(3.0 * side, arch.seed);
  const double tube = arch.thickness * (1.2 - 0.35 * elevation + lumps);
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
  const double reach = a.radius + kArchTubeMax * a.thickness + 0.5;  // clear of the walls
  a.centre.x = reach + (config.size_x - 2.0 * reach) * next();
  a.centre.y = reach + (config.size_y - 2.0 * reach) * next();
  a.seed = h;
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
      const double reach = a.radius + kArchTubeMax * a.thickness + 0.5;
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
      const double underside = a.centre.z + a.radius - a.thickness;  // thinnest tube + lumps
      const double opening = underside - terrain_height(c.x, c.y).height;
      if (opening > best_opening) best = a, best_opening = opening;
    }
    if (best_opening < kLeastOpening) continue;
    // Box of every point with |ring| and |across| <= the thickest tube.
    const double t = kArchTubeMax * best.thickness, reach = best.radius + t, eps = 1e-6;
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

// The gradient from four samples at the corners of a tetrahedron (as accurate
// as central differences, which need six): builds call this once per point.
glm::dvec3 TerrainSolid::normal(const glm::dvec3& p, double step) const {
  // Small enough to stay on one side of the early-out thresholds.
  const double h = step > 1e-7 ? std::min(step, 0.05) : 1e-3;
  const double a = value({p.x + h, p.y - h, p.z - h});
  const double b = value({p.x - h, p.y - h, p.z + h});
  const double c = value({p.x - h, p.y + h, p.z - h});
  const double d = value({p.x + h, p.y + h, p.z + h});
  const glm::dvec3 g{a - b - c + d, -a - b + c + d, -a + b - c + d};
  const double len = std::sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
  if (!(len > 0.0) || !std::isfinite(len)) return {0.0, 0.0, 1.0};
  return g / len;
}

uint16_t TerrainSolid::material(const glm::dvec3& p) const {
  const Feature feature = evaluate(p).feature;
  switch (feature) {
    case Feature::kArch:
    case Feature::kFloor:
      return kMaterialRock;
    case Feature::kCave:
      return kMaterialDirt;
    case Feature::kWall:
    case Feature::kGround:
      break;
  }
  const glm::dvec2 q = warped(p);
  const Height h = terrain_height(q.x, q.y);
  if (feature == Feature::kWall) {
    // The cut through the block: a soil layer over rock.
    return h.height - p.z < kWallSoilDepth ? kMaterialDirt : kMaterialRock;
  }
  // The slope of the ground where it came from (the warp only shifts it):
  // normal z = 1 / sqrt(1 + |grad H|^2). Overhangs come out steep, so rock.
  const double slope2 = h.dx * h.dx + h.dy * h.dy;
  const double min_slope2 = 1.0 / (kGrassMinNormalZ * kGrassMinNormalZ) - 1.0;
  if (slope2 > min_slope2) return kMaterialRock;
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
