#include "relight/exact_irradiance.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "scene/latlong.h"

namespace daylit::relight {

std::vector<glm::dvec3> ExactIrradiance(const scene::HdrImage& map, const std::vector<glm::vec3>& normals) {
  // Each texel as a direction and its radiance times solid angle.
  const size_t texels = static_cast<size_t>(map.width) * map.height;
  std::vector<glm::vec3> dirs(texels), power(texels);
  for (int v = 0; v < map.height; ++v) {
    const float solid_angle = static_cast<float>(scene::LatLongTexelSolidAngle(v, map.width, map.height));
    for (int u = 0; u < map.width; ++u) {
      const size_t t = static_cast<size_t>(v) * map.width + u;
      dirs[t] = glm::vec3(scene::LatLongDirection(u, v, map.width, map.height));
      const float* p = map.Pixel(u, v);
      power[t] = solid_angle * glm::vec3(p[0], p[1], p[2]);
    }
  }
  std::vector<glm::dvec3> irradiance(normals.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, normals.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      glm::dvec3 sum(0.0);
      // Per row in float, summed in double: 1024 terms per row keep float's error below 1e-5.
      for (int v = 0; v < map.height; ++v) {
        glm::vec3 row(0.0f);
        const size_t begin = static_cast<size_t>(v) * map.width;
        for (size_t t = begin; t < begin + static_cast<size_t>(map.width); ++t) {
          row += std::max(0.0f, glm::dot(normals[i], dirs[t])) * power[t];
        }
        sum += glm::dvec3(row);
      }
      irradiance[i] = sum;
    }
  });
  return irradiance;
}

scene::HdrImage DownsampleLatLong(const scene::HdrImage& map, int factor) {
  scene::HdrImage out{map.width / factor, map.height / factor, {}};
  out.rgb.assign(static_cast<size_t>(out.width) * out.height * 3, 0.0f);
  for (int v = 0; v < out.height; ++v) {
    for (int u = 0; u < out.width; ++u) {
      glm::dvec3 sum(0.0);
      double weight = 0.0;
      for (int dv = 0; dv < factor; ++dv) {
        const double w = scene::LatLongTexelSolidAngle(v * factor + dv, map.width, map.height);
        for (int du = 0; du < factor; ++du) {
          const float* p = map.Pixel(u * factor + du, v * factor + dv);
          sum += w * glm::dvec3(p[0], p[1], p[2]), weight += w;
        }
      }
      float* q = out.Pixel(u, v);
      for (int c = 0; c < 3; ++c) q[c] = static_cast<float>(sum[c] / weight);
    }
  }
  return out;
}

}  // namespace daylit::relight
