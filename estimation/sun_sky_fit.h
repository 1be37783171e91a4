// The per-frame fit of seed 001, per colour channel: observed radiance at sampled points of the
// diffuse surfaces against the model of design.md with its transfer terms (estimation/transfer.h),
//
//   y_i = ρ_i/π · (T_sun,i · E_sun + T_clear,i · E_clear + T_overcast,i · E_overcast)
//
// (seed 001 itself: T_sun = s·max(0, n·l), T_clear = T_overcast = V), for E ≥ 0; the sky's DHI is
// E_sky = E_clear + E_overcast. A sky between the clear one and an overcast one (a cloud passing)
// is a mix of the two, and the two shapes light walls and shadows differently. Robust: a
// median-based start from the shadowed and the sunlit samples, then iteratively reweighted least
// squares with a Cauchy loss on relative residuals (albedo and registration errors are
// multiplicative), so that a person walking through the view or a misregistered shadow edge does
// not move the estimate.
#pragma once

#include <array>
#include <optional>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "estimation/lighting_model.h"

namespace daylit::estimation {

// One sampled pixel: what the model needs and what the camera saw (radiance units: the
// linearised pixel divided by the exposure).
struct Sample {
  glm::vec3 radiance{0.0f};
  glm::vec3 albedo{0.0f};
  glm::vec3 sun{0.0f};  // a: irradiance per unit DNI (s·max(0, n·l) without interreflection)
  glm::vec3 sky{0.0f};  // b: irradiance per unit DHI of a clear sky (V with a uniform sky and no interreflection)
  glm::vec3 overcast{0.0f};  // irradiance per unit DHI of a uniform overcast sky
  bool sunlit = false;  // s·max(0, n·l) > 0: the direct sun reaches the point
  uint32_t pixel = 0;   // the camera pixel (row-major index into the bake's G-buffer)
  // The model surface the pixel sees (the bake's camera surface map): a surface's samples share
  // its departure from the model's sky (its albedo, the sky's shape toward its normal, gloss).
  uint32_t surface = 0;
};

// What the model predicts for `s` under `light` with the overcast share `overcast_share`:
// ρ/π · (T_sun·E_sun + T_clear·E_clear + T_overcast·E_overcast) with the parts of SplitLight,
// radiance units.
glm::vec3 PredictedRadiance(const Sample& s, const SunSky& light, double overcast_share);
// The same with the light already split into its parts (SplitLight).
glm::vec3 PredictedRadiance(const Sample& s, const LightParts& light);

struct SunSkyFitOptions {
  double cauchy_scale = 0.1;        // relative residual at which a sample's weight halves
  int iterations = 50;             // at most, per IRLS: it stops once the estimate moves less than its
                                    // tolerance (every frame of courtyard-a, -b, -c and -e within 30)
  bool accelerate = true;           // each reweighting step Anderson-accelerated (depth 1): the same
                                    // answer in two thirds of the steps; off: plain IRLS
  double sunlit_threshold = 0.05;   // s·max(0, n·l) above this: a sample that sees the sun well
  int min_stratum_samples = 30;     // per stratum (sunlit, shadowed) for full confidence
  double confident_residual = 0.25; // robust relative residual spread at which confidence is 1/e
                                    // (textured albedo and model gaps leave ~0.1-0.2 on real scenes)
  double confident_share = 0.5;     // a stratum's light this much from the term it measures (the sun
                                    // on sunlit samples, the sky on shadowed ones): a well-posed split
  double absent_sun_share = 0.05;   // below this share of the sunlit samples' light the sun counts
                                    // as absent (overcast): the split's conditioning is the sky's
  bool split_sky = true;            // fit E_clear and E_overcast apart (when the samples differ)
  // E_sun from the shadows the sun casts within each surface, not from how surfaces of different
  // orientation differ: each surface's sky light gets a gain of its own (a free factor on the
  // fitted sky's radiance there), so only a surface's sunlit samples against its own shadowed
  // ones tell the sun. How surfaces facing different ways differ rests on the sky's shape toward
  // each, which a photographed or hazy sky, gloss or a wrong albedo bend by tens of percent; a
  // cast shadow's edge on one surface rests on none of them. But where the model is right, the
  // surfaces' differences are information too. So the gains say which it is: their relative
  // spread s against `surface_model_error` m, what each surface's light is known to be off by in
  // an exact model (per surface and stratum, truth over daylit, 0.966-1.013 on courtyard-a's clear
  // frames: tests/transfer_truth_recording_test.cc), and E_sun = ρ·E_shadows + (1 − ρ)·E_scene
  // with ρ = (1 − m²/s²)·D²/(D² + var) where s > m, else 0: D = E_shadows − E_scene, var what
  // the shadows' estimate is unsure of, its samples' scatter and (m·E_shadows/share)², the model
  // error passed on by the share of the sun's information it rests on (where the two differ by no
  // more, the scene's fit, which knows more, is kept). Only where at least
  // `min_shadow_information` of the sun's information comes from within the surfaces (the Schur
  // complements' ratio).
  bool sun_from_shadows = true;
  double min_shadow_information = 0.05;
  double surface_model_error = 0.02;

  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

enum class SunSkyFitStatus {
  kConverged,
  kSkyOnly,         // no sunlit samples (sun below the horizon or every sample shadowed): E_sun = 0
  kNoConvergence,   // the reweighting ran out of `iterations` with the estimate still moving by more
                    // than its tolerance in some channel's fit (the split one whose overcast part
                    // the final ones take, or a final one): usable, the last iterate
  kTooFewSamples,   // fewer than 10 usable samples: nothing fitted
};

struct SunSkyFitSummary {
  SunSkyFitStatus status = SunSkyFitStatus::kTooFewSamples;
  SunSky light;                 // E_sun (DNI) and E_sky (DHI), RGB, ≥ 0
  double overcast_share = 0.0;  // the grey overcast part: E_overcast = overcast_share · mean(E_sky) (SplitLight)
  double confidence = 0.0;      // in [0, 1]
  double residual_spread = 0.0; // 1.4826·median |relative residual| over channels (robust σ)
  int sunlit_samples = 0;
  int shadowed_samples = 0;
  // Some sample's sun term is > 0 (the sun is above the horizon and lights something, if only by
  // reflection). Sun up without sunlit samples: E_sun is not observed, the fit reports 0 with
  // confidence 0, and the temporal filter holds the last estimate that had it.
  bool sun_up = false;
  double inlier_share = 0.0;    // samples with |relative residual| < 3·cauchy_scale
  int reweighting_steps = 0;    // IRLS steps over every channel's fits (the cost)
  // How well the sun/sky split is posed, from the fitted light (worst channel): the share of the
  // sunlit samples' predicted light that is direct sun, and of the shadowed samples' that is sky
  // (1 without such samples). A stratum lit mostly by the other term passes that term's model
  // error on, amplified by 1/share − 1: a weak sun behind thin cloud, shadows lit mostly by sun
  // reflected from nearby walls.
  double sun_share_sunlit = 1.0;
  double sky_share_shadowed = 1.0;
  // The share of the sun's information that comes from within the surfaces (their own shadows:
  // SunSkyFitOptions::sun_from_shadows), worst channel over the channels whose surfaces' gains
  // differ beyond the model's known error; 0 where none does (the scene's fit then stands and the
  // shadows' estimate is not made), without sunlit samples or with one surface.
  double shadow_information = 0.0;
  // ρ of SunSkyFitOptions::sun_from_shadows, the mean over channels: 0 the whole scene's E_sun,
  // 1 the shadows'.
  double shadow_weight = 0.0;
  // Per channel, where the shadows' estimate was made (0 elsewhere): its ρ; how sure it is, its
  // relative standard error: the casting surfaces' disagreement on the sun (WithinSurfaces'
  // sun_spread; not over √K: what misleads one surface's shadow, gloss, clutter, often misleads
  // the others alike), at least the model error m passed on by the share of the information it
  // holds, m/share, and its samples' scatter added in quadrature; how many surfaces cast shadows
  // (under two, the spread is unseen); and its difference from the scene's fit, relative to the
  // sun it gave. LightInterval reads them.
  struct ShadowSun {
    glm::dvec3 weight{0.0}, error{0.0}, difference{0.0};
    int casting_surfaces = 0;
  };
  ShadowSun shadow_sun;
  // With a sun colour given (FitSunSky), the light with E_sun of that colour: one magnitude from
  // the three channels, each weighed by what it knows of the sun (its normal equations' Schur
  // complement, the clear sky profiled out), and each channel's clear sky refitted with it. The
  // grey overcast part is the same. Clouds are grey: a cloud dims the beam, it does not colour
  // it, so a weak sun's colour is the clear one's, and the channel whose sun is the smallest part
  // of the light (blue under a low sun) no longer trades its sun for sky on its own.
  std::optional<SunSky> coloured;
  // What the estimator carried into this frame (FrameEstimator): the sun's colour here and its
  // weight (estimation/sun_colour.h); weight 0: none.
  glm::dvec3 carried_colour{1.0};
  double carried_weight = 0.0;
  // The frame's own light before the carried colour was mixed in (FitSunSkyAsCarried); `light`
  // itself when nothing was mixed.
  SunSky own;
  std::string message;

