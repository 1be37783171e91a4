#include "composite/object_bounce.h"

#include "base/check.h"

#include "base/options_check.h"

#include <cmath>

#include <tbb/parallel_for.h>

#include "bake/sampling.h"
#include "scene/object_mesh.h"

namespace daylit::composite {

namespace {

std::vector<glm::vec3> ShadingMeshes(const scene::Scene& scene, bool normals) {
  std::vector<glm::vec3> out;
  for (const scene::VirtualObject& o : scene.objects) {
    const scene::Mesh m = scene::ShadingMesh(o, scene);
    const std::vector<glm::vec3>& v = normals ? m.normals : m.positions;
    out.insert(out.end(), v.begin(), v.end());
  }
  return out;
}

}  // namespace

ObjectBounce::ObjectBounce(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
                           const scene::RayCaster& objects, const ObjectBounceOptions& options)
    : ObjectBounce(scene, bake, real, objects, ShadingMeshes(scene, false), ShadingMeshes(scene, true), options) {}

ObjectBounce::ObjectBounce(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
                           const scene::RayCaster& objects, const std::vector<glm::vec3>& positions,
                           const std::vector<glm::vec3>& normals, const ObjectBounceOptions& options)
    : real_(real), objects_(objects), options_(options) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  DAYLIT_CHECK(positions.size() == normals.size(), "{} points and {} normals", positions.size(), normals.size());
  // Albedo per real surface, by name from the bake's table.
  std::vector<glm::vec3> albedo(scene.model.surface_names.size(), glm::vec3(0.0f));
  for (const bake::SurfaceAlbedo& a : bake.albedo_table) {
    const int s = scene.model.SurfaceIndex(a.surface);
    if (s >= 0) albedo[static_cast<size_t>(s)] = a.albedo;
  }
  sun_loss_.assign(positions.size(), glm::vec3(0.0f));
  sky_loss_.assign(positions.size(), glm::vec3(0.0f));
  // The real points each vertex sees (before any object or the sky).
  const std::vector<glm::vec3> hemisphere = bake::CosineHemisphere(options_.rays);
  std::vector<std::vector<Seen>> per_vertex(positions.size());
  const float weight = 1.0f / static_cast<float>(hemisphere.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, positions.size(), 64), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t v = range.begin(); v != range.end(); ++v) {
      const glm::vec3 origin = positions[v] + options_.offset_m * normals[v];
      const glm::mat3 frame = bake::HemisphereFrame(normals[v], static_cast<uint32_t>(v));
      for (const glm::vec3& local : hemisphere) {
        const glm::vec3 dir = frame * local;
        const scene::RayHit hit = real_.Intersect(origin, dir);
        if (!hit.IsHit() || objects_.Occluded(origin, dir, 0.0f, hit.t)) continue;
        per_vertex[v].push_back({static_cast<uint32_t>(v), origin + hit.t * dir, hit.normal, weight * albedo[hit.surface]});
      }
    }
  });
  for (auto& list : per_vertex) seen_.insert(seen_.end(), list.begin(), list.end());
  // The sky the objects hide from each seen point: once.
  const std::vector<glm::vec3> sky = bake::CosineHemisphere(options_.sky_rays);
  std::vector<float> hidden(seen_.size(), 0.0f);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, seen_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 origin = seen_[i].point + options_.offset_m * seen_[i].normal;
      const glm::mat3 frame = bake::HemisphereFrame(seen_[i].normal, static_cast<uint32_t>(i));
      int n = 0;
      for (const glm::vec3& local : sky) {
        const glm::vec3 dir = frame * local;
        if (objects_.Occluded(origin, dir) && !real_.Occluded(origin, dir)) ++n;
      }
      hidden[i] = static_cast<float>(n) / static_cast<float>(sky.size());
    }
  });
  for (size_t i = 0; i < seen_.size(); ++i) sky_loss_[seen_[i].vertex] += seen_[i].albedo_over_n * hidden[i];
}

bool ObjectBounce::SetSun(const glm::vec3& sun_dir) {
  const glm::vec3 sun = glm::normalize(sun_dir);
  if (has_sun_ && sun == sun_) return false;  // the caller decides when it moved (scene::SunTracker)
  sun_ = sun, has_sun_ = true;
  std::vector<float> lost(seen_.size(), 0.0f);  // cos_y (s_y − s'_y)
  tbb::parallel_for(tbb::blocked_range<size_t>(0, seen_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const float cos_y = glm::dot(seen_[i].normal, sun);
      if (cos_y <= 0.0f) continue;
      const glm::vec3 origin = seen_[i].point + options_.offset_m * seen_[i].normal;
      if (!real_.Occluded(origin, sun) && objects_.Occluded(origin, sun)) lost[i] = cos_y;
    }
  });
  std::fill(sun_loss_.begin(), sun_loss_.end(), glm::vec3(0.0f));
  for (size_t i = 0; i < seen_.size(); ++i) sun_loss_[seen_[i].vertex] += seen_[i].albedo_over_n * lost[i];
  return true;
}

std::string ObjectBounceOptions::Check() const {
  return FirstProblem({InClosed("rays", rays, 1, 65536), InClosed("sky_rays", sky_rays, 1, 65536),
                       InOpenClosed("offset_m", offset_m, 0.0f, 0.1f)});
}

}  // namespace daylit::composite
