// How sure one frame's E_sun and E_sky are: a 90% interval per channel, from what the frame shows,
// never from a truth.
//
// The fit explains each stratum (sunlit samples, shadowed samples) as a whole, so a stratum's mean
// residual is near zero whatever the model gets wrong; what the frame does show is how much the
// surfaces within a stratum disagree. A surface whose light the model gets wrong (a window, clutter,
// gloss, a wrong albedo, a transfer term off) sits away from the others by its own bias. The
// stratum's model error δ is taken as the RMS of its surfaces' biases (each surface's mean
// relative residual, clipped at the fit's outlier bound, weighted by its samples, the one degree of freedom the fit took from them
// given back: × K/(K − 1) in variance for K surfaces), at least `floor`: not the spread divided by
// √K, because what misleads one surface (the captured sky, the sky's shape, the camera's response)
// often misleads its neighbours the same way.
//
// The split passes each stratum's error on to the term it does not measure, amplified where that
// term is a small part of its light (docs/estimation.md, Confidence): with s the sun's share of the
// sunlit samples' predicted light and q the sky's share of the shadowed samples', per channel,
//
//   E_sky:  e_sky² = (δ_shadowed / q)² + ((1 − q)/q · δ_sunlit)²
//   E_sun:  e_sun² = (δ_sunlit / s)² + ((1 − s)/s · e_sky)²
//
// or, where the estimator has measured it, as the fit itself passes it (StrataSensitivityOfFit:
// the sunlit samples tell the fit of E_sky too). The 90% interval is ±1.645·e (a normal error),
// with the sky shape's spread (SkyShapeSpreadOfFit, what the frame cannot tell of the sky's
// shape) added to e in quadrature. A sun under
// `absent_sun_share` of the sunlit samples' light is not observed: its interval says so
// (observed = false) rather than a width.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "estimation/sun_sky_fit.h"

namespace daylit::estimation {

struct LightIntervalOptions {
  double floor = 0.02;         // the least model error of a stratum: the strata of an exact model
                               // under the true light agree within 1-2% (tests/transfer_truth_recording_test.cc)
  double z = 1.645;            // the normal quantile of a two-sided 90% interval
  double max_half_width = 10;  // relative; beyond it the value says nothing (10 = ±1000%)
  // The sky's shape (SkyShapeSpreadOfFit) and the fit's sensitivity to each stratum
  // (StrataSensitivityOfFit): their refits take `sky_shape_iterations` of the fit's reweighting
  // steps, and the estimator makes them on a usable frame at least `sky_shape_every_s` after the
  // last that had them (a cloud takes seconds to pass), the frames between keeping the last: the
  // same cost a second whatever the frame rate.
  bool sky_shape = true;
  bool strata_sensitivity = true;
  int sky_shape_iterations = 3;
  double sky_shape_every_s = 2.0;
  std::string Check() const;
};

// How far E_sun and E_sky move with the sky's shape, as far as the frame cannot tell that shape:
// relative, one standard deviation, per channel.
struct SkyShapeSpread {
  glm::dvec3 sun{0.0}, sky{0.0};
};

// How the fit passes a stratum's error on to E_sun and E_sky: the relative change of each per unit
// relative bias of the shadowed stratum's radiance, per channel, signed. The fit is scale-free (all
// samples brighter by a factor give the light brighter by it), so the sunlit stratum's (grazing
// samples with it) is 1 minus it. known = false: not measured (IntervalOfFit then takes each term
// as measured by one stratum alone, below).
struct StrataSensitivity {
  glm::dvec3 sun{0.0}, sky{1.0};
  bool known = false;
};

// Relative half-widths of the 90% intervals (0.05: ±5%), per channel.
struct LightInterval {
  glm::dvec3 sun{0.0}, sky{0.0};
  bool sun_observed = false;  // false: no sunlit samples, or the sun too weak a part of their light
  // A sun not observed among sunlit samples: the largest E_sun the frame would not have seen, per
  // channel (absolute; 0 otherwise): the one that would be absent_sun_share of their light in the
  // worst channel, the others by the sun's colour. BoundsOf's upper bound is at least this.
  glm::dvec3 sun_bound{0.0};
  bool known = false;         // false: nothing fitted (the interval of a held frame is the last one's)
  // The strata's model errors (δ above, worst channel) and how many surfaces each had.
  double sunlit_error = 0.0, shadowed_error = 0.0;
  int sunlit_surfaces = 0, shadowed_surfaces = 0;
  // The sky shape's part (SkyShapeSpreadOfFit) that the interval includes.
  SkyShapeSpread sky_shape;
};

// The interval of `fit`, made from `samples`; `surface_of_pixel` is the bake's camera surface map
// (Sample::pixel indexes it). An unusable fit gives known = false. `shape`'s spread is added to
// each term's in quadrature. With `sensitivity` known, each stratum's error δ passes to E_sun and
// E_sky as the fit passes it (StrataSensitivityOfFit):
//
//   e_sky² = (k_sky · δ_shadowed)² + ((1 − k_sky) · δ_sunlit)²,  e_sun² = (k_sun · δ_shadowed)² + ((1 − k_sun) · δ_sunlit)²
//
// else by the shares s and q of the file's header, as if E_sky were measured by the shadowed
// samples alone and E_sun by the sunlit ones given E_sky. Where E_sun came partly from the
// surfaces' own shadows (fit.shadow_sun: E_sun = ρ·E_shadows + (1 − ρ)·E_scene), the surfaces'
// disagreement describes the scene's estimate only, and the two are mixed as a model average is:
// e_sun² = ρ·e_shadows² + (1 − ρ)·e_scene² + ρ(1 − ρ)·D², D their relative difference.
LightInterval IntervalOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                            const std::vector<Sample>& samples, const SunSkyFitSummary& fit,
                            const std::vector<uint32_t>& surface_of_pixel, const SkyShapeSpread& shape = {},
                            const StrataSensitivity& sensitivity = {});