  bool IsUsable() const { return status != SunSkyFitStatus::kTooFewSamples; }
};

// Whether a sample counts as sunlit (the sunlit stratum): the sun reaches it, and well, in every
// channel (its sun term above the options' sunlit_threshold). A sample the sun reaches only at a
// grazing angle is in neither stratum.
bool IsSunlit(const Sample& s, const SunSkyFitOptions& options);

// Fits E_sun and E_sky to `samples`. Never throws; a frame that cannot be fitted returns a
// summary with status kTooFewSamples and a message. With `sun_colour` (RGB, > 0), the summary
// also has the fit with E_sun that colour times one magnitude over the three channels (`coloured`).
SunSkyFitSummary FitSunSky(const SunSkyFitOptions& options, const std::vector<Sample>& samples,
                           const glm::dvec3* sun_colour = nullptr);

// A frame's own measure of its sun's colour: a model error in the sky part passes to E_sun
// amplified by (1 − share)/share (share: the sun's part of the sunlit samples' light, worst
// channel), so a frame weighs the inverse square of that (1 at a share of one half).
double SunColourWeight(const SunSkyFitSummary& fit);
// The light of `fit` (made with a sun colour of weight `carried_weight`): a weak sun (below the
// options' confident share) mixes its own fit with the coloured one by the two weights; a clear
// frame keeps its own.
SunSky MixWithCarriedColour(const SunSkyFitOptions& options, const SunSkyFitSummary& fit, double carried_weight);
// FitSunSky with the colour a frame carried (its carried_colour and carried_weight), mixed as the
// estimator mixes it: what refits of a frame's samples (the split check) do.
SunSkyFitSummary FitSunSkyAsCarried(const SunSkyFitOptions& options, const std::vector<Sample>& samples,
                                    const glm::dvec3& carried_colour, double carried_weight);

}  // namespace daylit::estimation
