#include "estimation/light_interval.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/gtx/component_wise.hpp>

#include "base/options_check.h"

namespace daylit::estimation {
namespace {

// One surface's samples in one stratum: their relative residuals, clipped, summed.
struct SurfaceResiduals {
  glm::dvec3 sum{0.0}, sum_sq{0.0};
  double n = 0.0;
};

// One stratum's model error per channel (the RMS of its surfaces' mean relative residuals, K/(K − 1)
// in variance) and how many surfaces it had.
struct StratumError {
  glm::dvec3 error{0.0};
  int surfaces = 0;
  // What the likelihood of a sky shape reads (SkyShapeSpreadOfFit): the surfaces' mean square
  // bias as the frame shows it, without the floor or the K/(K − 1), plus the noise of each
  // surface's mean (its samples' scatter over their count), per channel.
  glm::dvec3 observed{0.0};
};

StratumError ErrorOfStratum(const std::vector<SurfaceResiduals>& surfaces, double floor) {
  StratumError out;
  glm::dvec3 sum_sq(0.0), noise(0.0);
  double n = 0.0;
  for (const SurfaceResiduals& r : surfaces) {
    if (r.n < 3.0) continue;
    ++out.surfaces;
    const glm::dvec3 bias = r.sum / r.n;
    sum_sq += r.n * bias * bias;
    // n × the variance of the surface's mean: its samples' variance.
    noise += glm::max(r.sum_sq / r.n - bias * bias, glm::dvec3(0.0)) * (r.n / (r.n - 1.0));
    n += r.n;
  }
  const double k = out.surfaces;
  const glm::dvec3 variance = out.surfaces >= 2 ? sum_sq / n * (k / (k - 1.0)) : glm::dvec3(0.0);
  out.error = glm::max(glm::sqrt(variance), glm::dvec3(floor));
  if (n > 0.0) out.observed = (sum_sq + noise) / n;
  return out;
}

// The strata's model errors of `fit` on `samples` and the shares the split passes them on by.
struct StrataErrors {
  StratumError lit, shadowed;
  double lit_n = 0.0, shadowed_n = 0.0;
  glm::dvec3 s{0.0}, q{1.0};  // the sun's share of the sunlit samples' light, the sky's of the shadowed ones'
  // Over the sunlit samples: Σ of their radiance per unit E_sun, and Σ of their predicted radiance
  // from the sky (and the light the model reflects onto them) under the fit.
  glm::dvec3 lit_unit_sun{0.0}, lit_sky{0.0};
  // Σ over both strata of surfaces × their observed mean square bias (worst channel): how much
  // the surfaces disagree, all told, as the frame shows it.
  double Disagreement() const {
    return lit.surfaces * glm::compMax(lit.observed) + shadowed.surfaces * glm::compMax(shadowed.observed);
  }
  int Surfaces() const { return lit.surfaces + shadowed.surfaces; }
};

StrataErrors ErrorsOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                         const std::vector<Sample>& samples, const SunSkyFitSummary& fit,
                         const std::vector<uint32_t>& surface_of_pixel) {
  StrataErrors out;
  const LightParts all = SplitLight(fit.light, fit.overcast_share);
  const LightParts sun_only{all.sun, glm::vec3(0.0f), glm::vec3(0.0f)}, sky_only{glm::vec3(0.0f), all.clear, all.overcast};
  const LightParts unit_sun{glm::vec3(1.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
  // Relative residuals by stratum and surface, and each stratum's share of its light from the term
  // it measures (a mean of shares, as the fit's SplitShares).
  std::vector<SurfaceResiduals> lit, shadowed;  // by surface
  glm::dvec3 sun_share(0.0), sky_share(0.0);
  // Clipped where the fit stops counting a sample as an inlier (3 Cauchy scales): a walker or a
  // misregistered edge is the fit's outlier, not a surface's bias.
  const float clip = static_cast<float>(3.0 * fit_options.cauchy_scale);
  for (const Sample& s : samples) {
    const bool is_lit = IsSunlit(s, fit_options);
    if (!is_lit && s.sunlit) continue;  // grazing sun: neither stratum
    const glm::vec3 sun = PredictedRadiance(s, sun_only);
    const glm::vec3 predicted = sun + PredictedRadiance(s, sky_only);
    if (!(glm::compMin(predicted) > 0.0f)) continue;
    const uint32_t surface = s.pixel < surface_of_pixel.size() ? surface_of_pixel[s.pixel] : 0;
    std::vector<SurfaceResiduals>& stratum = is_lit ? lit : shadowed;
    if (surface >= stratum.size()) {
      if (surface > 1u << 16) continue;  // no surface (the sky): not a sample of the model
      stratum.resize(surface + 1);
    }
    SurfaceResiduals& r = stratum[surface];
    const glm::dvec3 residual(glm::clamp(s.radiance / predicted - 1.0f, -clip, clip));
    r.sum += residual;
    r.sum_sq += residual * residual;
    r.n += 1.0;
    if (is_lit) {
      sun_share += glm::dvec3(sun / predicted), out.lit_n += 1.0;
      out.lit_unit_sun += glm::dvec3(PredictedRadiance(s, unit_sun));
      out.lit_sky += glm::dvec3(predicted - sun);
    } else {
      sky_share += glm::dvec3(1.0f - sun / predicted), out.shadowed_n += 1.0;
    }
  }
  out.lit = ErrorOfStratum(lit, options.floor);
  out.shadowed = ErrorOfStratum(shadowed, options.floor);
  out.s = out.lit_n > 0.0 ? glm::clamp(sun_share / out.lit_n, 0.0, 1.0) : glm::dvec3(0.0);
  out.q = out.shadowed_n > 0.0 ? glm::clamp(sky_share / out.shadowed_n, 1e-3, 1.0) : glm::dvec3(1.0);
  return out;
}

// The largest sun a frame would not have seen. The sun is not observed where its share of the
// sunlit samples' light is under a = absent_sun_share in its worst channel w; there that share
// would be a with a sun of a/(1 − a) · sky_w / unit_w (the sums' ratio). The other channels have
// no such rule (a red sun can be seen in red and not in blue), so they take the sun's colour: the
// one carried (estimation/sun_colour.h), else the fit's own, else each channel's own share rule.
glm::dvec3 SunBound(const SunSkyFitOptions& fit_options, const SunSkyFitSummary& fit, const StrataErrors& strata) {
  glm::dvec3 out(0.0);
  if (!(strata.lit_n > 0.0) || !(glm::compMin(strata.lit_unit_sun) > 0.0)) return out;
  const double a = fit_options.absent_sun_share;
  const glm::dvec3 own = a / (1.0 - a) * strata.lit_sky / strata.lit_unit_sun;
  int w = 0;
  for (int c = 1; c < 3; ++c) {
    if (strata.s[c] < strata.s[w]) w = c;
  }
  glm::dvec3 colour(0.0);
  if (fit.carried_weight > 0.0 && glm::compMin(fit.carried_colour) > 0.0) {
    colour = fit.carried_colour;
  } else if (glm::compMin(fit.light.sun_rgb) > 0.0) {
    colour = fit.light.sun_rgb;
  }
  if (!(glm::compMin(colour) > 0.0)) return own;
  return glm::max(own, own[w] * colour / colour[w]);
}

}  // namespace

std::string LightIntervalOptions::Check() const {
  return FirstProblem({InOpenClosed("floor", floor, 0.0, 1.0), InOpenClosed("z", z, 0.0, 10.0),
                       InOpenClosed("max_half_width", max_half_width, 0.0, 1e6),
                       InClosed("sky_shape_iterations", sky_shape_iterations, 1, 100),
                       InClosed("sky_shape_every_s", sky_shape_every_s, 0.0, 3600.0)});
}

SkyShapeSpread SkyShapeSpreadOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                                   const std::vector<Sample>& samples, const SunSkyFitSummary& fit,
                                   const std::vector<uint32_t>& surface_of_pixel) {
  SkyShapeSpread out;
  if (!fit.IsUsable()) return out;
  const StrataErrors own = ErrorsOfFit(options, fit_options, samples, fit, surface_of_pixel);
  const int k = own.Surfaces();
  const double own_disagreement = own.Disagreement();
  if (k < 2 || !(own_disagreement > 0.0)) return out;
  SunSkyFitOptions alternative_options = fit_options;
  alternative_options.iterations = std::min(fit_options.iterations, options.sky_shape_iterations);
  double weights = 1.0;  // the fit's own shape, at zero distance from itself
  std::vector<Sample> shaped = samples;
  for (const bool clear : {true, false}) {
    // The whole sky of one shape: the captured clear sky's, or a uniform one's.
    for (size_t i = 0; i < samples.size(); ++i) {
      shaped[i].sky = clear ? samples[i].sky : samples[i].overcast;
      shaped[i].overcast = shaped[i].sky;
    }
    const SunSkyFitSummary alternative = FitSunSky(alternative_options, shaped);
    if (!alternative.IsUsable()) continue;
    const StrataErrors errors = ErrorsOfFit(options, fit_options, shaped, alternative, surface_of_pixel);
    // Its likelihood relative to the fit's own, the surfaces' biases taken as normal with a common
    // unknown variance (profiled out): (D²_alternative / D²_own)^(−K/2).
    const double weight = std::pow(std::max(errors.Disagreement() / own_disagreement, 1e-6), -0.5 * k);
    weights += weight;
    for (int c = 0; c < 3; ++c) {
      if (fit.light.sun_rgb[c] > 0.0f) out.sun[c] += weight * std::pow(alternative.light.sun_rgb[c] / fit.light.sun_rgb[c] - 1.0, 2.0);
      if (fit.light.sky_rgb[c] > 0.0f) out.sky[c] += weight * std::pow(alternative.light.sky_rgb[c] / fit.light.sky_rgb[c] - 1.0, 2.0);
    }
  }
  out.sun = glm::sqrt(out.sun / weights);
  out.sky = glm::sqrt(out.sky / weights);
  return out;
}

StrataSensitivity StrataSensitivityOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                                         const std::vector<Sample>& samples, const SunSkyFitSummary& fit) {
  StrataSensitivity out;
  if (!fit.IsUsable() || fit.sunlit_samples == 0) return out;
  // A bias the size of the floor: small beside the Cauchy scale (0.1), so the reweighting barely
  // changes and the response is the fit's linear one.
  constexpr double kBias = 0.02;
  SunSkyFitOptions refit_options = fit_options;
  refit_options.iterations = std::min(fit_options.iterations, options.sky_shape_iterations);
  // Every second sample: the sensitivity is the transfer terms', not the pixels' noise, and half
  // the samples halve the refits' cost.
  std::vector<Sample> half;
  half.reserve(samples.size() / 2 + 1);
  for (size_t i = 0; i < samples.size(); i += 2) half.push_back(samples[i]);
  const SunSkyFitSummary base = FitSunSky(refit_options, half);
  std::vector<Sample> biased = std::move(half);
  for (Sample& s : biased) {
    if (!s.sunlit) s.radiance *= static_cast<float>(1.0 + kBias);
  }
  const SunSkyFitSummary moved = FitSunSky(refit_options, biased);
  if (!base.IsUsable() || !moved.IsUsable()) return out;
  for (int c = 0; c < 3; ++c) {
    const double sun = base.light.sun_rgb[c], sky = base.light.sky_rgb[c];
    out.sun[c] = sun > 0.0 ? (moved.light.sun_rgb[c] / sun - 1.0) / kBias : 0.0;
    out.sky[c] = sky > 0.0 ? (moved.light.sky_rgb[c] / sky - 1.0) / kBias : 1.0;
  }
  out.known = true;
  return out;
}

