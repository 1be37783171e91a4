#include "pipeline/frame_fits.h"

#include <algorithm>
#include <map>

#include "base/error.h"
#include "pipeline/lighting_pipeline.h"

namespace daylit::pipeline {
namespace {

// Keeps the frames asked for as the pipeline hands them over, counting every frame it reads.
class KeepFrames : public FrameSink {
 public:
  explicit KeepFrames(std::map<size_t, FrameFit>* wanted) : wanted_(wanted) {}
  void Consume(const PipelineFrame& frame) override {
    const auto it = wanted_->find(position_++);
    if (it == wanted_->end()) return;
    FrameFit& out = it->second;
    out.row = frame.light.row;
    out.row.light = frame.light.fit.light;  // the fit's own, not the filter's
    out.row.confidence = frame.light.fit.confidence;
    out.fit = frame.light.fit;
    out.sun_dir = frame.sun.dir_in_scene;
    out.frame = frame.frame;  // its own buffer, never written again (frame_source.h); empty: unreadable
  }

 private:
  std::map<size_t, FrameFit>* wanted_;
  size_t position_ = 0;
};

}  // namespace

std::vector<FrameFit> FitRecordingFrames(const scene::Scene& scene, const bake::SceneBake& bake,
                                         const scene::RayCaster& caster, const std::vector<size_t>& positions,
                                         const estimation::FrameEstimatorOptions& options) {
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no recorded frames", scene.file.string());
  const size_t count = scene.frame_times->frames.size();
  std::map<size_t, FrameFit> wanted;
  for (const size_t position : positions) {
    if (position >= count) ThrowInputError("{}: frame {} is past the recording's {} frames", scene.file.string(), position, count);
    wanted.emplace(position, FrameFit{});
  }
  std::vector<FrameFit> out;
  if (wanted.empty()) return out;
  LightingPipelineOptions pipeline_options;
  pipeline_options.estimator = options;
  pipeline_options.max_frames = static_cast<int>(wanted.rbegin()->first + 1);
  pipeline_options.progress_label = "fit";
  LightingPipeline lighting(scene, bake, caster, pipeline_options);
  KeepFrames keep(&wanted);
  lighting.AddSink(&keep);
  lighting.Run(scene::OpenFrameSource(scene));
  for (const size_t position : positions) {
    const FrameFit& fit = wanted.at(position);
    const int index = scene.frame_times->frames[position].index;
    if (fit.frame.rgb.empty()) ThrowInputError("{}: frame {} cannot be decoded", scene.file.string(), index);
    out.push_back(fit);
  }
  return out;
}

FrameFit FitRecordingFrame(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                           size_t position, const estimation::FrameEstimatorOptions& options) {
  return std::move(FitRecordingFrames(scene, bake, caster, {position}, options).front());
}

}  // namespace daylit::pipeline
