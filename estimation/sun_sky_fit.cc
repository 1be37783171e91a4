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

// E_sun, E_clear, E_overcast of one channel.
using ChannelFit = std::array<double, 3>;

// The weighted normal equations of y ≈ Σ_j x_j·E_j: A = Σ w x xᵀ, b = Σ w x y, yy = Σ w y².
struct NormalEquations {
  std::array<std::array<double, 3>, 3> a{};
  std::array<double, 3> b{};
  double yy = 0.0;
};

// What a channel's normal equations know of its sun with the clear sky profiled out: the Schur
// complement A_ss − A_sc²/A_cc (information) and b_s − A_sc·b_c/A_cc (numerator; E_sun = their
// ratio). Without a clear sky's information, A_ss and b_s.
struct ProfiledSun {
  double numerator = 0.0, information = 0.0;
};
ProfiledSun ProfileSun(const NormalEquations& eq) {
  if (!(eq.a[1][1] > 0.0)) return {eq.b[0], eq.a[0][0]};
  return {eq.b[0] - eq.a[0][1] * eq.b[1] / eq.a[1][1], eq.a[0][0] - eq.a[0][1] * eq.a[0][1] / eq.a[1][1]};
}

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

bool IsSunlit(const Sample& s, const SunSkyFitOptions& options) {
  return s.sunlit && glm::compMin(s.sun) > options.sunlit_threshold;
}

std::string SunSkyFitOptions::Check() const {
  return FirstProblem({InOpenClosed("cauchy_scale", cauchy_scale, 0.0, 10.0), InClosed("iterations", iterations, 1, 1000),
                       InOpenClosed("sunlit_threshold", sunlit_threshold, 0.0, 0.999),
                       InClosed("min_stratum_samples", min_stratum_samples, 1, 1000000),
                       InOpenClosed("confident_residual", confident_residual, 0.0, 10.0),
                       InOpenClosed("confident_share", confident_share, 0.0, 1.0),
                       InOpenClosed("absent_sun_share", absent_sun_share, 0.0, confident_share),
                       InClosed("min_shadow_information", min_shadow_information, 0.0, 1.0),
                       InClosed("surface_model_error", surface_model_error, 0.0, 1.0)});
}

namespace {

// A fixed hash of a camera pixel (lowbias32): which subset a sample falls in.
uint32_t PixelHash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// For each sample, whether it falls in a fixed share of them, 1 in `stride` (by the hash's low bits)
// or, with `half`, one in two (by a high bit): chosen by its camera pixel, not by its place in the
// list. A sample that comes or goes as the sun moves then leaves every other one where it was; by
// place (every other sample), each later one changed sides, and the sky's split into its clear and
// overcast parts, which the half decides, moved E_sky by up to 2% for one sample in 8 000.
// Samples without distinct pixels (made by hand) fall back to their place.
std::vector<uint8_t> FixedSubset(const std::vector<Sample>& samples, size_t stride, bool half) {
  std::vector<uint8_t> in(samples.size());
  size_t count = 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    const uint32_t h = PixelHash(samples[i].pixel);
    in[i] = half ? (h >> 31) == 0 : h % stride == 0;
    count += in[i];
  }
  const size_t share = half ? 2 : stride, expected = samples.size() / share;
  if (share > 1 && (2 * count < expected || 2 * count > 3 * expected + 2)) {
    for (size_t i = 0; i < samples.size(); ++i) in[i] = i % share == 0;
  }
  return in;
}

// The robust fit of one channel over a set of samples, with the buffers it reuses from channel to
// channel. Load sets up the regressors; Start, Reweight and Residuals are the three steps.
class ChannelFitter {
 public:
  ChannelFitter(const SunSkyFitOptions& options, const std::vector<Sample>& samples, size_t count, bool with_sun)
      : options_(options), samples_(samples), with_sun_(with_sun), y_(count), w_(count), relative_(count), offset_(count), rest_(count),
        x_{std::vector<double>(count), std::vector<double>(count), std::vector<double>(count)},
        medians_(FixedSubset(samples, std::max<size_t>(1, count / 2000), false)), row_in_medians_(count) {
    scratch_.reserve(count);
  }

  // Medians (start, floor, spread) are taken over a fixed ~2000 of the samples (FixedSubset): they
  // give each to well under 1% and cost a quarter of the time. Whether sample i is one of them:
  bool InMedians(size_t i) const { return medians_[i] != 0; }
  // After Fit: the samples' residuals relative to the prediction, in the order of `rows`.
  const std::vector<double>& relative() const { return relative_; }
  bool converged() const { return converged_; }
  int steps() const { return steps_; }  // reweighting steps over every fit so far
  // The normal equations at the last fit's final weights (for the channel it was loaded with).
  NormalEquations FinalEquations() { return Equations(); }

