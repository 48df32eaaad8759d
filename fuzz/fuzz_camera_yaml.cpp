// ORB-SLAM2-style camera settings (--camera FILE).
#include "fuzz_input.h"
#include "pnpba/pipeline/camera.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return pnpba::fuzz::readAsFile(
      data, size, [](const std::string& path) { (void)pnpba::loadCameraYaml(path); });
}
