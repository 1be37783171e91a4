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
// - The atmosphere's transmittance carries a colour from one elevation to another only so far. A
//   colour measured at air mass m_i (Kasten and Young's, sky/atmosphere.h) with weight w_i has the
//   error variance frame_error²/w_i; carried to air mass m it gains the transmittance's error,
//   (error_per_air_mass · (m − m_i))², which is the same for every measurement (one atmosphere
//   model). The colour at m is the measurements' mean weighted by what each is worth at m, and it
//   is worth frame_error² over the variance of that mean, the common term counted once: a colour
//   drifts no further from where it was measured by being carried a minute at a time.
#pragma once

#include <map>
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
  // A frame's own measurement: its E_sun above the atmosphere (RGB, > 0) and its weight, at the
  // air mass of the At() before it.
  void Measure(const UtcTime& utc, const glm::dvec3& above, double weight);

 private:
  // What was measured near one air mass (bins 0.02 wide: 0.001 of colour at the default error per
  // air mass): Σ w, Σ w · log colour, Σ w · air mass.
  struct Measured {
    double weight = 0.0;
    glm::dvec3 log_sum{0.0};
    double air_mass_sum = 0.0;
  };
  void Add(const glm::dvec3& log_colour, double weight, double air_mass);
  void EndEpisode();
  SunColourOptions options_;
  std::map<long, Measured> measured_;  // earlier episodes' and the prior, by air mass bin
  bool in_episode_ = false;
  UtcTime episode_start_, last_;
  double air_mass_ = 1.0;                        // the frame at hand's (the last At's)
  Measured episode_;                             // this episode's frames
  double episode_best_ = 0.0;
};

}  // namespace daylit::estimation
