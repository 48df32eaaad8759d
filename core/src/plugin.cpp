#include "pnpba/core/plugin.h"

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <cstdlib>
#include <map>
#include <mutex>
#include <set>

#include "pnpba/core/error.h"

// Set by core/CMakeLists.txt.
#ifndef PNPBA_PLUGIN_ABI
#error "PNPBA_PLUGIN_ABI must be defined"
#endif

namespace pnpba {

namespace {

std::mutex& pluginMutex() {
  static std::mutex m;
  return m;
}

std::map<std::string, void*>& loadedPlugins() {
  static std::map<std::string, void*> handles;
  return handles;
}

// The file this code was loaded from: the executable (static libraries), libpnpba_core.so, a
// plugin or the Python module. For the executable the loader reports only argv[0], which a
// command found through PATH gives without its folder (and a caller may set to anything), so
// the executable is read from /proc/self/exe.
std::string thisObjectPath() {
  Dl_info info{};
  link_map* object = nullptr;
  if (dladdr1(reinterpret_cast<void*>(&pluginSearchPath), &info, reinterpret_cast<void**>(&object),
              RTLD_DL_LINKMAP) == 0) {
    return "";
  }
  char resolved[4096];
  const bool executable =
      object != nullptr && object->l_name != nullptr && object->l_name[0] == '\0';
  if (executable) {
    const ssize_t n = readlink("/proc/self/exe", resolved, sizeof resolved - 1);
    if (n > 0) return std::string(resolved, static_cast<size_t>(n));
  }
  if (info.dli_fname == nullptr) return "";
  if (realpath(info.dli_fname, resolved) == nullptr) return info.dli_fname;
  return resolved;
}

std::string folderOf(const std::string& path) {
  const size_t slash = path.rfind('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

bool startsWith(const std::string& s, const std::string& prefix) {
  return !prefix.empty() && s.compare(0, prefix.size(), prefix) == 0;
}

}  // namespace

std::vector<std::string> pluginSearchPath() {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("PNPBA_PLUGIN_DIR"); env != nullptr && *env != '\0') {
    dirs.push_back(env);
  }
  const std::string object = thisObjectPath();
  const std::string build_dir = PNPBA_PLUGIN_BUILD_DIR;
  const bool in_build_tree = startsWith(object, std::string(PNPBA_BINARY_DIR) + "/");
  if (in_build_tree) dirs.push_back(build_dir);
  if (!object.empty()) {
    // An installed tree, wherever it was moved: <libdir>/pnpba beside a shared libpnpba_core,
    // or <prefix>/<libdir>/pnpba above the executable (<prefix>/bin) or the Python module
    // (<prefix>/lib/python3/dist-packages/pnpba, a venv's lib/python3.X/site-packages/pnpba).
    std::string here = folderOf(object);
    dirs.push_back(here + "/pnpba");
    for (int up = 0; up < 5 && here.size() > 1; ++up) {
      here = folderOf(here);
      dirs.push_back((here == "/" ? "" : here) + "/" PNPBA_PLUGIN_INSTALL_SUBDIR);
    }
  }
  dirs.push_back(PNPBA_PLUGIN_INSTALL_DIR);
  if (!in_build_tree) dirs.push_back(build_dir);
  return dirs;
}

bool pluginLoaded(const std::string& name) {
  const std::lock_guard<std::mutex> lock(pluginMutex());
  return loadedPlugins().count(name) > 0;
}

void* pluginSymbol(const std::string& name, const std::string& symbol) {
  const std::lock_guard<std::mutex> lock(pluginMutex());
  void*& handle = loadedPlugins()[name];
  const std::string file = "libpnpba_" + name + ".so";
  if (handle == nullptr) {
    std::string tried;
    std::set<std::string> seen;
    for (const std::string& dir : pluginSearchPath()) {
      const std::string path = dir + "/" + file;
      if (!seen.insert(path).second) continue;  // the same folder reached twice
      // Lazy binding: a plugin's libraries (Open3D's are about 100) resolve their functions when
      // first called rather than all at load, which was most of the load's symbol lookups (the
      // Open3D plugin: 75 -> 55 ms in latency_bench, 36 -> 30 ms in the command-line tool, 32.5
      // -> 28 ms from Python). The ABI tag below still rejects a plugin of another build at once.
      // RTLD_DEEPBIND would save 10 ms more but binds the plugin's libraries to libstdc++'s and
      // libc's own std::cout, std::cerr and __libc_single_threaded where the executable holds
      // copies of them.
      void* h = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
      if (h == nullptr) {
        const char* why = dlerror();
        // A missing file is the common case; any other reason is worth reporting.
        tried += "\n  " + path + ": " +
                 (access(path.c_str(), F_OK) != 0 ? std::string("not found")
                  : why                           ? why
                                                  : "?");
        continue;
      }
      using Abi = const char*();
      auto* abi = reinterpret_cast<Abi*>(dlsym(h, "pnpba_plugin_abi"));
      if (abi == nullptr || std::string(abi()) != PNPBA_PLUGIN_ABI) {
        tried += "\n  " + path + ": built for another version of pnpba (" +
                 (abi ? abi() : "no ABI tag") + ", expected " PNPBA_PLUGIN_ABI ")";
        dlclose(h);
        continue;
      }
      handle = h;
      break;
    }
    if (handle == nullptr) {
      loadedPlugins().erase(name);
      throw Error("pnpba: cannot load the plugin " + file +
                  " (reinstall pnpba, or set PNPBA_PLUGIN_DIR to its folder); tried:" + tried);
    }
  }
  void* address = dlsym(handle, symbol.c_str());
  if (address == nullptr) throw Error("pnpba: plugin " + file + " lacks " + symbol);
  return address;
}

}  // namespace pnpba
