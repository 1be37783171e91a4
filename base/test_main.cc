// The main() of every test binary: GoogleTest's, after setting DAYLIT_TEST_ENVIRONMENT
// (cmake/DaylitHelpers.cmake: HOME, the XDG folders and TMPDIR inside the build tree, as
// "NAME=folder|NAME=folder...") and making its folders, so that no test reads or writes the
// user's home (the default bake cache is $XDG_CACHE_HOME/daylit, Mesa's shader cache
// $XDG_CACHE_HOME/mesa_shader_cache) or leaves files in /tmp. Child processes (the daylit binary
// run by the CLI tests) inherit it. Set before any test runs, test discovery included, whether
// the binary runs under ctest or alone.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

int main(int argc, char** argv) {
  std::string_view rest = DAYLIT_TEST_ENVIRONMENT;
  while (!rest.empty()) {
    const std::string_view entry = rest.substr(0, rest.find('|'));
    rest.remove_prefix(std::min(rest.size(), entry.size() + 1));
    const size_t eq = entry.find('=');
    const std::string name(entry.substr(0, eq)), folder(entry.substr(eq + 1));
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);  // a folder that cannot be made fails the tests that use it
    ::setenv(name.c_str(), folder.c_str(), 1);
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
