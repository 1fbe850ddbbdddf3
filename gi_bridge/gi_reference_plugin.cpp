// The path-traced reference as a plugin (ldc-gi-reference.so, target
// ldc_gi_reference_plugin) that the ldc tool dlopen()s only for `ldc gi
// --reference`: linking Embree (a 43 MB library with static constructors)
// into the tool cost every command its start-up. The boundary:
// gi_bridge/gi_plugin.h; the tool's side: tools/cmd_gi.cpp.
#include <exception>
#include <memory>
#include <span>
#include <string>

#include "gi_bridge/gi_plugin.h"
#include "gi_bridge/path_trace.h"

#ifndef LDC_GI_PLUGIN_ABI
#error "LDC_GI_PLUGIN_ABI must be defined (gi_bridge/CMakeLists.txt)"
#endif

namespace {

int radiance(const ldc::ContourMesh& mesh, const ldc::MaterialTable& materials, const ldc::GiLights& lights,
             std::span<const ldc::Ray> rays, int bounces, const ldc::PathTraceConfig& config,
             std::span<glm::vec3> out, std::string* message) {
  ldc::Result<std::unique_ptr<ldc::PathTracer>> pt = ldc::PathTracer::create(mesh, materials, lights);
  ldc::Status s = pt.ok() ? pt.value()->radiance_along(rays, bounces, out, config) : pt.status();
  if (s.ok()) return 0;
  *message = s.message();
  return static_cast<int>(s.code());
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int ldc_gi_plugin_abi() { return LDC_GI_PLUGIN_ABI; }
__attribute__((visibility("default"))) size_t ldc_gi_plugin_layout() { return ldc::gi_plugin_layout(); }

__attribute__((visibility("default"))) int ldc_gi_reference_radiance(
    const ldc::ContourMesh* mesh, const ldc::MaterialTable* materials, const ldc::GiLights* lights,
    const ldc::Ray* rays, size_t count, int bounces, const ldc::PathTraceConfig* config, glm::vec3* out,
    std::string* message) noexcept {
  try {
    return radiance(*mesh, *materials, *lights, std::span<const ldc::Ray>(rays, count), bounces, *config,
                    std::span<glm::vec3>(out, count), message);
  } catch (const std::exception& e) {
    try {
      *message = std::string("the path-tracing plugin failed: ") + e.what();
    } catch (...) {
    }
    return static_cast<int>(ldc::ErrorCode::kInternal);
  }
}

}  // extern "C"
