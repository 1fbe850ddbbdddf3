// The Vulkan GI engine as a plugin (ldc-gi-vulkan.so, target
// ldc_gi_vulkan_plugin) that the ldc tool dlopen()s only for `ldc gi
// --engine vulkan`: linking libvulkan into the tool cost every command its
// start-up. The boundary: gi_bridge/gi_plugin.h; the tool's side:
// tools/cmd_gi.cpp.
#include <exception>
#include <memory>
#include <string>

#include "gi_bridge/gi.h"
#include "gi_bridge/gi_plugin.h"

#ifndef LDC_GI_PLUGIN_ABI
#error "LDC_GI_PLUGIN_ABI must be defined (gi_bridge/CMakeLists.txt)"
#endif

extern "C" {

__attribute__((visibility("default"))) int ldc_gi_plugin_abi() { return LDC_GI_PLUGIN_ABI; }
__attribute__((visibility("default"))) size_t ldc_gi_plugin_layout() { return ldc::gi_plugin_layout(); }

__attribute__((visibility("default"))) int ldc_gi_vulkan_create(const ldc::GiConfig* config,
                                                                std::unique_ptr<ldc::GiEngine>* engine,
                                                                std::string* device, std::string* message) noexcept {
  try {
    ldc::Result<std::unique_ptr<ldc::GiEngine>> gi = ldc::make_vulkan_gi(*config, device);
    if (!gi.ok()) {
      *message = gi.status().message();
      return static_cast<int>(gi.status().code());
    }
    *engine = std::move(gi.value());
    return 0;
  } catch (const std::exception& e) {
    try {
      *message = std::string("the Vulkan GI plugin failed: ") + e.what();
    } catch (...) {
    }
    return static_cast<int>(ldc::ErrorCode::kInternal);
  }
}

}  // extern "C"