  // After a fit without the split (`fit`) and PrepareSurfaces: E_sun as each surface's own shadows show
  // it (SunSkyFitOptions::sun_from_shadows). y ≈ E_sun·x_sun + g_s·L_sky with L_sky the fitted
  // sky's radiance at the sample and g_s a gain per surface s, profiled out: with per-surface sums
  // S_ll = Σ w L², S_xl = Σ w x L, S_ly = Σ w L y,
  //   E_sun = (Σ w x y − Σ_s S_xl·S_ly / S_ll) / (Σ w x² − Σ_s S_xl² / S_ll),
  // the denominator its information; IRLS from `fit` with Reweight's weights. Also the whole-scene
  // model's information on E_sun at the same weights (Σ w x² less its part shared with the clear
  // sky), for a sun of given colour.
  struct WithinSurfaces {
    double sun = 0.0, information = 0.0, scene_information = 0.0;
    // How far the surfaces' gains differ: their relative standard deviation (weighted by each
    // surface's S_ll, × K/(K − 1) in variance for K surfaces).
    double gain_spread = 0.0;
    // The variance of `sun` from the samples' scatter: the weighted mean square residual (relative,
    // at Reweight's weights) over the information.
    double variance = 0.0;
    // How far the casting surfaces disagree on the sun: each one's own estimate (its sums alone,
    // its gain profiled out), their relative standard deviation about `sun` (weighted by each one's
    // information, × K/(K − 1) in variance), and K. Under two casting surfaces nothing shows it.
    double sun_spread = 0.0;
    int casting_surfaces = 0;
  };
  // Before SunWithinSurfaces, once for all channels: each of `rows`' surface, and which surfaces
  // tell the sun by their own shadow: those with both sunlit and shadowed samples,
  // min_stratum_samples of each. On the others the sun term varies only by the light reflected onto
  // them, and their contrasts say more of that model than of the sun.
  void PrepareSurfaces(const std::vector<size_t>& rows) {
    surface_of_row_.resize(rows.size());
    surfaces_ = 0;
    for (size_t k = 0; k < rows.size(); ++k) {
      // Surfaces beyond the table (none in a model of fewer than 65536) share its last entry.
      surface_of_row_[k] = std::min<uint32_t>(samples_[rows[k]].surface, kMaxSurfaces - 1);
      surfaces_ = std::max(surfaces_, surface_of_row_[k] + 1);
    }
    std::vector<std::array<int, 2>> strata(surfaces_, {0, 0});
    for (size_t k = 0; k < rows.size(); ++k) {
      const Sample& s = samples_[rows[k]];
      if (IsSunlit(s, options_)) {
        ++strata[surface_of_row_[k]][0];
      } else if (!s.sunlit) {
        ++strata[surface_of_row_[k]][1];
      }
    }
    casting_.assign(surfaces_, 0);
    for (uint32_t j = 0; j < surfaces_; ++j) {
      casting_[j] = std::min(strata[j][0], strata[j][1]) >= options_.min_stratum_samples ? 1 : 0;
    }
  }

  WithinSurfaces SunWithinSurfaces(const ChannelFit& fit, const NormalEquations& equations) {
    WithinSurfaces out;
    // The whole scene's information on the sun, its clear sky profiled out, at the same weights.
    out.scene_information = ProfileSun(equations).information;
    const uint32_t surfaces = surfaces_;
    gain_.assign(surfaces, 1.0);
    sums_.resize(surfaces);
    const double inv_scale = 1.0 / options_.cauchy_scale;
    double sun = fit[0];
    for (int iteration = 0; iteration < options_.iterations; ++iteration) {
      // Per surface: S_ll, S_xl, S_ly, S_xx, S_xy, Σ w d² and the rows.
      std::fill(sums_.begin(), sums_.end(), Sums{});
      for (size_t k = 0; k < m_; ++k) {
        // The fitted sky's radiance (the given overcast part and the clear one).
        const double x = x_[0][k], l = offset_[k] + x_[1][k] * fit[1] + x_[2][k] * fit[2], y = y_[k];
        const double prediction = x * sun + gain_[surface_of_row_[k]] * l, d = y - prediction;
        // The first pass is at the scene fit's own final weights (every gain 1, its sun).
        const double p = std::max(prediction, floor_);
        const double w = iteration == 0 ? w_[k] : 1.0 / (p * p + d * d * inv_scale * inv_scale);
        Sums& s = sums_[surface_of_row_[k]];
        s[0] += w * l * l, s[1] += w * x * l, s[2] += w * l * y, s[3] += w * x * x, s[4] += w * x * y;
        s[5] += w * d * d, s[6] += 1.0;
      }
      double numerator = 0.0, information = 0.0, scatter = 0.0, count = 0.0;
      for (uint32_t j = 0; j < surfaces; ++j) {
        const Sums& s = sums_[j];
        if (!casting_[j] || !(s[0] > 0.0)) continue;
        const ProfiledSun own = OwnSun(s);
        numerator += own.numerator, information += own.information;
        scatter += s[5], count += s[6];
      }
      out.information = information;
      out.variance = information > 0.0 && count > 0.0 ? scatter / count / information : 0.0;
      const double next = information > 0.0 ? std::max(0.0, numerator / information) : sun;
      for (uint32_t j = 0; j < surfaces; ++j) {
        const Sums& s = sums_[j];
        gain_[j] = s[0] > 0.0 ? (s[2] - s[1] * next) / s[0] : 1.0;
      }
      const double change = std::abs(next - sun) / std::max({next, sun, 1e-30});
      sun = next;
      if (change < 1e-4) break;
    }
    out.sun = sun;
    out.gain_spread = GainSpread(surfaces);
    SunSpread(surfaces, &out);
    return out;
  }

