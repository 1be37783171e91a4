#include "sky/sky_distribution.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include "base/latlong.h"
#include "sky/atmosphere.h"

namespace daylit::sky {
namespace {

size_t Index(int t, int g) { return static_cast<size_t>(t) * SkyDistribution::kGammaBins + static_cast<size_t>(g); }

// Entries without data take the value of the nearest entry with data (linear between two).
void FillFromNearest(std::vector<glm::dvec3>* values, const std::vector<uint8_t>& known) {
  const int n = static_cast<int>(values->size());
  for (int i = 0; i < n; ++i) {
    if (known[static_cast<size_t>(i)]) continue;
    int lo = i - 1, hi = i + 1;
    while (lo >= 0 && !known[static_cast<size_t>(lo)]) --lo;
    while (hi < n && !known[static_cast<size_t>(hi)]) ++hi;
    if (lo < 0 && hi >= n) return;
    if (lo < 0) {
      (*values)[static_cast<size_t>(i)] = (*values)[static_cast<size_t>(hi)];
    } else if (hi >= n) {
      (*values)[static_cast<size_t>(i)] = (*values)[static_cast<size_t>(lo)];
    } else {
      const double f = static_cast<double>(i - lo) / (hi - lo);
      (*values)[static_cast<size_t>(i)] = (1.0 - f) * (*values)[static_cast<size_t>(lo)] + f * (*values)[static_cast<size_t>(hi)];
    }
  }
}

// g(θ) + h(γ) fitted to `values` where `known` (weighted by `weight`, the bins' solid angles) by
// alternating weighted means; h on the upper hemisphere's rows only.
std::vector<glm::vec3> SeparableFit(const std::vector<glm::vec3>& values, const std::vector<uint8_t>& known,
                                    const std::vector<double>& weight) {
  constexpr int kT = SkyDistribution::kThetaBins, kG = SkyDistribution::kGammaBins, kHorizon = 90;
  std::vector<glm::dvec3> g(kT, glm::dvec3(0.0)), h(kG, glm::dvec3(0.0));
  std::vector<uint8_t> g_known(kT, 0), h_known(kG, 0);
  // A row or column whose seen bins weigh less than an eighth of the median row's or column's is
  // not fitted but takes its neighbours' factor: one odd bin at the horizon, alone in its column,
  // made the low sky opposite a sun 9° lower than the capture's five times the seen bins beside it.
  const auto least_weight = [&](bool theta, int lines, int others) {
    std::vector<double> line_weight;
    for (int i = 0; i < lines; ++i) {
      double w = 0.0;
      for (int j = 0; j < others; ++j) {
        const size_t b = theta ? Index(i, j) : Index(j, i);
        if (known[b]) w += weight[b];
      }
      if (w > 0.0) line_weight.push_back(w);
    }
    if (line_weight.empty()) return 0.0;
    std::nth_element(line_weight.begin(), line_weight.begin() + static_cast<ptrdiff_t>(line_weight.size() / 2), line_weight.end());
    return line_weight[line_weight.size() / 2] / 8.0;
  };
  const double least_row = least_weight(true, kT, kG), least_column = least_weight(false, kG, kHorizon);
  // One half-step: each entry i of `fitted` becomes the weighted mean, over the seen bins of its
  // row (θ: i = t) or column (γ: i = g) among the first `others` of the other axis, of the value
  // less the other factor.
  const auto half_step = [&](bool theta, int others, const std::vector<glm::dvec3>& other,
                             std::vector<glm::dvec3>* fitted, std::vector<uint8_t>* fitted_known) {
    for (size_t i = 0; i < fitted->size(); ++i) {
      glm::dvec3 num(0.0);
      double den = 0.0;
      for (int j = 0; j < others; ++j) {
        const size_t b = theta ? Index(static_cast<int>(i), j) : Index(j, static_cast<int>(i));
        if (!known[b]) continue;
        num += weight[b] * (glm::dvec3(values[b]) - other[static_cast<size_t>(j)]), den += weight[b];
      }
      (*fitted_known)[i] = den > 0.0 && den >= (theta ? least_row : least_column);
      if ((*fitted_known)[i]) (*fitted)[i] = num / den;
    }
    FillFromNearest(fitted, *fitted_known);
  };
  for (int iteration = 0; iteration < 30; ++iteration) {
    half_step(true, kG, h, &g, &g_known);
    half_step(false, kHorizon, g, &h, &h_known);
  }
  std::vector<glm::vec3> out(values.size());
  for (int t = 0; t < kT; ++t) {
    for (int j = 0; j < kG; ++j) out[Index(t, j)] = glm::vec3(g[static_cast<size_t>(t)] + h[static_cast<size_t>(j)]);
  }
  return out;
}

const Atmosphere& SharedAtmosphere() {
  static const Atmosphere atmosphere;
  return atmosphere;
}

// The lowest sun the atmosphere re-aims for (sin of 1°): below it the model's sky is the Earth's
// shadow, and a ratio against it means nothing.
constexpr float kLowestSunZ = 0.0175f;

}  // namespace

size_t SkyDistribution::BinOf(const glm::vec3& dir, const glm::vec3& sun_dir) {
  const glm::dvec3 d(dir);
  const double theta = glm::degrees(std::acos(std::clamp(d.z, -1.0, 1.0)));
  const double gamma = glm::degrees(std::acos(std::clamp(glm::dot(d, glm::dvec3(sun_dir)), -1.0, 1.0)));
  const int ti = std::min(kThetaBins - 1, static_cast<int>(theta));
  const int gi = std::min(kGammaBins - 1, static_cast<int>(gamma / 2.0));
  return Index(ti, gi);
}

std::vector<glm::vec3> SkyDistribution::AtmosphereTable(const glm::vec3& sun_dir, const Scattering& scattering) {
  const Atmosphere& atmosphere = SharedAtmosphere();
  std::vector<glm::vec3> table(static_cast<size_t>(kThetaBins) * kGammaBins);
  const double sun_mu = std::max(static_cast<double>(sun_dir.z), static_cast<double>(kLowestSunZ));
  constexpr int kHorizonRow = 89;  // θ 89.5°: the rows below the horizon take it
  tbb::parallel_for(0, kHorizonRow + 1, [&](int t) {
    const double view_mu = std::cos(glm::radians(t + 0.5));
    for (int g = 0; g < kGammaBins; ++g) {
      table[Index(t, g)] = glm::vec3(atmosphere.Radiance(view_mu, sun_mu, std::cos(glm::radians(2.0 * g + 1.0)), scattering));
    }
  });
  for (int t = kHorizonRow + 1; t < kThetaBins; ++t) {
    std::copy_n(table.begin() + static_cast<ptrdiff_t>(Index(kHorizonRow, 0)), kGammaBins,
                table.begin() + static_cast<ptrdiff_t>(Index(t, 0)));
  }
  return table;
}

Scattering SkyDistribution::FitAerosol(const std::vector<glm::dvec3>& sum, const std::vector<double>& weight,
                                       const glm::vec3& sun_dir) {
  // The captured sky's shape against the atmosphere's for aerosol scattering from 1e-6 to 1.3e-4
  // per metre (a very clear sky to a hazy one; 21e-6 is Bruneton and Neyret's): the weighted variance of log L_captured − log L_atmosphere about its mean, per channel (the
  // brightness and colour of the sky are the capture's, not the model's). Bins within 5° of the
  // sun (what is left of its disc) or 5° of the horizon (the skyline's edge) do not count.
  const auto cost_of = [&](double log2_mie) {
    Scattering candidate;
    candidate.mie = 1e-6 * std::exp2(log2_mie);
    const std::vector<glm::vec3> atmosphere = AtmosphereTable(sun_dir, candidate);
    glm::dvec3 mean(0.0), square(0.0);
    double total = 0.0;
    for (int t = 0; t < 85; ++t) {
      for (int g = 3; g < kGammaBins; ++g) {
        const size_t b = Index(t, g);
        if (weight[b] <= 0.0) continue;
        const glm::dvec3 r =
            glm::log(glm::max(sum[b] / weight[b], glm::dvec3(1e-9)) / glm::max(glm::dvec3(atmosphere[b]), glm::dvec3(1e-15)));
        mean += weight[b] * r, square += weight[b] * r * r, total += weight[b];
      }
    }
    if (total <= 0.0) return 0.0;
    mean /= total;
    const glm::dvec3 variance = square / total - mean * mean;
    return variance.x + variance.y + variance.z;
  };
  // Golden-section search over log2(mie / 1e-6) in [0, 7]: the cost has one minimum there on every
  // bundled capture; 12 evaluations narrow it to a hundredth of the range.
  constexpr double kRatio = 0.6180339887498949;
  double lo = 0.0, hi = 7.0;
  double x1 = hi - kRatio * (hi - lo), x2 = lo + kRatio * (hi - lo);
  double f1 = cost_of(x1), f2 = cost_of(x2);
  for (int i = 0; i < 10; ++i) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - kRatio * (hi - lo), f1 = cost_of(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + kRatio * (hi - lo), f2 = cost_of(x2);
    }
  }
  Scattering best;
  best.mie = 1e-6 * std::exp2(0.5 * (lo + hi));
  return best;
}

