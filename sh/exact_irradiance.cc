#include "sh/exact_irradiance.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include <glm/gtc/constants.hpp>

#include "base/latlong.h"

namespace daylit::sh {
namespace {

// Per row of the map, prefix sums over its texels u of P_u, P_u·cos α_u and P_u·sin α_u, where
// P_u = L·ΔΩ (RGB) and α_u the texel's azimuth: [row][k] holds the sums over u < k.
struct RowSums {
  int width = 0, height = 0;
  std::vector<glm::dvec3> p, p_cos, p_sin;  // (width + 1) per row

  explicit RowSums(const HdrImage& map) : width(map.width), height(map.height) {
    const size_t stride = static_cast<size_t>(width) + 1;
    p.assign(stride * height, glm::dvec3(0.0)), p_cos = p, p_sin = p;
    for (int v = 0; v < height; ++v) {
      const double solid_angle = LatLongTexelSolidAngle(v, width, height);
      for (int u = 0; u < width; ++u) {
        const double alpha = 2.0 * glm::pi<double>() * ((u + 0.5) / width - 0.5);
        const float* l = map.Pixel(u, v);
        const glm::dvec3 power = solid_angle * glm::dvec3(l[0], l[1], l[2]);
        const size_t k = static_cast<size_t>(v) * stride + static_cast<size_t>(u);
        p[k + 1] = p[k] + power;
        p_cos[k + 1] = p_cos[k] + power * std::cos(alpha);
        p_sin[k + 1] = p_sin[k] + power * std::sin(alpha);
      }
    }
  }
  // Sums over texels first..last (inclusive, wrapping around the row), first and last in
  // [0, width).
  void Range(int row, int first, int last, glm::dvec3* s, glm::dvec3* c, glm::dvec3* n) const {
    const size_t base = static_cast<size_t>(row) * (static_cast<size_t>(width) + 1);
    const auto sum = [&](const std::vector<glm::dvec3>& a) {
      if (first <= last) return a[base + static_cast<size_t>(last) + 1] - a[base + static_cast<size_t>(first)];
      return (a[base + static_cast<size_t>(width)] - a[base + static_cast<size_t>(first)]) + (a[base + static_cast<size_t>(last) + 1] - a[base]);
    };
    *s = sum(p), *c = sum(p_cos), *n = sum(p_sin);
  }
};

}  // namespace

std::vector<glm::dvec3> ExactIrradiance(const HdrImage& map, const std::vector<glm::vec3>& normals) {
  // n·ω = cos θn cos θ + sin θn sin θ cos(α − αn). In a row (θ fixed) that is a + b·cos(α − αn),
  // positive on one arc of azimuths around αn, so the row's share of E(n) is
  //   a·Σ_arc P + b·(cos αn·Σ_arc P cos α + sin αn·Σ_arc P sin α),
  // three prefix-sum differences: O(rows) per normal instead of O(texels), and the same sum as
  // texel by texel (texels on the arc's ends contribute ≈ 0 either way).
  const RowSums sums(map);
  const int w = map.width, h = map.height;
  std::vector<double> row_cos(static_cast<size_t>(h)), row_sin(static_cast<size_t>(h));
  for (int v = 0; v < h; ++v) {
    const double theta = glm::pi<double>() * (v + 0.5) / h;
    row_cos[static_cast<size_t>(v)] = std::cos(theta), row_sin[static_cast<size_t>(v)] = std::sin(theta);
  }
  std::vector<glm::dvec3> irradiance(normals.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, normals.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::dvec3 n = glm::normalize(glm::dvec3(normals[i]));
      const double sin_n = std::sqrt(std::max(0.0, 1.0 - n.z * n.z));
      const double alpha_n = std::atan2(n.x, n.y);  // ω = (sin θ sin α, sin θ cos α, cos θ)
      const double cos_an = std::cos(alpha_n), sin_an = std::sin(alpha_n);
      glm::dvec3 e(0.0);
      for (int v = 0; v < h; ++v) {
        const double a = n.z * row_cos[static_cast<size_t>(v)], b = sin_n * row_sin[static_cast<size_t>(v)];
        int first = 0, last = w - 1;
        if (b <= 1e-12 * std::abs(a)) {
          if (a <= 0.0) continue;  // the whole row behind the normal
        } else {
          const double c = -a / b;
          if (c >= 1.0) continue;
          if (c > -1.0) {
            const double half = std::acos(c);  // the arc |α − αn| < half
            first = static_cast<int>(std::ceil(w * ((alpha_n - half) / (2.0 * glm::pi<double>()) + 0.5) - 0.5));
            last = static_cast<int>(std::floor(w * ((alpha_n + half) / (2.0 * glm::pi<double>()) + 0.5) - 0.5));
            if (last < first) continue;
            if (last - first + 1 >= w) {
              first = 0, last = w - 1;
            } else {
              first = ((first % w) + w) % w, last = ((last % w) + w) % w;
            }
          }
        }
        glm::dvec3 s, sc, ss;
        sums.Range(v, first, last, &s, &sc, &ss);
        e += a * s + b * (cos_an * sc + sin_an * ss);
      }
      irradiance[i] = glm::max(e, glm::dvec3(0.0));
    }
  });
  return irradiance;
}

std::vector<glm::vec3> IcosahedronNormals(int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (glm::vec3& p : v) p = glm::normalize(p);
  std::vector<glm::uvec3> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                   {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::vector<glm::uvec3> next;
    next.reserve(faces.size() * 4);
    for (const glm::uvec3& f : faces) {
      // New midpoint vertices per face (shared edges are duplicated: only the centroids matter).
      const uint32_t a = static_cast<uint32_t>(v.size());
      v.push_back(glm::normalize(v[f.x] + v[f.y]));
      v.push_back(glm::normalize(v[f.y] + v[f.z]));
      v.push_back(glm::normalize(v[f.z] + v[f.x]));
      next.push_back({f.x, a, a + 2}), next.push_back({f.y, a + 1, a}), next.push_back({f.z, a + 2, a + 1});
      next.push_back({a, a + 1, a + 2});
    }
    faces.swap(next);
  }
  std::vector<glm::vec3> normals;
  normals.reserve(faces.size());
  for (const glm::uvec3& f : faces) normals.push_back(glm::normalize(v[f.x] + v[f.y] + v[f.z]));
  return normals;
}

std::vector<glm::dvec3> ExactIrradianceMap(const HdrImage& map, int width, int height) {
  std::vector<glm::vec3> normals(static_cast<size_t>(width) * height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) normals[static_cast<size_t>(v) * width + u] = glm::vec3(LatLongDirection(u, v, width, height));
  }
  return ExactIrradiance(map, normals);
}

HdrImage DownsampleLatLong(const HdrImage& map, int factor) {
  HdrImage out{map.width / factor, map.height / factor, {}};
  out.rgb.assign(static_cast<size_t>(out.width) * out.height * 3, 0.0f);
  for (int v = 0; v < out.height; ++v) {
    for (int u = 0; u < out.width; ++u) {
      glm::dvec3 sum(0.0);
      double weight = 0.0;
      for (int dv = 0; dv < factor; ++dv) {
        const double w = LatLongTexelSolidAngle(v * factor + dv, map.width, map.height);
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

}  // namespace daylit::sh
