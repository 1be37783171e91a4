// The main() of every test binary: GoogleTest's, after pointing the process's home, cache and
// temporary folders into the build tree (DAYLIT_BINARY_DIR/test-home, test-tmp), so that no test
// reads or writes the user's home (the default bake cache is $XDG_CACHE_HOME/daylit, Mesa's
// shader cache $XDG_CACHE_HOME/mesa_shader_cache) or leaves files in /tmp. Child processes (the
// daylit binary run by the CLI tests) inherit it. Set before any test runs, test discovery
// included, whether the binary runs under ctest or alone.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  const fs::path root(DAYLIT_BINARY_DIR);
  const std::pair<const char*, fs::path> folders[] = {
      {"HOME", root / "test-home"},
      {"XDG_CACHE_HOME", root / "test-home" / "cache"},
      {"XDG_CONFIG_HOME", root / "test-home" / "config"},
      {"XDG_DATA_HOME", root / "test-home" / "share"},
      {"TMPDIR", root / "test-tmp"},
  };
  for (const auto& [name, path] : folders) {
    std::error_code ec;
    fs::create_directories(path, ec);  // a folder that cannot be made fails the tests that use it
    ::setenv(name, path.c_str(), 1);
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
