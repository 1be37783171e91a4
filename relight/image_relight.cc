#include "relight/image_relight.h"

#include "base/check.h"

#include "base/options_check.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "base/statistics.h"
#include "scene/hdr_image.h"

namespace daylit::relight {

ImageRelighter::ImageRelighter(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                               ImageRelightOptions options)
    : surface_(bake, estimation::TransferPoints::Camera(bake.camera), bake.camera.width, bake.camera.height, false,
               scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f), caster, options.transfer) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  const int width = bake.camera.width;
  terms_.width = width, terms_.height = bake.camera.height;
  terms_.floor = options.floor;
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(terms_.height);
  std::vector<uint8_t>& kind = terms_.kind;
  kind.assign(n, options.sky == SkyPixels::kFollow ? kSkyPixel : kKeptPixel);
  for (const uint32_t p : surface_.model_points()) kind[p] = kModelPixel;
  if (options.sky == SkyPixels::kFollow) {
    std::vector<glm::dvec2> pixels;
    for (size_t p = 0; p < n; ++p) {
      if (kind[p] != kSkyPixel) continue;
      sky_pixels_.push_back(static_cast<uint32_t>(p));
      pixels.emplace_back(static_cast<double>(p % static_cast<size_t>(width)), static_cast<double>(p / static_cast<size_t>(width)));
    }
    for (const glm::dvec3& d : scene.Camera().UnprojectToWorldRays(pixels)) sky_dirs_.emplace_back(d);
  }
}

void ImageRelighter::Fill(const glm::vec3& sun_dir, PixelTerms* terms) {
  const size_t n = terms_.kind.size();
  terms->sun.assign(n, glm::vec3(0.0f));
  terms->clear.assign(n, glm::vec3(0.0f));
  terms->overcast.assign(n, glm::vec3(0.0f));
  surface_.Compute(sun_dir, &scratch_);
  const std::vector<uint32_t>& model = surface_.model_points();
  for (size_t i = 0; i < model.size(); ++i) {
    terms->sun[model[i]] = scratch_[i].sun;
    terms->clear[model[i]] = scratch_[i].clear;
    terms->overcast[model[i]] = scratch_[i].overcast;
  }
  if (sky_pixels_.empty()) return;
  const std::vector<glm::vec3> shape = surface_.transfer().ClearSkyPerUnitDhi(sun_dir, sky_dirs_);
  for (size_t i = 0; i < sky_pixels_.size(); ++i) {
    terms->clear[sky_pixels_[i]] = shape[i];
    terms->overcast[sky_pixels_[i]] = glm::vec3(glm::one_over_pi<float>());
  }
}

bool ImageRelighter::SetSuns(const glm::vec3& now, const glm::vec3& next) {
  // The caller decides when a sun has moved (scene::SunTracker): any other sun is redone.
  const auto moved = [](const std::optional<glm::vec3>& from, const glm::vec3& to) { return !from || *from != to; };
  const bool now_moved = moved(now_sun_, now), next_moved = moved(next_sun_, next);
  if (now_moved) Fill(now, &terms_.now), now_sun_ = now, terms_.now_sun = now;
  if (next_moved) Fill(next, &terms_.next), next_sun_ = next;
  return now_moved || next_moved;
}

glm::vec3 RatioTerms::FloorOf(const LightParts& now_parts) const {
  return floor * (now_parts.sun * std::max(0.0f, now_sun.z) + now_parts.clear + now_parts.overcast);
}

namespace {

// E_new / E_now for every pixel, handed to `per_pixel(p, ratio)`.
template <typename PerPixel>
RelightStats ForEachRatio(const RatioTerms& t, const LightParts& now, const LightParts& next, PerPixel per_pixel) {
  const glm::vec3 floor = t.FloorOf(now);
  return tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, t.kind.size(), 16384), RelightStats{},
      [&](const tbb::blocked_range<size_t>& range, RelightStats stats) {
        for (size_t p = range.begin(); p < range.end(); ++p) {
          const uint8_t kind = t.kind[p];
          if (kind == kKeptPixel) {
            per_pixel(p, glm::vec3(1.0f));
            continue;
          }
          glm::vec3 e_now = estimation::Irradiance(now, t.now.sun[p], t.now.clear[p], t.now.overcast[p]);
          const glm::vec3 e_new = estimation::Irradiance(next, t.next.sun[p], t.next.clear[p], t.next.overcast[p]);
          if (kind == kModelPixel) {
            ++stats.model_pixels;
            if (glm::any(glm::lessThan(e_now, floor))) ++stats.clamped, e_now = glm::max(e_now, floor);
          } else {
            e_now = glm::max(e_now, glm::vec3(1e-20f));
          }
          per_pixel(p, e_new / e_now);
        }
        return stats;
      },
      [](RelightStats a, const RelightStats& b) {
        a.model_pixels += b.model_pixels, a.clamped += b.clamped;
        return a;
      });
}

}  // namespace

