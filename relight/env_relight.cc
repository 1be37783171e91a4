#include "relight/env_relight.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>
#include <opencv2/core.hpp>

#include "report/plot.h"
#include "base/latlong.h"

namespace daylit::relight {

EnvRelighter::EnvRelighter(const bake::SceneBake& bake, const glm::vec3& capture_position,
                           const scene::RayCaster& caster, estimation::TransferOptions options)
    : bake_(bake),
      surface_(bake, estimation::TransferPoints::Env(bake.env), bake.env.width, bake.env.height, true,
               capture_position, caster, options) {
  const bake::EnvMapMaps& env = bake.env;
  texel_dirs_.reserve(env.surface.size());
  for (int v = 0; v < env.height; ++v) {
    for (int u = 0; u < env.width; ++u) texel_dirs_.push_back(glm::vec3(LatLongDirection(u, v, env.width, env.height)));
  }
}

bool EnvRelighter::SetSun(const glm::vec3& sun_dir) {
  if (sun_ && *sun_ == sun_dir) return false;  // the caller decides when it moved (scene::SunTracker)
  sun_ = sun_dir;
  surface_.Compute(sun_dir, &terms_);
  // The sky's shape in every texel's direction: the map's sky texels and the sky layer.
  sky_shape_ = surface_.transfer().ClearSkyPerUnitDhi(sun_dir, texel_dirs_);
  return true;
}

void EnvRelighter::Relight(const estimation::SunSky& light, double overcast_share,
                           std::vector<glm::vec3>* radiance) const {
  const bake::EnvMapMaps& env = bake_.env;
  radiance->resize(env.surface.size());
  const LightParts e = SplitLight(light, overcast_share);
  // Sky texels first (model texels overwrite theirs below).
  const glm::vec3 uniform = e.overcast * glm::one_over_pi<float>();
  for (size_t t = 0; t < sky_shape_.size(); ++t) (*radiance)[t] = e.clear * sky_shape_[t] + uniform;
  const std::vector<uint32_t>& model_texels = surface_.model_points();
  for (size_t i = 0; i < model_texels.size(); ++i) {
    const estimation::Transfer& T = terms_[i];
    const uint32_t t = model_texels[i];
    (*radiance)[t] = env.albedo[t] * glm::one_over_pi<float>() * estimation::Irradiance(e, T);
  }
}

void EnvRelighter::RelightWithSky(const estimation::SunSky& light, double overcast_share,
                                  std::vector<glm::vec3>* stacked) const {
  Relight(light, overcast_share, stacked);
  const size_t texels = sky_shape_.size();
  stacked->resize(2 * texels);
  const LightParts e = SplitLight(light, overcast_share);
  const glm::vec3 uniform = e.overcast * glm::one_over_pi<float>();
  for (size_t t = 0; t < texels; ++t) (*stacked)[texels + t] = e.clear * sky_shape_[t] + uniform;
}

void EnvRelighter::Basis(EnvBasis* basis) const {
  // The map under each light alone, at unit strength.
  const estimation::SunSky sun_only{glm::dvec3(1.0), glm::dvec3(0.0)}, sky_only{glm::dvec3(0.0), glm::dvec3(1.0)};
  RelightWithSky(sun_only, 0.0, &basis->sun);
  RelightWithSky(sky_only, 0.0, &basis->clear);
  RelightWithSky(sky_only, 1.0, &basis->overcast);
}

namespace {

float Luminance(const glm::vec3& l) { return scene::Luminance(&l.x); }

// The 99th percentile of `luminance` (reordered), the white of a preview.
float WhiteOf(std::vector<float>& luminance) {
  const size_t k = luminance.size() * 99 / 100;
  std::nth_element(luminance.begin(), luminance.begin() + static_cast<ptrdiff_t>(k), luminance.end());
  return std::max(luminance[k], 1e-6f);
}

// `radiance` / `white`, clamped, sRGB-encoded, as an 8-bit BGR image.
cv::Mat Preview(int width, int height, const std::vector<glm::vec3>& radiance, float white) {
  cv::Mat preview(height, width, CV_8UC3);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const glm::vec3 l = glm::clamp(radiance[static_cast<size_t>(v) * width + u] / white, 0.0f, 1.0f);
      cv::Vec3b& p = preview.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) {
        const float e = l[c] <= 0.0031308f ? 12.92f * l[c] : 1.055f * std::pow(l[c], 1.0f / 2.4f) - 0.055f;
        p[2 - c] = static_cast<uint8_t>(std::lround(255.0f * e));
      }
    }
  }
  return preview;
}

