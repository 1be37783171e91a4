// Order-2 real spherical harmonics (9 coefficients per channel) for irradiance, after
// R. Ramamoorthi and P. Hanrahan, "An Efficient Representation for Irradiance Environment
// Maps", SIGGRAPH 2001: project radiance L(ω) onto Y_lm, then E(n) = Σ Â_l L_lm Y_lm(n) with
// Â_0 = π, Â_1 = 2π/3, Â_2 = π/4 (the clamped-cosine convolution, their eq. 8).
//
// Coefficient layout (index: lm, polynomial in the unit direction (x, y, z)):
//   0: 00  0.282095         1: 1-1 0.488603 y    2: 10 0.488603 z    3: 11 0.488603 x
//   4: 2-2 1.092548 xy      5: 2-1 1.092548 yz   6: 20 0.315392 (3z² − 1)
//   7: 21  1.092548 xz      8: 22  0.546274 (x² − y²)
#pragma once

#include <array>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

namespace daylit::sh {

using Sh9Basis = std::array<double, 9>;

// Â_l of the clamped-cosine convolution for each coefficient (sh9.h's order): Â_0, Â_1 (×3),
// Â_2 (×5). Irradiance coefficients are radiance coefficients times these.
inline constexpr Sh9Basis kCosineLobe = {glm::pi<double>(),           2.0 * glm::pi<double>() / 3.0,
                                         2.0 * glm::pi<double>() / 3.0, 2.0 * glm::pi<double>() / 3.0,
                                         glm::pi<double>() / 4.0,     glm::pi<double>() / 4.0,
                                         glm::pi<double>() / 4.0,     glm::pi<double>() / 4.0,
                                         glm::pi<double>() / 4.0};

// RGB radiance projected on the 9 basis functions.
struct ShRgb9 {
  std::array<glm::dvec3, 9> coefficients{};

  // Adds radiance arriving from unit direction `dir` over solid angle `solid_angle_sr`.
  void AddRadiance(const glm::dvec3& dir, const glm::dvec3& radiance, double solid_angle_sr);
  // Irradiance on a surface with unit normal `n` (clamped-cosine convolution).
  glm::dvec3 Irradiance(const glm::dvec3& n) const;
  // Radiance reconstructed in direction `dir` (band-limited; for inspection).
  glm::dvec3 Radiance(const glm::dvec3& dir) const;
};

// Y_lm(dir) for the 9 functions above.
Sh9Basis EvalSh9(const glm::dvec3& dir);

// Projects a W×H lat-long RGB map (scene/latlong.h; row-major, 3 floats per texel) onto SH9.
ShRgb9 ProjectLatLong(const float* rgb, int width, int height);

}  // namespace daylit::sh
