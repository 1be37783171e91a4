#include "capture/response.h"

#include <gtest/gtest.h>

namespace daylit::capture {
namespace {

TEST(ResponseTest, SrgbMatchesIec61966Values) {
  const CameraResponse srgb;
  EXPECT_NEAR(srgb.ToLinear(0.5), 0.214041, 1e-6);
  EXPECT_NEAR(srgb.ToLinear(0.04045), 0.04045 / 12.92, 1e-12);  // the linear segment's end
  EXPECT_NEAR(srgb.LinearLut8()[128], 0.2158605, 1e-6);
  EXPECT_FLOAT_EQ(srgb.LinearLut8()[255], 1.0f);
}

TEST(ResponseTest, EveryCurveRoundTrips) {
  for (const CameraResponse r : {CameraResponse{ResponseCurve::kLinear, 1.0},
                                 CameraResponse{ResponseCurve::kSrgb, 1.0},
                                 CameraResponse{ResponseCurve::kGamma, 2.6}}) {
    for (int i = 0; i <= 1000; ++i) {
      const double x = i / 1000.0;
      ASSERT_NEAR(r.ToEncoded(r.ToLinear(x)), x, 1e-9) << r.Describe() << " at " << x;
    }
  }
  EXPECT_NEAR((CameraResponse{ResponseCurve::kGamma, 2.0}.ToLinear(0.5)), 0.25, 1e-12);
}

TEST(ResponseTest, TableLinearizationFollowsTheCurve) {
  const CameraResponse srgb;
  std::vector<float> encoded(10001), linear(encoded.size());
  for (size_t i = 0; i < encoded.size(); ++i) encoded[i] = static_cast<float>(i) / 10000.0f;
  srgb.Linearize(encoded.data(), linear.data(), encoded.size());
  for (size_t i = 0; i < encoded.size(); ++i) ASSERT_NEAR(linear[i], srgb.ToLinear(encoded[i]), 1e-5) << encoded[i];
}

}  // namespace
}  // namespace daylit::capture
