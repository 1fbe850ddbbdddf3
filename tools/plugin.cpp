// Loading the tool's plugins: tools/plugin.h.
#include "plugin.h"

#include <dlfcn.h>

#include <filesystem>
#include <system_error>

namespace ldc::tool {
namespace {

std::filesystem::path exe_dir() {
  std::error_code ec;
  return std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
}

// dlerror() text without the path it may begin with (the caller names it).
std::string dl_reason(const std::string& path) {
  const char* e = dlerror();
  std::string reason = e != nullptr ? e : "unknown error";
  if (reason.starts_with(path + ": ")) reason.erase(0, path.size() + 2);
  return reason;
}

// Loads one candidate; on failure, why (without the path).
Result<LoadedPlugin> open_plugin(const PluginSpec& spec, const std::string& path) {
  // RTLD_LOCAL: the plugin's dependencies stay out of the tool's namespace.
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) return Status(ErrorCode::kIoError, dl_reason(path));
  auto abi = reinterpret_cast<int (*)()>(dlsym(handle, spec.abi_symbol));
  LoadedPlugin plugin;
  bool complete = abi != nullptr;
  std::string names = spec.abi_symbol;
  for (const char* name : spec.symbols) {
    plugin.symbols.push_back(dlsym(handle, name));
    complete = complete && plugin.symbols.back() != nullptr;
    names += std::string(" / ") + name;
  }
  auto layout = spec.layout_symbol != nullptr ? reinterpret_cast<size_t (*)()>(dlsym(handle, spec.layout_symbol))
                                              : nullptr;
  if (spec.layout_symbol != nullptr) {
    complete = complete && layout != nullptr;
    names += std::string(" / ") + spec.layout_symbol;
  }
  std::string why;
  if (!complete) {
    why = std::string("not an ldc ") + spec.kind + " plugin (no " + names + ")";
  } else if (const int plugin_abi = abi(); plugin_abi != spec.abi) {
    why = "plugin ABI " + std::to_string(plugin_abi) + ", this tool needs " + std::to_string(spec.abi) +
          " (a stale plugin from another ldc build)";
  } else if (layout != nullptr && layout() != spec.layout) {
    why = "plugin built with other type layouts than this tool (a stale plugin from another ldc build)";
  }
  if (why.empty()) return plugin;
  dlclose(handle);
  return Status(ErrorCode::kUnsupported, why);
}

}  // namespace

std::vector<std::string> plugin_paths(const PluginSpec& spec) {
  const std::filesystem::path dir = exe_dir();
  return {(dir / spec.file).string(), (dir / spec.install_rel / spec.file).lexically_normal().string()};
}

Result<LoadedPlugin> load_plugin(const PluginSpec& spec) {
  std::string tried;
  for (const std::string& path : plugin_paths(spec)) {
    Result<LoadedPlugin> plugin = open_plugin(spec, path);
    if (plugin.ok()) return plugin;
    tried += (tried.empty() ? "" : "; ") + path + ": " + plugin.status().message();
  }
  return Status(ErrorCode::kUnsupported, tried);
}

}  // namespace ldc::tool
