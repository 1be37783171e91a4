#include "estimation/sun_sky_fit.h"

#include "base/options_check.h"

#include "base/statistics.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Core>
#include <fmt/format.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>

namespace daylit::estimation {
namespace {

constexpr int kMinSamples = 10;

bool IsSunlit(const Sample& s, const SunSkyFitOptions& options) {
  return s.sunlit && glm::compMin(s.sun) > options.sunlit_threshold;
}

// E_sun, E_clear, E_overcast of one channel.
using ChannelFit = std::array<double, 3>;

// The weighted normal equations of y ≈ Σ_j x_j·E_j: A = Σ w x xᵀ, b = Σ w x y, yy = Σ w y².
struct NormalEquations {
  std::array<std::array<double, 3>, 3> a{};
  std::array<double, 3> b{};
  double yy = 0.0;
};

// The least-squares E ≥ 0 over the unknowns in `free` (the others stay 0): every subset of them is
// solved and the best feasible one wins (three unknowns at most: seven subsets, each a 3×3 solve).
ChannelFit SolveNonNegative(const NormalEquations& eq, const std::array<bool, 3>& free) {
  const auto& a = eq.a;
  const auto& b = eq.b;
  ChannelFit best{0.0, 0.0, 0.0};
  double best_cost = eq.yy;
  for (unsigned mask = 1; mask < 8; ++mask) {
    std::array<size_t, 3> idx{};
    size_t m = 0;
    bool allowed = true;
    for (size_t j = 0; j < 3; ++j) {
      if (mask & (1u << j)) allowed = allowed && free[j], idx[m++] = j;
    }
    if (!allowed) continue;
    // Solve the m×m system by Gaussian elimination with partial pivoting.
    std::array<std::array<double, 4>, 3> g{};
    for (size_t r = 0; r < m; ++r) {
      for (size_t c = 0; c < m; ++c) g[r][c] = a[idx[r]][idx[c]];
      g[r][3] = b[idx[r]];
    }
    bool singular = false;
    for (size_t c = 0; c < m && !singular; ++c) {
      size_t pivot = c;
      for (size_t r = c + 1; r < m; ++r) pivot = std::abs(g[r][c]) > std::abs(g[pivot][c]) ? r : pivot;
      std::swap(g[c], g[pivot]);
      if (!(std::abs(g[c][c]) > 1e-12 * std::abs(a[idx[c]][idx[c]]) && g[c][c] != 0.0)) {
        singular = true;
        break;
      }
      for (size_t r = 0; r < m; ++r) {
        if (r == c) continue;
        const double f = g[r][c] / g[c][c];
        for (size_t k = c; k < 4; ++k) g[r][k] -= f * g[c][k];
      }
    }
    if (singular) continue;
    ChannelFit e{0.0, 0.0, 0.0};
    bool feasible = true;
    for (size_t r = 0; r < m; ++r) e[idx[r]] = g[r][3] / g[r][r], feasible = feasible && e[idx[r]] >= 0.0;
    if (!feasible) continue;
    // cost = yᵀWy − 2 eᵀb + eᵀA e
    double cost = eq.yy;
    for (size_t j = 0; j < 3; ++j) {
      cost -= 2.0 * e[j] * b[j];
      for (size_t k = 0; k < 3; ++k) cost += e[j] * a[j][k] * e[k];
    }
    if (cost < best_cost) best_cost = cost, best = e;
  }
  return best;
}

}  // namespace

std::string SunSkyFitOptions::Check() const {
  return FirstProblem({InOpenClosed("cauchy_scale", cauchy_scale, 0.0, 10.0), InClosed("iterations", iterations, 1, 1000),
                       InOpenClosed("sunlit_threshold", sunlit_threshold, 0.0, 0.999),
                       InClosed("min_stratum_samples", min_stratum_samples, 1, 1000000),
                       InOpenClosed("confident_residual", confident_residual, 0.0, 10.0)});
}

SunSkyFitSummary FitSunSky(const SunSkyFitOptions& options, const std::vector<Sample>& samples) {
  SunSkyFitSummary summary;
  std::vector<size_t> usable;
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    if (glm::compMax(s.sky) > 0.0f || glm::compMax(s.sun) > 0.0f) usable.push_back(i);
    if (IsSunlit(s, options)) {
      ++summary.sunlit_samples;
    } else if (!s.sunlit) {
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
  // Two skies (clear-shaped and overcast) when the samples tell them apart, else one.
  bool two_skies = options.split_sky;
  if (two_skies) {
    two_skies = false;
    for (const size_t i : usable) two_skies = two_skies || samples[i].sky != samples[i].overcast;
  }
  std::vector<double> y(n), w(n), relative(n), scratch;
  std::array<std::vector<double>, 3> x{std::vector<double>(n), std::vector<double>(n), std::vector<double>(n)};
  scratch.reserve(n);
  // Medians (start, floor, spread) are taken over every `stride`-th sample: ~2000 of them give each
  // to well under 1% and cost a quarter of the time.
  const size_t stride = std::max<size_t>(1, n / 2000);
  // One channel: E_sun and E_sky, or, with `split`, E_sun, E_clear and E_overcast; else the sky's
  // regressor is the clear one and the overcast one mixed by `share`. `start`, if given, replaces
  // the median-based start. Fits the samples `rows`.
  int unconverged_channels = 0;  // final fits that ran out of IRLS iterations
  const auto fit_channel = [&](int c, bool split, double share, const ChannelFit* start,
                               const std::vector<size_t>& rows) {
    const size_t m = rows.size();
    std::vector<double>&u = x[0], &v = x[1];
    for (size_t k = 0; k < m; ++k) {
      const Sample& s = samples[rows[k]];
      const double a = s.albedo[c] * glm::one_over_pi<double>();
      y[k] = s.radiance[c];
      u[k] = a * s.sun[c];
      v[k] = split ? a * s.sky[c] : a * ((1.0 - share) * s.sky[c] + share * s.overcast[c]);
      x[2][k] = split ? a * s.overcast[c] : 0.0;
    }
    const std::array<bool, 3> free{with_sun, true, split};
    // The weighted normal equations of the m samples with the weights in w (all three
    // regressors; an unused one is zero), vectorised by Eigen.
    const Eigen::Map<const Eigen::ArrayXd> ey(y.data(), static_cast<Eigen::Index>(m)),
        ex0(x[0].data(), static_cast<Eigen::Index>(m)), ex1(x[1].data(), static_cast<Eigen::Index>(m)),
        ex2(x[2].data(), static_cast<Eigen::Index>(m));
    Eigen::Map<Eigen::ArrayXd> ew(w.data(), static_cast<Eigen::Index>(m));
    const auto normal_equations = [&] {
      NormalEquations eq;
      const Eigen::ArrayXd w0 = ew * ex0, w1 = ew * ex1, w2 = ew * ex2;
      eq.a[0][0] = (w0 * ex0).sum(), eq.a[0][1] = (w0 * ex1).sum(), eq.a[0][2] = (w0 * ex2).sum();
      eq.a[1][1] = (w1 * ex1).sum(), eq.a[1][2] = (w1 * ex2).sum(), eq.a[2][2] = (w2 * ex2).sum();
      eq.b[0] = (w0 * ey).sum(), eq.b[1] = (w1 * ey).sum(), eq.b[2] = (w2 * ey).sum();
      eq.yy = (ew * ey.square()).sum();
      eq.a[1][0] = eq.a[0][1], eq.a[2][0] = eq.a[0][2], eq.a[2][1] = eq.a[1][2];
      return eq;
    };
    ChannelFit fit{0.0, 0.0, 0.0};
    if (start != nullptr) {
      fit = *start;
    } else {
      // Robust start, one sky: the sky from the shadowed samples alone, then the sun from the
      // sunlit ones.
      scratch.clear();
      for (size_t k = 0; k < m; k += stride) {
        if (!samples[rows[k]].sunlit && v[k] > 0.0) scratch.push_back(y[k] / v[k]);
      }
      fit[1] = MedianInPlace(scratch, 0.0);
      if (scratch.empty()) {
        ew.setOnes();
        fit = SolveNonNegative(normal_equations(), {with_sun, true, false});
      }
      scratch.clear();
      for (size_t k = 0; k < m; k += stride) {
        if (IsSunlit(samples[rows[k]], options)) scratch.push_back((y[k] - v[k] * fit[1]) / u[k]);
      }
      if (with_sun && !scratch.empty()) fit[0] = std::max(0.0, MedianInPlace(scratch, 0.0));
    }
    const auto predict = [&](size_t k) { return x[0][k] * fit[0] + x[1][k] * fit[1] + x[2][k] * fit[2]; };
    // IRLS, Cauchy weights on residuals relative to the prediction, floored at a tenth of the
    // start's median prediction so that near-black points do not dominate.
    scratch.clear();
    for (size_t k = 0; k < m; k += stride) scratch.push_back(predict(k));
    const double floor = std::max(1e-12, 0.1 * MedianInPlace(scratch, 0.0));
    const double inv_scale = 1.0 / options.cauchy_scale;
    // Least squares on relative residuals: 1/scale² times the Cauchy weight 1/(1 + r²), that is
    // 1/(scale² + d²/c²) for a residual d.
    const auto reweighted = [&] {
      const Eigen::ArrayXd prediction = ex0 * fit[0] + ex1 * fit[1] + ex2 * fit[2];
      const Eigen::ArrayXd d = ey - prediction;
      ew = (prediction.max(floor).square() + d.square() * (inv_scale * inv_scale)).inverse();
      return normal_equations();
    };
    // Until the estimate moves less than `tolerance` (relative). The split only feeds the pooled
    // overcast share, so it stops sooner.
    const double tolerance = split ? 1e-3 : 1e-4;
    bool converged = false;
    for (int iteration = 0; iteration < options.iterations && !converged; ++iteration) {
      const ChannelFit next = SolveNonNegative(reweighted(), free);
      double change = 0.0;
      const double size = std::max({next[0], next[1] + next[2], 1e-30});
      for (size_t j = 0; j < 3; ++j) change = std::max(change, std::abs(next[j] - fit[j]) / size);
      fit = next;
      converged = change < tolerance;
    }
    if (!split && !converged) ++unconverged_channels;
    for (size_t k = 0; k < m; ++k) {
      const double prediction = predict(k);
      relative[k] = (y[k] - prediction) / std::max(prediction, floor);
    }
    return fit;
  };
  // The overcast share of the sky is one number for all channels (clouds are grey): fitted per
  // channel (on half the samples), then pooled, then each channel fitted again with it.
  // Per-channel shares let a small model error in one channel trade sun for sky there.
  double share = 0.0;
  std::array<ChannelFit, 3> split_fits{};
  if (two_skies) {
    // Half the samples are plenty for one number pooled over three channels.
    std::vector<size_t> every_other;
    for (size_t k = 0; k < n; k += 2) every_other.push_back(usable[k]);
    glm::dvec3 clear(0.0), overcast(0.0);
    for (int c = 0; c < 3; ++c) {
      split_fits[static_cast<size_t>(c)] = fit_channel(c, true, 0.0, nullptr, every_other);
      clear[c] = split_fits[static_cast<size_t>(c)][1], overcast[c] = split_fits[static_cast<size_t>(c)][2];
    }
    const double sky = glm::compAdd(clear + overcast);
    share = sky > 0.0 ? glm::compAdd(overcast) / sky : 0.0;
  }
  summary.overcast_share = share;
  for (int c = 0; c < 3; ++c) {
    // Starting from the split fit, with its two skies summed.
    const ChannelFit& split = split_fits[static_cast<size_t>(c)];
    const ChannelFit start{split[0], split[1] + split[2], 0.0};
    const ChannelFit fit = fit_channel(c, false, share, two_skies ? &start : nullptr, usable);
    summary.light.sun_rgb[c] = fit[0];
    summary.light.sky_rgb[c] = fit[1];
    scratch.clear();
    for (size_t k = 0; k < n; ++k) {
      all_residuals.push_back(std::abs(relative[k]));
      if (k % stride == 0) scratch.push_back(std::abs(relative[k]));
    }
    spreads.push_back(1.4826 * MedianInPlace(scratch, 0.0));
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
  summary.status = unconverged_channels > 0 ? SunSkyFitStatus::kNoConvergence
                   : with_sun                ? SunSkyFitStatus::kConverged
                                             : SunSkyFitStatus::kSkyOnly;
  summary.message = fmt::format("{} samples ({} sunlit, {} shadowed), residual spread {:.3f}{}", n,
                                summary.sunlit_samples, summary.shadowed_samples, summary.residual_spread,
                                unconverged_channels > 0
                                    ? fmt::format("; {} of 3 channels still moving after {} iterations",
                                                  unconverged_channels, options.iterations)
                                    : std::string());
  return summary;
}

}  // namespace daylit::estimation
