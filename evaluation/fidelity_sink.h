// The composite of every frame against the path tracer's (groundtruth/ of recording-format.md):
// per frame, the objects' and their shadows' relative error (CompareComposite); after the run,
// fidelity.csv, its plot fidelity.png, worst_vs_truth.png (truth | daylit | difference for the
// worst frame) and the report's lines with the mean and the worst frame of each.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "evaluation/composite_truth.h"
#include "evaluation/run_report.h"
#include "pipeline/lighting_pipeline.h"

namespace daylit::evaluation {

struct FrameFidelity {
  int frame = 0;
  CompositeFidelity fidelity;
};

class FidelitySink final : public pipeline::FrameSink {
 public:
  explicit FidelitySink(const scene::Scene& scene);
  // Frames whose image shows their own light and that have truth composites.
  void Consume(const pipeline::PipelineFrame& frame) override;

  const std::vector<FrameFidelity>& frames() const { return frames_; }
  // Nothing when no frame was compared.
  void Finish(const std::filesystem::path& dir, RunReport* report) const;

 private:
  const scene::Scene& scene_;
  const capture::Linearizer linearizer_;
  std::vector<FrameFidelity> frames_;
  std::vector<float> linear_;
  double worst_ = -1.0, worst_exposure_ = 1.0;
  std::vector<float> worst_truth_, worst_composite_;
};

// frame,object_error,object_pixels,shadow_error,shadow_pixels,frame_shadow_error,false_shadow_pixels
std::string FidelityCsv(const std::vector<FrameFidelity>& rows);
void PlotFidelity(const std::vector<FrameFidelity>& rows, const std::string& title, const std::filesystem::path& png);

}  // namespace daylit::evaluation
