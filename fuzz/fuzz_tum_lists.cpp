// TUM lists: rgb.txt / depth.txt (stamped file names), associate.txt, groundtruth.txt.
#include "fuzz_input.h"
#include "pnpba/evaluation/tum_dataset.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The first byte picks the list kind, so one corpus covers all three readers.
  if (size == 0) return 0;
  const uint8_t kind = data[0] % 3;
  return pnpba::fuzz::readAsFile(data + 1, size - 1, [kind](const std::string& path) {
    if (kind == 0) (void)pnpba::readStampedList(path);
    if (kind == 1) (void)pnpba::readAssociations(path);
    if (kind == 2) (void)pnpba::readTrajectory(path);
  });
}