  // WithinSurfaces' sun_spread and casting_surfaces from the last pass's sums.
  void SunSpread(uint32_t surfaces, WithinSurfaces* out) const {
    double weight = 0.0, sum_sq = 0.0, k = 0.0;
    for (uint32_t j = 0; j < surfaces; ++j) {
      const Sums& s = sums_[j];
      if (!casting_[j] || !(s[0] > 0.0)) continue;
      const ProfiledSun profiled = OwnSun(s);
      if (!(profiled.information > 0.0)) continue;
      const double own = profiled.numerator / profiled.information;
      weight += profiled.information, sum_sq += profiled.information * (own - out->sun) * (own - out->sun), k += 1.0;
    }
    out->casting_surfaces = static_cast<int>(k);
    if (k >= 2.0 && out->sun > 0.0) out->sun_spread = std::sqrt(sum_sq / weight * k / (k - 1.0)) / out->sun;
  }

  // After a fit without the split (`fit`), before SunWithinSurfaces: the gains' spread (GainSpread)
  // at the fit's own sun and final weights, one pass. Within the model's known error the scene's
  // fit stands (FitSunSky's ρ is 0) and the shadows' estimate is not needed.
  double GainSpreadAt(const ChannelFit& fit) {
    const uint32_t surfaces = surfaces_;
    gain_.resize(surfaces);
    sums_.assign(surfaces, Sums{});
    for (size_t k = 0; k < m_; ++k) {
      const double x = x_[0][k], l = offset_[k] + x_[1][k] * fit[1] + x_[2][k] * fit[2], w = w_[k];
      Sums& s = sums_[surface_of_row_[k]];
      s[0] += w * l * l, s[1] += w * x * l, s[2] += w * l * y_[k];
    }
    for (uint32_t j = 0; j < surfaces; ++j) {
      const Sums& s = sums_[j];
      gain_[j] = s[0] > 0.0 ? (s[2] - s[1] * fit[0]) / s[0] : 1.0;
    }
    return GainSpread(surfaces);
  }

  // The relative spread of the first `surfaces` gains (SunWithinSurfaces; weighted by S_ll, × K/(K − 1)
  // in variance): every surface's gain says how far the scene's sky is off there, casting a shadow
  // or not.
  double GainSpread(uint32_t surfaces) const {
    double weight = 0.0, mean = 0.0, k = 0.0;
    for (uint32_t j = 0; j < surfaces; ++j) {
      if (sums_[j][0] > 0.0) weight += sums_[j][0], mean += sums_[j][0] * gain_[j], k += 1.0;
    }
    if (!(k >= 2.0 && weight > 0.0 && mean > 0.0)) return 0.0;
    mean /= weight;
    double variance = 0.0;
    for (uint32_t j = 0; j < surfaces; ++j) {
      if (sums_[j][0] > 0.0) variance += sums_[j][0] * (gain_[j] - mean) * (gain_[j] - mean);
    }
    return std::sqrt(variance / weight * k / (k - 1.0)) / mean;
  }

  // Channel `c` over the samples `rows`: with `split`, E_sun, E_clear and E_overcast; without,
  // E_sun and E_clear with E_overcast given as `overcast` (the grey part, the same in every
  // channel). `start`, if given, replaces the median-based start.
  ChannelFit Fit(int c, bool split, double overcast, const ChannelFit* start, const std::vector<size_t>& rows) {
    Load(c, split, overcast, rows);
    ChannelFit fit = start != nullptr ? *start : MedianStart(rows);
    fit = Reweight(fit, split);
    for (size_t k = 0; k < m_; ++k) {
      const double prediction = Predict(fit, k);
      relative_[k] = (y_[k] - prediction) / std::max(prediction, floor_);
    }
    return fit;
  }

 private:
  Eigen::Map<Eigen::ArrayXd> Column(std::vector<double>& v) const {
    return Eigen::Map<Eigen::ArrayXd>(v.data(), static_cast<Eigen::Index>(m_));
  }
  double Predict(const ChannelFit& fit, size_t k) const {
    return offset_[k] + x_[0][k] * fit[0] + x_[1][k] * fit[1] + x_[2][k] * fit[2];
  }

