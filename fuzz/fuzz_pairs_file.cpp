// 3D-2D pairs files (bundle_adjust_pairs and --pairs).
#include "fuzz_input.h"
#include "pnpba/pipeline/pairs_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return pnpba::fuzz::readAsFile(data, size,
                                 [](const std::string& path) { (void)pnpba::readPairsFile(path); });
}
