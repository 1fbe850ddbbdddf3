// The OpenVDB export as a plugin (ldc-vdb.so, target ldc_vdb_plugin) that
// the ldc tool dlopen()s only when it writes a .vdb file: linking OpenVDB
// into the tool cost every command ~60 ms of dynamic relocation at start-up.
//
// The boundary is plain C: no exception and no std:: type crosses it. Grids
// are passed as pointers to ldc::VoxelGrid, which is safe only because the
// tool and the plugin are built from the same source tree; the ABI number
// (LDC_VDB_PLUGIN_ABI, set in voxelize/CMakeLists.txt for both sides) and the
// VoxelGrid size refuse a plugin left over from another build. The tool's
// side is tools/cmd_voxelize.cpp (VdbPlugin): change both together and bump
// LDC_VDB_PLUGIN_ABI when the entry points or their structs change.
#include <cstddef>
#include <exception>
#include <string>
#include <vector>

#include "voxelize/vdb.h"
#include "voxelize/vdb_plugin.h"

#ifndef LDC_VDB_PLUGIN_ABI
#error "LDC_VDB_PLUGIN_ABI must be defined (voxelize/CMakeLists.txt)"
#endif

extern "C" {

// The ABI number this plugin was built with; the tool checks it on load.
__attribute__((visibility("default"))) int ldc_vdb_plugin_abi() { return LDC_VDB_PLUGIN_ABI; }

// Writes the grids to one .vdb file (ldc::save_vdb). Returns 0 or an
// ldc::ErrorCode value, with the message (naming the file) given to on_error.
// grid_bytes is the caller's sizeof(ldc::VoxelGrid): a mismatch means that
// the plugin comes from another build.
__attribute__((visibility("default"))) int ldc_vdb_plugin_write(const LdcVdbGrid* grids, size_t count,
                                                                size_t grid_bytes, const char* path,
                                                                const char* source, LdcVdbErrorFn on_error,
                                                                void* user) noexcept;

}  // extern "C"

namespace {

int report(ldc::ErrorCode code, const std::string& message, LdcVdbErrorFn on_error, void* user) {
  if (on_error != nullptr) on_error(user, message.c_str());
  return static_cast<int>(code);
}

int write_grids(const LdcVdbGrid* grids, size_t count, size_t grid_bytes, const char* path, const char* source,
                LdcVdbErrorFn on_error, void* user) {
  if (grid_bytes != sizeof(ldc::VoxelGrid)) {
    return report(ldc::ErrorCode::kInternal,
                  std::string(path) + ": the OpenVDB plugin comes from another ldc build (VoxelGrid is " +
                      std::to_string(sizeof(ldc::VoxelGrid)) + " bytes there, " + std::to_string(grid_bytes) +
                      " in the tool): reinstall ldc",
                  on_error, user);
  }
  std::vector<ldc::VdbGridSet> sets;
  sets.reserve(count);
  for (size_t i = 0; i < count; ++i) sets.push_back({grids[i].grid, grids[i].suffix});
  ldc::Status s = ldc::save_vdb(sets, path, source);
  return s.ok() ? 0 : report(s.code(), s.message(), on_error, user);
}

// The message names the file; where building it fails too (out of memory),
// the bare exception text is all that is sent.
int report_exception(const char* path, const char* what, LdcVdbErrorFn on_error, void* user) noexcept {
  const auto code = static_cast<int>(ldc::ErrorCode::kIoError);
  if (on_error == nullptr) return code;
  try {
    on_error(user, (std::string(path) + ": cannot write the .vdb file: " + what).c_str());
  } catch (...) {
    on_error(user, what);
  }
  return code;
}

}  // namespace

int ldc_vdb_plugin_write(const LdcVdbGrid* grids, size_t count, size_t grid_bytes, const char* path,
                         const char* source, LdcVdbErrorFn on_error, void* user) noexcept {
  // save_vdb lets no exception out; this catches the rest (bad_alloc while
  // copying the grid names) so that none unwinds into the tool.
  try {
    return write_grids(grids, count, grid_bytes, path, source, on_error, user);
  } catch (const std::exception& e) {
    return report_exception(path, e.what(), on_error, user);
  } catch (...) {
    return report_exception(path, "unknown exception", on_error, user);
  }
}
