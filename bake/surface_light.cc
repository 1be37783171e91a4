#include "bake/surface_light.h"

#include "base/options_check.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include <glm/gtc/constants.hpp>

#include "bake/sampling.h"
#include "base/latlong.h"

namespace daylit::bake {
namespace {

constexpr size_t kGrain = 64;  // points per task

// E_sun·s·max(0, n·l) at a point with unit normal `normal`, the shadow ray leaving from
// `origin` (the point, already moved off its surface).
glm::vec3 DirectSun(const CaptureScene& capture, const glm::vec3& origin, const glm::vec3& normal) {
  const CaptureSun& sun = capture.sun;
  const float cos_sun = glm::dot(normal, sun.dir);
  if (!sun.above_horizon || cos_sun <= 0.0f || capture.caster->Occluded(origin, sun.dir)) return glm::vec3(0.0f);
  return sun.dni_rgb * cos_sun;
}

bool IsHidden(const CaptureScene& capture, const glm::vec3& y, const scene::RayHit& hit) {
  const glm::vec3 toward = y - capture.capture_position;
  const size_t texel = static_cast<size_t>(LatLongTexel(glm::dvec3(toward), capture.env->width, capture.env->height));
  return !CaptureSees(toward, hit.normal, hit.surface, (*capture.env_distance)[texel], (*capture.env_surface)[texel],
                      (*capture.env_normal)[texel], capture.env->height);
}

// Radiance of model point y (hit by a ray, with `hit`'s surface and normal) at capture time.
glm::vec3 RadianceAt(const CaptureScene& capture, const glm::vec3& y, const scene::RayHit& hit) {
  const glm::vec3 toward = y - capture.capture_position;
  const int texel = LatLongTexel(glm::dvec3(toward), capture.env->width, capture.env->height);
  const glm::vec3 texel_radiance = TexelRadiance(*capture.env, texel);
  if (capture.hidden == nullptr || capture.env_distance == nullptr) return texel_radiance;
  if (CaptureSees(toward, hit.normal, hit.surface, (*capture.env_distance)[static_cast<size_t>(texel)],
                  (*capture.env_surface)[static_cast<size_t>(texel)], (*capture.env_normal)[static_cast<size_t>(texel)],
                  capture.env->height)) {
    return texel_radiance;
  }
  const glm::vec3 e = capture.hidden->IndirectAt(y, hit.normal, hit.surface) +
                      DirectSun(capture, y + 2e-3f * hit.normal, hit.normal);
  return capture.hidden->albedo[hit.surface] * glm::one_over_pi<float>() * e;
}

}  // namespace

// A texel stands for y only if it shows a point this close to it: light under an overhang
// changes over a fraction of a metre, and a texel that grazes a roof's underside shows a point up
// to 1.6 m nearer its lit edge. Farther, y is hidden, and takes its cell's light.
constexpr float kMostSlack = 0.25f;

bool CaptureSees(const glm::vec3& toward, const glm::vec3& normal, uint32_t surface, float seen_distance,
                 uint32_t seen_surface, const glm::vec3& seen_normal, int env_height) {
  // The capture point sees y unless its own ray toward y stops clearly short of it. The texel's
  // ray can be up to a texel off y's direction; on y's own surface seen at a grazing angle that
  // moves its hit along the surface by distance·angle / cos, so the slack grows with obliquity.
  const float distance = glm::length(toward);
  // The side of y that is looked at must face the capture point: from behind its plane the
  // capture point sees another side (a slab's sunlit top, seen from a wall above it, is its
  // underside from a capture point below it), however close the texel's hit is.
  if (glm::dot(normal, toward) >= 0.0f) return false;
  const float texel_angle = 2.0f * glm::pi<float>() / static_cast<float>(env_height);
  const bool same_surface = seen_surface == surface && glm::dot(seen_normal, normal) > 0.9f;
  const float obliquity = std::max(0.05f, std::abs(glm::dot(normal, toward / distance)));
  const float slack = std::min(kMostSlack, 0.05f + distance * texel_angle * (same_surface ? 2.0f / obliquity : 2.0f));
  return seen_distance >= 0.0f && seen_distance >= distance - slack;
}

void IntegrateCaptureIrradiance(const CaptureScene& capture, const RayOptions& options, const glm::vec3* points,
                                const glm::vec3* normals, size_t count, float* sky_visibility, glm::vec3* irradiance,
                                glm::vec3* direct, Progress* progress) {
  const std::vector<glm::vec3> hemisphere = CosineHemisphere(options.hemisphere_rays);
  const float inv_rays = 1.0f / static_cast<float>(hemisphere.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 origin = points[i] + options.offset_m * normals[i];
      const glm::mat3 frame = HemisphereFrame(normals[i], static_cast<uint32_t>(i));
      glm::vec3 sum(0.0f);
      int sky = 0;
      for (const glm::vec3& local : hemisphere) {
        const glm::vec3 dir = frame * local;
        const scene::RayHit hit = capture.caster->Intersect(origin, dir);
        if (!hit.IsHit()) {
          sum += Lookup(*capture.sky, dir);
          ++sky;
        } else {
          sum += RadianceAt(capture, origin + hit.t * dir, hit);
        }
      }
      const glm::vec3 sun_part = DirectSun(capture, origin, normals[i]);
      sky_visibility[i] = static_cast<float>(sky) * inv_rays;
      irradiance[i] = glm::pi<float>() * inv_rays * sum + sun_part;
      if (direct != nullptr) direct[i] = sun_part;
    }
    if (progress != nullptr) progress->Advance(range.size());
  });
}

