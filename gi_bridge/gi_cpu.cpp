// The CPU reference: the same kernels as the Vulkan shaders
// (shaders/gi_common.glsl, included here), run over the items in parallel.
#include <chrono>
#include <cmath>

#include <tbb/parallel_for.h>

#include "gi_bridge/detail/gi_engine.h"

namespace ldc::detail {
namespace {

using glm::ivec3;
using glm::ivec4;
using glm::vec3;
using glm::vec4;
using glm::abs;
using glm::clamp;
using glm::dot;
using glm::exp;
using glm::floor;
using glm::inversesqrt;
using glm::length;
using glm::max;
using glm::min;
using glm::sqrt;

struct Buffers {
  std::vector<float> occ, alpha;
  std::vector<int32_t> vmap, fsrc;
  std::vector<ivec4> surf_pos;
  std::vector<vec4> attr, light_prev, light_next, pre, qin, qout, plight, cones;
};

#define GI_CONST static constexpr
#define OUT(T) T&
#define GI_INLINE [[gnu::always_inline]]
#define INOUT(T) T&
#define XYZ(v) vec3(v)
#define IXYZ(v) ivec3(v)

// One kernel invocation context: the uniform block, the push constants and
// the buffers, reached through the accessors gi_common.glsl expects.
struct Kernels {
  GiParams P;
  GiPush pc;
  Buffers* b;

  float occ_load(int i) const { return b->occ[size_t(i)]; }
  float alpha_load(int i) const { return b->alpha[size_t(i)]; }
  void alpha_store(int i, float a) const { b->alpha[size_t(i)] = a; }
  int vmap_load(int i) const { return b->vmap[size_t(i)]; }
  ivec4 surf_pos_load(int i) const { return b->surf_pos[size_t(i)]; }
  vec4 attr_load(int i) const { return b->attr[size_t(i)]; }
  int fsrc_load(int i) const { return b->fsrc[size_t(i)]; }
  vec4 light_load(int i) const { return b->light_prev[size_t(i)]; }
  void light_store(int i, vec4 v) const { b->light_next[size_t(i)] = v; }
  vec4 pre_load(int i) const { return b->pre[size_t(i)]; }
  void pre_store(int i, vec4 v) const { b->pre[size_t(i)] = v; }
  vec4 qin_load(int i) const { return b->qin[size_t(i)]; }
  void qout_store(int i, vec4 v) const { b->qout[size_t(i)] = v; }
  vec4 plight_load(int i) const { return b->plight[size_t(i)]; }
  vec4 cone_load(int i) const { return b->cones[size_t(i)]; }
  void cone_store(int i, vec4 v) const { b->cones[size_t(i)] = v; }

#include "gi_bridge/shaders/gi_common.glsl"
};

#undef GI_CONST
#undef OUT
#undef INOUT
#undef XYZ
#undef IXYZ
#undef GI_INLINE

class CpuGi final : public GiEngineBase {
 public:
  explicit CpuGi(const GiConfig& config) : GiEngineBase(config) {}
  const char* name() const override { return "cpu"; }

 protected:
  Status upload(const GiLayout& layout) override {
    params_ = layout.params;
    b_.occ = layout.occ;
    b_.vmap = layout.vmap;
    b_.surf_pos = layout.surf_pos;
    b_.attr = layout.attr;
    b_.fsrc = layout.face_src;
    b_.alpha.assign(layout.voxels() * 16, 0.0f);
    b_.light_prev.assign(layout.surfaces() * 18, vec4(0.0f));
    b_.light_next = b_.light_prev;
    b_.pre.assign(layout.surfaces() * 48, vec4(0.0f));
    b_.cones.assign(layout.surfaces() * 48, vec4(0.0f));
    return upload_lights(layout);
  }

  Status upload_vmap(const GiLayout& layout) override {
    b_.vmap = layout.vmap;
    return {};
  }

  Status upload_lights(const GiLayout& layout) override {
    params_ = layout.params;
    b_.plight = layout.light_volume;
    return {};
  }

  Status run_steps(const std::vector<GiStep>& steps) override {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    for (double& k : last_kernel_seconds_) k = 0.0;
    for (const GiStep& step : steps) {
      const auto start = Clock::now();
      if (step.kernel == GiKernel::kCommit) {
        commit(step.first, step.count);
      } else {
        run_kernel(step);
      }
      last_kernel_seconds_[int(step.kernel) - 1] += std::chrono::duration<double>(Clock::now() - start).count();
    }
    last_device_seconds_ = std::chrono::duration<double>(Clock::now() - t0).count();
    return {};
  }

  Status set_queries(const std::vector<vec4>& qin) override {
    b_.qin = qin;
    b_.qout.assign(qin.size() / 2, vec4(0.0f));
    return {};
  }
  Status get_queries(std::vector<vec4>& qout, size_t count) override {
    qout.assign(b_.qout.begin(), b_.qout.begin() + ptrdiff_t(count));
    return {};
  }
  Status read_light(std::vector<vec4>& light) override {
    light = b_.light_prev;
    return {};
  }

 private:
  void run_kernel(const GiStep& step) {
    Kernels k{params_, GiPush{step.first, step.count, step.level, 0}, &b_};
    tbb::parallel_for(tbb::blocked_range<int>(0, step.count, 64), [&](const tbb::blocked_range<int>& r) {
      for (int gid = r.begin(); gid < r.end(); ++gid) {
        switch (step.kernel) {
          case GiKernel::kAlpha: k.kernel_alpha(gid); break;
          case GiKernel::kPrecombine: k.kernel_precombine(gid); break;
          case GiKernel::kUpdate: k.kernel_update(gid); break;
          case GiKernel::kQuery: k.kernel_query(gid); break;
          case GiKernel::kCones: k.kernel_cones(gid); break;
          case GiKernel::kCommit: break;  // run_steps copies
        }
      }
    });
  }

  void commit(int first, int count) {
    std::copy(b_.light_next.begin() + ptrdiff_t(first) * 18, b_.light_next.begin() + ptrdiff_t(first + count) * 18,
              b_.light_prev.begin() + ptrdiff_t(first) * 18);
  }

  GiParams params_{};
  Buffers b_;
};

}  // namespace
}  // namespace ldc::detail

namespace ldc {
std::unique_ptr<GiEngine> make_cpu_gi(const GiConfig& config) {
  return std::make_unique<detail::CpuGi>(config);
}
}  // namespace ldc