LightInterval IntervalOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                            const std::vector<Sample>& samples, const SunSkyFitSummary& fit,
                            const std::vector<uint32_t>& surface_of_pixel, const SkyShapeSpread& shape,
                            const StrataSensitivity& sensitivity) {
  LightInterval out;
  if (!fit.IsUsable()) return out;
  out.known = true;
  const StrataErrors strata = ErrorsOfFit(options, fit_options, samples, fit, surface_of_pixel);
  const StratumError& lit_error = strata.lit;
  const StratumError& shadowed_error = strata.shadowed;
  out.sunlit_error = glm::compMax(lit_error.error), out.sunlit_surfaces = lit_error.surfaces;
  out.shadowed_error = glm::compMax(shadowed_error.error), out.shadowed_surfaces = shadowed_error.surfaces;
  const glm::dvec3 s = strata.s, q = strata.q;
  out.sky_shape = shape;
  // Without shadowed samples E_sky rests on the sunlit ones alone: their error, unamplified, is the
  // least it can have.
  const glm::dvec3 shadowed_delta = strata.shadowed_n > 0.0 ? shadowed_error.error : glm::max(lit_error.error, glm::dvec3(options.floor));
  const glm::dvec3 sky = sensitivity.known
                             ? glm::sqrt(glm::pow(sensitivity.sky * shadowed_delta, glm::dvec3(2.0)) +
                                         glm::pow((1.0 - sensitivity.sky) * lit_error.error, glm::dvec3(2.0)))
                             : glm::sqrt(glm::pow(shadowed_delta / q, glm::dvec3(2.0)) +
                                         glm::pow((1.0 - q) / q * lit_error.error, glm::dvec3(2.0)));
  out.sky = glm::min(options.z * glm::sqrt(sky * sky + shape.sky * shape.sky), glm::dvec3(options.max_half_width));
  out.sun_observed = strata.lit_n > 0.0 && glm::compMin(s) >= fit_options.absent_sun_share;
  if (out.sun_observed) {
    glm::dvec3 sun = sensitivity.known
                         ? glm::sqrt(glm::pow(sensitivity.sun * shadowed_delta, glm::dvec3(2.0)) +
                                     glm::pow((1.0 - sensitivity.sun) * lit_error.error, glm::dvec3(2.0)))
                         : glm::sqrt(glm::pow(lit_error.error / s, glm::dvec3(2.0)) + glm::pow((1.0 - s) / s * sky, glm::dvec3(2.0)));
    // Where E_sun is partly the shadows' (ρ·E_shadows + (1 − ρ)·E_scene), the surfaces'
    // disagreement above describes the scene's estimate only; the two mixed as the estimates are: the
    // variance of a model average, ρ·e_shadows² + (1 − ρ)·e_scene² + ρ(1 − ρ)·D². With under two
    // casting surfaces nothing shows how far the shadows' estimate is off, and it is taken as unsure
    // as the scene's.
    const SunSkyFitSummary::ShadowSun& shadows = fit.shadow_sun;
    for (int c = 0; c < 3; ++c) {
      const double rho = shadows.weight[c];
      if (!(rho > 0.0)) continue;
      const double own = shadows.casting_surfaces >= 2 ? shadows.error[c] : std::max(shadows.error[c], sun[c]);
      const double d = shadows.difference[c];
      sun[c] = std::sqrt(rho * own * own + (1.0 - rho) * sun[c] * sun[c] + rho * (1.0 - rho) * d * d);
    }
    out.sun = glm::min(options.z * glm::sqrt(sun * sun + shape.sun * shape.sun), glm::dvec3(options.max_half_width));
  } else {
    out.sun = glm::dvec3(options.max_half_width);
    out.sun_bound = SunBound(fit_options, fit, strata);
  }
  return out;
}

IntervalBounds BoundsOf(const SunSky& light, const LightInterval& interval) {
  IntervalBounds out;
  for (int c = 0; c < 3; ++c) {
    out.sun[c] = {std::max(0.0, light.sun_rgb[c] * (1.0 - interval.sun[c])),
                  std::max(light.sun_rgb[c] * (1.0 + interval.sun[c]), interval.sun_bound[c])};
    out.sky[c] = {std::max(0.0, light.sky_rgb[c] * (1.0 - interval.sky[c])), light.sky_rgb[c] * (1.0 + interval.sky[c])};
  }
  return out;
}

const char* IntervalCsvHeader() {
  return "sun_r_lo,sun_r_hi,sun_g_lo,sun_g_hi,sun_b_lo,sun_b_hi,sky_r_lo,sky_r_hi,sky_g_lo,sky_g_hi,sky_b_lo,sky_b_hi";
}

std::string IntervalCsvFields(const IntervalBounds& bounds) {
  std::string out;
  for (const std::array<glm::dvec2, 3>* term : {&bounds.sun, &bounds.sky}) {
    for (const glm::dvec2& b : *term) out += fmt::format(",{:.6g},{:.6g}", b.x, b.y);
  }
  return out;
}

}  // namespace daylit::estimation
