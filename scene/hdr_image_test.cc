#include "scene/hdr_image.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "base/error.h"

namespace daylit::scene {
namespace {

std::filesystem::path Temp(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("daylit_hdr_" + std::to_string(::getpid()) + "_" + name);
}

TEST(HdrImageTest, TinyOrBlackEnvMapsAreRefusedByName) {
  // A 2x1 map passes for 2:1; an all-black one has no light: both would give E = 0 and NaN errors.
  const auto message = [](const HdrImage& image) {
    try {
      CheckEnvMap(image, "env.exr");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(HdrImage{2, 1, std::vector<float>(6, 1.0f)}),
            "env.exr: 2x1 is too small for a light probe (at least 64 texels across: each under 6°)");
  EXPECT_EQ(message(HdrImage{128, 64, std::vector<float>(128 * 64 * 3, 0.0f)}),
            "env.exr: every texel is black: a light probe with no light (estimates would be 0 and errors NaN)");
  std::vector<float> one_light(128 * 64 * 3, 0.0f);
  one_light[777] = 0.5f;
  EXPECT_EQ(message(HdrImage{128, 64, one_light}), "");
}

TEST(HdrImageTest, ReadsTheBundledEnvMapAsFloats) {
  const HdrImage env = ReadHdrImage(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/envmap.exr");
  ASSERT_EQ(env.width, 1024);
  ASSERT_EQ(env.height, 512);
  EXPECT_NO_THROW(CheckEnvMap(env, "envmap.exr"));
  // The sun disc is in the map unclipped: far brighter than half-float's 65504 would matter
  // for, and far brighter than the sky.
  float peak = 0.0f;
  for (const float v : env.rgb) peak = std::max(peak, v);
  EXPECT_GT(peak, 1000.0f);
}

TEST(HdrImageTest, MultiChannelExrRoundTripsFloatHalfAndUint) {
  const int w = 5, h = 3;
  std::vector<float> a(w * h), b(w * h);
  std::vector<uint32_t> ids(w * h);
  for (int i = 0; i < w * h; ++i) a[i] = 1e5f * static_cast<float>(i) + 0.125f, b[i] = 0.5f * static_cast<float>(i), ids[i] = 4000000u + static_cast<uint32_t>(i);
  const auto path = Temp("layers.exr");
  WriteExr(path, w, h, {{"point.X", ExrPixelType::kFloat, a.data(), nullptr},
                        {"V.Y", ExrPixelType::kHalf, b.data(), nullptr},
                        {"surface", ExrPixelType::kUint, nullptr, ids.data()}});
  const ExrChannels back = ReadExrChannels(path, {"V.Y", "point.X"});
  ASSERT_EQ(back.width, w);
  EXPECT_EQ(back.planes[1], a);  // float: exact
  EXPECT_EQ(back.planes[0], b);  // halves of these values are exact
  EXPECT_EQ(ReadExrChannels(path, {}, {"surface"}).uints[0], ids);
  EXPECT_THROW(ReadExrChannels(path, {"albedo.R"}), InputError);
  std::filesystem::remove(path);
}

// A header attribute or a pixel chunk whose size runs past the end of the file: OpenEXR would
// allocate the claimed bytes (up to 2 GB, found by fuzz_exr) before it notices the file is short.
TEST(HdrImageTest, SizesThatLeaveTheFileAreRefusedBeforeOpenExrAllocatesThem) {
  const int w = 16, h = 64;  // ZIP: 16 rows a chunk, 4 chunks
  std::vector<float> r(w * h);
  for (int i = 0; i < w * h; ++i) r[i] = std::sin(0.1f * static_cast<float>(i));
  const auto path = Temp("whole.exr");
  WriteExr(path, w, h, {{"R", ExrPixelType::kFloat, r.data(), nullptr}});
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(ReadExrChannels(path, {"R"}).planes[0], r);
  const auto message = [](const std::filesystem::path& file) {
    try {
      ReadExrChannels(file, {"R"});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const auto damaged = Temp("damaged.exr");
  std::ofstream(damaged, std::ios::binary) << bytes.substr(0, bytes.size() - 10);  // the last chunk cut short
  EXPECT_NE(message(damaged).find("a chunk claims"), std::string::npos) << message(damaged);
  std::string huge_attribute = bytes;
  const size_t at = huge_attribute.find(std::string("compression\0compression\0", 24));
  ASSERT_NE(at, std::string::npos);
  const int32_t size = 0x7fffffff;
  huge_attribute.replace(at + 24, 4, reinterpret_cast<const char*>(&size), 4);
  std::ofstream(damaged, std::ios::binary | std::ios::trunc) << huge_attribute;
  EXPECT_NE(message(damaged).find("attribute 'compression' claims 2147483647 bytes past the end"), std::string::npos)
      << message(damaged);
  std::filesystem::remove(path), std::filesystem::remove(damaged);
}

// A run-length encoded Radiance scan line built by hand: R a run of 128s, G a dump of 0, 16, ...,
// 112, B a run of 0s, E a run of 129, so each texel is (128, 16k, 0)·2^(129−136) = (1, k/8, 0).
// A run of length 0 (stb_image loops forever on it) and a file cut inside the line are errors.
TEST(HdrImageTest, RunLengthScanLinesDecodeAndHostileOnesAreRefused) {
  const std::string header = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
  std::string line = {2, 2, 0, 8, static_cast<char>(128 + 8), static_cast<char>(128), 8};
  for (int k = 0; k < 8; ++k) line += static_cast<char>(16 * k);
  line += {static_cast<char>(128 + 8), 0, static_cast<char>(128 + 8), static_cast<char>(129)};
  const auto path = Temp("rle.hdr");
  std::ofstream(path, std::ios::binary) << header << line;
  const HdrImage image = ReadHdrImage(path);
  ASSERT_EQ(image.width, 8);
  ASSERT_EQ(image.height, 1);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(image.Pixel(k, 0)[0], 1.0f) << k;
    EXPECT_EQ(image.Pixel(k, 0)[1], static_cast<float>(k) / 8.0f) << k;
    EXPECT_EQ(image.Pixel(k, 0)[2], 0.0f) << k;
  }
  const auto message = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    try {
      ReadHdrImage(path);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string zero_run = line;
  zero_run[4] = 0;  // R: a dump of 0 values
  EXPECT_NE(message(header + zero_run).find("a run of 0 in scan line 0"), std::string::npos) << message(header + zero_run);
  EXPECT_NE(message(header + line.substr(0, 12)).find("ends inside scan line 0"), std::string::npos);
  std::filesystem::remove(path);
}

TEST(HdrImageTest, EnvMapChecksNameTheCause) {
  HdrImage image{64, 32, std::vector<float>(64 * 32 * 3, 1.0f)};
  EXPECT_NO_THROW(CheckEnvMap(image, "e.exr"));
  image.Pixel(3, 2)[1] = NAN;
  image.Pixel(5, 2)[0] = -1.0f;
  try {
    CheckEnvMap(image, "e.exr");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "e.exr: 1 texel values are NaN or infinite and 1 are negative, first at (u 3, v 2)");
  }
  HdrImage square{4, 4, std::vector<float>(4 * 4 * 3, 1.0f)};
  EXPECT_THROW(CheckEnvMap(square, "e.exr"), InputError);
  EXPECT_THROW(ReadHdrImage(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/model.obj"), InputError);
}

TEST(HdrImageTest, ReadsRadianceHdr) {
  // A Radiance file written by OpenCV, read back through the same path users' .hdr probes take.
  const auto path = Temp("probe.hdr");
  cv::Mat bgr(2, 4, CV_32FC3, cv::Scalar(0, 0, 0));
  bgr.at<cv::Vec3f>(0, 1)[2] = 1000.0f;
  bgr.at<cv::Vec3f>(1, 2)[0] = 0.25f;
  ASSERT_TRUE(cv::imwrite(path.string(), bgr));
  const HdrImage back = ReadHdrImage(path);
  EXPECT_NEAR(back.Pixel(1, 0)[0], 1000.0f, 1000.0f / 128);  // RGBE: 8-bit mantissa
  EXPECT_NEAR(back.Pixel(2, 1)[2], 0.25f, 0.25f / 128);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace daylit::scene