  // y_ holds the samples' radiance, offset_ the known part of it (the given overcast light's),
  // x_ the regressors of the unknowns.
  void Load(int c, bool split, double overcast, const std::vector<size_t>& rows) {
    m_ = rows.size();
    free_ = {with_sun_, true, split};
    for (size_t k = 0; k < m_; ++k) {
      const Sample& s = samples_[rows[k]];
      row_in_medians_[k] = medians_[rows[k]];
      const double a = s.albedo[c] * glm::one_over_pi<double>();
      y_[k] = s.radiance[c];
      x_[0][k] = a * s.sun[c];
      x_[1][k] = a * s.sky[c];
      x_[2][k] = split ? a * s.overcast[c] : 0.0;
      offset_[k] = split ? 0.0 : a * overcast * s.overcast[c];
      rest_[k] = y_[k] - offset_[k];
    }
  }

  // The weighted normal equations of the samples with the weights in w_ for the radiance less its
  // known part, vectorised by Eigen. Without the split the third regressor is all zero (Load):
  // its sums are left at zero, the same numbers for a third less work.
  NormalEquations Equations() {
    const Eigen::Map<Eigen::ArrayXd> ey = Column(rest_), ex0 = Column(x_[0]), ex1 = Column(x_[1]), ex2 = Column(x_[2]);
    const Eigen::Map<Eigen::ArrayXd> ew = Column(w_);
    NormalEquations eq;
    w0_ = ew * ex0, w1_ = ew * ex1;
    eq.a[0][0] = (w0_ * ex0).sum(), eq.a[0][1] = (w0_ * ex1).sum(), eq.a[1][1] = (w1_ * ex1).sum();
    eq.b[0] = (w0_ * ey).sum(), eq.b[1] = (w1_ * ey).sum();
    if (free_[2]) {
      w2_ = ew * ex2;
      eq.a[0][2] = (w0_ * ex2).sum(), eq.a[1][2] = (w1_ * ex2).sum(), eq.a[2][2] = (w2_ * ex2).sum();
      eq.b[2] = (w2_ * ey).sum();
    }
    eq.yy = (ew * ey.square()).sum();
    eq.a[1][0] = eq.a[0][1], eq.a[2][0] = eq.a[0][2], eq.a[2][1] = eq.a[1][2];
    return eq;
  }

  // Robust start, one sky: the sky from the shadowed samples alone, then the sun from the sunlit
  // ones.
  ChannelFit MedianStart(const std::vector<size_t>& rows) {
    ChannelFit fit{0.0, 0.0, 0.0};
    scratch_.clear();
    for (size_t k = 0; k < m_; ++k) {
      if (row_in_medians_[k] && !samples_[rows[k]].sunlit && x_[1][k] > 0.0) scratch_.push_back(rest_[k] / x_[1][k]);
    }
    fit[1] = MedianInPlace(scratch_, 0.0);
    if (scratch_.empty()) {
      Column(w_).setOnes();
      fit = SolveNonNegative(Equations(), {with_sun_, true, false});
    }
    scratch_.clear();
    for (size_t k = 0; k < m_; ++k) {
      if (row_in_medians_[k] && IsSunlit(samples_[rows[k]], options_)) {
        scratch_.push_back((rest_[k] - x_[1][k] * fit[1]) / x_[0][k]);
      }
    }
    if (with_sun_ && !scratch_.empty()) fit[0] = std::max(0.0, MedianInPlace(scratch_, 0.0));
    return fit;
  }

