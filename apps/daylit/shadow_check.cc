#include "apps/daylit/shadow_check.h"

#include <cmath>

#include "base/log.h"

namespace daylit::app {

void ShadowCheckSink::Consume(const pipeline::PipelineFrame& frame) {
  if (frame.frame.rgb.empty()) {
    observer_.AddUnreadable(frame.frame);
  } else {
    observer_.Add(frame.frame, frame.light.row);
  }
}

std::optional<calibrate::ShadowCheck> CheckShadowsAndSay(const scene::Scene& scene, const bake::SceneBake& bake,
                                                         const scene::RayCaster& caster,
                                                         const calibrate::ShadowObservations& observed,
                                                         evaluation::RunReport* report) {
  const std::optional<calibrate::ShadowCheck> check = calibrate::CheckShadows(scene, bake, caster, observed);
  if (!check) {
    Log().info("shadow check: no burst shows the sun clearly on the model; north and the clock cannot be checked");
    return check;
  }
  if (report != nullptr) {
    report->Figure("shadow_check/north_offset_deg", check->north_offset_deg);
    report->Figure("shadow_check/disagree", check->disagree);
  }
  if (std::abs(check->north_offset_deg) > kShadowCheckNorthDeg) {
    Log().warn("{}: the frames' shadows fall where the model's would with north {:+.2f} deg off ({:.1f}% of {} shadow-edge "
               "pixels on the wrong side): north_azimuth_deg or the frames' clock is off; run daylit calibrate-scene",
               scene.file.string(), check->north_offset_deg, 100.0 * check->disagree, check->edge_pixels);
  } else {
    Log().info("shadow check: the frames' shadows agree with the model's (north within {:.2f} deg of the best, {:.1f}% of "
               "shadow-edge pixels on the wrong side)",
               std::abs(check->north_offset_deg), 100.0 * check->disagree);
  }
  return check;
}

}  // namespace daylit::app
