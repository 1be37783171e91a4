// The self-check that needs no ground truth (real footage has none): for each surface and each
// stratum (sunlit, shadowed), the ratio of the radiance the camera saw to the radiance the model
// predicts under each frame's own fit (estimation::PredictedRadiance), per channel, over the run.
// A fit explains the whole frame, so a surface whose ratio stays away from 1 is one the model gets
// wrong: its albedo (both strata off alike), its geometry or the sun's visibility on it (the
// sunlit stratum off), or light the model does not carry to it, such as something unmodelled in
// front of it (the shadowed stratum off). `daylit estimate --residuals DIR` writes what this
// finds (docs/estimation.md).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "bake/bake.h"
#include "base/utc_time.h"
#include "evaluation/run_report.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/scene.h"

namespace daylit::evaluation {

struct ResidualOptions {
  double threshold = 0.12;        // |observed/predicted − 1| beyond this, in any channel, is a bias
  int min_samples_per_frame = 20; // a stratum's frame counts with this many samples of it
  int min_frames = 10;            // a stratum is judged over at least this many frames

  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// One surface's stratum over the run, or over one burst of it.
struct StratumResidual {
  int burst = -1;        // −1: the whole run
  std::string surface;
  bool sunlit = false;
  int frames = 0;        // frames with enough samples of it
  size_t samples = 0;    // over those frames
  glm::dvec3 ratio{0.0}; // median over frames of Σ observed / Σ predicted, per channel
  bool biased = false;   // frames ≥ min_frames and |ratio − 1| > threshold in some channel
};

// A surface the residuals name, and what most likely causes it.
struct ResidualFinding {
  std::string surface;
  std::string cause;  // "its albedo", "its geometry or the sun's visibility on it", ...
  std::string message;
};

class ResidualSink final : public pipeline::FrameSink {
 public:
  ResidualSink(const scene::Scene& scene, const bake::SceneBake& bake, ResidualOptions options = {});
  // Frames with a usable fit: their samples against the fit's prediction.
  void Consume(const pipeline::PipelineFrame& frame) override;

  // Every surface's strata that had samples, surfaces in the model's order, sunlit first.
  std::vector<StratumResidual> Strata() const;
  // The same per burst (frames less than 2 s apart), bursts in order: a burst's bias averages
  // away over a run of several.
  std::vector<StratumResidual> BurstStrata() const;
  std::vector<ResidualFinding> Findings() const;
  // residuals.csv, residuals.png (the ratios as bars) and worst_frame_residuals.png (the frame
  // with the largest residual spread, each sample coloured by its ratio) into `dir`; each finding
  // as a warning on stderr and a report line.
  void Finish(const std::filesystem::path& dir, RunReport* report) const;

 private:
  struct Accumulated {
    std::vector<glm::dvec3> ratios;  // per frame
    size_t samples = 0;
  };
  // A surface's stratum over `strata` (the run's or a burst's); nullopt when no frame had enough
  // samples of it.
  std::optional<StratumResidual> StratumOf(const std::vector<Accumulated>& strata, size_t surface, bool sunlit) const;
  const scene::Scene& scene_;
  const bake::SceneBake& bake_;
  ResidualOptions options_;
  std::vector<Accumulated> strata_;  // [surface · 2 + sunlit]
  std::vector<std::vector<Accumulated>> bursts_;  // the same per burst
  std::optional<UtcTime> last_utc_;
  // The worst frame so far: its residual spread, its number, and its image (8-bit, the samples
  // drawn on it).
  double worst_spread_ = -1.0;
  int worst_frame_ = -1;
  cv::Mat worst_image_;
};

// residuals.csv: burst,surface,stratum,frames,samples,ratio_r,ratio_g,ratio_b,biased (burst "all":
// the whole run).
std::string ResidualsCsv(const std::vector<StratumResidual>& strata);

}  // namespace daylit::evaluation