std::vector<glm::vec3> RadianceOf(const HdrImage& image) {
  std::vector<glm::vec3> out(static_cast<size_t>(image.width) * image.height);
  for (size_t i = 0; i < out.size(); ++i) out[i] = glm::vec3(image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]);
  return out;
}

}  // namespace

EnvComparison CompareEnvMaps(const bake::EnvMapMaps& env, const std::vector<glm::vec3>& relit,
                             const HdrImage& truth) {
  const std::vector<glm::vec3> want = RadianceOf(truth);
  std::vector<float> luminance;
  for (size_t t = 0; t < want.size(); ++t) {
    if (!env.IsSky(t)) luminance.push_back(Luminance(want[t]));
  }
  std::nth_element(luminance.begin(), luminance.begin() + static_cast<ptrdiff_t>(luminance.size() / 2), luminance.end());
  const float floor = luminance.empty() ? 0.0f : 1e-3f * luminance[luminance.size() / 2];
  EnvComparison cmp;
  double sum = 0.0;
  for (int v = 0; v < env.height; ++v) {
    const double solid_angle = LatLongTexelSolidAngle(v, env.width, env.height);
    for (int u = 0; u < env.width; ++u) {
      const size_t t = static_cast<size_t>(v) * env.width + u;
      if (env.IsSky(t)) {
        const double cos_theta = LatLongDirection(u, v, env.width, env.height).z;
        if (cos_theta <= 0.0) continue;
        cmp.sky_dhi += solid_angle * cos_theta * Luminance(relit[t]);
        cmp.true_sky_dhi += solid_angle * cos_theta * Luminance(want[t]);
        continue;
      }
      if (Luminance(want[t]) < floor || glm::compMin(want[t]) <= 0.0f) continue;
      const glm::vec3 e = glm::abs(relit[t] - want[t]) / want[t];
      sum += (e.x + e.y + e.z) / 3.0;
      ++cmp.surface_texels;
    }
  }
  cmp.surface_error = cmp.surface_texels > 0 ? sum / static_cast<double>(cmp.surface_texels) : 0.0;
  return cmp;
}

void WriteEnvComparison(const std::filesystem::path& png, const bake::EnvMapMaps& env,
                        const std::vector<glm::vec3>& relit, const HdrImage& truth) {
  const int w = env.width, h = env.height;
  const std::vector<glm::vec3> want = RadianceOf(truth);
  std::vector<float> luminance(want.size());
  for (size_t t = 0; t < want.size(); ++t) luminance[t] = Luminance(want[t]);
  const float white = WhiteOf(luminance);  // one exposure for both maps
  cv::Mat difference(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t t = static_cast<size_t>(v) * w + u;
      const float lw = Luminance(want[t]);
      const float d = lw > 0.0f ? std::clamp((Luminance(relit[t]) - lw) / lw / 0.25f, -1.0f, 1.0f) : 0.0f;
      const auto level = [](float x) { return static_cast<uint8_t>(std::lround(255.0f * (1.0f - x))); };
      difference.at<cv::Vec3b>(v, u) = d >= 0.0f ? cv::Vec3b(level(d), level(d), 255) : cv::Vec3b(255, level(-d), level(-d));
    }
  }
  report::WritePng(png, {Preview(w, h, want, white), Preview(w, h, relit, white), difference});
}

void WriteEnvMap(const std::filesystem::path& exr, int width, int height, const std::vector<glm::vec3>& radiance) {
  const size_t n = static_cast<size_t>(width) * height;
  std::vector<float> luminance(n);
  for (size_t i = 0; i < n; ++i) luminance[i] = Luminance(radiance[i]);
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "glm::vec3 must be three packed floats");
  scene::WriteRgbExr(exr, width, height, &radiance[0].x);
  std::filesystem::path png = exr;
  report::WritePng(png.replace_extension(".png"), {Preview(width, height, radiance, WhiteOf(luminance))});
}

}  // namespace daylit::relight
