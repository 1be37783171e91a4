// The sun's colour carried from frame to frame. Clouds are grey: a cloud dims the beam, it does not
// colour it. So a weak sun, whose colour its own frame measures badly (a model error in the sky
// part passes to E_sun amplified by (1 − share)/share, share the sun's part of the sunlit
// samples' light), has the colour that frames with a strong sun measured. The colour is kept above
// the atmosphere (divided by its transmittance, sky/atmosphere.h) so that it holds as the sun
// moves; it starts from the capture's sun (sun_irradiance_rgb, or the map's disc).
//
// How much a colour is worth is counted in frames whose sun is half their sunlit samples' light
// (weight 1; a frame weighs ((share/(1 − share))², the inverse square of its amplification). Two
// things keep that count honest:
// - The frames of one episode (frames less than 2 s apart, at most a minute of them) share their
//   model's errors: an overcast burst's hundred weak suns are as wrong as one of them. An episode
//   is worth its best frame, not the sum of its frames; its colour is their weighted mean.
// - The atmosphere's transmittance carries a colour from one elevation to another only so far: a
//   colour carried across an air mass Δm (Kasten and Young's, sky/atmosphere.h) is worth at most
//   (frame_error / (error_per_air_mass · Δm))².
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "base/utc_time.h"

namespace daylit::estimation {

struct SunColourOptions {
  bool on = true;
  double prior_weight = 0.25;        // the capture's sun, in frames of weight 1
  double frame_error = 0.02;         // the colour error of a frame of weight 1: a stratum's model
                                     // error (the strata agree within 1-2% under the true light,
                                     // tests/transfer_truth_recording_test.cc)
  double error_per_air_mass = 0.05;  // the transmittance's colour error per unit of air mass it
                                     // carries a colour across: 3-8% on the bundled recordings'
                                     // clear suns (docs/sky.md)
  double episode_s = 60.0;           // the longest episode
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

class SunColourMemory {
 public:
  // Nothing known: At() has weight 0 until a frame is measured.
  explicit SunColourMemory(SunColourOptions options = {}) : options_(options) {}
  // Known from the capture's sun: its colour above the atmosphere (RGB, > 0) and its air mass.
  SunColourMemory(SunColourOptions options, const glm::dvec3& prior, double prior_air_mass);

  struct Colour {
    glm::dvec3 above{1.0};  // relative RGB above the atmosphere (green 1)
    double weight = 0.0;    // in frames of weight 1; 0: nothing known
  };
  // What is known for a frame at `utc` with the sun at `air_mass`.
  Colour At(const UtcTime& utc, double air_mass);
  // A frame's own measurement: its E_sun above the atmosphere (RGB, > 0) and its weight.
  void Measure(const UtcTime& utc, const glm::dvec3& above, double weight);

 private:
  void StartEpisode(const UtcTime& utc, double air_mass);
  SunColourOptions options_;
  glm::dvec3 log_carried_{0.0};  // earlier episodes'
  double carried_weight_ = 0.0;
  double carried_air_mass_ = 1.0;
  bool in_episode_ = false;
  UtcTime episode_start_, last_;
  glm::dvec3 episode_sum_{0.0};  // Σ w · log colour
  double episode_weight_sum_ = 0.0, episode_best_ = 0.0;
};

}  // namespace daylit::estimation
