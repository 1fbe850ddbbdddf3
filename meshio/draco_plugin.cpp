// Draco reading and writing as a plugin of the ldc tool (ldc-draco.so,
// target ldc_draco_plugin): meshio_detail::encode_draco / decode_draco
// (draco.cpp) behind the entry points of draco_plugin.h. The tool's side:
// tools/draco_codec.cpp.
#include <exception>
#include <string>
#include <string_view>
#include <utility>

#include "meshio/detail/codecs.h"
#include "meshio/draco_plugin.h"

#ifndef LDC_DRACO_PLUGIN_ABI
#error "LDC_DRACO_PLUGIN_ABI must be defined (meshio/CMakeLists.txt)"
#endif

namespace {

int failed(const ldc::Status& s, std::string* message) {
  *message = s.message();
  return static_cast<int>(s.code());
}

int caught(const char* what, std::string* message) noexcept {
  try {
    *message = std::string("the Draco plugin failed: ") + what;
  } catch (...) {
  }
  return static_cast<int>(ldc::ErrorCode::kInternal);
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int ldc_draco_plugin_abi() { return LDC_DRACO_PLUGIN_ABI; }
__attribute__((visibility("default"))) size_t ldc_draco_plugin_layout() { return ldc::draco_plugin_layout(); }

__attribute__((visibility("default"))) int ldc_draco_encode(const ldc::ContourMesh* mesh,
                                                            const ldc::ExportOptions* options,
                                                            const std::string* path, std::string* bytes,
                                                            std::string* message) noexcept {
  try {
    ldc::Result<std::string> r = ldc::meshio_detail::encode_draco(*mesh, *options, *path);
    if (!r.ok()) return failed(r.status(), message);
    *bytes = std::move(r.value());
    return 0;
  } catch (const std::exception& e) {
    return caught(e.what(), message);
  }
}

__attribute__((visibility("default"))) int ldc_draco_decode(const char* data, size_t size, const std::string* path,
                                                            ldc::ContourMesh* mesh, std::string* message) noexcept {
  try {
    ldc::Result<ldc::ContourMesh> r = ldc::meshio_detail::decode_draco(std::string_view(data, size), *path);
    if (!r.ok()) return failed(r.status(), message);
    *mesh = std::move(r.value());
    return 0;
  } catch (const std::exception& e) {
    return caught(e.what(), message);
  }
}

}  // extern "C"
