#include "lightfit/probe.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

#include "base/error.h"
#include "base/latlong.h"

namespace daylit::lightfit {
namespace {

double Luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// Bilinear lookup at continuous pixel coordinates (x, y), pixel centres at integers; clamped at
// the borders.
glm::dvec3 Bilinear(const HdrImage& image, double x, double y) {
  x = std::clamp(x, 0.0, image.width - 1.0), y = std::clamp(y, 0.0, image.height - 1.0);
  const int x0 = std::min(static_cast<int>(x), image.width - 2 < 0 ? 0 : image.width - 2);
  const int y0 = std::min(static_cast<int>(y), image.height - 2 < 0 ? 0 : image.height - 2);
  const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
  const double fx = x - x0, fy = y - y0;
  const auto at = [&](int u, int v) {
    const float* p = image.Pixel(u, v);
    return glm::dvec3(p[0], p[1], p[2]);
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
}

}  // namespace

HdrImage AngularToLatLong(const HdrImage& angular, int width, int height) {
  HdrImage map;
  map.width = width, map.height = height;
  map.rgb.assign(static_cast<size_t>(width) * height * 3, 0.0f);
  constexpr int kSub = 3;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      glm::dvec3 sum(0.0);
      for (int sv = 0; sv < kSub; ++sv) {
        for (int su = 0; su < kSub; ++su) {
          const glm::dvec3 d = LatLongDirection(u - 0.5 + (su + 0.5) / kSub, v - 0.5 + (sv + 0.5) / kSub, width, height);
          // The gallery's frame: forward −Z, up +Y, right +X; daylit's (x, y, z) is its (x, z, −y).
          const double alpha = std::acos(std::clamp(d.y, -1.0, 1.0));  // angle from forward
          const double side = std::hypot(d.x, d.z);
          const double r = alpha / glm::pi<double>();
          const double px = side > 0.0 ? r * d.x / side : 0.0, py = side > 0.0 ? r * d.z / side : 0.0;
          const double x = (px + 1.0) * 0.5 * angular.width - 0.5, y = (1.0 - py) * 0.5 * angular.height - 0.5;
          sum += Bilinear(angular, x, y);
        }
      }
      float* out = map.Pixel(u, v);
      for (int c = 0; c < 3; ++c) out[c] = static_cast<float>(sum[c] / (kSub * kSub));
    }
  }
  return map;
}

std::string ClippedSourceWarning(const HdrImage& map, int min_texels) {
  std::vector<double> luminance(static_cast<size_t>(map.width) * map.height);
  for (int v = 0; v < map.height; ++v) {
    for (int u = 0; u < map.width; ++u) luminance[static_cast<size_t>(v) * map.width + u] = Luminance(map.Pixel(u, v));
  }
  if (luminance.empty()) return {};
  const double peak = *std::max_element(luminance.begin(), luminance.end());
  const long at_peak = std::count(luminance.begin(), luminance.end(), peak);
  std::nth_element(luminance.begin(), luminance.begin() + luminance.size() / 2, luminance.end());
  const double median = luminance[luminance.size() / 2];
  if (at_peak < min_texels || !(peak > 50.0 * median)) return {};
  return fmt::format("{} texels share the peak luminance {:.4g} exactly, {:.0f} times the median: the brightest "
                     "source looks clipped, so its irradiance, and every light fitted to it, is too low",
                     at_peak, peak, peak / std::max(median, 1e-30));
}

Probe LoadProbe(const std::filesystem::path& path) {
  Probe probe;
  const HdrImage image = scene::ReadHdrImage(path);
  const std::string name = path.string();
  const bool angular = image.width == image.height;
  if (!angular && image.width != 2 * image.height) {
    ThrowInputError("{}: {}x{} is neither a 2:1 latitude-longitude map nor a square angular map", name, image.width,
                    image.height);
  }
  scene::CheckLightProbe(image, name);
  if (angular) {
    probe.map = AngularToLatLong(image, 1024, 512);
    probe.converted_from_angular = true;
  } else {
    probe.map = image;
  }
  if (std::string clipped = ClippedSourceWarning(probe.map); !clipped.empty()) probe.warnings.push_back(name + ": " + clipped);
  return probe;
}

}  // namespace daylit::lightfit
