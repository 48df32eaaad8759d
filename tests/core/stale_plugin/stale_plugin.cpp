// A plugin of "another version" for plugin_test.cpp: its ABI tag is not this build's.
extern "C" __attribute__((visibility("default"))) const char* pnpba_plugin_abi() {
  return "pnpba-0.0.0-stale";
}
extern "C" __attribute__((visibility("default"))) int pnpba_stale_answer() { return 42; }
