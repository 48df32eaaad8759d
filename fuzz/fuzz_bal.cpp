// BAL problem files (bundle_adjust_bal's input).
#include "fuzz_input.h"
#include "pnpba/bal/bal_problem.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return pnpba::fuzz::readAsFile(data, size, [](const std::string& path) {
    const pnpba::BalProblem p = pnpba::readBal(path);
    (void)p.cost();  // the indices the reader accepted must be usable
  });
}
