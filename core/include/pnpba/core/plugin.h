// Plugins: the parts of pnpba whose libraries are slow to load live in small shared modules
// opened on first use, so that a run which never needs them does not pay for them. Measured on
// a 2-core machine: OpenCV's image codecs pull in about 120 shared libraries (GDAL among them)
// and 90 ms of start-up, Open3D about 80 more libraries and 80 ms; `--help`, a bad-input exit
// and a pair the feature path settles need neither.
//
// A plugin `name` is the file libpnpba_<name>.so. It is looked for, in order, in
//   $PNPBA_PLUGIN_DIR                        (when set)
//   the build tree's lib/pnpba               (first when the running code was built there)
//   <libdir>/pnpba of the installed tree the running executable, library or Python module is
//   in (found by walking up from it), then the configured install prefix's
// and must export `pnpba_plugin_abi()` returning this build's ABI tag: a stale plugin of another
// version is passed over, never called.
#pragma once

#include <string>
#include <vector>

namespace pnpba {

// The address of `symbol` in plugin `name`, loading the plugin on first use (thread-safe).
// Throws Error naming the plugin, every file tried and why each failed.
void* pluginSymbol(const std::string& name, const std::string& symbol);

template <class Function>
Function* pluginFunction(const std::string& name, const std::string& symbol) {
  return reinterpret_cast<Function*>(pluginSymbol(name, symbol));
}

// The folders searched for plugins, in order.
std::vector<std::string> pluginSearchPath();

// True when plugin `name` is loaded in this process (tests check what a run loaded).
bool pluginLoaded(const std::string& name);

}  // namespace pnpba