  // IRLS from `fit`: Cauchy weights on residuals relative to the prediction, floored at a tenth
  // of the start's median prediction so that near-black points do not dominate; until a step
  // moves the estimate less than a tolerance (relative), the step from the point its weights were
  // taken at (a fixed point's test, accelerated or not). The split only feeds the pooled overcast
  // share, so it stops sooner.
  ChannelFit Reweight(ChannelFit fit, bool split) {
    scratch_.clear();
    for (size_t k = 0; k < m_; ++k) {
      if (row_in_medians_[k]) scratch_.push_back(Predict(fit, k));
    }
    floor_ = std::max(1e-12, 0.1 * MedianInPlace(scratch_, 0.0));
    const double inv_scale = 1.0 / options_.cauchy_scale;
    const Eigen::Map<Eigen::ArrayXd> ey = Column(y_), ex0 = Column(x_[0]), ex1 = Column(x_[1]), ex2 = Column(x_[2]);
    const Eigen::Map<Eigen::ArrayXd> eoffset = Column(offset_);
    Eigen::Map<Eigen::ArrayXd> ew = Column(w_);
    const double tolerance = split ? 1e-3 : 1e-4;
    converged_ = false;
    ChannelFit at = fit;  // where the weights are taken
    ChannelFit last_step{}, last_next{};
    bool have_last = false;
    for (int iteration = 0; iteration < options_.iterations && !converged_; ++iteration) {
      // Least squares on relative residuals: 1/scale² times the Cauchy weight 1/(1 + r²), that
      // is 1/(scale² + d²/c²) for a residual d.
      if (free_[2]) {
        prediction_ = eoffset + ex0 * at[0] + ex1 * at[1] + ex2 * at[2];
      } else {
        prediction_ = eoffset + ex0 * at[0] + ex1 * at[1];  // x_[2] is zero
      }
      ew = (prediction_.max(floor_).square() + (ey - prediction_).square() * (inv_scale * inv_scale)).inverse();
      const ChannelFit next = SolveNonNegative(Equations(), free_);
      double change = 0.0;
      const double size = std::max({next[0], next[1] + next[2], 1e-30});
      for (size_t j = 0; j < 3; ++j) change = std::max(change, std::abs(next[j] - at[j]) / size);
      fit = next;
      converged_ = change < tolerance;
      ++steps_;
      if (converged_ || !options_.accelerate) {
        at = next;
        continue;
      }
      // Anderson acceleration of depth 1 (Walker & Ni, SIAM J. Numer. Anal. 49, 2011): the next
      // point is the combination of the last two steps' results that best cancels their steps;
      // a point outside the non-negative set, or no step change to go by, takes the plain step.
      ChannelFit step{};
      for (size_t j = 0; j < 3; ++j) step[j] = next[j] - at[j];
      at = next;
      if (have_last) {
        double df_f = 0.0, df_df = 0.0;
        for (size_t j = 0; j < 3; ++j) {
          const double df = step[j] - last_step[j];
          df_f += df * step[j], df_df += df * df;
        }
        if (df_df > 0.0) {
          const double gamma = df_f / df_df;
          ChannelFit mixed{};
          bool inside = std::isfinite(gamma);
          for (size_t j = 0; j < 3; ++j) {
            mixed[j] = next[j] - gamma * (next[j] - last_next[j]);
            inside = inside && mixed[j] >= 0.0;
          }
          if (inside) at = mixed;
        }
      }
      last_step = step, last_next = next, have_last = true;
    }
    return fit;
  }

  const SunSkyFitOptions& options_;
  const std::vector<Sample>& samples_;
  const bool with_sun_;
  static constexpr uint32_t kMaxSurfaces = 1u << 16;
  std::vector<double> y_, w_, relative_, scratch_, offset_, rest_;  // rest_: y_ less offset_
  // SunWithinSurfaces' buffers: each row's surface, each surface's gain and sums.
  using Sums = std::array<double, 7>;
  // What one surface's sums (S_ll > 0) know of the sun with its gain profiled out:
  // S_xy − S_xl·S_ly/S_ll over S_xx − S_xl²/S_ll.
  static ProfiledSun OwnSun(const Sums& s) { return {s[4] - s[1] * s[2] / s[0], s[3] - s[1] * s[1] / s[0]}; }
  std::vector<uint32_t> surface_of_row_;
  std::vector<uint8_t> casting_;  // per surface: it has both strata
  uint32_t surfaces_ = 0;
  std::vector<double> gain_;
  std::vector<Sums> sums_;
  std::array<std::vector<double>, 3> x_;
  size_t m_ = 0;
  std::array<bool, 3> free_{};
  const std::vector<uint8_t> medians_;  // per sample: one the medians read
  std::vector<uint8_t> row_in_medians_;  // the same per loaded row
  double floor_ = 0.0;
  bool converged_ = false;
  int steps_ = 0;  // reweighting steps over every fit
  Eigen::ArrayXd prediction_, w0_, w1_, w2_;  // Reweight's and Equations' buffers, kept between fits
};

// The overcast part of the sky is grey, one value for all channels (lighting_model.h): fitted
// per channel on half the samples, then pooled (the mean over the channels). Per-channel parts let
// a small model error in one channel trade sun for sky there. Also returns each channel's split
// fit in `split_fits`.
double PooledOvercast(ChannelFitter* fitter, const std::vector<Sample>& samples, const std::vector<size_t>& usable,
                      std::array<ChannelFit, 3>* split_fits, int* unconverged) {
  const std::vector<uint8_t> half = FixedSubset(samples, 2, true);
  std::vector<size_t> every_other;
  for (const size_t i : usable) {
    if (half[i]) every_other.push_back(i);
  }
  double overcast = 0.0;
  for (int c = 0; c < 3; ++c) {
    ChannelFit& fit = (*split_fits)[static_cast<size_t>(c)];
    fit = fitter->Fit(c, true, 0.0, nullptr, every_other);
    *unconverged += fitter->converged() ? 0 : 1;
    overcast += fit[2] / 3.0;
  }
  return overcast;
}

