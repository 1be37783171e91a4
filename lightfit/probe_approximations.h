// Seed 002's benchmark for one light probe: the probe approximated by N directional lights plus
// ambient (median cut; irradiance optimization) and by SH9, each scored in seed 002's measure
// (the mean and max relative irradiance error over the normals of a subdivided icosahedron,
// against the exact irradiance of the map), and the smallest N under a mean-error threshold.
// `daylit lights` writes its files from this; fits are cached, so the automatic search reuses the
// table's fits.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lightfit/light_fit.h"
#include "lightfit/lights.h"
#include "scene/hdr_image.h"
#include "sh/sh9.h"

namespace daylit::lightfit {

enum class Method { kMedianCut, kIrradianceOptimization, kSh9 };

const char* MethodKey(Method method);   // "mediancut", "io", "sh" (file names, --method)
const char* MethodName(Method method);  // "median cut", "irradiance optimization", "SH9"
std::optional<Method> ParseMethod(const std::string& key);
// The most lights a method takes: irradiance optimization's dense normal equations grow as
// (5N)², median cut's regions are cheap; SH9 has 9 coefficients and no N.
int MaxLights(Method method);

struct LightsApproximation {
  Method method = Method::kMedianCut;
  int n = 0;
  LightSet lights;
  ApproximationError error;      // per normal, relative (seed 002's measure)
  double seconds = 0.0;          // the fit's wall time
  int iterations = 0;            // irradiance optimization: Ceres' iterations
  bool converged = true;         // irradiance optimization: stopped on its tolerances
  std::string termination;       // irradiance optimization: Ceres' message
};

struct Sh9Approximation {
  sh::ShRgb9 radiance;                 // the map's radiance projected on SH9
  ApproximationError error;            // per normal, relative
  ApproximationError error_to_max;     // relative to the largest irradiance (Ramamoorthi & Hanrahan's)
};

class ProbeApproximations {
 public:
  // `map` (lat-long, linear) is kept by reference.
  ProbeApproximations(const HdrImage& map, const LightFitOptions& fit);

  // `method` (not kSh9) with `n` lights, 1 ≤ n ≤ MaxLights(method) (a broken caller otherwise:
  // CHECK); fitted once, then looked up.
  const LightsApproximation& Lights(Method method, int n);
  const Sh9Approximation& Sh9();

  // The smallest n ≤ MaxLights(method) whose mean error is below `threshold` (in (0, 1)):
  // doubling, then bisection, which assumes the error falls with n (it does, nearly
  // monotonically, on seed 002's probes). Empty when even the most lights do not reach it.
  std::optional<int> AutomaticN(Method method, double threshold);

  // Every fit made for `method`, in increasing n.
  std::vector<const LightsApproximation*> Fitted(Method method) const;

 private:
  const HdrImage& map_;
  LightFitOptions fit_;
  std::vector<glm::vec3> normals_;
  std::vector<glm::dvec3> truth_;
  std::map<std::pair<Method, int>, LightsApproximation> fits_;
  std::optional<Sh9Approximation> sh9_;
};

}  // namespace daylit::lightfit
