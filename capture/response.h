// How a camera encodes linear light in pixel values, and its inverse (linearisation).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <string>

namespace daylit::capture {

enum class ResponseCurve { kLinear, kSrgb, kGamma };

struct CameraResponse {
  ResponseCurve curve = ResponseCurve::kSrgb;
  double gamma = 2.2;  // for kGamma: encoded = linear^(1/gamma); > 0

  // Linear value in [0, 1] of an encoded value in [0, 1] (IEC 61966-2-1 for sRGB).
  double ToLinear(double encoded) const;
  // Encoded value in [0, 1] of a linear value (clamped to [0, 1]).
  double ToEncoded(double linear) const;
  // ToLinear for the 256 codes of an 8-bit image, code / 255 as the encoded value.
  std::array<float, 256> LinearLut8() const;
  std::string Describe() const;  // "srgb", "linear", "gamma 2.2"

  // Linear floats of an encoded float image (any channel count, values in [0, 1]), through a
  // Linearizer.
  void Linearize(const float* encoded, float* linear, size_t count) const;
};

// A response's inverse as a 4097-entry table with linear interpolation (exact to 1e-5 of the
// curve): built once, then a few operations per value, so that a consumer can linearise only the
// pixels it reads.
class Linearizer {
 public:
  explicit Linearizer(const CameraResponse& response);
  float operator()(float encoded) const {
    const float x = std::clamp(encoded, 0.0f, 1.0f) * kSteps;
    const int i = std::min(static_cast<int>(x), kSteps - 1);
    const float f = x - static_cast<float>(i);
    return table_[static_cast<size_t>(i)] + f * (table_[static_cast<size_t>(i) + 1] - table_[static_cast<size_t>(i)]);
  }
  void Apply(const float* encoded, float* linear, size_t count) const;

 private:
  static constexpr int kSteps = 4096;
  std::array<float, kSteps + 1> table_{};
};

}  // namespace daylit::capture
