#include "relight/object_shadows.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "bake/sampling.h"

namespace daylit::relight {
namespace {

// Whether the ray origin + t·dir (t > 0, dir unit) passes through the sphere (centre, radius).
bool RayMeetsSphere(const glm::vec3& origin, const glm::vec3& dir, const glm::vec4& sphere) {
  const glm::vec3 to = glm::vec3(sphere) - origin;
  const float along = glm::dot(to, dir);
  const float r2 = sphere.w * sphere.w;
  if (along < 0.0f) return glm::dot(to, to) <= r2;
  return glm::dot(to, to) - along * along <= r2;
}

}  // namespace

ObjectShadows::ObjectShadows(const scene::Scene& scene, const bake::CameraGBuffer& gbuffer, const scene::RayCaster& real,
                             const scene::RayCaster& objects, const ObjectShadowOptions& options)
    : gbuffer_(gbuffer), real_(real), objects_(objects), options_(options) {
  // Bounding spheres from the meshes themselves (surface i of the objects' model is object i).
  const scene::SceneModel& model = objects.model();
  std::vector<glm::vec3> lo(scene.objects.size(), glm::vec3(1e30f)), hi(scene.objects.size(), glm::vec3(-1e30f));
  for (const scene::Triangle& t : model.triangles) {
    for (const uint32_t v : t.v) lo[t.surface] = glm::min(lo[t.surface], model.vertices[v]), hi[t.surface] = glm::max(hi[t.surface], model.vertices[v]);
  }
  for (size_t o = 0; o < lo.size(); ++o) {
    if (lo[o].x > hi[o].x) continue;
    const glm::vec3 centre = 0.5f * (lo[o] + hi[o]);
    spheres_.emplace_back(centre, 0.5f * glm::length(hi[o] - lo[o]) + 1e-3f);
  }
  // V' once: the pixels near an object cast cosine-weighted rays; a ray that reaches the sky past
  // the real model but meets an object is sky the object hides.
  const size_t pixels = gbuffer.point.size();
  std::vector<uint32_t> near;
  for (size_t p = 0; p < pixels; ++p) {
    if (gbuffer.surface[p] == bake::kNoSurface) continue;
    for (const glm::vec4& s : spheres_) {
      if (glm::distance(gbuffer.point[p], glm::vec3(s)) < options_.reach_radii * s.w) {
        near.push_back(static_cast<uint32_t>(p));
        break;
      }
    }
  }
  const std::vector<glm::vec3> hemisphere = bake::CosineHemisphere(options_.sky_rays);
  std::vector<float> lost(near.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, near.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const uint32_t p = near[i];
      const glm::vec3 origin = gbuffer.point[p] + options_.offset_m * gbuffer.normal[p];
      const glm::mat3 frame = bake::HemisphereFrame(gbuffer.normal[p], p);
      int hidden = 0;
      for (const glm::vec3& local : hemisphere) {
        const glm::vec3 dir = frame * local;
        bool toward_object = false;
        for (const glm::vec4& s : spheres_) toward_object = toward_object || RayMeetsSphere(origin, dir, s);
        if (toward_object && objects_.Occluded(origin, dir) && !real_.Occluded(origin, dir)) ++hidden;
      }
      lost[i] = static_cast<float>(hidden) / static_cast<float>(hemisphere.size());
    }
  });
  for (size_t i = 0; i < near.size(); ++i) {
    if (lost[i] <= 0.0f) continue;
    Affected a;
    a.pixel = near[i];
    a.sky = gbuffer.sky_visibility[near[i]];
    a.sky_lost = std::min(lost[i], a.sky);
    affected_.push_back(a);
  }
}

