// Compiled into every plugin (cmake/PnpbaModule.cmake, pnpba_plugin): the tag the loader in
// core/src/plugin.cpp compares with its own before it calls anything in the plugin.
extern "C" __attribute__((visibility("default"))) const char* pnpba_plugin_abi() {
  return PNPBA_PLUGIN_ABI;
}
