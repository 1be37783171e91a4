#include "capture/video_decoder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
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

// Every pixel of an odd-sized frame with padded rows against the conversion written out per pixel
// (in double): the columns past the last chroma sample, the odd columns' halfway chroma and the
// rows' vertical weights.
TEST(VideoDecoderTest, ConversionMatchesThePerPixelFormulaEverywhere) {
  const int w = 37, h = 23, cw = 19, ch = 12, y_stride = 40, c_stride = 24;
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> code(0, 255);
  std::vector<uint8_t> y(static_cast<size_t>(y_stride * h)), u(static_cast<size_t>(c_stride * ch)), v(u.size());
  for (uint8_t& b : y) b = static_cast<uint8_t>(code(rng));
  for (uint8_t& b : u) b = static_cast<uint8_t>(code(rng));
  for (uint8_t& b : v) b = static_cast<uint8_t>(code(rng));
  for (const bool bt709 : {false, true}) {
    cv::Mat out;
    Yuv420ToRgb(y.data(), y_stride, u.data(), c_stride, v.data(), c_stride, w, h, bt709, &out);
    ASSERT_EQ(out.type(), CV_32FC3);
    const double kr = bt709 ? 0.2126 : 0.299, kb = bt709 ? 0.0722 : 0.114, kg = 1.0 - kr - kb;
    const auto chroma = [&](const std::vector<uint8_t>& plane, int row, int col) {
      // Vertically centred between the two rows it spans, horizontally on even columns.
      const double cy = std::clamp((row - 0.5) / 2.0, 0.0, ch - 1.0), cx = std::min(col / 2.0, cw - 1.0);
      const auto at = [&](int i, int j) { return static_cast<double>(plane[static_cast<size_t>(i * c_stride + j)]); };
      const int i0 = static_cast<int>(cy), j0 = static_cast<int>(cx);
      const int i1 = std::min(i0 + 1, ch - 1), j1 = std::min(j0 + 1, cw - 1);
      const double fy = cy - i0, fx = cx - j0;
      const double c = (1 - fy) * ((1 - fx) * at(i0, j0) + fx * at(i0, j1)) + fy * ((1 - fx) * at(i1, j0) + fx * at(i1, j1));
      return (c - 128.0) / 224.0;
    };
    double worst = 0.0;
    for (int row = 0; row < h; ++row) {
      for (int col = 0; col < w; ++col) {
        const double l = (y[static_cast<size_t>(row * y_stride + col)] - 16.0) / 219.0;
        const double cb = chroma(u, row, col), cr = chroma(v, row, col);
        const double rgb[3] = {l + 2 * (1 - kr) * cr, l - 2 * (1 - kb) * kb / kg * cb - 2 * (1 - kr) * kr / kg * cr,
                               l + 2 * (1 - kb) * cb};
        for (int c = 0; c < 3; ++c) {
          worst = std::max(worst, std::abs(out.at<cv::Vec3f>(row, col)[c] - std::clamp(rgb[c], 0.0, 1.0)));
        }
      }
    }
    EXPECT_LT(worst, 1e-5) << (bt709 ? "BT.709" : "BT.601");
  }
}

}  // namespace
}  // namespace daylit::capture
