// The tool's plugins (issue 22): heavy, rarely used dependencies (OpenVDB,
// Vulkan, Embree) are not linked into the ldc tool, whose every command
// would pay their relocation and static constructors at start-up; the
// command that needs one dlopen()s its plugin. A plugin is looked for beside
// the tool (the build tree) and then at its install path relative to the
// tool (<bindir>/<rel>/, i.e. <libdir>/ldc), and refused when its ABI number
// is not the tool's (a stale plugin from another build).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "ldc/status.h"

namespace ldc::tool {

struct PluginSpec {
  const char* file;         // "ldc-vdb.so"
  const char* install_rel;  // the install folder relative to the tool's folder
  const char* kind;         // "OpenVDB": "not an ldc OpenVDB plugin"
  const char* abi_symbol;   // int (*)(): the plugin's ABI number
  int abi;                  // the number this tool needs
  std::vector<const char*> symbols;  // the entry points the tool calls
  // Optional (nullptr: none): size_t (*)(), the layout of the C++ types
  // that cross, which must be `layout` (a plugin from another build).
  const char* layout_symbol;
  size_t layout;
};

// The plugin's entry points, in the order of PluginSpec::symbols. The
// library is never closed: what it keeps (TBB, a Vulkan instance) lives
// until exit.
struct LoadedPlugin {
  std::vector<void*> symbols;
};

// The candidate paths, in the order they are tried.
std::vector<std::string> plugin_paths(const PluginSpec& spec);

// Loads the first candidate that is a plugin of the tool's ABI. On failure
// the status message lists every path tried with why it failed
// ("P1: why; P2: why"), for the caller to put into its own sentence.
Result<LoadedPlugin> load_plugin(const PluginSpec& spec);

// Whether the Draco plugin (tools/draco_codec.cpp) loads: a .drc output is
// refused with its message ("path: a .drc file needs ...") before the work.
Status check_draco_plugin(const std::string& path);

}  // namespace ldc::tool