// The fit's sensitivity to the shadowed stratum: every second of `samples` refitted
// (sky_shape_iterations of the fit's reweighting steps) as they are and with the shadowed samples'
// radiance 2% higher. The
// shares' rule above takes E_sky as resting on the shadowed samples alone; the fit also draws it
// from the sky's part of the sunlit samples' light (a quarter of it and more under a low sun), and
// on the bundled recordings the shadowed samples move E_sky by 0.2-1.0 times their bias where q's
// rule says 1.1-3.5 (docs/estimation.md). Unknown (known = false) for an unusable fit or one
// without sunlit samples.
StrataSensitivity StrataSensitivityOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                                         const std::vector<Sample>& samples, const SunSkyFitSummary& fit);

// The sky's shape. The fit mixes two: the captured clear sky re-aimed (E_clear) and a uniform one
// (E_overcast). A sky of another shape (another haze, thin cloud, a photographed sky unlike the
// capture's) moves E_sky by tens of percent while the fit still explains the frame, and the
// surfaces' disagreement above does not show it. So the frame is refitted with its whole sky of
// each shape; each refit is weighed by its likelihood against the fit's own, the surfaces' biases
// taken as normal with an unknown common variance (profiled out): (D²_refit / D²_own)^(−K/2), D²
// the sum over both strata of surfaces × their mean square bias as the frame shows it (worst
// channel; not δ: without δ's floor, which hides every difference under it, and with the noise of
// each surface's mean added, so that two shapes both within the pixels' noise weigh alike) and K
// the surfaces. The spread is the root of the
// weighted mean square of the refits' relative differences in E_sun and E_sky from the fit's (the
// fit's own shape counted with weight 1 and difference 0): the between-model part of a Bayesian
// model average's variance.
SkyShapeSpread SkyShapeSpreadOfFit(const LightIntervalOptions& options, const SunSkyFitOptions& fit_options,
                                   const std::vector<Sample>& samples, const SunSkyFitSummary& fit,
                                   const std::vector<uint32_t>& surface_of_pixel);

// The interval's bounds around `light` per channel: [v·(1 − h), v·(1 + h)], the low bound at
// least 0 (x: low, y: high). A sun not observed has [0, v·(1 + max_half_width)], the high bound at
// least its sun_bound: an estimate of 0 is not a bound of 0.
struct IntervalBounds {
  std::array<glm::dvec2, 3> sun, sky;
};
IntervalBounds BoundsOf(const SunSky& light, const LightInterval& interval);

// The bounds as CSV columns, the same in estimates.csv and bursts.csv: the header's names
// (sun_r_lo,sun_r_hi,...,sky_b_lo,sky_b_hi, no leading comma) and one row's fields (each after a
// comma).
const char* IntervalCsvHeader();
std::string IntervalCsvFields(const IntervalBounds& bounds);

}  // namespace daylit::estimation
