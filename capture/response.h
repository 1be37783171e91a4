// How a camera encodes linear light in pixel values, and its inverse (linearisation).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace daylit::capture {

enum class ResponseCurve { kLinear, kSrgb, kGamma, kTable };

// A calibrated response (`daylit calibrate-response`): per channel (R, G, B), the linear value of
// each of the 256 8-bit codes, non-decreasing, 1 at code 255.
struct ResponseTable {
  std::filesystem::path file;
  std::array<std::vector<double>, 3> linear;
};

struct CameraResponse {
  ResponseCurve curve = ResponseCurve::kSrgb;
  double gamma = 2.2;  // for kGamma: encoded = linear^(1/gamma); > 0
  std::shared_ptr<const ResponseTable> table;  // for kTable

  // Linear value in [0, 1] of an encoded value in [0, 1] (IEC 61966-2-1 for sRGB) in channel
  // 0, 1, 2 (R, G, B; only a table differs between them).
  double ToLinear(double encoded, int channel = 1) const;
  // Encoded value in [0, 1] of a linear value (clamped to [0, 1]).
  double ToEncoded(double linear, int channel = 1) const;
  // ToLinear for the 256 codes of an 8-bit image, code / 255 as the encoded value.
  std::array<float, 256> LinearLut8(int channel = 1) const;
  std::string Describe() const;  // "srgb", "linear", "gamma 2.2", "table response.csv"

  // Linear floats of an encoded interleaved RGB float image (values in [0, 1]), through a
  // Linearizer.
  void Linearize(const float* encoded, float* linear, size_t count) const;
};

// A response's inverse as a 4097-entry table with linear interpolation (exact to 1e-5 of the
// curve): built once, then a few operations per value, so that a consumer can linearise only the
// pixels it reads.
class Linearizer {
 public:
  explicit Linearizer(const CameraResponse& response);
  // `channel`: 0, 1, 2 for R, G, B.
  float operator()(float encoded, int channel) const {
    const std::array<float, kSteps + 1>& table = tables_[static_cast<size_t>(channel)];
    const float x = std::clamp(encoded, 0.0f, 1.0f) * kSteps;
    const int i = std::min(static_cast<int>(x), kSteps - 1);
    const float f = x - static_cast<float>(i);
    return table[static_cast<size_t>(i)] + f * (table[static_cast<size_t>(i) + 1] - table[static_cast<size_t>(i)]);
  }
  // Interleaved RGB values.
  void Apply(const float* encoded, float* linear, size_t count) const;

 private:
  static constexpr int kSteps = 4096;
  std::array<std::array<float, kSteps + 1>, 3> tables_{};
};

// The response itself the same way, for writing linear images as the camera would (the video of
// a replay): the table runs over √linear, where the curves are smooth (sRGB's toe and a gamma's
// start are steep in linear terms), 4097 entries: within 0.001 of a code of the analytic curves,
// 0.02 of a code of a table's (its kinks at the codes).
class Encoder {
 public:
  explicit Encoder(const CameraResponse& response);
  // `linear` in [0, 1] (clamped); `channel`: 0, 1, 2 for R, G, B. Encoded in [0, 1].
  float operator()(float linear, int channel) const {
    const std::array<float, kSteps + 1>& table = tables_[static_cast<size_t>(channel)];
    const float x = std::sqrt(std::clamp(linear, 0.0f, 1.0f)) * kSteps;
    const int i = std::min(static_cast<int>(x), kSteps - 1);
    const float f = x - static_cast<float>(i);
    return table[static_cast<size_t>(i)] + f * (table[static_cast<size_t>(i) + 1] - table[static_cast<size_t>(i)]);
  }
  // Interleaved RGB values, each × `scale` first (the exposure, for radiance units).
  void Apply(const float* linear, float scale, float* encoded, size_t count) const;

 private:
  static constexpr int kSteps = 4096;
  std::array<std::array<float, kSteps + 1>, 3> tables_{};
};

// RGB floats (width·height·3, row-major from the top) as the camera would store them, 8-bit BGR
// for OpenCV: each value × `scale`, through `response` when it is linear light (the response
// non-null), else taken as already encoded; clamped to [0, 1], rounded to the nearest code.
cv::Mat EncodeToBgr8(const float* rgb, int width, int height, double scale, const CameraResponse* response);

// Reads a response table: CSV `code,r,g,b`, 256 rows for codes 0-255, linear values finite,
// ≥ 0 and non-decreasing (scaled here so that code 255 is 1). Throws InputError naming the
// file, line and column.
std::shared_ptr<const ResponseTable> ReadResponseTable(const std::filesystem::path& csv);
// Writes one, atomically, with 8 significant digits.
void WriteResponseTable(const std::filesystem::path& csv, const ResponseTable& table);

// Debevec and Malik's response recovery (OpenCV's CalibrateDebevec) from an exposure bracket:
// 8-bit images (BGR, as cv::imread gives them) of a static scene with their exposure times in
// seconds. The curve is made non-decreasing and scaled to 1 at code 255 per channel.
ResponseTable CalibrateResponse(const std::vector<cv::Mat>& images, const std::vector<float>& seconds);

}  // namespace daylit::capture
