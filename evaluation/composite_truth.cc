#include "evaluation/composite_truth.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "base/error.h"
#include "report/plot.h"
#include "scene/hdr_image.h"

namespace daylit::evaluation {

std::optional<TruthFrame> ReadTruthFrame(const scene::Scene& scene, int index) {
  namespace fs = std::filesystem;
  if (!scene.groundtruth.composites) return std::nullopt;
  const fs::path dir = *scene.groundtruth.composites;
  TruthFrame truth;
  truth.with_file = dir / "with_objects" / fmt::format("{:06d}.exr", index);
  const fs::path without_file = dir / "without_objects" / fmt::format("{:06d}.exr", index);
  const fs::path mask_file = dir / "objects_mask" / fmt::format("{:06d}.png", index);
  if (!fs::is_regular_file(truth.with_file) || !fs::is_regular_file(without_file) || !fs::is_regular_file(mask_file)) {
    return std::nullopt;
  }
  HdrImage with = scene::ReadHdrImage(truth.with_file), without = scene::ReadHdrImage(without_file);
  truth.mask = cv::imread(mask_file.string(), cv::IMREAD_GRAYSCALE);
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  if (with.width != w || with.height != h || without.width != w || without.height != h || truth.mask.cols != w ||
      truth.mask.rows != h) {
    ThrowInputError("{}: the truth of frame {} is not {}x{}", dir.string(), index, w, h);
  }
  truth.with = std::move(with.rgb), truth.without = std::move(without.rgb);
  return truth;
}

// A pixel is in the objects' shadow when they change it by more than this (either image).
constexpr double kShadowChange = 0.02;

CompositeFidelity CompareComposite(const std::vector<float>& composite, const std::vector<float>& frame,
                                   const std::vector<float>& truth_with, const std::vector<float>& truth_without,
                                   const cv::Mat& mask) {
  CompositeFidelity f;
  const size_t pixels = truth_with.size() / 3;
  // Pixels black in the truth (a gap no light reaches: courtyard-b's strip under its portico roof
  // renders exactly 0 and reads 0-6 code values in the video) have no relative error to speak of:
  // they count when the truth is brighter than a thousandth of the frame's median.
  std::vector<float> brightness(pixels);
  for (size_t p = 0; p < pixels; ++p) brightness[p] = std::max({truth_without[3 * p], truth_without[3 * p + 1], truth_without[3 * p + 2]});
  std::vector<float> sorted = brightness;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<ptrdiff_t>(pixels / 2), sorted.end());
  const float dark = pixels > 0 ? 1e-3f * sorted[pixels / 2] : 0.0f;
  for (size_t p = 0; p < pixels; ++p) {
    const float lit = std::max({truth_with[3 * p], truth_with[3 * p + 1], truth_with[3 * p + 2], brightness[p]});
    if (!(lit > dark)) {
      ++f.dark_pixels;
      continue;
    }
    double error = 0.0, change = 0.0, drawn = 0.0, frame_error = 0.0;
    for (size_t k = 0; k < 3; ++k) {
      const double t = truth_with[3 * p + k], w = truth_without[3 * p + k];
      error += std::abs(composite[3 * p + k] - t) / std::max(t, 1e-6) / 3.0;
      frame_error += std::abs(frame[3 * p + k] - w) / std::max(w, 1e-6) / 3.0;
      change = std::max(change, std::abs(t / std::max(w, 1e-6) - 1.0));
      drawn = std::max(drawn, std::abs(composite[3 * p + k] / std::max(frame[3 * p + k], 1e-6f) - 1.0));
    }
    if (mask.data[p] >= 128) {
      f.object_error += error, ++f.object_pixels;
    } else if (mask.data[p] == 0 && (change > kShadowChange || drawn > kShadowChange)) {
      f.shadow_error += error, f.frame_shadow_error += frame_error, ++f.shadow_pixels;
      f.false_shadow_pixels += change > kShadowChange ? 0 : 1;
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

}  // namespace daylit::evaluation