SkyDistribution::SkyDistribution(const HdrImage& env, const std::vector<uint8_t>& is_sky, const glm::vec3& sun_dir)
    : sun_(sun_dir) {
  std::vector<glm::dvec3> sum(static_cast<size_t>(kThetaBins) * kGammaBins, glm::dvec3(0.0));
  std::vector<double> weight(sum.size(), 0.0);
  for (int v = 0; v < env.height; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, env.width, env.height);
    for (int u = 0; u < env.width; ++u) {
      if (!is_sky[static_cast<size_t>(v) * env.width + u]) continue;
      const float* p = env.Pixel(u, v);
      const size_t b = BinOf(glm::vec3(LatLongDirection(u, v, env.width, env.height)), sun_dir);
      sum[b] += solid_angle * glm::dvec3(p[0], p[1], p[2]);
      weight[b] += solid_angle;
    }
  }
  // The captured sky over the atmosphere's under the same sun. With the sun below the horizon
  // there is nothing to re-aim: the ratio is the sky itself (an atmosphere of 1).
  const bool physical = sun_dir.z >= kLowestSunZ;
  if (physical) scattering_ = FitAerosol(sum, weight, sun_dir);
  const std::vector<glm::vec3> atmosphere =
      physical ? AtmosphereTable(sun_dir, scattering_) : std::vector<glm::vec3>(sum.size(), glm::vec3(1.0f));
  // Bins the capture never saw as sky take log R from a separable fit g(θ) + h(γ) to the seen bins
  // (the form of the Perez and CIE skies' gradation × indicatrix). It is R that is filled, not the
  // sky: R is smooth where the sky is not, the atmosphere having the horizon's brightening, the
  // aureole's core and the colour.
  // (Held-out parts of the bundled captures, docs/sky.md: the high sky is filled within 1-6%
  // where a fit of log L itself missed it by 12-24%; a harmonic fill of the fit's misfit was no
  // better.)
  std::vector<glm::vec3> log_ratio(sum.size(), glm::vec3(0.0f));
  std::vector<uint8_t> known(sum.size(), 0);
  bool any = false;
  for (size_t b = 0; b < sum.size(); ++b) {
    if (weight[b] <= 0.0) continue;
    const glm::vec3 mean(sum[b] / weight[b]);
    log_ratio[b] = glm::log(glm::max(mean, glm::vec3(1e-6f)) / glm::max(atmosphere[b], glm::vec3(1e-12f)));
    known[b] = 1;
    any = true;
  }
  if (!any) return;  // no sky at all: nothing to fill
  const std::vector<glm::vec3> separable = SeparableFit(log_ratio, known, weight);
  for (size_t b = 0; b < sum.size(); ++b) {
    if (!known[b]) log_ratio[b] = separable[b];
  }
  // The table as daylit made it before the atmosphere, for comparisons (Under(sun, false)): the
  // same separable fit of log L itself.
  auto plain = std::make_shared<std::vector<glm::vec3>>(sum.size());
  {
    std::vector<glm::vec3> log_mean(sum.size(), glm::vec3(0.0f));
    for (size_t b = 0; b < sum.size(); ++b) {
      if (known[b]) log_mean[b] = glm::log(glm::max(glm::vec3(sum[b] / weight[b]), glm::vec3(1e-6f)));
    }
    const std::vector<glm::vec3> fitted = SeparableFit(log_mean, known, weight);
    for (size_t b = 0; b < sum.size(); ++b) (*plain)[b] = known[b] ? glm::vec3(sum[b] / weight[b]) : glm::exp(fitted[b]);
  }
  plain_ = std::move(plain);
  auto ratio = std::make_shared<std::vector<glm::vec3>>(sum.size());
  mean_.resize(sum.size());
  for (int t = 0; t < kThetaBins; ++t) {
    for (int g = 0; g < kGammaBins; ++g) {
      const size_t b = Index(t, g);
      (*ratio)[b] = glm::exp(log_ratio[b]);
      mean_[b] = known[b] ? glm::vec3(sum[b] / weight[b]) : atmosphere[b] * (*ratio)[b];
    }
  }
  if (physical) ratio_ = std::move(ratio);
}

