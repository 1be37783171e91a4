#include "estimation/sun_colour.h"

#include <algorithm>
#include <cmath>

#include "base/options_check.h"
#include "capture/frame_times.h"

namespace daylit::estimation {

std::string SunColourOptions::Check() const {
  return FirstProblem({InOpenClosed("prior_weight", prior_weight, 0.0, 1e6), InOpenClosed("frame_error", frame_error, 0.0, 1.0),
                       InOpenClosed("error_per_air_mass", error_per_air_mass, 0.0, 1.0),
                       InOpenClosed("episode_s", episode_s, 0.0, 1e9)});
}

SunColourMemory::SunColourMemory(SunColourOptions options, const glm::dvec3& prior, double prior_air_mass)
    : options_(options),
      log_carried_(glm::log(prior / prior.y)),
      carried_weight_(options.prior_weight),
      carried_air_mass_(prior_air_mass) {}

void SunColourMemory::StartEpisode(const UtcTime& utc, double air_mass) {
  // The episode that ends joins what is carried, worth its best frame.
  if (in_episode_ && episode_weight_sum_ > 0.0) {
    const glm::dvec3 log_episode = episode_sum_ / episode_weight_sum_;
    log_carried_ = (carried_weight_ * log_carried_ + episode_best_ * log_episode) / (carried_weight_ + episode_best_);
    carried_weight_ += episode_best_;
  }
  in_episode_ = true;
  episode_start_ = utc;
  episode_sum_ = glm::dvec3(0.0);
  episode_weight_sum_ = episode_best_ = 0.0;
  // Carried to this air mass: worth at most what the transmittance gets right across it.
  const double moved = std::abs(air_mass - carried_air_mass_) * options_.error_per_air_mass;
  if (moved > 0.0) carried_weight_ = std::min(carried_weight_, std::pow(options_.frame_error / moved, 2.0));
  carried_air_mass_ = air_mass;
}

SunColourMemory::Colour SunColourMemory::At(const UtcTime& utc, double air_mass) {
  if (!in_episode_ || !(utc.SecondsSince(last_) < capture::kBurstGapS) ||
      !(utc.SecondsSince(episode_start_) < options_.episode_s)) {
    StartEpisode(utc, air_mass);
  }
  last_ = utc;
  Colour out;
  const double episode = episode_weight_sum_ > 0.0 ? episode_best_ : 0.0;
  out.weight = carried_weight_ + episode;
  if (out.weight <= 0.0) return out;
  const glm::dvec3 log_episode = episode > 0.0 ? episode_sum_ / episode_weight_sum_ : glm::dvec3(0.0);
  out.above = glm::exp((carried_weight_ * log_carried_ + episode * log_episode) / out.weight);
  return out;
}

void SunColourMemory::Measure(const UtcTime& utc, const glm::dvec3& above, double weight) {
  if (!(weight > 0.0) || !(glm::min(above.x, glm::min(above.y, above.z)) > 0.0)) return;
  last_ = utc;
  episode_sum_ += weight * glm::log(above / above.y);
  episode_weight_sum_ += weight;
  episode_best_ = std::max(episode_best_, weight);
}

}  // namespace daylit::estimation
