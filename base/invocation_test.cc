#include "base/invocation.h"

#include <gtest/gtest.h>

#include <filesystem>

namespace daylit {
namespace {

// The command line reads back in a POSIX shell as the same words: plain words bare, the others
// (spaces, quotes, $, an empty word) single-quoted.
TEST(InvocationTest, TheCommandLineQuotesWhatAShellWouldSplitOrExpand) {
  const char* const argv[] = {"build/bin/daylit", "replay", "my recordings/a", "--out", "it's.mp4", "$HOME", "", "--frames=20"};
  RecordInvocation(8, argv);
  const Invocation& r = CurrentInvocation();
  ASSERT_EQ(r.argv.size(), 8u);
  EXPECT_EQ(r.CommandLine(), "build/bin/daylit replay 'my recordings/a' --out 'it'\\''s.mp4' '$HOME' '' --frames=20");
  EXPECT_EQ(r.cwd, std::filesystem::current_path().string());
  EXPECT_EQ(r.started_utc.size(), 20u) << r.started_utc;  // 2026-12-07T12:00:00Z
  EXPECT_EQ(r.started_utc.back(), 'Z');
}

}  // namespace
}  // namespace daylit