RelightStats ApplyRatio(const RatioTerms& terms, const LightParts& now, const LightParts& next, float* rgb) {
  return ForEachRatio(terms, now, next, [rgb](size_t p, const glm::vec3& ratio) {
    rgb[3 * p] *= ratio.x, rgb[3 * p + 1] *= ratio.y, rgb[3 * p + 2] *= ratio.z;
  });
}

RelightStats RatioOf(const RatioTerms& terms, const LightParts& now, const LightParts& next, float* ratio) {
  return ForEachRatio(terms, now, next, [ratio](size_t p, const glm::vec3& r) {
    ratio[3 * p] = r.x, ratio[3 * p + 1] = r.y, ratio[3 * p + 2] = r.z;
  });
}

std::vector<uint8_t> ShadowLayout(const bake::CameraGBuffer& g, const PixelTerms& terms, const SceneLight& light,
                                  const float* rgb) {
  std::vector<uint8_t> layout(g.diffuse.size(), 255);
  if (light.sun_dir.z <= 0.0f) return layout;
  const float inv_pi = glm::one_over_pi<float>();
  for (size_t p = 0; p < layout.size(); ++p) {
    if (!g.diffuse[p]) continue;
    const float cos = glm::dot(g.normal[p], light.sun_dir);
    if (cos <= 0.25f) continue;
    // Green: the sky's terms and the sun's reflected part (T_sun less the direct sun, if the pixel
    // is sunlit in the model), then the direct sun on top.
    const float t_sun = terms.sun[p].y;
    const float reflected = t_sun >= cos ? t_sun - cos : t_sun;
    const float shadowed = light.parts.clear.y * terms.clear[p].y + light.parts.overcast.y * terms.overcast[p].y +
                           light.parts.sun.y * reflected;
    const float direct = light.parts.sun.y * cos;
    if (direct < shadowed || shadowed <= 0.0f || g.albedo[p].y <= 0.0f) continue;
    const float scale = g.albedo[p].y * inv_pi;
    const float threshold = scale * std::sqrt(shadowed * (shadowed + direct));
    layout[p] = rgb[3 * p + 1] < threshold ? 1 : 0;
  }
  return layout;
}

double ShadowIoU(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  size_t both = 0, either = 0;
  for (size_t p = 0; p < a.size() && p < b.size(); ++p) {
    if (a[p] == 255 || b[p] == 255) continue;
    both += (a[p] == 1 && b[p] == 1) ? 1 : 0;
    either += (a[p] == 1 || b[p] == 1) ? 1 : 0;
  }
  return either > 0 ? static_cast<double>(both) / static_cast<double>(either) : 1.0;
}

double DiffuseError(const bake::CameraGBuffer& g, const float* a, const float* b) {
  std::vector<double> lum;
  for (size_t p = 0; p < g.diffuse.size(); ++p) {
    if (g.diffuse[p]) lum.push_back(scene::Luminance(b + 3 * p));
  }
  const double floor = 1e-3 * MedianInPlace(lum, 0.0);
  double sum = 0.0;
  size_t count = 0;
  for (size_t p = 0; p < g.diffuse.size(); ++p) {
    if (!g.diffuse[p] || scene::Luminance(b + 3 * p) < floor) continue;
    const float* x = a + 3 * p;
    const float* y = b + 3 * p;
    if (y[0] <= 0.0f || y[1] <= 0.0f || y[2] <= 0.0f) continue;
    sum += (std::abs(x[0] - y[0]) / y[0] + std::abs(x[1] - y[1]) / y[1] + std::abs(x[2] - y[2]) / y[2]) / 3.0;
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

glm::dvec2 ClearSkyFactors(double from_deg, double to_deg, int month) {
  // ASHRAE Handbook of Fundamentals (1985), clear-day constants per month: B the atmosphere's
  // optical depth, C the diffuse factor; A (the apparent extraterrestrial DNI) cancels in the factors.
  static constexpr double kB[12] = {0.142, 0.144, 0.156, 0.180, 0.196, 0.205, 0.207, 0.201, 0.177, 0.160, 0.149, 0.142};
  const double b = kB[std::clamp(month, 1, 12) - 1];
  const auto dni = [b](double elevation_deg) {
    const double s = std::sin(glm::radians(elevation_deg));
    return s > 0.0 ? std::exp(-b / s) : 0.0;
  };
  const double from = dni(from_deg), to = dni(to_deg);
  // The sun down at either end: no sun, and the sky as it is (the model has no twilight).
  if (from <= 0.0 || to <= 0.0) return {0.0, 1.0};
  // DHI = C·DNI on a horizontal surface: the same factor as the DNI's, C being per month.
  return {to / from, to / from};
}

std::string ImageRelightOptions::Check() const {
  return FirstProblem({InOpenClosed("floor", floor, 0.0f, 1.0f), Nested("transfer", transfer.Check())});
}

}  // namespace daylit::relight
