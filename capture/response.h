// How a camera encodes linear light in pixel values, and its inverse (linearisation).
#pragma once

#include <array>
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
  // 4097-entry table with linear interpolation (exact to 1e-5 of the curve).
  void Linearize(const float* encoded, float* linear, size_t count) const;
};

}  // namespace daylit::capture