uint64_t HiddenSurfaceModel::CellKey(const glm::vec3& y, const glm::vec3& normal, uint32_t surface) {
  return SurfaceCellKey(y, normal, surface, kCellSize);
}

glm::vec3 HiddenSurfaceModel::IndirectAt(const glm::vec3& y, const glm::vec3& normal, uint32_t surface) const {
  const auto it = cell_indirect.find(CellKey(y, normal, surface));
  return it != cell_indirect.end() ? it->second : indirect[surface];
}

void GatherHiddenCells(const CaptureScene& capture, const RayOptions& options, const glm::vec3* points,
                       const glm::vec3* normals, size_t count, HiddenSurfaceModel* hidden, Progress* progress) {
  struct Found {
    uint64_t order;  // point · rays + ray: the first finder wins, whatever the threads did
    glm::vec3 point, normal;
    uint32_t surface;
  };
  const std::vector<glm::vec3> hemisphere = CosineHemisphere(options.hemisphere_rays);
  tbb::enumerable_thread_specific<std::unordered_map<uint64_t, Found>> found_by_thread;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    std::unordered_map<uint64_t, Found>& found = found_by_thread.local();
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 origin = points[i] + options.offset_m * normals[i];
      const glm::mat3 frame = HemisphereFrame(normals[i], static_cast<uint32_t>(i));
      for (size_t r = 0; r < hemisphere.size(); ++r) {
        const glm::vec3 dir = frame * hemisphere[r];
        const scene::RayHit hit = capture.caster->Intersect(origin, dir);
        if (!hit.IsHit()) continue;
        const glm::vec3 y = origin + hit.t * dir;
        if (!IsHidden(capture, y, hit)) continue;
        const Found f{i * hemisphere.size() + r, y, hit.normal, hit.surface};
        const auto [it, inserted] = found.emplace(HiddenSurfaceModel::CellKey(y, hit.normal, hit.surface), f);
        if (!inserted && f.order < it->second.order) it->second = f;
      }
    }
    if (progress != nullptr) progress->Advance(range.size());
  });
  std::unordered_map<uint64_t, Found> cells;
  for (const auto& found : found_by_thread) {
    for (const auto& [key, f] : found) {
      const auto [it, inserted] = cells.emplace(key, f);
      if (!inserted && f.order < it->second.order) it->second = f;
    }
  }
  std::vector<std::pair<uint64_t, Found>> list(cells.begin(), cells.end());
  std::vector<glm::vec3> indirect(list.size());
  const float inv_rays = 1.0f / static_cast<float>(hemisphere.size());
  // Twice: first the hidden points a cell sees take their surface's indirect light, then their
  // own cells' from the first pass. Under an arcade the hidden points are mostly other hidden
  // cells (the roof's underside sees the wall behind the pillars and the floor beneath it), and a
  // surface's median, taken over its open and lit parts, gave them a third too much.
  for (int pass = 0; pass < 2; ++pass) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, list.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t k = range.begin(); k != range.end(); ++k) {
        const Found& f = list[k].second;
        const glm::vec3 origin =
            SurfaceCellOrigin(f.point, f.normal, HiddenSurfaceModel::kCellSize) + options.offset_m * f.normal;
        const glm::mat3 frame = HemisphereFrame(f.normal, static_cast<uint32_t>(list[k].first));
        glm::vec3 sum(0.0f);
        for (const glm::vec3& local : hemisphere) {
          const glm::vec3 dir = frame * local;
          const scene::RayHit hit = capture.caster->Intersect(origin, dir);
          sum += hit.IsHit() ? RadianceAt(capture, origin + hit.t * dir, hit) : Lookup(*capture.sky, dir);
        }
        indirect[k] = glm::pi<float>() * inv_rays * sum;
      }
    });
    for (size_t k = 0; k < list.size(); ++k) hidden->cell_indirect[list[k].first] = indirect[k];
  }
}

