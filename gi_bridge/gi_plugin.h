// The entry points of the ldc tool's GI plugins (issue 22), which the tool
// dlopen()s only for the command that needs them (tools/cmd_gi.cpp), so that
// no other command pays Vulkan's or Embree's start-up:
//   ldc-gi-vulkan.so     (gi_vulkan_plugin.cpp, ldc::gi)            ldc gi --engine vulkan
//   ldc-gi-reference.so  (gi_reference_plugin.cpp, ldc::gi_reference) ldc gi --reference
// Unlike the OpenVDB plugin's plain C, C++ types cross this boundary (a
// GiEngine made in the plugin, ldc structs by pointer): the tool and its
// plugins are built from the same tree by the same compiler. An ABI number
// (LDC_GI_PLUGIN_ABI, gi_bridge/CMakeLists.txt, both sides) and the layout
// signature below refuse a plugin left over from another build. No
// exception crosses: each entry point returns 0 or an ldc::ErrorCode with
// its message. Change both sides together and bump LDC_GI_PLUGIN_ABI when
// anything here changes.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "contour/contour.h"
#include "gi_bridge/gi.h"
#include "ldc/query.h"

namespace ldc {

struct PathTraceConfig;

// The sizes of what crosses, folded: another build with other layouts
// gives another number (checked on load with the ABI number).
constexpr size_t gi_plugin_layout() {
  return (sizeof(ldc::GiConfig) * 1000003u) ^ (sizeof(ldc::GiLights) * 10007u) ^ (sizeof(ldc::Cascades) * 101u) ^
         (sizeof(ldc::ContourMesh) * 7u) ^ (sizeof(ldc::MaterialTable) * 3u) ^ sizeof(ldc::Ray) ^
         (sizeof(ldc::Status) << 20);
}

}  // namespace ldc

extern "C" {

// Both plugins: ldc_gi_plugin_abi(), the ABI number they were built with,
// and ldc_gi_plugin_layout(), their ldc::gi_plugin_layout().
using LdcGiPluginAbiFn = int (*)();
using LdcGiPluginLayoutFn = size_t (*)();

// ldc-gi-vulkan.so, ldc_gi_vulkan_create: make_vulkan_gi(*config, device).
// 0 with *engine set, or an ldc::ErrorCode with *message (no Vulkan device:
// the tool then falls back to the CPU engine, as it always did).
using LdcGiVulkanCreateFn = int (*)(const ldc::GiConfig* config, std::unique_ptr<ldc::GiEngine>* engine,
                                    std::string* device, std::string* message);

// ldc-gi-reference.so, ldc_gi_reference_radiance: PathTracer::create(*mesh,
// *materials, *lights), then radiance_along(rays, bounces, out, *config):
// out[i] for rays[i], i < count. 0, or an ldc::ErrorCode with *message.
using LdcGiReferenceRadianceFn = int (*)(const ldc::ContourMesh* mesh, const ldc::MaterialTable* materials,
                                         const ldc::GiLights* lights, const ldc::Ray* rays, size_t count,
                                         int bounces, const ldc::PathTraceConfig* config, glm::vec3* out,
                                         std::string* message);

}  // extern "C"
