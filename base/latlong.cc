#include "base/latlong.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace daylit {
namespace {

constexpr double kPi = glm::pi<double>();

}  // namespace

glm::dvec3 LatLongDirection(double u, double v, int width, int height) {
  const double theta = kPi * (v + 0.5) / height;
  const double alpha = 2.0 * kPi * ((u + 0.5) / width - 0.5);
  return {std::sin(theta) * std::sin(alpha), std::sin(theta) * std::cos(alpha), std::cos(theta)};
}

glm::dvec2 LatLongCoordinates(const glm::dvec3& dir, int width, int height) {
  const glm::dvec3 d = glm::normalize(dir);
  const double theta = std::acos(std::clamp(d.z, -1.0, 1.0));
  const double alpha = std::atan2(d.x, d.y);  // 0 along +Y, +π/2 along +X
  double u = (alpha / (2.0 * kPi) + 0.5) * width - 0.5;
  if (u >= width - 0.5) u -= width;
  return {u, theta / kPi * height - 0.5};
}

int LatLongTexel(const glm::dvec3& dir, int width, int height) {
  const glm::dvec2 uv = LatLongCoordinates(dir, width, height);
  int u = static_cast<int>(std::lround(uv.x));
  if (u < 0) u += width;
  if (u >= width) u -= width;
  const int v = std::clamp(static_cast<int>(std::lround(uv.y)), 0, height - 1);
  return v * width + u;
}

double LatLongTexelSolidAngle(int v, int width, int height) {
  const double theta0 = kPi * v / height;
  const double theta1 = kPi * (v + 1) / height;
  return 2.0 * kPi / width * (std::cos(theta0) - std::cos(theta1));
}

}  // namespace daylit
