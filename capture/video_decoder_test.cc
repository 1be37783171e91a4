#include "capture/video_decoder.h"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "base/error.h"

namespace daylit::capture {
namespace {

TEST(VideoDecoderTest, ConversionMatchesTheStandardOnFlatColours) {
  // Limited-range BT.601: (Y, U, V) = (235, 128, 128) is white, (16, 128, 128) black, and
  // (81, 90, 240) is the standard's 75%-free red (R' = 1, G' = B' = 0).
  for (const auto& [yuv, rgb] : std::vector<std::pair<std::array<uint8_t, 3>, std::array<float, 3>>>{
           {{235, 128, 128}, {1, 1, 1}}, {{16, 128, 128}, {0, 0, 0}}, {{81, 90, 240}, {1, 0, 0}}}) {
    std::vector<uint8_t> y(16, yuv[0]), u(4, yuv[1]), v(4, yuv[2]);
    cv::Mat out;
    Yuv420ToRgb(y.data(), 4, u.data(), 2, v.data(), 2, 4, 4, false, &out);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out.at<cv::Vec3f>(2, 2)[c], rgb[static_cast<size_t>(c)], 0.01f) << c;
  }
  EXPECT_THROW(VideoDecoder(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/model.obj"), InputError);
}

}  // namespace
}  // namespace daylit::capture
