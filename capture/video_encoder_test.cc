#include "capture/video_encoder.h"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <random>
#include <string>

#include <sys/resource.h>

#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "capture/video_decoder.h"

namespace daylit::capture {
namespace {

namespace fs = std::filesystem;

// A smooth colour field with some texture, encoded values in [0.05, 0.95].
cv::Mat TestFrame(int w, int h, int seed, float noise_amplitude = 0.01f) {
  cv::Mat rgb(h, w, CV_32FC3);
  std::mt19937 rng(static_cast<uint32_t>(seed));
  std::uniform_real_distribution<float> noise(-noise_amplitude, noise_amplitude);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float fx = static_cast<float>(x) / static_cast<float>(w), fy = static_cast<float>(y) / static_cast<float>(h);
      rgb.at<cv::Vec3f>(y, x) = {0.05f + 0.85f * fx + noise(rng), 0.5f + 0.4f * std::sin(6.0f * fy + 0.1f * static_cast<float>(seed)),
                                 0.05f + 0.8f * fy * fx};
    }
  }
  return rgb;
}

cv::Mat ThroughYuv(const cv::Mat& rgb) {
  const int w = rgb.cols, h = rgb.rows;
  std::vector<uint8_t> y(static_cast<size_t>(w * h)), u(static_cast<size_t>(w * h / 4)), v(u.size());
  RgbToYuv420(rgb, y.data(), w, u.data(), w / 2, v.data(), w / 2);
  cv::Mat back;
  Yuv420ToRgb(y.data(), w, u.data(), w / 2, v.data(), w / 2, w, h, false, &back);
  return back;
}

TEST(VideoEncoderTest, ConversionIsTheDecodersInverseToRounding) {
  const cv::Mat rgb = TestFrame(320, 240, 1, 0.0f);  // smooth: 4:2:0 keeps all its colour
  const cv::Mat back = ThroughYuv(rgb);
  cv::Mat diff = back - rgb;
  const double bias = cv::mean(diff.reshape(1))[0];
  cv::Mat absolute = cv::abs(diff);
  const double mean = cv::mean(absolute.reshape(1))[0];
  // 8-bit luma steps are 1/219 of full scale: ±0.6 of a full-range code; chroma rounding and
  // siting add a little. No bias.
  EXPECT_LT(mean, 0.4 / 255.0);
  EXPECT_LT(std::abs(bias), 0.02 / 255.0);
}

TEST(VideoEncoderTest, LosslessH264ReadsBackExactlyWithFrameNumbers) {
  const fs::path dir = fs::path(DAYLIT_BINARY_DIR) / "video_encoder_test";
  fs::create_directories(dir);
  const fs::path file = dir / "lossless.mp4";
  {
    VideoEncoder encoder(file, 160, 120, VideoEncoderOptions{10.0, 0, "veryfast"});
    for (int i = 0; i < 10; ++i) encoder.Write(TestFrame(160, 120, i));
    encoder.Finish();
  }
  VideoDecoder decoder(file);
  cv::Mat frame;
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(decoder.Next(&frame)) << i;
    EXPECT_EQ(decoder.last_index(), i);
    EXPECT_EQ(cv::norm(frame, ThroughYuv(TestFrame(160, 120, i)), cv::NORM_INF), 0.0) << "frame " << i;
  }
  EXPECT_FALSE(decoder.Next(&frame));
}

TEST(VideoEncoderTest, BadSizesAndPathsAreErrorsNamingTheFile) {
  EXPECT_THROW(VideoEncoder("/tmp/odd.mp4", 161, 120), InputError);
  // Its options are checked before anything is opened: a frame rate no video has.
  const fs::path fast = fs::path(DAYLIT_BINARY_DIR) / "video_encoder_test" / "fast.mp4";
  fs::create_directories(fast.parent_path());
  try {
    VideoEncoder(fast, 160, 120, VideoEncoderOptions{5000.0});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fast.string() + ": fps: 5000"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(fast));
  try {
    VideoEncoder("/no/such/folder/out.mp4", 160, 120);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/folder/out.mp4: cannot open for writing"), std::string::npos) << e.what();
  }
}

// A full disk is the machine's failure (SystemError, exit 1), not the input's: the file's size
// limited to 16 KiB for this process (its signal ignored, so writes fail with EFBIG as on a full
// disk), lossless frames of noise, tens of KiB each.
TEST(VideoEncoderTest, AFullDiskIsTheMachinesFailureNotTheInputs) {
  const fs::path dir = fs::path(DAYLIT_BINARY_DIR) / "video_encoder_test";
  fs::create_directories(dir);
  const fs::path file = dir / "full.mp4";
  struct LimitedFileSize {
    rlimit before{};
    void (*handler)(int) = SIG_DFL;
    LimitedFileSize() {
      getrlimit(RLIMIT_FSIZE, &before);
      handler = std::signal(SIGXFSZ, SIG_IGN);
      rlimit limited = before;
      limited.rlim_cur = 16 * 1024;
      setrlimit(RLIMIT_FSIZE, &limited);
    }
    ~LimitedFileSize() {
      setrlimit(RLIMIT_FSIZE, &before);
      std::signal(SIGXFSZ, handler);
    }
  };
  std::string message;
  {
    const LimitedFileSize limit;
    try {
      VideoEncoder encoder(file, 160, 120, VideoEncoderOptions{10.0, 0, "veryfast"});
      for (int i = 0; i < 20; ++i) encoder.Write(TestFrame(160, 120, i, 0.3f));
      encoder.Finish();
      ADD_FAILURE() << "no error";
    } catch (const SystemError& e) {
      message = e.what();
    } catch (const InputError& e) {
      ADD_FAILURE() << "an input error: " << e.what();
    }
  }
  EXPECT_NE(message.find(file.string() + ": cannot"), std::string::npos) << message;
  EXPECT_NE(message.find("too large"), std::string::npos) << message;  // EFBIG's words, from libav
  fs::remove(file);
}

}  // namespace
}  // namespace daylit::capture
