#include "capture/camera_calibration.h"

#include <gtest/gtest.h>

#include <cstdio>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"

namespace daylit::capture {
namespace {

// A 9×6 (inner corners) board of 3 cm squares seen by a 640×480 pinhole camera, fx = fy = 600,
// principal point (322, 236), no distortion: each view is the board texture warped by the
// homography K [r1 r2 t] of its pose.
constexpr double kFx = 600.0, kCx = 322.0, kCy = 236.0, kSquare = 0.03;
constexpr int kPx = 40;  // texture pixels per square

cv::Mat BoardTexture() {
  // 10 × 7 squares inside a one-square white margin.
  cv::Mat t(9 * kPx, 12 * kPx, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < 7; ++r) {
    for (int c = 0; c < 10; ++c) {
      if ((r + c) % 2 == 0) t(cv::Rect((c + 1) * kPx, (r + 1) * kPx, kPx, kPx)).setTo(0);
    }
  }
  return t;
}

cv::Mat View(const cv::Mat& texture, const cv::Vec3d& rvec, double distance) {
  cv::Matx33d r;
  cv::Rodrigues(rvec, r);
  // The board's centre (between the inner corners) on the optical axis at `distance`.
  const cv::Vec3d centre(4 * kSquare, 2.5 * kSquare, 0.0);
  const cv::Vec3d t = cv::Vec3d(0, 0, distance) - r * centre;
  const cv::Matx33d k(kFx, 0, kCx, 0, kFx, kCy, 0, 0, 1);
  const cv::Matx33d rt(r(0, 0), r(0, 1), t[0], r(1, 0), r(1, 1), t[1], r(2, 0), r(2, 1), t[2]);
  // Texture pixel (u, v) → board metres: the first inner corner is 2 squares in.
  const double m = kSquare / kPx;
  const cv::Matx33d s(m, 0, -2 * kSquare, 0, m, -2 * kSquare, 0, 0, 1);
  cv::Mat view;
  cv::warpPerspective(texture, view, cv::Mat(k * rt * s), cv::Size(640, 480), cv::INTER_AREA, cv::BORDER_CONSTANT,
                      cv::Scalar(160));
  return view;
}

TEST(CameraCalibrationTest, RecoversTheIntrinsicsOfSyntheticViews) {
  const cv::Mat texture = BoardTexture();
  std::vector<cv::Mat> views;
  std::vector<std::string> names;
  const std::vector<cv::Vec3d> poses = {{0.3, 0.0, 0.0},  {-0.3, 0.1, 0.05}, {0.0, 0.35, 0.0}, {0.1, -0.35, 0.1},
                                        {0.25, 0.25, 0.2}, {-0.2, -0.25, -0.1}, {0.4, -0.1, 0.0}, {0.0, 0.0, 0.3}};
  for (size_t i = 0; i < poses.size(); ++i) {
    views.push_back(View(texture, poses[i], 0.55 + 0.03 * static_cast<double>(i % 3)));
    names.push_back("view" + std::to_string(i));
  }
  views.push_back(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)));  // no board in it
  names.push_back("blank");
  const CameraCalibration c = CalibrateCamera(views, names, Chessboard{9, 6, kSquare});
  std::printf("fx %.2f fy %.2f cx %.2f cy %.2f rms %.3f px, %zu views used\n", c.fx, c.fy, c.cx, c.cy, c.rms_px, c.used.size());
  EXPECT_EQ(c.used.size(), poses.size());
  EXPECT_EQ(c.width, 640);
  EXPECT_EQ(c.height, 480);
  EXPECT_NEAR(c.fx, kFx, 0.01 * kFx);
  EXPECT_NEAR(c.fy, kFx, 0.01 * kFx);
  EXPECT_NEAR(c.cx, kCx, 3.0);
  EXPECT_NEAR(c.cy, kCy, 3.0);
  EXPECT_LT(c.rms_px, 0.3);
  ASSERT_EQ(c.distortion.size(), 5u);
  EXPECT_LT(std::abs(c.distortion[0]), 0.05);
}

TEST(CameraCalibrationTest, TooFewBoardsOrMixedSizesAreErrors) {
  const cv::Mat texture = BoardTexture();
  const std::vector<cv::Mat> one = {View(texture, {0.2, 0.1, 0.0}, 0.6), cv::Mat(480, 640, CV_8UC1, cv::Scalar(90))};
  try {
    CalibrateCamera(one, {"a.png", "b.png"}, Chessboard{9, 6, kSquare});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("found in 1 of 2 images; at least 3"), std::string::npos) << e.what();
  }
  const std::vector<cv::Mat> mixed = {View(texture, {0.2, 0.1, 0.0}, 0.6), cv::Mat(240, 320, CV_8UC1)};
  try {
    CalibrateCamera(mixed, {"a.png", "small.png"}, Chessboard{9, 6, kSquare});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("small.png: 320x240, but a.png is 640x480"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace daylit::capture
