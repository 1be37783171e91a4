#include "bake/sampling.h"

#include <cmath>

#include <glm/gtc/constants.hpp>

namespace daylit::bake {
namespace {

float RadicalInverse2(uint32_t bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return static_cast<float>(bits) * 2.3283064365386963e-10f;
}

}  // namespace

std::vector<glm::vec3> CosineHemisphere(int count) {
  std::vector<glm::vec3> dirs;
  dirs.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    // Malley's method: uniform points on the disc, lifted to the hemisphere.
    const float u1 = (static_cast<float>(i) + 0.5f) / static_cast<float>(count);
    const float u2 = RadicalInverse2(static_cast<uint32_t>(i));
    const float r = std::sqrt(u1);
    const float phi = 2.0f * glm::pi<float>() * u2;
    dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1)));
  }
  return dirs;
}

glm::mat3 BasisAround(const glm::vec3& n) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  const glm::vec3 t(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  const glm::vec3 bt(b, sign + n.y * n.y * a, -n.y);
  return glm::mat3(t, bt, n);
}

std::vector<glm::vec3> SphericalFibonacci(int count) {
  std::vector<glm::vec3> dirs;
  dirs.reserve(static_cast<size_t>(count));
  const double golden = glm::pi<double>() * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * i;
    dirs.emplace_back(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
  }
  return dirs;
}

float RotationOf(uint32_t key) {
  // PCG-style integer hash.
  key = key * 747796405u + 2891336453u;
  key = ((key >> ((key >> 28u) + 4u)) ^ key) * 277803737u;
  key = (key >> 22u) ^ key;
  return static_cast<float>(key) * 2.3283064365386963e-10f * 2.0f * glm::pi<float>();
}

glm::mat3 HemisphereFrame(const glm::vec3& n, uint32_t key) {
  const float angle = RotationOf(key);
  const float c = std::cos(angle), s = std::sin(angle);
  const glm::mat3 spin(glm::vec3(c, s, 0.0f), glm::vec3(-s, c, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f));
  return BasisAround(n) * spin;
}

uint64_t SurfaceCellKey(const glm::vec3& y, const glm::vec3& normal, uint64_t seed, float size) {
  const glm::ivec3 cell(glm::floor(y / size));
  const glm::ivec3 side(glm::round(normal * 8.0f));
  uint64_t key = seed;
  for (const int v : {cell.x, cell.y, cell.z}) key = key * 0x100000001b3ull ^ static_cast<uint64_t>(static_cast<uint32_t>(v));
  for (const int v : {side.x, side.y, side.z}) key = key * 0x100000001b3ull ^ static_cast<uint64_t>(v + 8);
  return key;
}

glm::vec3 SurfaceCellOrigin(const glm::vec3& y, const glm::vec3& normal, float size) {
  const glm::vec3 centre = (glm::floor(y / size) + 0.5f) * size;
  return centre - glm::dot(centre - y, normal) * normal;
}

}  // namespace daylit::bake
