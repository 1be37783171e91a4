// Decoding the bundled recording against its noise-free ground truth: the exact conversion of
// capture/video_decoder.h, and the bias of OpenCV's default path that it removes.
#include <gtest/gtest.h>

#include <algorithm>

#include <fmt/format.h>

#include <opencv2/videoio.hpp>

#include "capture/response.h"
#include "capture/video_decoder.h"
#include "scene/hdr_image.h"
#include "scene/scene.h"

namespace daylit {
namespace {

using capture::CameraResponse;
using capture::VideoDecoder;

constexpr int kFrame = 40;  // a frame with a noise-free ground truth (groundtruth/without_objects)

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + static_cast<ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Median of decoded / true linear value over pixels whose true value is in [lo, hi).
double MedianRatio(const cv::Mat& linear_rgb, const HdrImage& truth, double exposure, double lo, double hi) {
  std::vector<double> ratios;
  for (int y = 0; y < truth.height; ++y) {
    for (int x = 0; x < truth.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double t = exposure * truth.Pixel(x, y)[c];
        if (t >= lo && t < hi) ratios.push_back(linear_rgb.at<cv::Vec3f>(y, x)[c] / t);
      }
    }
  }
  return Median(ratios);
}

cv::Mat Linearize(const cv::Mat& encoded_rgb) {
  const CameraResponse srgb;
  cv::Mat out(encoded_rgb.size(), CV_32FC3);
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      for (int c = 0; c < 3; ++c) out.at<cv::Vec3f>(y, x)[c] = static_cast<float>(srgb.ToLinear(encoded_rgb.at<cv::Vec3f>(y, x)[c]));
    }
  }
  return out;
}

TEST(VideoDecoderTest, DecodesTheRecordingExactly) {
  const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const HdrImage truth = scene::ReadHdrImage(
      fmt::format(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/groundtruth/without_objects/{:06d}.exr", kFrame));
  const double exposure = scene.frame_times->ExposureOf(kFrame, scene.exposure);

  VideoDecoder decoder(scene.frames.video);
  EXPECT_EQ(decoder.width(), 960);
  cv::Mat rgb;
  for (int f = 0; f <= kFrame; ++f) ASSERT_TRUE(decoder.Next(&rgb)) << f;
  const cv::Mat ours = Linearize(rgb);

  // OpenCV's default path, for comparison: its BGR 8-bit frame, linearised the same way.
  cv::VideoCapture capture(scene.frames.video.string(), cv::CAP_FFMPEG);
  cv::Mat bgr;
  for (int f = 0; f <= kFrame; ++f) capture.read(bgr);
  cv::Mat theirs_encoded(bgr.size(), CV_32FC3);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      for (int c = 0; c < 3; ++c) theirs_encoded.at<cv::Vec3f>(y, x)[c] = bgr.at<cv::Vec3b>(y, x)[2 - c] / 255.0f;
    }
  }
  const cv::Mat theirs = Linearize(theirs_encoded);

  // From 0.05 to 0.8 (linear, after exposure) the exact conversion reads the truth within 0.5%
  // overall, and within 1.5% in every octave from 0.1 up; OpenCV's default path reads 2.6% dark.
  const double mid_ours = MedianRatio(ours, truth, exposure, 0.05, 0.8);
  const double mid_theirs = MedianRatio(theirs, truth, exposure, 0.05, 0.8);
  std::printf("decoded/true linear, 0.05..0.8: ours %.4f, OpenCV default %.4f\n", mid_ours, mid_theirs);
  EXPECT_NEAR(mid_ours, 1.0, 0.005);
  EXPECT_LT(mid_theirs, 0.985);
  for (const double lo : {0.1, 0.2, 0.4}) {
    const double band = MedianRatio(ours, truth, exposure, lo, 2 * lo);
    std::printf("  %.2f..%.2f: ours %.4f, OpenCV default %.4f\n", lo, 2 * lo, band, MedianRatio(theirs, truth, exposure, lo, 2 * lo));
    EXPECT_NEAR(band, 1.0, 0.015) << lo;
  }
  // Darker, the data itself departs from its noise-free truth: +3% at 0.05..0.1, and deep shadow
  // (0.01..0.05) reads 16-31% above it with either decoder (8-bit
  // limited-range luma steps are 6-18% of linear light there, and the data's own noise floor):
  // not a decoding matter; recorded for the estimation (docs/bake.md, issue 4). Ours still reads
  // it higher than the truncating default, by the truncation's 1-1.4 codes.
  EXPECT_GT(MedianRatio(ours, truth, exposure, 0.01, 0.05), MedianRatio(theirs, truth, exposure, 0.01, 0.05) * 1.04);
}

}  // namespace
}  // namespace daylit
