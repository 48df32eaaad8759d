// Direct-BA inputs: poses.txt (first byte even) and points.txt (odd).
#include "fuzz_input.h"
#include "pnpba/direct/direct_ba.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const bool poses = data[0] % 2 == 0;
  return pnpba::fuzz::readAsFile(data + 1, size - 1, [poses](const std::string& path) {
    if (poses) {
      (void)pnpba::readDirectPoses(path);
    } else {
      (void)pnpba::readDirectPoints(path);
    }
  });
}
