#include "lightfit/probe_approximations.h"

#include <algorithm>
#include <chrono>

#include "base/check.h"
#include "sh/exact_irradiance.h"

namespace daylit::lightfit {

namespace {

struct MethodInfo {
  Method method;
  const char* key;
  const char* name;
  int max_lights;
};
constexpr MethodInfo kMethods[] = {
    {Method::kMedianCut, "mediancut", "median cut", 1024},
    {Method::kIrradianceOptimization, "io", "irradiance optimization", 128},
    {Method::kSh9, "sh", "SH9", 9},
};

const MethodInfo& InfoOf(Method method) {
  for (const MethodInfo& info : kMethods) {
    if (info.method == method) return info;
  }
  DAYLIT_CHECK(false, "method {}", static_cast<int>(method));
}

}  // namespace

const char* MethodKey(Method method) { return InfoOf(method).key; }
const char* MethodName(Method method) { return InfoOf(method).name; }
int MaxLights(Method method) { return InfoOf(method).max_lights; }

std::optional<Method> ParseMethod(const std::string& key) {
  for (const MethodInfo& info : kMethods) {
    if (key == info.key) return info.method;
  }
  return std::nullopt;
}

ProbeApproximations::ProbeApproximations(const HdrImage& map, const LightFitOptions& fit)
    : map_(map), fit_(fit), normals_(sh::IcosahedronNormals(5)), truth_(sh::ExactIrradiance(map, normals_)) {}

const LightsApproximation& ProbeApproximations::Lights(Method method, int n) {
  DAYLIT_CHECK(method != Method::kSh9 && n >= 1 && n <= MaxLights(method), "{} with {} lights", MethodKey(method), n);
  const auto key = std::make_pair(method, n);
  if (const auto found = fits_.find(key); found != fits_.end()) return found->second;
  const auto start = std::chrono::steady_clock::now();
  LightsApproximation row;
  row.method = method;
  row.n = n;
  if (method == Method::kIrradianceOptimization) {
    const LightFitResult fit = IrradianceOptimization(map_, n, fit_);
    row.lights = fit.lights;
    row.iterations = fit.iterations;
    row.converged = fit.converged;
    row.termination = fit.termination;
  } else {
    row.lights = MedianCutLights(map_, n);
  }
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  row.error = RelativeError(truth_, row.lights.Irradiance(normals_));
  return fits_.emplace(key, std::move(row)).first->second;
}

const Sh9Approximation& ProbeApproximations::Sh9() {
  if (!sh9_) {
    Sh9Approximation sh9;
    sh9.radiance = sh::ProjectLatLong(map_.rgb.data(), map_.width, map_.height);
    std::vector<glm::dvec3> e(normals_.size());
    for (size_t i = 0; i < normals_.size(); ++i) e[i] = sh9.radiance.Irradiance(glm::dvec3(normals_[i]));
    sh9.error = RelativeError(truth_, e);
    sh9.error_to_max = RelativeToMaxError(truth_, e);
    sh9_ = std::move(sh9);
  }
  return *sh9_;
}

std::optional<int> ProbeApproximations::AutomaticN(Method method, double threshold) {
  DAYLIT_CHECK(threshold > 0.0 && threshold < 1.0, "threshold {}", threshold);
  const int max = MaxLights(method);
  int below = 1;
  while (Lights(method, below).error.mean >= threshold) {
    if (below == max) return std::nullopt;
    below = std::min(2 * below, max);
  }
  int above = below / 2;  // its error is ≥ threshold (or it is 0 lights)
  while (below - above > 1) {
    const int middle = (above + below) / 2;
    (Lights(method, middle).error.mean < threshold ? below : above) = middle;
  }
  return below;
}

std::vector<const LightsApproximation*> ProbeApproximations::Fitted(Method method) const {
  std::vector<const LightsApproximation*> rows;
  for (const auto& [key, row] : fits_) {
    if (key.first == method) rows.push_back(&row);
  }
  return rows;
}

}  // namespace daylit::lightfit
