// Global illumination from the voxel cascades: cone tracing in 16 fixed
// directions (the talk's "Lighting" part), on the GPU through Vulkan compute
// (make_vulkan_gi, target ldc::gi, built with LDC_WITH_VULKAN) and on the CPU
// (make_cpu_gi, target ldc::gi_cpu, always built), both running the same
// kernels (shaders/gi_common.glsl is compiled by glslc and included by the
// CPU code), so they agree to float rounding.
//
// Directions. gi_directions(): 16 unit vectors forming a spherical 5-design
// (every polynomial of degree <= 5 on the sphere integrates exactly as their
// mean; found by minimising sum_{k=1..5} sum_{i,j} P_k(d_i . d_j), residual
// 5e-10; the first is +z; smallest angle between two is 50.2 degrees). The
// same set is used everywhere: cones from voxels, cones from query points,
// the sky's basis and the precombined buffers.
//
// Cones. Each cone covers 4 pi / 16 sr (half-angle acos(7/8) = 29.0 deg).
// From its apex it is marched at steps of half a voxel of the level whose
// voxel is the largest not wider than the cone (at least the start level),
// moving to a coarser level where the position leaves a level's box; at each
// step the 8-voxel trilinear sample gives an opacity a (the faces looking
// back at the apex, weighted by d_axis^2; a corner counts only when its
// voxel lies wholly ahead of the plane through the apex normal to the axis,
// so a cone never reads the coarse voxel holding its own surface) and light
// premultiplied by opacity: the mean light of the faces that show a surface
// (their own, or one propagated from the surface in front, see Light)
// among the faces on the apex's side of the voxel, times a. Composited
// front to back as in volume ray marching (opacity corrected for the
// half-voxel step: 1 - sqrt(1 - a)). A cone that leaves the coarsest
// level receives the sky times its transmittance.
//
// Queries (irradiance(), an image's final gather) from air open to the sky
// trace each cone as GiConfig::query_rays narrow rays spread over it (their
// voxels at most 1/8 of their distance wide; blocks of empty voxels
// skipped) and take their mean: a wide cone grazing a surface reads the
// half-covered voxels beside it as a new layer at every step and darkens
// what it lights (issue 25). Queries from sealed air and the voxel updates
// keep the cones.
//
// Light. Per surface voxel and face the cascades hold three radiance buffers
// (the talk's volumetric light buffers): D = emission + direct light of sky
// and point lights reflected once, B1 = D gathered and reflected, B2 = B1
// gathered and reflected. Reflection is Lambertian: for a face with albedo
// rho and normal n, L_out = rho * sum_i c_i L_i / sum_i c_i with
// c_i = max(0, n . d_i) (so a uniform radiance L gives irradiance pi L
// exactly). One update pass traces the 16 cones once and writes all three
// from the previous frame's buffers (the talk's one-pass scheme): after 3
// frames of a static scene they equal three separate passes.
//
// Sky: 16 spherical radial basis lobes on the directions, normalised to a
// partition of unity: L_sky(w) = sum_i a_i B_i(w), B_i = exp(k (w . d_i - 1))
// / sum_j exp(k (w . d_j - 1)). A cone i that escapes gets a_i.
// Point lights: radiant intensity I [radiance * m^2]. Two ways, chosen by
// GiConfig::light_volume:
//  - exact (default; at most kGiMaxPointLights): their irradiance at a
//    point (or voxel face) with normal n is the exact I max(0, n . w) / r^2
//    times a visibility: the transmittance of a narrow shadow cone (half-
//    angle atan 0.1) marched through the cascades toward the light, opacity
//    only. An unoccluded light is exact; shadows are as soft as the
//    cascades' voxels at the distance. (Blending the 16 cones'
//    transmittances by the light's direction gave a mean error of 42% on
//    the Cornell box's light instead of 31%, but 10% instead of 15% in the
//    landscape's cave: see docs/benchmarks.md.)
//  - injected (the talk's method; at most kGiMaxInjectedPointLights): each
//    light is splatted into a light volume cascaded like the G-buffer, at
//    every level, over the 8 voxels around it by trilinear weights, as an
//    emission density I w / s^3 (s the level's voxel size): the trilinear
//    reconstruction integrates to I over space. A cone marching through it
//    adds T * density * step (T the transmittance built so far), so over
//    all directions the cones gather I / r^2 on average; per direction it
//    varies with where the light falls between the cones' axes, and a
//    light nearer than a voxel to a surface is blurred over it. The march
//    costs one more trilinear lookup per step whatever the number of
//    lights; splatting costs 8 writes per light and level (on the host).
// Faces behind a surface: the voxelizer propagates a surface's face to the
// solid voxel behind it (voxelize.h); that face shows the surface's light
// (GiLayout::face_src), so a cone entering a wall, which samples both
// voxels, sees the wall's full radiance.
// Emission (MaterialTable) is written into D directly.
// Sealed air: the sky counts only from air a flood from the cascades' box
// faces reaches (through voxels under half solid), and air it does not
// reach forms pockets; a pocket holding no point light and no glowing face
// is black: its faces store no light and a query whose apex sees only its
// air gets none (walls thinner than a coarse voxel would otherwise let the
// outside's light in). load() numbers the pockets; set_lights() re-marks
// them when a light enters or leaves one.
//
// Outputs: radiance() reads back the per-face light cascades; irradiance()
// answers batches of points with normals by 16 cones from each point.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "ldc/status.h"
#include "voxelize/voxelize.h"

