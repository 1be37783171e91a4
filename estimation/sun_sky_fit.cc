#include "estimation/sun_sky_fit.h"

#include "base/statistics.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

namespace daylit::estimation {
namespace {

constexpr int kMinSamples = 10;

double Median(std::vector<double> v) { return MedianInPlace(v, 0.0); }

struct ChannelFit {
  double sun = 0.0, sky = 0.0;
};

// Weighted least squares for y ≈ u·E_sun + v·E_sky with E ≥ 0 (two unknowns: the unconstrained
// solution if it is feasible, else the better of the two one-variable solutions).
ChannelFit SolveNonNegative(const std::vector<double>& y, const std::vector<double>& u, const std::vector<double>& v,
                            const std::vector<double>& w, bool with_sun) {
  double suu = 0, suv = 0, svv = 0, suy = 0, svy = 0;
  for (size_t i = 0; i < y.size(); ++i) {
    suu += w[i] * u[i] * u[i], suv += w[i] * u[i] * v[i], svv += w[i] * v[i] * v[i];
    suy += w[i] * u[i] * y[i], svy += w[i] * v[i] * y[i];
  }
  const auto cost = [&](double sun, double sky) {
    double c = 0.0;
    for (size_t i = 0; i < y.size(); ++i) {
      const double r = y[i] - u[i] * sun - v[i] * sky;
      c += w[i] * r * r;
    }
    return c;
  };
  const double det = suu * svv - suv * suv;
  if (with_sun && det > 1e-12 * suu * svv) {
    const ChannelFit free{(svv * suy - suv * svy) / det, (suu * svy - suv * suy) / det};
    if (free.sun >= 0.0 && free.sky >= 0.0) return free;
  }
  const ChannelFit sky_only{0.0, svv > 0.0 ? std::max(0.0, svy / svv) : 0.0};
  if (!with_sun) return sky_only;
  const ChannelFit sun_only{suu > 0.0 ? std::max(0.0, suy / suu) : 0.0, 0.0};
  return cost(sky_only.sun, sky_only.sky) <= cost(sun_only.sun, sun_only.sky) ? sky_only : sun_only;
}

}  // namespace

bool SunSkyFitOptions::Check(std::string* why) const {
  if (!(cauchy_scale > 0.0) || iterations < 1 || !(sunlit_threshold > 0.0 && sunlit_threshold < 1.0) ||
      min_stratum_samples < 1 || !(confident_residual > 0.0)) {
    *why = fmt::format("sun/sky fit options out of range (cauchy_scale {}, iterations {}, sunlit_threshold {}, "
                       "min_stratum_samples {}, confident_residual {})",
                       cauchy_scale, iterations, sunlit_threshold, min_stratum_samples, confident_residual);
    return false;
  }
  return true;
}

SunSkyFitSummary FitSunSky(const SunSkyFitOptions& options, const std::vector<Sample>& samples) {
  SunSkyFitSummary summary;
  std::vector<size_t> usable;
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    if (s.sky > 0.0f || s.sun > 0.0f) usable.push_back(i);
    if (s.sun > options.sunlit_threshold) {
      ++summary.sunlit_samples;
    } else if (s.sun <= 0.0f) {
      ++summary.shadowed_samples;
    }
  }
  if (static_cast<int>(usable.size()) < kMinSamples) {
    summary.message = fmt::format("{} usable samples (need {})", usable.size(), kMinSamples);
    return summary;
  }
  const bool with_sun = summary.sunlit_samples > 0;
  const size_t n = usable.size();
  std::vector<double> spreads;
  std::vector<double> all_residuals;
  all_residuals.reserve(3 * n);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> y(n), u(n), v(n), w(n, 1.0);
    for (size_t k = 0; k < n; ++k) {
      const Sample& s = samples[usable[k]];
      y[k] = s.radiance[c];
      u[k] = s.albedo[c] * glm::one_over_pi<double>() * s.sun;
      v[k] = s.albedo[c] * glm::one_over_pi<double>() * s.sky;
    }
    // Robust start: the sky from the shadowed samples alone, then the sun from the sunlit ones.
    std::vector<double> sky_ratios, sun_ratios;
    for (size_t k = 0; k < n; ++k) {
      if (samples[usable[k]].sun <= 0.0f && v[k] > 0.0) sky_ratios.push_back(y[k] / v[k]);
    }
    ChannelFit fit{0.0, Median(sky_ratios)};
    if (sky_ratios.empty()) fit = SolveNonNegative(y, u, v, w, with_sun);
    for (size_t k = 0; k < n; ++k) {
      if (samples[usable[k]].sun > options.sunlit_threshold) sun_ratios.push_back((y[k] - v[k] * fit.sky) / u[k]);
    }
    if (with_sun && !sun_ratios.empty()) fit.sun = std::max(0.0, Median(sun_ratios));
    // IRLS, Cauchy weights on residuals relative to the prediction (floored at a tenth of the
    // median prediction, so near-black points do not dominate).
    std::vector<double> relative(n);
    for (int iteration = 0; iteration < options.iterations; ++iteration) {
      std::vector<double> predictions(n);
      for (size_t k = 0; k < n; ++k) predictions[k] = u[k] * fit.sun + v[k] * fit.sky;
      const double floor = std::max(1e-12, 0.1 * Median(predictions));
      for (size_t k = 0; k < n; ++k) {
        const double scale = std::max(predictions[k], floor);
        relative[k] = (y[k] - predictions[k]) / scale;
        const double r = relative[k] / options.cauchy_scale;
        // Least squares on relative residuals: weight 1/scale² times the Cauchy weight.
        w[k] = 1.0 / (scale * scale * (1.0 + r * r));
      }
      fit = SolveNonNegative(y, u, v, w, with_sun);
    }
    summary.light.sun_rgb[c] = fit.sun;
    summary.light.sky_rgb[c] = fit.sky;
    std::vector<double> magnitude(n);
    for (size_t k = 0; k < n; ++k) magnitude[k] = std::abs(relative[k]), all_residuals.push_back(magnitude[k]);
    spreads.push_back(1.4826 * Median(magnitude));
  }
  summary.residual_spread = *std::max_element(spreads.begin(), spreads.end());
  size_t inliers = 0;
  for (const double r : all_residuals) inliers += r < 3.0 * options.cauchy_scale ? 1 : 0;
  summary.inlier_share = static_cast<double>(inliers) / static_cast<double>(all_residuals.size());
  // Confidence: small robust residuals, and both strata present (sunlit and shadowed samples are
  // what separates E_sun from E_sky; without sunlit ones E_sun is not observed at all).
  const double fit_quality = std::exp(-std::pow(summary.residual_spread / options.confident_residual, 2.0));
  const double strata = std::min(1.0, static_cast<double>(summary.shadowed_samples) / options.min_stratum_samples) *
                        (with_sun ? std::min(1.0, static_cast<double>(summary.sunlit_samples) / options.min_stratum_samples) : 1.0);
  summary.confidence = fit_quality * strata * summary.inlier_share;
  summary.status = with_sun ? SunSkyFitStatus::kConverged : SunSkyFitStatus::kSkyOnly;
  summary.message = fmt::format("{} samples ({} sunlit, {} shadowed), residual spread {:.3f}", n,
                                summary.sunlit_samples, summary.shadowed_samples, summary.residual_spread);
  return summary;
}

}  // namespace daylit::estimation
