// Draco for the ldc tool (issue 22): the tool links meshio without draco.cpp
// (ldc_meshio_no_draco, meshio/CMakeLists.txt) and defines its two Draco
// functions here, through the Draco plugin (ldc-draco.so, meshio/draco_plugin.h)
// that is dlopen()ed on the first .drc file read or written, so that no
// other command pays libdraco's start-up. The same bytes and the same
// messages as ldc::meshio.
#include <string>
#include <string_view>

#include "meshio/draco_codec.h"
#include "meshio/draco_plugin.h"
#include "plugin.h"

#if !defined(LDC_DRACO_PLUGIN_FILE) || !defined(LDC_DRACO_PLUGIN_INSTALL_REL) || !defined(LDC_DRACO_PLUGIN_ABI)
#error "the Draco plugin's file name, install path and ABI come from tools/CMakeLists.txt"
#endif

namespace ldc::meshio_detail {
namespace {

struct DracoPlugin {  // a struct: see VdbPlugin in cmd_voxelize.cpp
  LdcDracoEncodeFn encode = nullptr;
  LdcDracoDecodeFn decode = nullptr;
};

Result<DracoPlugin> load_draco_plugin() {
  const tool::PluginSpec spec{LDC_DRACO_PLUGIN_FILE, LDC_DRACO_PLUGIN_INSTALL_REL, "Draco", "ldc_draco_plugin_abi",
                              LDC_DRACO_PLUGIN_ABI, {"ldc_draco_encode", "ldc_draco_decode"},
                              "ldc_draco_plugin_layout", draco_plugin_layout()};
  Result<tool::LoadedPlugin> plugin = tool::load_plugin(spec);
  if (plugin.ok()) {
    return DracoPlugin{reinterpret_cast<LdcDracoEncodeFn>(plugin.value().symbols[0]),
                       reinterpret_cast<LdcDracoDecodeFn>(plugin.value().symbols[1])};
  }
  return Status(ErrorCode::kUnsupported, "a .drc file needs the Draco plugin " LDC_DRACO_PLUGIN_FILE
                                         ", which did not load (tried " + plugin.status().message() + ")");
}

// Loaded once, on the first .drc file.
const Result<DracoPlugin>& draco_plugin() {
  static const Result<DracoPlugin> plugin = load_draco_plugin();
  return plugin;
}

Status plugin_status(const std::string& path) {
  const Result<DracoPlugin>& plugin = draco_plugin();
  return plugin.ok() ? Status() : error_at(plugin.status().code(), path, plugin.status().message());
}

}  // namespace

Result<std::string> encode_draco(const ContourMesh& mesh, const ExportOptions& options, const std::string& path) {
  if (Status s = plugin_status(path); !s.ok()) return s;
  const DracoPlugin& plugin = draco_plugin().value();
  std::string bytes;
  std::string message = path + ": the Draco plugin failed without a message";
  const int code = plugin.encode(&mesh, &options, &path, &bytes, &message);
  if (code != 0) return Status(static_cast<ErrorCode>(code), message);
  return bytes;
}

Result<ContourMesh> decode_draco(std::string_view bytes, const std::string& path) {
  if (Status s = plugin_status(path); !s.ok()) return s;
  const DracoPlugin& plugin = draco_plugin().value();
  ContourMesh mesh;
  std::string message = path + ": the Draco plugin failed without a message";
  const int code = plugin.decode(bytes.data(), bytes.size(), &path, &mesh, &message);
  if (code != 0) return Status(static_cast<ErrorCode>(code), message);
  return mesh;
}

}  // namespace ldc::meshio_detail

namespace ldc::tool {

Status check_draco_plugin(const std::string& path) { return meshio_detail::plugin_status(path); }

}  // namespace ldc::tool
