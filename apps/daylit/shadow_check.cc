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
    report->Figure("shadow_check/kappa", check->kappa);
    report->Figure("shadow_check/kappa_sun_turned_away", check->kappa_away);
    report->Figure("shadow_check/sun_skill", check->SunSkill());
    report->Figure("shadow_check/model_matches_footage", check->ModelMatchesFootage() ? 1.0 : 0.0);
  }
  if (!check->ModelMatchesFootage()) {
    Log().warn("{}: the model's shadows do not match the frames' at any north within {:.0f} deg: with the frames' sun they "
               "agree little better than with a sun turned 20-40 deg away (kappa {:.2f} against {:.2f}: {:.2f} of the rest "
               "explained, at most {:.2f}; best north {:+.2f} deg, {:.1f}% of {} shadow-edge pixels on the wrong side); the "
               "model, the camera pose, north or the place may not be this footage's, and every estimate rests on them: check "
               "them (daylit render, calibrate-camera) before trusting the light",
               scene.file.string(), calibrate::kShadowCheckNorthRangeDeg, check->kappa, check->kappa_away, check->SunSkill(),
               kShadowCheckMinSunSkill, check->north_offset_deg, 100.0 * check->disagree_best, check->edge_pixels);
    return check;
  }
  if (std::abs(check->north_offset_deg) > kShadowCheckNorthDeg) {
    Log().warn("{}: the frames' shadows fall where the model's would with north {:+.2f} deg off ({:.1f}% of {} shadow-edge "
               "pixels on the wrong side): north_azimuth_deg or the frames' clock is off; run daylit calibrate-scene",
               scene.file.string(), check->north_offset_deg, 100.0 * check->disagree, check->edge_pixels);
  } else {
    Log().info("shadow check: the frames' shadows agree with the model's (north within {:.2f} deg of the best, {:.1f}% of "
               "shadow-edge pixels on the wrong side; the frames' sun explains {:.2f} of the agreement a sun turned away leaves)",
               std::abs(check->north_offset_deg), 100.0 * check->disagree, check->SunSkill());
  }
  return check;
}

}  // namespace daylit::app