SkyDistribution SkyDistribution::Under(const glm::vec3& sun_dir, bool reaim) const {
  SkyDistribution under = *this;
  under.sun_ = sun_dir;
  if (!reaim && plain_ != nullptr) under.mean_ = *plain_;
  if (!reaim || empty() || ratio_ == nullptr) return under;  // nothing to re-aim: the table as captured
  const std::vector<glm::vec3> atmosphere = AtmosphereTable(sun_dir, scattering_);
  for (size_t b = 0; b < under.mean_.size(); ++b) under.mean_[b] = atmosphere[b] * (*ratio_)[b];
  return under;
}

glm::dvec3 SkyDistribution::SunUnder(const glm::vec3& sun_dir, const glm::dvec3& capture_dni) const {
  if (ratio_ == nullptr) return capture_dni;
  const Atmosphere& atmosphere = SharedAtmosphere();
  const glm::dvec3 here = atmosphere.Transmittance(sun_.z, scattering_);
  const glm::dvec3 there = atmosphere.Transmittance(std::max(static_cast<double>(sun_dir.z), static_cast<double>(kLowestSunZ)), scattering_);
  return capture_dni * there / glm::max(here, glm::dvec3(1e-9));
}

glm::vec3 SkyDistribution::Radiance(const glm::vec3& dir) const {
  if (mean_.empty()) return glm::vec3(0.0f);
  // Bilinear between bin centres (θ at i + 0.5°, γ at 2j + 1°): nearest bins drew rings.
  const float theta = glm::degrees(std::acos(std::clamp(dir.z, -1.0f, 1.0f)));
  const float gamma = glm::degrees(std::acos(std::clamp(glm::dot(dir, sun_), -1.0f, 1.0f)));
  const float t = std::clamp(theta - 0.5f, 0.0f, static_cast<float>(kThetaBins - 1));
  const float g = std::clamp(0.5f * gamma - 0.5f, 0.0f, static_cast<float>(kGammaBins - 1));
  const int t0 = std::min(static_cast<int>(t), kThetaBins - 2), g0 = std::min(static_cast<int>(g), kGammaBins - 2);
  const float ft = t - static_cast<float>(t0), fg = g - static_cast<float>(g0);
  const auto at = [&](int ti, int gi) { return mean_[Index(ti, gi)]; };
  return (1.0f - ft) * ((1.0f - fg) * at(t0, g0) + fg * at(t0, g0 + 1)) + ft * ((1.0f - fg) * at(t0 + 1, g0) + fg * at(t0 + 1, g0 + 1));
}