// The worst channel's share of the sunlit samples' predicted light that is direct sun, and of the
// shadowed samples' that is sky (SunSkyFitSummary); 1 for a stratum without samples.
void SplitShares(const SunSkyFitOptions& options, const std::vector<Sample>& samples, const std::vector<size_t>& usable,
                 SunSkyFitSummary* summary) {
  glm::dvec3 sun_lit(0.0), all_lit(0.0), sky_shadow(0.0), all_shadow(0.0);
  // The model's two parts of each sample's predicted radiance: PredictedRadiance with one term.
  const LightParts all = SplitLight(summary->light, summary->overcast_share);
  const LightParts sun_only{all.sun, glm::vec3(0.0f), glm::vec3(0.0f)}, sky_only{glm::vec3(0.0f), all.clear, all.overcast};
  for (const size_t i : usable) {
    const Sample& s = samples[i];
    const bool lit = IsSunlit(s, options);
    if (!lit && s.sunlit) continue;  // grazing sun: neither stratum
    const glm::dvec3 sun(PredictedRadiance(s, sun_only));
    const glm::dvec3 sky(PredictedRadiance(s, sky_only));
    // Each sample weighs as its share (a mean of shares, not a share of sums: bright points do
    // not outvote dim ones).
    const glm::dvec3 total = glm::max(sun + sky, glm::dvec3(1e-30));
    if (lit) {
      sun_lit += sun / total, all_lit += glm::dvec3(1.0);
    } else {
      sky_shadow += sky / total, all_shadow += glm::dvec3(1.0);
    }
  }
  summary->sun_share_sunlit = all_lit.x > 0.0 ? glm::compMin(sun_lit / all_lit) : 1.0;
  summary->sky_share_shadowed = all_shadow.x > 0.0 ? glm::compMin(sky_shadow / all_shadow) : 1.0;
}

// A share's factor on the confidence: 1 from `confident_share` up, proportional below it.
double ShareFactor(const SunSkyFitOptions& options, double share) { return std::min(1.0, share / options.confident_share); }

// Confidence: small robust residuals, both strata present (sunlit and shadowed samples are what
// separates E_sun from E_sky; without sunlit ones E_sun is not observed at all), and a well-posed
// split. The sun's share factor falls with the sun's share down to `absent_sun_share`; below it
// the sun counts as absent (an overcast frame: E_sun ≈ 0 is then what the samples say, and well
// said), so the factor rises linearly back to 1 at a share of 0, with no jump.
double Confidence(const SunSkyFitOptions& options, const SunSkyFitSummary& summary, bool with_sun) {
  const double fit_quality = std::exp(-std::pow(summary.residual_spread / options.confident_residual, 2.0));
  const double strata = std::min(1.0, static_cast<double>(summary.shadowed_samples) / options.min_stratum_samples) *
                        (summary.sun_up ? std::min(1.0, static_cast<double>(summary.sunlit_samples) / options.min_stratum_samples) : 1.0);
  const double s = summary.sun_share_sunlit, s0 = options.absent_sun_share;
  const double at_s0 = ShareFactor(options, s0);
  const double sun_split = !with_sun ? 1.0 : s >= s0 ? ShareFactor(options, s) : 1.0 - (1.0 - at_s0) * s / s0;
  const double sky_split = ShareFactor(options, summary.sky_share_shadowed);
  return fit_quality * strata * summary.inlier_share * sun_split * sky_split;
}

}  // namespace

glm::vec3 PredictedRadiance(const Sample& s, const LightParts& light) {
  return s.albedo * glm::one_over_pi<float>() * Irradiance(light, s.sun, s.sky, s.overcast);
}

glm::vec3 PredictedRadiance(const Sample& s, const SunSky& light, double overcast_share) {
  return PredictedRadiance(s, SplitLight(light, overcast_share));
}

