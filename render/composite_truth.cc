#include "render/composite_truth.h"

#include <algorithm>
#include <cmath>

#include "report/plot.h"

namespace daylit::render {

CompositeFidelity CompareComposite(const std::vector<float>& composite, const std::vector<float>& frame,
                                   const std::vector<float>& truth_with, const std::vector<float>& truth_without,
                                   const cv::Mat& mask) {
  CompositeFidelity f;
  const size_t pixels = truth_with.size() / 3;
  for (size_t p = 0; p < pixels; ++p) {
    double error = 0.0, change = 0.0, frame_error = 0.0;
    for (size_t k = 0; k < 3; ++k) {
      const double t = truth_with[3 * p + k], w = truth_without[3 * p + k];
      error += std::abs(composite[3 * p + k] - t) / std::max(t, 1e-6) / 3.0;
      frame_error += std::abs(frame[3 * p + k] - w) / std::max(w, 1e-6) / 3.0;
      change = std::max(change, std::abs(t / std::max(w, 1e-6) - 1.0));
    }
    if (mask.data[p] >= 128) {
      f.object_error += error, ++f.object_pixels;
    } else if (mask.data[p] == 0 && change > 0.02) {
      f.shadow_error += error, f.frame_shadow_error += frame_error, ++f.shadow_pixels;
    }
  }
  if (f.object_pixels > 0) f.object_error /= static_cast<double>(f.object_pixels);
  if (f.shadow_pixels > 0) {
    f.shadow_error /= static_cast<double>(f.shadow_pixels);
    f.frame_shadow_error /= static_cast<double>(f.shadow_pixels);
  }
  return f;
}

void WriteCompositeStrip(const std::filesystem::path& png, int width, int height, const std::vector<float>& truth,
                         const std::vector<float>& composite, double exposure, const capture::CameraResponse& response) {
  std::vector<float> difference(truth.size());
  for (size_t i = 0; i < truth.size(); ++i) difference[i] = 4.0f * std::abs(composite[i] - truth[i]);
  cv::Mat strip;
  cv::hconcat(std::vector<cv::Mat>{capture::EncodeToBgr8(truth.data(), width, height, exposure, &response),
                                   capture::EncodeToBgr8(composite.data(), width, height, exposure, &response),
                                   capture::EncodeToBgr8(difference.data(), width, height, exposure, &response)},
              strip);
  report::WritePng(png, {strip});
}

}  // namespace daylit::render
