// Every input the fuzzers once crashed on (fuzz/regressions/<target>/), replayed through its
// target in the normal suite: each must end with a result or an InputError (fuzz/targets.h).
// Under the sanitizer pass of scripts/test.sh a memory or UB error fails it too.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz/targets.h"

namespace daylit::fuzz {
namespace {

namespace fs = std::filesystem;

class FuzzRegressionTest : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzRegressionTest, EveryKeptInputEndsWithAResultOrAnInputError) {
  const Target& target = FindTarget(GetParam());
  const fs::path folder = fs::path(DAYLIT_SOURCE_DIR) / "fuzz" / "regressions" / GetParam();
  target.init();
  // The seeds too: the inputs the target is known to accept must still be read.
  const fs::path seeds = fs::path(DAYLIT_BINARY_DIR) / "test-tmp" / ("fuzz_seeds_" + GetParam() + "_" + std::to_string(::getpid()));
  fs::create_directories(seeds);
  target.write_seeds(seeds);
  size_t inputs = 0;
  for (const fs::path& dir : {folder, seeds}) {
    if (!fs::is_directory(dir)) continue;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
      std::ifstream in(entry.path(), std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), {});
      SCOPED_TRACE(entry.path().string());
      target.run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
      ++inputs;
    }
  }
  fs::remove_all(seeds);
  EXPECT_GT(inputs, 0u);
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzRegressionTest,
                         ::testing::Values("scene_json", "obj", "csv", "exr", "hdr", "gltf", "bake_cache", "video", "http_request"),
                         [](const ::testing::TestParamInfo<std::string>& param) { return param.param; });

}  // namespace
}  // namespace daylit::fuzz
