#include "lightfit/lights.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "base/latlong.h"

namespace daylit::lightfit {
namespace {

// Summed-area table of a per-texel value: sat[(v)·(w+1) + u] = Σ over rows < v, columns < u.
struct SummedArea {
  int w = 0, h = 0;
  std::vector<double> sat;
  SummedArea(int width, int height, const std::vector<double>& value) : w(width), h(height) {
    sat.assign(static_cast<size_t>(w + 1) * (h + 1), 0.0);
    for (int v = 0; v < h; ++v) {
      double row = 0.0;
      for (int u = 0; u < w; ++u) {
        row += value[static_cast<size_t>(v) * w + u];
        sat[static_cast<size_t>(v + 1) * (w + 1) + u + 1] = sat[static_cast<size_t>(v) * (w + 1) + u + 1] + row;
      }
    }
  }
  // Σ over columns [u0, u1), rows [v0, v1).
  double Sum(int u0, int v0, int u1, int v1) const {
    const auto at = [&](int u, int v) { return sat[static_cast<size_t>(v) * (w + 1) + u]; };
    return at(u1, v1) - at(u0, v1) - at(u1, v0) + at(u0, v0);
  }
};

struct Region {
  int u0, v0, u1, v1;  // [u0, u1) × [v0, v1)
};

}  // namespace

glm::dvec3 LightSet::Irradiance(const glm::vec3& normal) const {
  glm::dvec3 e(ambient);
  for (const DirectionalLight& l : lights) e += glm::dvec3(l.irradiance) * std::max(0.0, static_cast<double>(glm::dot(normal, l.direction)));
  return e;
}

std::vector<glm::dvec3> LightSet::Irradiance(const std::vector<glm::vec3>& normals) const {
  std::vector<glm::dvec3> e(normals.size());
  for (size_t i = 0; i < normals.size(); ++i) e[i] = Irradiance(normals[i]);
  return e;
}

std::string LightSetJson(const LightSet& set) {
  const auto array = [](const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  nlohmann::json lights = nlohmann::json::array();
  for (const DirectionalLight& l : set.lights) lights.push_back({{"direction", array(l.direction)}, {"irradiance", array(l.irradiance)}});
  const nlohmann::json json = {{"ambient", array(set.ambient)}, {"lights", lights}};
  return json.dump(2) + "\n";
}

LightSet MedianCut(const HdrImage& map, int levels) { return MedianCutLights(map, 1 << levels); }

LightSet MedianCutLights(const HdrImage& map, int n) {
  const int w = map.width, h = map.height;
  std::vector<double> luminance(static_cast<size_t>(w) * h);
  for (int v = 0; v < h; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, w, h);
    for (int u = 0; u < w; ++u) {
      const float* p = map.Pixel(u, v);
      luminance[static_cast<size_t>(v) * w + u] = solid_angle * (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]);
    }
  }
  const SummedArea sat(w, h, luminance);
  // Cuts `r` in two (appended to `out`) along its longer side, the width measured at its middle
  // latitude (sin θ), where the luminance halves; a single texel stays whole.
  const auto split = [&](const Region& r, std::vector<Region>& out) {
    const double theta = glm::pi<double>() * 0.5 * (r.v0 + r.v1) / h;
    const double width = (r.u1 - r.u0) * std::sin(theta) * 2.0 * glm::pi<double>() / w;
    const double height = (r.v1 - r.v0) * glm::pi<double>() / h;
    const bool split_u = width >= height ? r.u1 - r.u0 > 1 : r.v1 - r.v0 <= 1;
    const int lo = split_u ? r.u0 : r.v0, hi = split_u ? r.u1 : r.v1;
    if (hi - lo < 2) {
      out.push_back(r);
      return;
    }
    const double total = sat.Sum(r.u0, r.v0, r.u1, r.v1);
    // The cut c in (lo, hi) where the first part's sum is closest to half.
    int cut = lo + 1;
    double best = 1e300;
    for (int c = lo + 1; c < hi; ++c) {
      const double part = split_u ? sat.Sum(r.u0, r.v0, c, r.v1) : sat.Sum(r.u0, r.v0, r.u1, c);
      const double d = std::abs(part - 0.5 * total);
      if (d < best) best = d, cut = c;
    }
    out.push_back(split_u ? Region{r.u0, r.v0, cut, r.v1} : Region{r.u0, r.v0, r.u1, cut});
    out.push_back(split_u ? Region{cut, r.v0, r.u1, r.v1} : Region{r.u0, cut, r.u1, r.v1});
  };
  std::vector<Region> regions = {{0, 0, w, h}};
  // Whole levels of Debevec's cut while they fit in n, then the brightest regions cut once more.
  while (2 * regions.size() <= static_cast<size_t>(n)) {
    std::vector<Region> next;
    for (const Region& r : regions) split(r, next);
    if (next.size() == regions.size()) break;  // nothing left to cut
    regions.swap(next);
  }
  const size_t extra = static_cast<size_t>(n) - std::min(regions.size(), static_cast<size_t>(n));
  std::stable_sort(regions.begin(), regions.end(), [&](const Region& a, const Region& b) {
    return sat.Sum(a.u0, a.v0, a.u1, a.v1) > sat.Sum(b.u0, b.v0, b.u1, b.v1);
  });
  std::vector<Region> cut;
  for (size_t i = 0; i < regions.size(); ++i) {
    if (i < extra) {
      split(regions[i], cut);
    } else {
      cut.push_back(regions[i]);
    }
  }
  LightSet set;
  for (const Region& r : cut) {
    glm::dvec3 power(0.0), centroid(0.0);
    for (int v = r.v0; v < r.v1; ++v) {
      const double solid_angle = LatLongTexelSolidAngle(v, w, h);
      for (int u = r.u0; u < r.u1; ++u) {
        const float* p = map.Pixel(u, v);
        const glm::dvec3 texel = solid_angle * glm::dvec3(p[0], p[1], p[2]);
        power += texel;
        centroid += luminance[static_cast<size_t>(v) * w + u] * LatLongDirection(u, v, w, h);
      }
    }
    const glm::dvec3 middle = LatLongDirection((r.u0 + r.u1) / 2, (r.v0 + r.v1) / 2, w, h);
    const glm::dvec3 direction = glm::length(centroid) > 0.0 ? glm::normalize(centroid) : middle;
    set.lights.push_back({glm::vec3(direction), glm::vec3(power)});
  }
  return set;
}