glm::dvec3 SkyDistribution::HorizontalIrradiance() const {
  // Midpoint rule on a 0.5° × 1° grid of the upper hemisphere: finer than the bins.
  constexpr int kRows = 180, kColumns = 360;
  glm::dvec3 sum(0.0);
  for (int r = 0; r < kRows; ++r) {
    const double theta = 0.5 * glm::pi<double>() * (r + 0.5) / kRows;
    const double weight = std::cos(theta) * std::sin(theta) * (0.5 * glm::pi<double>() / kRows) *
                          (2.0 * glm::pi<double>() / kColumns);
    for (int c = 0; c < kColumns; ++c) {
      const double phi = 2.0 * glm::pi<double>() * (c + 0.5) / kColumns;
      const glm::vec3 dir(glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)));
      sum += weight * glm::dvec3(Radiance(dir));
    }
  }
  return sum;
}

HdrImage SkyOnly(const HdrImage& env, const std::vector<uint8_t>& is_sky, const glm::vec3& sun_dir) {
  const SkyDistribution distribution(env, is_sky, sun_dir);
  if (distribution.empty()) return env;
  HdrImage sky = env;
  for (int v = 0; v < env.height; ++v) {
    for (int u = 0; u < env.width; ++u) {
      if (is_sky[static_cast<size_t>(v) * env.width + u]) continue;
      const glm::vec3 m = distribution.Radiance(glm::vec3(LatLongDirection(u, v, env.width, env.height)));
      float* p = sky.Pixel(u, v);
      p[0] = m.x, p[1] = m.y, p[2] = m.z;
    }
  }
  return sky;
}

}  // namespace daylit::sky
