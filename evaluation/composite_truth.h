// Composites against a path tracer's frame with the objects physically present
// (groundtruth/with_objects): the mean relative error of linear radiance, averaged over RGB, over
// the objects' pixels (mask ≥ 128) and over the pixels of their shadows. Those are the union of
// both shadow masks, off the objects (mask 0): where the truth with objects differs from the truth
// without by more than 2%, or daylit's composite from the frame it was drawn into, so that a
// shadow drawn where the truth has none counts as much as one missed. And a strip for a person to
// look at: truth | daylit | difference.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "capture/response.h"
#include "scene/scene.h"

namespace daylit::evaluation {

// The path tracer's frame `index` (groundtruth/ of recording-format.md): with the objects and
// without them (linear RGB, row-major from the top) and the objects' mask (8-bit).
struct TruthFrame {
  std::filesystem::path with_file;
  std::vector<float> with, without;
  cv::Mat mask;
};
// nullopt when the recording has no composites for that frame; InputError naming the folder when
// they are not the camera's size.
std::optional<TruthFrame> ReadTruthFrame(const scene::Scene& scene, int index);

struct CompositeFidelity {
  double object_error = 0.0;
  size_t object_pixels = 0;
  double shadow_error = 0.0;
  size_t shadow_pixels = 0;        // the union of both shadow masks
  size_t false_shadow_pixels = 0;  // of them, where only daylit drew a shadow
  double frame_shadow_error = 0.0;  // the frame itself (before compositing) against the truth
                                    // without objects, on the same pixels: the camera's own share
  size_t dark_pixels = 0;           // left out: black in the truth (below 1/1000 of the median)
};

// All images camera-size, linear RGB row-major from the top; `mask` 8-bit.
CompositeFidelity CompareComposite(const std::vector<float>& composite, const std::vector<float>& frame,
                                   const std::vector<float>& truth_with, const std::vector<float>& truth_without,
                                   const cv::Mat& mask);

// truth | daylit | |difference| × 4, each encoded as the camera would (linear × exposure through
// the response, 8 bits), written atomically as PNG.
void WriteCompositeStrip(const std::filesystem::path& png, int width, int height, const std::vector<float>& truth,
                         const std::vector<float>& composite, double exposure, const capture::CameraResponse& response);

}  // namespace daylit::evaluation