bool ObjectShadows::SetSun(const glm::vec3& sun_dir) {
  const glm::vec3 sun = glm::normalize(sun_dir);
  if (has_sun_ && glm::dot(sun, sun_) > std::cos(glm::radians(0.05f))) return false;
  sun_ = sun, has_sun_ = true;
  // Keep the sky-loss pixels, drop the previous sun's shadow-only ones, then find this sun's.
  std::erase_if(affected_, [](const Affected& a) { return a.sky_lost <= 0.0f; });
  std::vector<uint8_t> listed(gbuffer_.point.size(), 0);
  for (const Affected& a : affected_) listed[a.pixel] = 1;
  std::vector<uint32_t> passing;  // facing the sun, sun ray through an object's sphere
  for (size_t p = 0; p < gbuffer_.point.size(); ++p) {
    if (gbuffer_.surface[p] == bake::kNoSurface || listed[p] || glm::dot(gbuffer_.normal[p], sun) <= 0.0f) continue;
    const glm::vec3 origin = gbuffer_.point[p] + options_.offset_m * gbuffer_.normal[p];
    for (const glm::vec4& s : spheres_) {
      if (RayMeetsSphere(origin, sun, s)) {
        passing.push_back(static_cast<uint32_t>(p));
        break;
      }
    }
  }
  for (const uint32_t p : passing) affected_.push_back(Affected{p});
  tbb::parallel_for(tbb::blocked_range<size_t>(0, affected_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Affected& a = affected_[i];
      const glm::vec3 n = gbuffer_.normal[a.pixel];
      const glm::vec3 origin = gbuffer_.point[a.pixel] + options_.offset_m * n;
      a.cos_sun = std::max(0.0f, glm::dot(n, sun));
      a.sun_real = a.cos_sun > 0.0f && !real_.Occluded(origin, sun) ? 1 : 0;
      a.sun_with = a.sun_real && !objects_.Occluded(origin, sun) ? 1 : 0;
    }
  });
  // Shadow-only pixels the objects do not shade after all are dropped; order by pixel.
  std::erase_if(affected_, [](const Affected& a) { return a.sky_lost <= 0.0f && a.sun_with == a.sun_real; });
  std::sort(affected_.begin(), affected_.end(), [](const Affected& a, const Affected& b) { return a.pixel < b.pixel; });
  return true;
}

namespace {

glm::vec3 RatioOf(const estimation::SunSky& light, float cos_sun, float sky, float sky_lost, bool sun_real, bool sun_with) {
  glm::vec3 ratio(1.0f);
  for (int c = 0; c < 3; ++c) {
    const float e_sun = static_cast<float>(light.sun_rgb[c]) * cos_sun, e_sky = static_cast<float>(light.sky_rgb[c]);
    const float before = e_sky * sky + (sun_real ? e_sun : 0.0f);
    const float after = e_sky * (sky - sky_lost) + (sun_with ? e_sun : 0.0f);
    if (before > 1e-12f) ratio[c] = std::max(0.0f, after) / before;
  }
  return ratio;
}

}  // namespace

void ObjectShadows::Apply(const estimation::SunSky& light, float* rgb) const {
  for (const Affected& a : affected_) {
    const glm::vec3 r = RatioOf(light, a.cos_sun, a.sky, a.sky_lost, a.sun_real, a.sun_with);
    float* p = rgb + 3 * static_cast<size_t>(a.pixel);
    p[0] *= r.x, p[1] *= r.y, p[2] *= r.z;
  }
}

glm::vec3 ObjectShadows::Ratio(const estimation::SunSky& light, size_t pixel) const {
  const auto it = std::lower_bound(affected_.begin(), affected_.end(), pixel,
                                   [](const Affected& a, size_t p) { return a.pixel < p; });
  if (it == affected_.end() || it->pixel != pixel) return glm::vec3(1.0f);
  return RatioOf(light, it->cos_sun, it->sky, it->sky_lost, it->sun_real, it->sun_with);
}

size_t ObjectShadows::SkyLossPixels() const {
  return static_cast<size_t>(std::count_if(affected_.begin(), affected_.end(), [](const Affected& a) { return a.sky_lost > 0.0f; }));
}

size_t ObjectShadows::ShadowPixels() const {
  return static_cast<size_t>(std::count_if(affected_.begin(), affected_.end(), [](const Affected& a) { return a.sun_with != a.sun_real; }));
}

}  // namespace daylit::relight
