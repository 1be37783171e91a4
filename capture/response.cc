#include "capture/response.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace daylit::capture {

double CameraResponse::ToLinear(double encoded) const {
  const double v = std::clamp(encoded, 0.0, 1.0);
  switch (curve) {
    case ResponseCurve::kLinear: return v;
    case ResponseCurve::kGamma: return std::pow(v, gamma);
    case ResponseCurve::kSrgb:
      return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  }
  return v;
}

double CameraResponse::ToEncoded(double linear) const {
  const double v = std::clamp(linear, 0.0, 1.0);
  switch (curve) {
    case ResponseCurve::kLinear: return v;
    case ResponseCurve::kGamma: return std::pow(v, 1.0 / gamma);
    case ResponseCurve::kSrgb:
      return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  }
  return v;
}

std::array<float, 256> CameraResponse::LinearLut8() const {
  std::array<float, 256> lut{};
  for (int i = 0; i < 256; ++i) lut[static_cast<size_t>(i)] = static_cast<float>(ToLinear(i / 255.0));
  return lut;
}

void CameraResponse::Linearize(const float* encoded, float* linear, size_t count) const {
  Linearizer(*this).Apply(encoded, linear, count);
}

Linearizer::Linearizer(const CameraResponse& response) {
  for (int i = 0; i <= kSteps; ++i) table_[static_cast<size_t>(i)] = static_cast<float>(response.ToLinear(static_cast<double>(i) / kSteps));
}

void Linearizer::Apply(const float* encoded, float* linear, size_t count) const {
  for (size_t k = 0; k < count; ++k) linear[k] = (*this)(encoded[k]);
}

std::string CameraResponse::Describe() const {
  switch (curve) {
    case ResponseCurve::kLinear: return "linear";
    case ResponseCurve::kSrgb: return "srgb";
    case ResponseCurve::kGamma: return fmt::format("gamma {}", gamma);
  }
  return "?";
}

}  // namespace daylit::capture