void SkyVisibility(const scene::RayCaster& caster, const RayOptions& options, const glm::vec3* points,
                   const glm::vec3* normals, size_t count, float* sky_visibility, Progress* progress) {
  const std::vector<glm::vec3> hemisphere = CosineHemisphere(options.hemisphere_rays);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const glm::vec3 origin = points[i] + options.offset_m * normals[i];
      const glm::mat3 frame = HemisphereFrame(normals[i], static_cast<uint32_t>(i));
      int sky = 0;
      for (const glm::vec3& local : hemisphere) sky += caster.Occluded(origin, frame * local) ? 0 : 1;
      sky_visibility[i] = static_cast<float>(sky) / static_cast<float>(hemisphere.size());
    }
    if (progress != nullptr) progress->Advance(range.size());
  });
}

namespace {

// The points of `indices` (or all `count` when null) facing `sun_dir`, block by block on both
// cores, their shadow rays traced together as packets: lit(i, cos_sun) for those it reaches,
// unlit(i) for the others.
template <typename Lit, typename Unlit>
void ForSunRays(const scene::RayCaster& caster, const glm::vec3* points, const glm::vec3* normals, const uint32_t* indices,
                size_t count, const glm::vec3& sun_dir, float offset_m, Lit lit, Unlit unlit) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 2048), [&](const tbb::blocked_range<size_t>& range) {
    thread_local std::vector<glm::vec3> origins;
    thread_local std::vector<size_t> facing;  // point indices
    thread_local std::vector<uint8_t> occluded;
    origins.clear(), facing.clear();
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const size_t i = indices != nullptr ? indices[k] : k;
      if (glm::dot(normals[i], sun_dir) > 0.0f) {
        origins.push_back(points[i] + offset_m * normals[i]);
        facing.push_back(i);
      } else {
        unlit(i);
      }
    }
    occluded.resize(origins.size());
    caster.OccludedAlong(origins.data(), origins.size(), sun_dir, 0.0f, occluded.data());
    for (size_t j = 0; j < facing.size(); ++j) {
      const size_t i = facing[j];
      if (occluded[j]) {
        unlit(i);
      } else {
        lit(i, glm::dot(normals[i], sun_dir));
      }
    }
  });
}

}  // namespace

void SunVisibility(const scene::RayCaster& caster, const glm::vec3* points, const glm::vec3* normals, size_t count,
                   const glm::vec3& sun_dir, float offset_m, uint8_t* visible) {
  ForSunRays(
      caster, points, normals, nullptr, count, sun_dir, offset_m, [&](size_t i, float) { visible[i] = 1; },
      [&](size_t i) { visible[i] = 0; });
}

void DirectSun(const scene::RayCaster& caster, const glm::vec3* points, const glm::vec3* normals,
               const std::vector<uint32_t>& indices, const glm::vec3& sun_dir, float offset_m, float* direct,
               uint8_t* visible) {
  if (sun_dir.z <= 0.0f) {  // night
    for (const uint32_t i : indices) {
      direct[i] = 0.0f;
      if (visible != nullptr) visible[i] = 0;
    }
    return;
  }
  ForSunRays(
      caster, points, normals, indices.data(), indices.size(), sun_dir, offset_m,
      [&](size_t i, float cos_sun) {
        direct[i] = cos_sun;
        if (visible != nullptr) visible[i] = 1;
      },
      [&](size_t i) {
        direct[i] = 0.0f;
        if (visible != nullptr) visible[i] = 0;
      });
}

std::string RayOptions::Check() const {
  return FirstProblem({InClosed("hemisphere_rays", hemisphere_rays, 16, 65536), InOpenClosed("offset_m", offset_m, 0.0f, 0.1f)});
}

}  // namespace daylit::bake