SunSkyFitSummary FitSunSky(const SunSkyFitOptions& options, const std::vector<Sample>& samples,
                           const glm::dvec3* sun_colour) {
  SunSkyFitSummary summary;
  std::vector<size_t> usable;
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    if (glm::compMax(s.sky) > 0.0f || glm::compMax(s.sun) > 0.0f) usable.push_back(i);
    summary.sun_up = summary.sun_up || glm::compMax(s.sun) > 0.0f;
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
  // Two skies (clear-shaped and overcast) when the samples tell them apart, else one.
  bool two_skies = false;
  for (const size_t i : usable) two_skies = two_skies || (options.split_sky && samples[i].sky != samples[i].overcast);
  ChannelFitter fitter(options, samples, n, with_sun);
  std::array<ChannelFit, 3> split_fits{};
  // The fits that ran out of IRLS iterations: the split ones (whose overcast part every channel's
  // final fit takes) and the final ones.
  int unconverged_fits = 0;
  const int fits = two_skies ? 6 : 3;
  const double overcast = two_skies ? PooledOvercast(&fitter, samples, usable, &split_fits, &unconverged_fits) : 0.0;
  // Each channel fitted again with the pooled overcast part given, starting from its split fit's
  // sun and clear sky.
  std::vector<double> spreads, all_residuals, scratch;
  all_residuals.reserve(3 * n);
  std::array<NormalEquations, 3> final_equations{};
  // The sun from the shadows within the surfaces needs two surfaces: one surface's own sky gain is
  // the whole scene's sky.
  bool several_surfaces = false;
  for (const size_t i : usable) several_surfaces = several_surfaces || samples[i].surface != samples[usable[0]].surface;
  const bool from_shadows = options.sun_from_shadows && with_sun && several_surfaces;
  if (from_shadows) fitter.PrepareSurfaces(usable);
  std::array<double, 3> mixed_information{0.0, 0.0, 0.0};  // where ρ > 0: what the channel knows of the sun
  double shadow_information = 1.0;  // worst channel, over those where it was needed
  bool shadows_measured = false;
  for (int c = 0; c < 3; ++c) {
    const ChannelFit& split = split_fits[static_cast<size_t>(c)];
    const ChannelFit start{split[0], split[1], 0.0};
    const ChannelFit fit = fitter.Fit(c, false, overcast, two_skies ? &start : nullptr, usable);
    unconverged_fits += fitter.converged() ? 0 : 1;
    summary.light.sun_rgb[c] = fit[0];
    summary.light.sky_rgb[c] = fit[1] + overcast;
    // The normal equations at the final weights: for a sun of given colour, and for the clear sky
    // that follows the shadows' sun.
    NormalEquations& equations = final_equations[static_cast<size_t>(c)];
    if (sun_colour != nullptr) equations = fitter.FinalEquations();
    if (from_shadows && fitter.GainSpreadAt(fit) > options.surface_model_error) {
      if (sun_colour == nullptr) equations = fitter.FinalEquations();
      const ChannelFitter::WithinSurfaces w = fitter.SunWithinSurfaces(fit, equations);
      const double share = w.scene_information > 0.0 ? std::clamp(w.information / w.scene_information, 0.0, 1.0) : 0.0;
      shadow_information = std::min(shadow_information, share), shadows_measured = true;
      // The shadows' weight: none while the surfaces' gains differ by no more than their known
      // model error m, then 1 − m²/spread² (the part of the spread beyond m over the whole); times
      // D²/(D² + var) with D the two estimates' difference and var what the shadows' estimate is
      // unsure of: its samples' scatter, and the model error m of the light it rests on passed on
      // by 1/share (it rests on that share of what the frame knows of the sun). Where the two
      // differ by less, the scene's fit, which knows more, is kept.
      const double m = options.surface_model_error, spread = w.gain_spread, difference = w.sun - fit[0];
      const double model = share > 0.0 ? m * w.sun / share : 0.0;
      const double rho = share >= options.min_shadow_information && share > 0.0 && spread > m
                             ? (1.0 - m * m / (spread * spread)) * difference * difference /
                                   (difference * difference + w.variance + model * model)
                             : 0.0;
      summary.shadow_sun.weight[c] = rho;
      summary.shadow_weight += rho / 3.0;
      if (rho > 0.0) {
        // The clear sky follows the sun at the fit's final weights.
        const double sun = rho * w.sun + (1.0 - rho) * fit[0];
        if (sun > 0.0) {  // relative to the sun given
          const double least = std::max(w.sun_spread * w.sun, model) / sun;
          summary.shadow_sun.error[c] = std::sqrt(least * least + w.variance / (sun * sun));
          summary.shadow_sun.difference[c] = difference / sun;
        }
        summary.shadow_sun.casting_surfaces = w.casting_surfaces;
        const double clear = equations.a[1][1] > 0.0 ? std::max(0.0, (equations.b[1] - equations.a[0][1] * sun) / equations.a[1][1]) : fit[1];
        summary.light.sun_rgb[c] = sun;
        summary.light.sky_rgb[c] = clear + overcast;
        // What the channel knows of the sun, for a sun of given colour: the two informations
        // mixed as the estimates are.
        mixed_information[static_cast<size_t>(c)] = rho * w.information + (1.0 - rho) * w.scene_information;
      }
    }
    scratch.clear();
    for (size_t k = 0; k < n; ++k) {
      all_residuals.push_back(std::abs(fitter.relative()[k]));
      if (fitter.InMedians(usable[k])) scratch.push_back(std::abs(fitter.relative()[k]));
    }
    spreads.push_back(1.4826 * MedianInPlace(scratch, 0.0));
  }
  summary.shadow_information = shadows_measured ? shadow_information : 0.0;
  if (sun_colour != nullptr && with_sun && glm::compMin(*sun_colour) > 0.0) {
    // The sun's colour given (clouds are grey: a cloud dims the beam, it does not colour it): one
    // magnitude s for E_sun = s·colour over the three channels, each channel's clear sky profiled
    // out at the final weights. Each channel's information on its E_sun is the Schur complement
    // A_ss − A_sc²/A_cc of its normal equations, so s weighs the channels by what they know of the
    // sun, and the clear sky follows.
    double num = 0.0, den = 0.0;
    for (int c = 0; c < 3; ++c) {
      const NormalEquations& eq = final_equations[static_cast<size_t>(c)];
      const double colour = (*sun_colour)[c];
      if (summary.shadow_sun.weight[c] > 0.0) {  // what the channel knows of the sun, shadows and all
        const double information = mixed_information[static_cast<size_t>(c)];
        num += colour * summary.light.sun_rgb[c] * information, den += colour * colour * information;
        continue;
      }
      if (!(eq.a[1][1] > 0.0)) continue;
      const ProfiledSun profiled = ProfileSun(eq);
      num += colour * profiled.numerator, den += colour * colour * profiled.information;
    }
    if (den > 0.0) {
      const double magnitude = std::max(0.0, num / den);
      SunSky coloured;
      for (int c = 0; c < 3; ++c) {
        const NormalEquations& eq = final_equations[static_cast<size_t>(c)];
        const double sun = magnitude * (*sun_colour)[c];
        const double clear = eq.a[1][1] > 0.0 ? std::max(0.0, (eq.b[1] - eq.a[0][1] * sun) / eq.a[1][1])
                                              : summary.light.sky_rgb[c] - overcast;
        coloured.sun_rgb[c] = sun;
        coloured.sky_rgb[c] = clear + overcast;
      }
      summary.coloured = coloured;
    }
  }
  summary.residual_spread = *std::max_element(spreads.begin(), spreads.end());
  // The share that gives that grey part back (SplitLight).
  const double mean_sky = glm::compAdd(summary.light.sky_rgb) / 3.0;
  summary.overcast_share = mean_sky > 0.0 ? std::clamp(overcast / mean_sky, 0.0, 1.0) : 0.0;
  size_t inliers = 0;
  for (const double r : all_residuals) inliers += r < 3.0 * options.cauchy_scale ? 1 : 0;
  summary.inlier_share = static_cast<double>(inliers) / static_cast<double>(all_residuals.size());
  SplitShares(options, samples, usable, &summary);
  summary.confidence = Confidence(options, summary, with_sun);
  summary.reweighting_steps = fitter.steps();
  summary.status = unconverged_fits > 0 ? SunSkyFitStatus::kNoConvergence
                   : with_sun                ? SunSkyFitStatus::kConverged
                                             : SunSkyFitStatus::kSkyOnly;
  summary.own = summary.light;
  summary.message = fmt::format("{} samples ({} sunlit, {} shadowed{}), residual spread {:.3f}{}", n,
                                summary.sunlit_samples, summary.shadowed_samples,
                                summary.sun_up && !with_sun ? ": the sun is up but reaches none, E_sun not observed" : "",
                                summary.residual_spread,
                                unconverged_fits > 0
                                    ? fmt::format("; {} of {} channel fits still moving after {} iterations",
                                                  unconverged_fits, fits, options.iterations)
                                    : std::string());
  return summary;
}