namespace ldc {

inline constexpr int kGiDirections = 16;
inline constexpr int kGiMaxPointLights = 8;          // exact point lights
inline constexpr int kGiMaxInjectedPointLights = 65536;  // GiConfig::light_volume
inline constexpr int kGiMaxLevels = 16;
inline constexpr int kGiMaxQueryRays = 16;  // GiConfig::query_rays

// The 16 directions (see the header comment).
const std::array<glm::vec3, kGiDirections>& gi_directions();
// The k-th of n unit directions spread evenly over cone `cone` (cos >= 7/8
// to its axis): rings of equal solid angle, turned by the golden angle; one
// ray (n = 1) is the axis. The queries' rays (GiConfig::query_rays) are
// these. [Limit: 0 <= k < n]
glm::dvec3 gi_cone_ray(int cone, int k, int n);

struct SkyLight {
  // Radiance amplitude of each lobe. [Units: radiance] [Limit: >= 0, finite]
  std::array<glm::vec3, kGiDirections> amplitude{};
  // Lobe sharpness k. [Limit: 0.5 .. 64] [Default: 6]
  float sharpness = 6.0f;

  // The same radiance in every direction (exact in this basis).
  static SkyLight uniform(const glm::vec3& radiance);
  // Lobes set to the zenith colour above, mixed to the horizon colour at
  // the horizon and the ground colour below, by the lobe's direction's
  // component along up_axis (0 x, 1 y, 2 z) [Limit: 0, 1, 2; others are z]
  // [Default: 2, z up].
  static SkyLight gradient(const glm::vec3& zenith, const glm::vec3& horizon, const glm::vec3& ground,
                           int up_axis = 2);
  // L_sky(w) for a unit direction.
  glm::vec3 radiance(const glm::vec3& w) const;
};

struct PointLight {
  glm::dvec3 position{0.0};  // [Units: m] world
  glm::vec3 intensity{0.0f};  // [Units: radiance * m^2, irradiance I / r^2 facing it] [Limit: >= 0]
};

struct GiLights {
  SkyLight sky;
  // [Limit: size <= kGiMaxPointLights, or kGiMaxInjectedPointLights with GiConfig::light_volume]
  std::vector<PointLight> points;
};

class World;

// Point lights inside the solid light nothing: every path from them is
// blocked, as the path tracer finds. The cascades cannot see that: a
// light within a voxel or two of a surface reaches out through the partial
// opacity of the voxels around it (issue 25: a light buried in the main
// job's pillar lit its chamber at 8 times the path tracer's light). Removes
// the lights that World::inside places in the solid and returns their
// indices in the list as given, for the caller to report. Keep calling it
// after edits: a player can build over a light.
std::vector<size_t> remove_buried_lights(const World& world, GiLights* lights);

struct GiConfig {
  // Read the 16-direction precombined light/opacity buffers (one lookup per
  // trilinear corner) instead of blending three faces at every step.
  // Same results to float rounding. [Default: on]
  bool precombined = true;
  // frame() updates one level per frame on the cascades' schedule (level k
  // every 2^(k+1) frames) instead of every level. [Default: on]
  bool staggered = true;
  // Third bounce boost: B2 * min(1, B2 / B1) * boost added to queries with
  // 3 bounces. [Limit: 0 .. 1] [Default: 0 (off)]
  float third_bounce_boost = 0.0f;
  // Near/far split cones (the talk's "split cone trace"): the far part of
  // each of the 16 cones (from near_far_split voxels on) is traced once per
  // surface voxel from its centre and shared by its six faces; the near
  // part is marched per face from the face (half a voxel out along its
  // normal) up to where the far part starts, and the far part is
  // composited behind it (L_near + T_near * L_far). Off: the centre's
  // cones, from one voxel on, are shared whole by the faces (cheaper; the
  // faces then see no detail nearer than a voxel from the centre).
  // Measured (bench_gi 200 512, docs/benchmarks.md): mean error vs the
  // path tracer -0.3 to -0.6 points on the landscape, +0.5 to +1.7 on the
  // Cornell box and spot; full update time 0.96-1.24x on the CPU engine,
  // 0.99-1.26x on lavapipe (single runs, noisy). Off by default: no clear
  // gain on the benchmark and the per-face marches are unmeasured on a GPU.
  // [Default: off]
  bool near_far = false;
  // Where the far part starts. [Units: voxels of the updated level] [Limit: 1 .. 16] [Default: 2.5 (the
  // talk: about a metre at its 0.4 m voxels)]
  float near_far_split = 2.5f;
  // Point lights injected into a cascaded light volume that the cones
  // gather (the talk's method: any number of lights at the same cost per
  // cone step) instead of evaluated exactly per light (see the header
  // comment for both). [Default: off (exact)]
  bool light_volume = false;
  // Query apex offset along the normal. [Units: voxels of the start level] [Limit: 0 .. 4] [Default: 1]
  float query_offset = 1.0f;
  // Queries (irradiance(): the final gather of an image) from air open to
  // the sky trace each of the 16 cones as this many narrow rays spread
  // evenly over it, and take their mean; 0 traces the cones themselves. A
  // wide cone grazing a surface reads the half-covered voxels beside it as
  // a new layer at every step: inside the main job's tunnel near its mouth,
  // cones saw 0.57 of the sky that exact rays see, 8 rays 0.89 (issue 25;
  // docs/gi.md). Queries in sealed air keep the cones (rays lost up to 17%
  // of a thin-walled glowing room's light at a corner). The voxel updates
  // keep the cones too. Costs about 4 times the cones' query time on the
  // CPU engine, 3 times on lavapipe.
  // [Limit: 0 .. kGiMaxQueryRays] [Default: 8]
  int query_rays = 8;
};
Status check_gi_config(const GiConfig& config);
// Checks the lights against the limits of `config`'s point light mode.
Status check_gi_lights(const GiLights& lights, const GiConfig& config);

// What a frame or a level update did.
struct GiTimings {
  int levels_updated = 0;
  size_t surface_voxels = 0;
  double seconds = 0.0;  // wall time (GPU: recording, submit, fence)
  // Time the device spent on the work itself: GPU timestamps around the
  // update's command buffer (Vulkan), the kernels' wall time (CPU engine);
  // < 0 where the device's queue has no timestamps.
  double device_seconds = -1.0;
  // device_seconds split by stage, in the order they run: the cones (each
  // surface voxel's 16 cone traces), the light update, the copy of the new
  // light over the old, the precombine of the next pass's cone inputs.
  // GPU timestamps between the stages (Vulkan), each stage's wall time (CPU
  // engine); all < 0 where device_seconds is.
  struct Stages {
    double cones = -1.0, update = -1.0, copy = -1.0, precombine = -1.0;
  } stage_device_seconds;
};

// Per-face radiance read back: for each surface voxel (level, global voxel
// coordinates) its six faces' D, B1, B2.
struct GiRadiance {
  std::vector<glm::ivec4> voxels;                 // xyz global voxel, w level
  std::vector<std::array<glm::vec3, 18>> light;   // [face * 3 + channel]
};

class GiEngine {
 public:
  virtual ~GiEngine() = default;
  virtual const char* name() const = 0;

