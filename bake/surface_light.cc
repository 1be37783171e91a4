#include "bake/surface_light.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include <glm/gtc/constants.hpp>

#include "bake/sampling.h"

namespace daylit::bake {
namespace {

constexpr size_t kGrain = 64;  // points per task

// The hemisphere pattern turned to the normal and rotated about it by a per-point angle.
glm::mat3 FrameFor(const glm::vec3& normal, size_t index) {
  const float angle = RotationOf(static_cast<uint32_t>(index));
  const float c = std::cos(angle), s = std::sin(angle);
  const glm::mat3 spin(glm::vec3(c, s, 0.0f), glm::vec3(-s, c, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f));
  return BasisAround(normal) * spin;
}

}  // namespace

void IntegrateCaptureIrradiance(const CaptureScene& capture, const RayOptions& options, const glm::vec3* points,
                                const glm::vec3* normals, size_t count, float* sky_visibility, glm::vec3* irradiance,
                                Progress* progress) {
  const std::vector<glm::vec3> hemisphere = CosineHemisphere(options.hemisphere_rays);
  const float inv_rays = 1.0f / static_cast<float>(hemisphere.size());
  const CaptureSun& sun = capture.sun;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 origin = points[i] + options.offset_m * normals[i];
      const glm::mat3 frame = FrameFor(normals[i], i);
      glm::vec3 sum(0.0f);
      int sky = 0;
      for (const glm::vec3& local : hemisphere) {
        const glm::vec3 dir = frame * local;
        const scene::RayHit hit = capture.caster->Intersect(origin, dir);
        if (!hit.IsHit()) {
          sum += Lookup(*capture.sky, dir);
          ++sky;
        } else {
          sum += Lookup(*capture.env, origin + hit.t * dir - capture.capture_position);
        }
      }
      glm::vec3 e = glm::pi<float>() * inv_rays * sum;
      const float cos_sun = glm::dot(normals[i], sun.dir);
      if (sun.above_horizon && cos_sun > 0.0f && !capture.caster->Occluded(origin, sun.dir)) e += sun.dni_rgb * cos_sun;
      sky_visibility[i] = static_cast<float>(sky) * inv_rays;
      irradiance[i] = e;
    }
    if (progress != nullptr) progress->Advance(range.size());
  });
}

void SkyVisibility(const scene::RayCaster& caster, const RayOptions& options, const glm::vec3* points,
                   const glm::vec3* normals, size_t count, float* sky_visibility, Progress* progress) {
  const std::vector<glm::vec3> hemisphere = CosineHemisphere(options.hemisphere_rays);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 origin = points[i] + options.offset_m * normals[i];
      const glm::mat3 frame = FrameFor(normals[i], i);
      int sky = 0;
      for (const glm::vec3& local : hemisphere) sky += caster.Occluded(origin, frame * local) ? 0 : 1;
      sky_visibility[i] = static_cast<float>(sky) / static_cast<float>(hemisphere.size());
    }
    if (progress != nullptr) progress->Advance(range.size());
  });
}

void SunVisibility(const scene::RayCaster& caster, const glm::vec3* points, const glm::vec3* normals, size_t count,
                   const glm::vec3& sun_dir, float offset_m, uint8_t* visible) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 2048), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      visible[i] = glm::dot(normals[i], sun_dir) > 0.0f &&
                           !caster.Occluded(points[i] + offset_m * normals[i], sun_dir)
                       ? 1
                       : 0;
    }
  });
}

}  // namespace daylit::bake
