// The entry points of the OpenVDB plugin (ldc-vdb.so, voxelize/vdb_plugin.cpp)
// that the ldc tool dlopen()s to write .vdb files (tools/cmd_voxelize.cpp).
// Plain C across the boundary: no exception and no std:: type crosses it.
// Change both sides together and bump LDC_VDB_PLUGIN_ABI
// (voxelize/CMakeLists.txt) when anything here changes.
#pragma once

#include <cstddef>

#include "voxelize/voxelize.h"

extern "C" {

// One grid set: the grid and the suffix of its OpenVDB grid names ("_L0").
struct LdcVdbGrid {
  const ldc::VoxelGrid* grid;
  const char* suffix;
};

// Receives the error message (valid during the call only).
using LdcVdbErrorFn = void (*)(void* user, const char* message);

// ldc_vdb_plugin_abi(): the ABI number the plugin was built with.
using LdcVdbAbiFn = int (*)();

// ldc_vdb_plugin_write(): writes the grids to one .vdb file (ldc::save_vdb).
// Returns 0 or an ldc::ErrorCode value, with the message (naming the file)
// given to on_error. grid_bytes is the caller's sizeof(ldc::VoxelGrid): a
// mismatch means the plugin comes from another build.
using LdcVdbWriteFn = int (*)(const LdcVdbGrid* grids, size_t count, size_t grid_bytes, const char* path,
                              const char* source, LdcVdbErrorFn on_error, void* user);

}  // extern "C"
