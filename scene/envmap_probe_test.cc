#include "scene/envmap_probe.h"

#include <gtest/gtest.h>

#include "base/error.h"

namespace daylit::scene {
namespace {

TEST(EnvMapProbeTest, ReadsExrHeaderOfTheBundledRecording) {
  const EnvMapHeader h = ProbeEnvMap(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/envmap.exr");
  EXPECT_EQ(h.width, 1024);
  EXPECT_EQ(h.height, 512);
  EXPECT_EQ(h.format, "OpenEXR");
  EXPECT_NE(h.channels.find('R'), std::string::npos);
}

TEST(EnvMapProbeTest, NonImagesAreInputErrors) {
  EXPECT_THROW(ProbeEnvMap(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/model.obj"), InputError);
  EXPECT_THROW(ProbeEnvMap(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/frames.csv.exr"), InputError);
}

}  // namespace
}  // namespace daylit::scene
