// One libFuzzer binary per target (fuzz/CMakeLists.txt sets DAYLIT_FUZZ_TARGET). With
// DAYLIT_FUZZ_SEEDS=DIR in the environment it first writes the target's seed inputs into DIR
// (scripts/fuzz.sh does, beside the bundled recordings' files).
#include <cstdlib>
#include <filesystem>

#include "fuzz/targets.h"

namespace {
const daylit::fuzz::Target* target = nullptr;
}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  target = &daylit::fuzz::FindTarget(DAYLIT_FUZZ_TARGET);
  target->init();
  if (const char* seeds = std::getenv("DAYLIT_FUZZ_SEEDS")) {
    std::filesystem::create_directories(seeds);
    target->write_seeds(seeds);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  target->run(data, size);
  return 0;
}
