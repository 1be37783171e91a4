#include "estimation/sun_colour.h"

#include <algorithm>
#include <cmath>

#include "base/options_check.h"
#include "capture/frame_times.h"

namespace daylit::estimation {
namespace {

constexpr double kAirMassBin = 0.02;

}  // namespace

std::string SunColourOptions::Check() const {
  return FirstProblem({InOpenClosed("prior_weight", prior_weight, 0.0, 1e6), InOpenClosed("frame_error", frame_error, 0.0, 1.0),
                       InOpenClosed("error_per_air_mass", error_per_air_mass, 0.0, 1.0),
                       InOpenClosed("episode_s", episode_s, 0.0, 1e9)});
}

SunColourMemory::SunColourMemory(SunColourOptions options, const glm::dvec3& prior, double prior_air_mass)
    : options_(options) {
  Add(glm::log(prior / prior.y), options.prior_weight, prior_air_mass);
}

void SunColourMemory::Add(const glm::dvec3& log_colour, double weight, double air_mass) {
  Measured& bin = measured_[std::lround(air_mass / kAirMassBin)];
  bin.weight += weight;
  bin.log_sum += weight * log_colour;
  bin.air_mass_sum += weight * air_mass;
}

void SunColourMemory::EndEpisode() {
  // The episode joins what is carried, worth its best frame, at its frames' mean air mass.
  if (in_episode_ && episode_.weight > 0.0) {
    Add(episode_.log_sum / episode_.weight, episode_best_, episode_.air_mass_sum / episode_.weight);
  }
  episode_ = Measured{};
  episode_best_ = 0.0;
}

SunColourMemory::Colour SunColourMemory::At(const UtcTime& utc, double air_mass) {
  if (!in_episode_ || capture::StartsBurst(last_, utc) ||
      !(utc.SecondsSince(episode_start_) < options_.episode_s)) {
    EndEpisode();
    in_episode_ = true;
    episode_start_ = utc;
  }
  last_ = utc;
  air_mass_ = air_mass;
  // Each measurement (a bin, and this episode worth its best frame) weighed by what it is worth
  // here, 1 / (1/w + k Δm²) with k = (error_per_air_mass / frame_error)²; the mean's variance (in
  // units of frame_error²) is Σ a²/w over the measurements' shares a, plus k times the squared
  // distance of their mean air mass, the transmittance's error that all of them share.
  const double k = std::pow(options_.error_per_air_mass / options_.frame_error, 2.0);
  double worth_sum = 0.0, share_sq_over_w = 0.0, air_mass_mean = 0.0;
  glm::dvec3 log_mean(0.0);
  const auto take = [&](double weight, const glm::dvec3& log_colour, double at) {
    const double worth = 1.0 / (1.0 / weight + k * (air_mass - at) * (air_mass - at));
    worth_sum += worth;
    share_sq_over_w += worth * worth / weight;
    air_mass_mean += worth * at;
    log_mean += worth * log_colour;
  };
  for (const auto& [bin, m] : measured_) {
    if (m.weight > 0.0) take(m.weight, m.log_sum / m.weight, m.air_mass_sum / m.weight);
  }
  if (episode_.weight > 0.0) take(episode_best_, episode_.log_sum / episode_.weight, episode_.air_mass_sum / episode_.weight);
  Colour out;
  if (!(worth_sum > 0.0)) return out;
  air_mass_mean /= worth_sum;
  const double variance = share_sq_over_w / (worth_sum * worth_sum) + k * (air_mass - air_mass_mean) * (air_mass - air_mass_mean);
  out.weight = 1.0 / variance;
  out.above = glm::exp(log_mean / worth_sum);
  return out;
}

void SunColourMemory::Measure(const UtcTime& utc, const glm::dvec3& above, double weight) {
  if (!(weight > 0.0) || !(glm::min(above.x, glm::min(above.y, above.z)) > 0.0)) return;
  last_ = utc;
  episode_.weight += weight;
  episode_.log_sum += weight * glm::log(above / above.y);
  episode_.air_mass_sum += weight * air_mass_;
  episode_best_ = std::max(episode_best_, weight);
}

}  // namespace daylit::estimation
