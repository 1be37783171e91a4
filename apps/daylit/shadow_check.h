// The quick shadow check of `daylit info` and `daylit estimate`: do the frames' shadows fall where
// the model's do? A north (or clock) that is off moves them apart; beyond the equivalent of 0.5°
// of north this warns and suggests `daylit calibrate-scene`. A model that matches at no north (a
// wrong model file, another camera's pose, the wrong place: calibrate::ShadowCheck::SunSkill)
// is warned about as such.
#pragma once

#include <optional>

#include "bake/bake.h"
#include "calibrate/shadow_calibration.h"
#include "evaluation/run_report.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::app {

inline constexpr double kShadowCheckNorthDeg = 0.5;
using calibrate::kShadowCheckMinSunSkill;

// Feeds the pipeline's frames to a ShadowObserver. With `stop_at_first_sunlit_burst` it ends the
// run once a burst (or stretch, ObserveOptions::max_burst_s) has shown the sun on the model: live
// --calibrate's first clear minute.
class ShadowCheckSink final : public pipeline::FrameSink {
 public:
  ShadowCheckSink(const scene::Scene& scene, const bake::SceneBake& bake, const calibrate::ObserveOptions& options = {},
                  bool stop_at_first_sunlit_burst = false)
      : observer_(scene, bake, options), stop_at_first_(stop_at_first_sunlit_burst) {}
  void Consume(const pipeline::PipelineFrame& frame) override;
  bool StopRequested() const override { return stop_at_first_ && observer_.sunlit_bursts() > 0; }
  calibrate::ShadowObservations Finish() { return observer_.Finish(); }

 private:
  calibrate::ShadowObserver observer_;
  bool stop_at_first_ = false;
};

// Runs the check on what was observed: warns (stderr) when the model's shadows match the frames'
// at no north (ModelMatchesFootage), else when they sit where a north more than
// kShadowCheckNorthDeg off would put them; says on stderr when the footage cannot tell
// (no clear burst). Adds shadow_check/* figures to `report` when given. Returns the check.
std::optional<calibrate::ShadowCheck> CheckShadowsAndSay(const scene::Scene& scene, const bake::SceneBake& bake,
                                                         const scene::RayCaster& caster,
                                                         const calibrate::ShadowObservations& observed,
                                                         evaluation::RunReport* report);

}  // namespace daylit::app