double SunColourWeight(const SunSkyFitSummary& fit) {
  const double share = std::clamp(fit.sun_share_sunlit, 0.0, 1.0);
  const double odds = share / std::max(1.0 - share, 1e-3);
  return odds * odds;
}

SunSky MixWithCarriedColour(const SunSkyFitOptions& options, const SunSkyFitSummary& fit, double carried_weight) {
  if (!fit.coloured || !(carried_weight > 0.0) || fit.sun_share_sunlit >= options.confident_share) return fit.light;
  const double own = SunColourWeight(fit);
  const double t = own / (own + carried_weight);
  SunSky mixed;
  mixed.sun_rgb = t * fit.light.sun_rgb + (1.0 - t) * fit.coloured->sun_rgb;
  mixed.sky_rgb = t * fit.light.sky_rgb + (1.0 - t) * fit.coloured->sky_rgb;
  return mixed;
}

SunSkyFitSummary FitSunSkyAsCarried(const SunSkyFitOptions& options, const std::vector<Sample>& samples,
                                    const glm::dvec3& carried_colour, double carried_weight) {
  SunSkyFitSummary fit = carried_weight > 0.0 ? FitSunSky(options, samples, &carried_colour) : FitSunSky(options, samples);
  fit.carried_colour = carried_colour;
  fit.carried_weight = carried_weight;
  fit.own = fit.light;
  if (fit.IsUsable() && fit.sunlit_samples > 0) fit.light = MixWithCarriedColour(options, fit, carried_weight);
  return fit;
}

}  // namespace daylit::estimation
