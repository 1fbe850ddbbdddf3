// Internals shared by the CPU and Vulkan engines: the flat buffers both
// upload (layouts in shaders/gi_common.glsl) and the frame logic on top of
// a small set of backend primitives.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gi_bridge/gi.h"

namespace ldc::detail {

// std140 twin of the shaders' uniform block Params.
struct GiParams {
  glm::vec4 dirs[16];
  glm::vec4 sky[16];
  glm::vec4 light_pos[kGiMaxPointLights];
  glm::vec4 light_int[kGiMaxPointLights];
  glm::vec4 fparams;   // x level 0 voxel size, y third bounce boost, z query offset, w unused
  glm::ivec4 iparams;  // x N, y K, z flags, w exact point lights
  glm::vec4 fparams2;  // x near/far split distance (voxels of the updated level), yzw unused
  glm::ivec4 iparams2;  // x rays per cone of the queries (GiConfig::query_rays), yzw unused
  glm::ivec4 lo[kGiMaxLevels];
  glm::ivec4 surf[kGiMaxLevels];  // per level x first updated surface voxel, y their count
  glm::vec4 rays[kGiDirections * kGiMaxQueryRays];  // cone i's query rays at i * kGiMaxQueryRays + k (unit xyz)
};
static_assert(sizeof(GiParams) == 16 * (16 + 16 + 8 + 8 + 1 + 1 + 1 + 1 + 16 + 16 + 16 * kGiMaxQueryRays));

struct GiPush {
  int first = 0;
  int count = 0;
  int level = 0;
  int pad = 0;
};

// The shaders' kernels (GI_KERNEL 1..5), and kCommit: the copy of
// light_next to light_prev for surface voxels [first, first + count).
enum class GiKernel { kAlpha = 1, kPrecombine = 2, kUpdate = 3, kQuery = 4, kCones = 5, kCommit = 6 };

// One step of the work a backend runs in a batch: `kernel` over `count`
// items from `first`, with pc.level = level.
struct GiStep {
  GiKernel kernel = GiKernel::kUpdate;
  int first = 0, count = 0, level = 0;
};

// vmap's flags (gi_common.glsl's vmap_flags): less than half solid, sealed
// from the sky with no light inside, open to the sky.
constexpr int32_t kVoxelAir = 1, kVoxelDark = 2, kVoxelOpen = 4;

struct GiLayout {
  GiParams params{};
  int n = 0, k = 0;
  glm::dvec3 origin{0.0};
  std::vector<float> occ;             // K N^3 * 6
  std::vector<int32_t> vmap;          // K N^3
  std::vector<glm::ivec4> surf_pos;   // S: local xyz, level
  std::vector<glm::vec4> attr;        // S * 18
  std::vector<int32_t> face_src;      // S * 6: light slot (s * 6 + face) a face shows, or -1
  std::vector<glm::vec4> light_volume;  // K N^3 injected point lights (GiConfig::light_volume), else empty
  std::vector<int32_t> pocket;          // K N^3: sealed air's pocket (numbered over all levels), or -1
  std::vector<uint8_t> pocket_glows;    // per pocket: an emissive face looks into it
  std::vector<uint8_t> pocket_lit;      // per pocket: glows or holds a point light (as vmap's dark flags say)
  // Per level the entries start at level_first: level_count surface voxels
  // (updated), then level_shadow voxels that only show their neighbours'
  // light on propagated faces (precombined, never updated).
  std::vector<int> level_first, level_count, level_shadow;
  size_t voxels() const { return size_t(k) * size_t(n) * size_t(n) * size_t(n); }
  // Index of voxel c (local coordinates) of level l: the kernels' voxel_index.
  size_t voxel(int l, const glm::ivec3& c) const {
    return ((size_t(l) * size_t(n) + size_t(c.z)) * size_t(n) + size_t(c.y)) * size_t(n) + size_t(c.x);
  }
  size_t surfaces() const { return surf_pos.size(); }
};

Result<GiLayout> build_gi_layout(const Cascades& cascades, const GiLights& lights, const GiConfig& config);

// The frame logic; backends supply the primitives.
class GiEngineBase : public GiEngine {
 public:
  explicit GiEngineBase(const GiConfig& config) : config_(config) {}
  Status load(const Cascades& cascades, const GiLights& lights) override;
  Status set_lights(const GiLights& lights) override;
  Result<GiTimings> frame() override;
  Result<GiTimings> update_level(int level) override;
  Result<GiTimings> update_all(int passes) override;
  Status irradiance(std::span<const glm::dvec3> points, std::span<const glm::vec3> normals, int bounces,
                    std::span<glm::vec3> out) override;
  Result<GiRadiance> radiance() override;

 protected:
  // Allocates and fills every buffer from the layout; light, pre and alpha zeroed.
  virtual Status upload(const GiLayout& layout) = 0;
  // Replaces the uniform block and the light volume (set_lights).
  virtual Status upload_lights(const GiLayout& layout) = 0;
  // Replaces the voxel map (set_lights, when a sealed pocket's darkness changed).
  virtual Status upload_vmap(const GiLayout& layout) = 0;
  // Runs the steps in order, each seeing what the ones before wrote (the
  // Vulkan engine records them in one command buffer: one submit), and
  // sets last_device_seconds_ (GiTimings::device_seconds) and
  // last_kernel_seconds_.
  virtual Status run_steps(const std::vector<GiStep>& steps) = 0;
  Status run(GiKernel kernel, int first, int count, int level) { return run_steps({{kernel, first, count, level}}); }
  virtual Status set_queries(const std::vector<glm::vec4>& qin) = 0;
  virtual Status get_queries(std::vector<glm::vec4>& qout, size_t count) = 0;
  virtual Status read_light(std::vector<glm::vec4>& light) = 0;

  Result<GiTimings> update_levels(const std::vector<int>& levels);

  GiConfig config_;
  GiLayout layout_;
  bool loaded_ = false;
  uint64_t frame_ = 0;
  double last_device_seconds_ = -1.0;
  // The last run_steps' device time per kernel, [int(GiKernel) - 1]; -1
  // where it was not measured.
  double last_kernel_seconds_[6] = {-1.0, -1.0, -1.0, -1.0, -1.0, -1.0};
};

}  // namespace ldc::detail