ApproximationError RelativeError(const std::vector<glm::dvec3>& truth, const std::vector<glm::dvec3>& approximation) {
  glm::dvec3 peak(0.0);
  for (const glm::dvec3& e : truth) peak = glm::max(peak, e);
  ApproximationError error;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (!glm::all(glm::greaterThanEqual(truth[i], 1e-3 * peak)) || !glm::all(glm::greaterThan(truth[i], glm::dvec3(0.0)))) continue;
    const glm::dvec3 r = glm::abs(approximation[i] - truth[i]) / truth[i];
    const double e = (r.x + r.y + r.z) / 3.0;
    error.mean += e, error.max = std::max(error.max, e);
    ++error.normals;
  }
  if (error.normals > 0) error.mean /= static_cast<double>(error.normals);
  return error;
}

ApproximationError RelativeToMaxError(const std::vector<glm::dvec3>& truth, const std::vector<glm::dvec3>& approximation) {
  glm::dvec3 peak(0.0);
  for (const glm::dvec3& e : truth) peak = glm::max(peak, e);
  ApproximationError error;
  if (!glm::all(glm::greaterThan(peak, glm::dvec3(0.0)))) return error;
  for (size_t i = 0; i < truth.size(); ++i) {
    const glm::dvec3 r = glm::abs(approximation[i] - truth[i]) / peak;
    const double e = (r.x + r.y + r.z) / 3.0;
    error.mean += e, error.max = std::max(error.max, e);
  }
  error.normals = truth.size();
  if (error.normals > 0) error.mean /= static_cast<double>(error.normals);
  return error;
}

}  // namespace daylit::lightfit