  // Takes the cascades' packed G-buffer (Cascades::pack) and surface voxels
  // of every valid level, and the lights; clears the light buffers.
  virtual Status load(const Cascades& cascades, const GiLights& lights) = 0;
  // Replaces the sky and point lights of a loaded scene (a game moving its
  // lights) without re-uploading the G-buffer. The light buffers keep their
  // values and follow over the next updates (3 passes settle a static scene).
  virtual Status set_lights(const GiLights& lights) = 0;
  // One frame: the scheduled level when staggered, otherwise every level.
  virtual Result<GiTimings> frame() = 0;
  // One lighting pass of one level (from the previous frame's buffers).
  virtual Result<GiTimings> update_level(int level) = 0;
  // Every level, `passes` times (3 passes give D, B1 and B2 of a static scene).
  virtual Result<GiTimings> update_all(int passes = 1) = 0;
  // Irradiance (rgb) at world points with unit normals, with 1, 2 or 3
  // bounces (1: sources seen directly and D; 2: + B1; 3: + B2 and the boost).
  virtual Status irradiance(std::span<const glm::dvec3> points, std::span<const glm::vec3> normals, int bounces,
                            std::span<glm::vec3> out) = 0;
  virtual Result<GiRadiance> radiance() = 0;
};

std::unique_ptr<GiEngine> make_cpu_gi(const GiConfig& config = {});

// Vulkan 1.1 compute (lavapipe or a GPU). Fails with a message naming the
// reason when no Vulkan device is found. `device_name` receives its name.
Result<std::unique_ptr<GiEngine>> make_vulkan_gi(const GiConfig& config = {}, std::string* device_name = nullptr);

}  // namespace ldc
