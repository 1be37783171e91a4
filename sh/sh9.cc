#include "sh/sh9.h"

#include <cmath>

#include <glm/gtc/constants.hpp>

#include "base/latlong.h"

namespace daylit::sh {
namespace {


}  // namespace

Sh9Basis EvalSh9(const glm::dvec3& d) {
  return {0.282095,
          0.488603 * d.y,
          0.488603 * d.z,
          0.488603 * d.x,
          1.092548 * d.x * d.y,
          1.092548 * d.y * d.z,
          0.315392 * (3.0 * d.z * d.z - 1.0),
          1.092548 * d.x * d.z,
          0.546274 * (d.x * d.x - d.y * d.y)};
}

void ShRgb9::AddRadiance(const glm::dvec3& dir, const glm::dvec3& radiance, double solid_angle_sr) {
  const Sh9Basis y = EvalSh9(dir);
  for (size_t i = 0; i < 9; ++i) coefficients[i] += radiance * (y[i] * solid_angle_sr);
}

glm::dvec3 ShRgb9::Irradiance(const glm::dvec3& n) const {
  const Sh9Basis y = EvalSh9(n);
  glm::dvec3 e(0.0);
  for (size_t i = 0; i < 9; ++i) e += coefficients[i] * (kCosineLobe[i] * y[i]);
  return e;
}

glm::dvec3 ShRgb9::Radiance(const glm::dvec3& dir) const {
  const Sh9Basis y = EvalSh9(dir);
  glm::dvec3 l(0.0);
  for (size_t i = 0; i < 9; ++i) l += coefficients[i] * y[i];
  return l;
}

ShRgb9 ProjectLatLong(const float* rgb, int width, int height) {
  ShRgb9 sh;
  for (int v = 0; v < height; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, width, height);
    for (int u = 0; u < width; ++u) {
      const float* texel = rgb + (static_cast<size_t>(v) * width + u) * 3;
      sh.AddRadiance(LatLongDirection(u, v, width, height), glm::dvec3(texel[0], texel[1], texel[2]),
                     solid_angle);
    }
  }
  return sh;
}

}  // namespace daylit::sh
