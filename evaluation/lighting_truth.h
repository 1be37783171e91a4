// The estimates against a recording's ground truth (groundtruth.csv of recording-format.md), and
// their plot over time.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "estimation/frame_estimator.h"
#include "evaluation/run_report.h"
#include "scene/scene.h"

namespace daylit::evaluation {

// Against groundtruth.csv: median over frames of |estimate/truth − 1| per channel, for E_sun
// (frames where the true E_sun is > 0), E_sky, and the sun/sky ratio. Throws InputError naming
// the file and row for a malformed table.
struct TruthComparison {
  glm::dvec3 sun_error{0.0}, sky_error{0.0}, ratio_error{0.0};
  int frames = 0;
  std::vector<estimation::SunSky> truth;  // per frame, aligned with the estimates
};
TruthComparison CompareWithTruth(const std::vector<estimation::FrameEstimate>& frames,
                                 const std::filesystem::path& groundtruth_csv);

// Estimate vs truth over time, per channel: a PNG with a sun panel and a sky panel.
void PlotEstimates(const std::vector<estimation::FrameEstimate>& frames, const TruthComparison* truth,
                   const std::string& title, const std::filesystem::path& png);

// The estimates of a run as estimates.csv (`csv`) and their plot (`png`); with the scene's ground
// truth, the median errors as the report's lines. Returns the comparison, if there was truth.
std::optional<TruthComparison> ReportLighting(const scene::Scene& scene, const std::vector<estimation::FrameEstimate>& frames,
                                              const std::filesystem::path& csv, const std::filesystem::path& png,
                                              RunReport* report);

}  // namespace daylit::evaluation
