// Irradiance Optimization (seed 000 §3.2, seed 002 §4.2): N directional lights, each an RGB
// irradiance and a direction given by two angles, plus an optional RGB ambient term, fitted so
// that the lights' diffuse irradiance matches a probe's true irradiance over a set of normals:
//
//   min Σ_n Σ_rgb ((ambient + Σ_i irradiance_i · max(0, n · direction_i) − E(n)) / E(n))²
//
// i.e. in seed 002's relative measure, with irradiance and ambient ≥ 0. Solved with Ceres
// (Levenberg-Marquardt, analytic Jacobian). Each light's angles are measured in a frame around
// its initial direction, so no light starts at the parametrisation's pole.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "lightfit/lights.h"
#include "scene/hdr_image.h"

namespace daylit::lightfit {

struct LightFitOptions {
  bool ambient = true;       // fit the ambient term (else it stays at the initial value)
  int max_iterations = 200;  // Levenberg-Marquardt iterations
  // Converged when one iteration lowers the cost by less than `function_tolerance` of it, or
  // `stall_window` iterations together by less than `stall_fraction`: the clamped cosine's kink
  // leaves a long tail of tiny steps once the lights have found their places.
  double function_tolerance = 1e-4;
  int stall_window = 10;
  double stall_fraction = 0.01;
  int threads = 2;
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

struct LightFitResult {
  LightSet lights;
  int iterations = 0;
  bool converged = false;       // stopped on the tolerances above, not on the iteration limit
  double initial_cost = 0.0;    // ½ Σ r² at the start and at the end
  double final_cost = 0.0;
  std::string termination;      // Ceres's message
};

// Fits `initial` (its lights and ambient are the starting point) to the true irradiance `truth`
// at `normals`. Normals whose truth is below 1e-3 of the maximum in any channel are left out, as
// in RelativeError.
LightFitResult FitLights(const std::vector<glm::vec3>& normals, const std::vector<glm::dvec3>& truth,
                         const LightSet& initial, const LightFitOptions& options = {});

// Irradiance Optimization of a whole probe: N lights started from median cut's N regions
// (MedianCutLights), the ambient from the irradiance the lights leave unexplained, then fitted
// to the exact irradiance (sh::ExactIrradiance) at FitNormals(n).
LightFitResult IrradianceOptimization(const HdrImage& map, int n, const LightFitOptions& options = {});

// The normals IrradianceOptimization fits at: a subdivided icosahedron with at least 20
// residuals (3 per normal) per parameter (3 + 5n): 1280 normals up to 32 lights, then 5120.
// Irradiance is a smooth function of the normal, so the 20 480 normals of the error measure
// are as well fitted (they are the test set, the fit never sees them).
std::vector<glm::vec3> FitNormals(int n);

// The analytic residuals and Jacobian of FitLights' problem for one normal, exposed for the test
// that checks them against numeric differentiation. `parameters`: ambient (3), then per light
// irradiance (3) and angles (2) around the frame of `initial`'s light. Returns 3 residuals and,
// row-major, their 3 × (3 + 5N) Jacobian.
void LightFitResidual(const LightSet& initial, const glm::vec3& normal, const glm::dvec3& truth,
                      const std::vector<double>& parameters, double residuals[3], std::vector<double>* jacobian);

}  // namespace daylit::lightfit
