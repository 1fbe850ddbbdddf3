// The entry points of the ldc tool's Draco plugin (ldc-draco.so,
// meshio/draco_plugin.cpp), which the tool dlopen()s only to read or write a
// .drc file (tools/draco_codec.cpp), so that no other command pays libdraco's
// start-up (issue 22). The library ldc::meshio is unchanged: it links Draco.
// C++ types cross by pointer: the tool and the plugin are built from the same
// tree by the same compiler; the ABI number (LDC_DRACO_PLUGIN_ABI,
// meshio/CMakeLists.txt) and ldc::draco_plugin_layout() refuse a plugin from
// another build. No exception crosses. Change both sides together and bump
// LDC_DRACO_PLUGIN_ABI when anything here changes.
#pragma once

#include <cstddef>
#include <string>

#include "meshio/meshio.h"

namespace ldc {

// The sizes of what crosses, folded (checked on load with the ABI number).
constexpr size_t draco_plugin_layout() {
  return (sizeof(ContourMesh) * 10007u) ^ (sizeof(ExportOptions) * 101u) ^ sizeof(std::string) ^
         (sizeof(Status) << 20);
}

}  // namespace ldc

extern "C" {

// ldc_draco_plugin_abi(), ldc_draco_plugin_layout(): what the plugin was built with.
using LdcDracoAbiFn = int (*)();
using LdcDracoLayoutFn = size_t (*)();

// ldc_draco_encode: meshio_detail::encode_draco(*mesh, *options, path) into
// *bytes. 0, or an ldc::ErrorCode with *message (naming the file).
using LdcDracoEncodeFn = int (*)(const ldc::ContourMesh* mesh, const ldc::ExportOptions* options,
                                 const std::string* path, std::string* bytes, std::string* message);

// ldc_draco_decode: meshio_detail::decode_draco({data, size}, path) into
// *mesh. 0, or an ldc::ErrorCode with *message (naming the file).
using LdcDracoDecodeFn = int (*)(const char* data, size_t size, const std::string* path, ldc::ContourMesh* mesh,
                                 std::string* message);

}  // extern "C"
