#include "composite/object_shadows.h"

#include "base/check.h"

#include "base/options_check.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <tbb/parallel_for.h>

#include <glm/gtc/constants.hpp>

#include "bake/parallax.h"
#include "bake/sampling.h"
#include "base/latlong.h"

namespace daylit::composite {
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

ObjectShadows::ObjectShadows(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
                             const scene::RayCaster& objects, const ObjectShadowOptions& options)
    : gbuffer_(bake.camera), real_(real), objects_(objects), options_(options) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  const bake::CameraGBuffer& gbuffer = bake.camera;
  // Bounding spheres from the meshes themselves (surface i of the objects' model is object i).
  std::vector<glm::vec3> lo, hi;
  objects.model().SurfaceBounds(&lo, &hi);
  for (size_t o = 0; o < lo.size(); ++o) {
    if (lo[o].x > hi[o].x) continue;
    const glm::vec3 centre = 0.5f * (lo[o] + hi[o]);
    spheres_.emplace_back(centre, 0.5f * glm::length(hi[o] - lo[o]) + 1e-3f);
  }
  // The covered directions, once: the pixels near an object cast cosine-weighted rays; a ray that
  // meets an object before the real model carries light the object now blocks (sky, or the real
  // surface behind it).
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
  const glm::vec3 capture = scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f);
  const int env_w = bake.env.width, env_h = bake.env.height;
  std::vector<Affected> found(near.size());
  std::vector<std::vector<uint32_t>> texels(near.size()), sides(near.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, near.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const uint32_t p = near[i];
      const glm::vec3 origin = gbuffer.point[p] + options_.offset_m * gbuffer.normal[p];
      const glm::mat3 frame = bake::HemisphereFrame(gbuffer.normal[p], p);
      Affected& a = found[i];
      a.pixel = p;
      int sky = 0;
      for (const glm::vec3& local : hemisphere) {
        const glm::vec3 dir = frame * local;
        bool toward_object = false;
        for (const glm::vec4& s : spheres_) toward_object = toward_object || RayMeetsSphere(origin, dir, s);
        if (!toward_object) continue;
        const scene::RayHit object = objects_.Intersect(origin, dir);
        if (!object.IsHit() || real_.Occluded(origin, dir, 0.0f, object.t)) continue;  // none, or a wall in front
        // What the object hides: the real point behind it, seen from the capture position, or the
        // sky in that direction (bake/parallax.h).
        const scene::RayHit behind = real_.Intersect(origin, dir, object.t);
        texels[i].push_back(bake::ParallaxTexel(origin, dir, behind, capture, env_w, env_h));
        sides[i].push_back(2 * object.triangle + (object.back_face ? 1u : 0u));
        sky += behind.IsHit() ? 0 : 1;
      }
      a.sky_lost = static_cast<float>(sky) / static_cast<float>(hemisphere.size());
      a.covers = !texels[i].empty();
    }
  });
  ray_weight_ = glm::pi<float>() / static_cast<float>(hemisphere.size());
  for (size_t i = 0; i < near.size(); ++i) {
    if (!found[i].covers) continue;
    found[i].first = static_cast<uint32_t>(covered_texels_.size());
    found[i].count = static_cast<uint32_t>(texels[i].size());
    covered_texels_.insert(covered_texels_.end(), texels[i].begin(), texels[i].end());
    covered_sides_.insert(covered_sides_.end(), sides[i].begin(), sides[i].end());
    FindNeighbours(&found[i]);
    affected_.push_back(found[i]);
  }
  // The sides met, and each covered ray's side as an index among them.
  reflecting_sides_ = covered_sides_;
  std::sort(reflecting_sides_.begin(), reflecting_sides_.end());
  reflecting_sides_.erase(std::unique(reflecting_sides_.begin(), reflecting_sides_.end()), reflecting_sides_.end());
  for (uint32_t& side : covered_sides_) {
    side = static_cast<uint32_t>(std::lower_bound(reflecting_sides_.begin(), reflecting_sides_.end(), side) - reflecting_sides_.begin());
  }
  pi_over_albedo_.resize(pixels);
  for (size_t p = 0; p < pixels; ++p) pi_over_albedo_[p] = glm::pi<float>() / glm::max(gbuffer.albedo[p], glm::vec3(1e-3f));
}

constexpr uint32_t kAllNeighbours = (1u << 25) - 1;
// The most a pixel can brighten by what the objects reflect onto it: a bound against a B read
// low from a dark, noisy neighbourhood, far above what a diffuse object gives back.
constexpr float kMostGain = 2.0f;

ObjectShadows::Footprint ObjectShadows::FootprintOf(uint32_t pixel) const {
  // The surface's step per pixel along x and y, from the G-buffer's neighbours on the same plane
  // (a central difference, else one-sided; none at a lone pixel).
  const int w = gbuffer_.width, h = gbuffer_.height;
  const int x = static_cast<int>(pixel % static_cast<uint32_t>(w)), y = static_cast<int>(pixel / static_cast<uint32_t>(w));
  const glm::vec3 p = gbuffer_.point[pixel], n = gbuffer_.normal[pixel];
  const auto on_plane = [&](int u, int v, glm::vec3* q) {
    if (u < 0 || v < 0 || u >= w || v >= h) return false;
    const size_t i = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
    if (gbuffer_.surface[i] != gbuffer_.surface[pixel] || glm::dot(gbuffer_.normal[i], n) < 0.999f) return false;
    *q = gbuffer_.point[i];
    return std::abs(glm::dot(*q - p, n)) < 1e-3f;
  };
  const auto step = [&](int du, int dv) {
    glm::vec3 a(0.0f), b(0.0f);
    const bool ahead = on_plane(x + du, y + dv, &a), behind = on_plane(x - du, y - dv, &b);
    if (ahead && behind) return 0.5f * (a - b);
    if (ahead) return a - p;
    if (behind) return p - b;
    return glm::vec3(0.0f);
  };
  return {step(1, 0), step(0, 1)};
}

void ObjectShadows::FindNeighbours(Affected* a) const {
  const int w = gbuffer_.width, h = gbuffer_.height;
  const int x = static_cast<int>(a->pixel % static_cast<uint32_t>(w)), y = static_cast<int>(a->pixel / static_cast<uint32_t>(w));
  a->neighbours = 0;
  for (int dy = -2; dy <= 2; ++dy) {
    for (int dx = -2; dx <= 2; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= w || v >= h) continue;
      const size_t q = static_cast<size_t>(v) * static_cast<size_t>(w) + static_cast<size_t>(u);
      if (gbuffer_.surface[q] == gbuffer_.surface[a->pixel]) a->neighbours |= 1u << ((dy + 2) * 5 + dx + 2);
    }
  }
}

void ObjectShadows::SetEnvBasis(const relight::EnvBasis& basis) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, affected_.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Affected& a = affected_[i];
      glm::vec3 sun(0.0f), clear(0.0f), overcast(0.0f);
      for (uint32_t k = a.first; k < a.first + a.count; ++k) {
        const uint32_t t = covered_texels_[k];
        sun += basis.sun[t], clear += basis.clear[t], overcast += basis.overcast[t];
      }
      a.covered_sun = ray_weight_ * sun, a.covered_clear = ray_weight_ * clear, a.covered_overcast = ray_weight_ * overcast;
    }
  });
  has_basis_ = true;
  loss_ready_ = false;
}

void ObjectShadows::SetObjectRadiance(const std::array<std::vector<glm::vec3>, 3>& radiance) {
  for (const std::vector<glm::vec3>& part : radiance) {
    DAYLIT_CHECK(part.size() == reflecting_sides_.size(), "radiance for {} sides, not {}", part.size(), reflecting_sides_.size());
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, affected_.size(), 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Affected& a = affected_[i];
      glm::vec3 sun(0.0f), clear(0.0f), overcast(0.0f);
      for (uint32_t k = a.first; k < a.first + a.count; ++k) {
        const uint32_t side = covered_sides_[k];
        sun += radiance[0][side], clear += radiance[1][side], overcast += radiance[2][side];
      }
      a.reflected_sun = ray_weight_ * sun, a.reflected_clear = ray_weight_ * clear, a.reflected_overcast = ray_weight_ * overcast;
    }
  });
  loss_ready_ = false;
}

bool ObjectShadows::SetSun(const glm::vec3& sun_dir) {
  const glm::vec3 sun = glm::normalize(sun_dir);
  if (has_sun_ && sun == sun_) return false;  // the caller decides when it moved (scene::SunTracker)
  sun_ = sun, has_sun_ = true;
  // Directions over the sun's disc (radius 0.2665°), a Fibonacci spiral of equal areas, each with
  // a place in the pixel (a stratified grid, visited in a scrambled order so that the disc's
  // rings and the pixel's rows do not line up).
  disc_.clear();
  jitter_.clear();
  const int grid = static_cast<int>(std::ceil(std::sqrt(static_cast<float>(options_.sun_rays))));
  const glm::mat3 basis = bake::BasisAround(sun);
  const float radius = std::tan(glm::radians(0.2665f));
  for (int k = 0; k < options_.sun_rays; ++k) {
    const float r = radius * std::sqrt((static_cast<float>(k) + 0.5f) / static_cast<float>(options_.sun_rays));
    const float phi = 2.39996323f * static_cast<float>(k);
    disc_.push_back(glm::normalize(sun + r * (std::cos(phi) * basis[0] + std::sin(phi) * basis[1])));
    const int cell = (k * 7 + 3) % (grid * grid);
    jitter_.emplace_back((static_cast<float>(cell % grid) + 0.5f) / static_cast<float>(grid) - 0.5f,
                         (static_cast<float>(cell / grid) + 0.5f) / static_cast<float>(grid) - 0.5f);
  }
  // Keep the sky-loss pixels, drop the previous sun's shadow-only ones, then find this sun's.
  std::erase_if(affected_, [](const Affected& a) { return !a.covers; });
  std::vector<uint8_t> listed(gbuffer_.point.size(), 0);
  for (const Affected& a : affected_) listed[a.pixel] = 1;
  // Only a point whose sun rays can pass an object's bounding sphere (widened by more than the
  // disc's radius) can lose sun to it.
  const auto sun_may_meet_object = [&](const glm::vec3& origin) {
    for (const glm::vec4& s : spheres_) {
      if (RayMeetsSphere(origin, sun, glm::vec4(glm::vec3(s), s.w + 0.01f * glm::distance(origin, glm::vec3(s))))) return true;
    }
    return false;
  };
  std::vector<uint32_t> passing;  // not listed yet, facing the sun, sun ray through an object's sphere
  for (size_t p = 0; p < gbuffer_.point.size(); ++p) {
    if (gbuffer_.surface[p] == bake::kNoSurface || listed[p] || glm::dot(gbuffer_.normal[p], sun) <= 0.0f) continue;
    if (sun_may_meet_object(gbuffer_.point[p] + options_.offset_m * gbuffer_.normal[p])) passing.push_back(static_cast<uint32_t>(p));
  }
  for (const uint32_t p : passing) {
    affected_.push_back(Affected{p});
    FindNeighbours(&affected_.back());
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, affected_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Affected& a = affected_[i];
      const glm::vec3 n = gbuffer_.normal[a.pixel];
      const glm::vec3 origin = gbuffer_.point[a.pixel] + options_.offset_m * n;
      a.cos_sun = std::max(0.0f, glm::dot(n, sun));
      // The sun is a disc: the share of it the objects newly hide gives the penumbrae. A ray
      // counts when an object stops it and the real model does not (no double darkening); the
      // objects' few triangles are asked first. Each ray leaves from another point of the
      // pixel's footprint, so that the share is the pixel's, as a camera integrates it: an edge
      // sampled at pixel centres only is a staircase of full and no shadow, each pixel up to half
      // a pixel's light off (courtyard-a's sunny frames: most of the shadows' error).
      int lost = 0;
      if (a.cos_sun > 0.0f && sun_may_meet_object(origin)) {
        const Footprint f = FootprintOf(a.pixel);
        for (size_t k = 0; k < disc_.size(); ++k) {
          const glm::vec2 j = jitter_[k];
          const glm::vec3 from = origin + j.x * f.dx + j.y * f.dy;
          lost += objects_.Occluded(from, disc_[k]) && !real_.Occluded(from, disc_[k]) ? 1 : 0;
        }
      }
      a.sun_lost = static_cast<float>(lost) / static_cast<float>(disc_.size());
    }
  });
  // Shadow-only pixels the objects do not shade after all are dropped; order by pixel.
  std::erase_if(affected_, [](const Affected& a) { return !a.covers && a.sun_lost == 0.0f; });
  std::sort(affected_.begin(), affected_.end(), [](const Affected& a, const Affected& b) { return a.pixel < b.pixel; });
  loss_ready_ = false;
  return true;
}

void ObjectShadows::PrepareLoss() {
  loss_.resize(affected_.size());
  for (size_t i = 0; i < affected_.size(); ++i) {
    const Affected& a = affected_[i];
    Loss& l = loss_[i];
    l.pixel = a.pixel, l.neighbours = a.neighbours;
    l.sun = glm::vec3(a.cos_sun * a.sun_lost), l.clear = l.overcast = glm::vec3(0.0f);
    if (!a.covers) continue;
    if (has_basis_) {
      l.sun += a.covered_sun, l.clear = a.covered_clear, l.overcast = a.covered_overcast;
    } else {
      l.clear = l.overcast = glm::vec3(a.sky_lost);  // E_sky · the covered share
    }
    // What the objects send back the same way (0 until SetObjectRadiance): the loss can turn into
    // a gain.
    l.sun -= a.reflected_sun, l.clear -= a.reflected_clear, l.overcast -= a.reflected_overcast;
  }
  const uint32_t w = static_cast<uint32_t>(gbuffer_.width);
  row_begin_.assign(static_cast<size_t>(gbuffer_.height) + 1, 0);
  for (const Affected& a : affected_) ++row_begin_[a.pixel / w + 1];
  for (size_t y = 1; y < row_begin_.size(); ++y) row_begin_[y] += row_begin_[y - 1];
  loss_ready_ = true;
}

void ObjectShadows::Apply(const estimation::SunSky& light, double overcast_share, float* rgb) {
  // B, the irradiance each pixel shows, from the frame itself: π·L/ρ, averaged over the pixel's
  // 5×5 neighbours on the same surface so that the camera's noise is not read as light. The
  // pixel then keeps the share (B − ΔB)/B of its own value, noise included.
  if (affected_.empty()) return;
  if (!loss_ready_) PrepareLoss();
  const estimation::LightParts e = estimation::SplitLight(light, overcast_share);
  const int w = gbuffer_.width, h = gbuffer_.height;
  const size_t row_floats = 3 * static_cast<size_t>(w);
  const int first_row = static_cast<int>(loss_.front().pixel / static_cast<uint32_t>(w));
  const int last_row = static_cast<int>(loss_.back().pixel / static_cast<uint32_t>(w));
  // π·L/ρ over the rows the affected pixels span and two more on each side, all read before any
  // pixel changes.
  const int y0 = std::max(0, first_row - 2), y1 = std::min(h, last_row + 3);
  const size_t offset = static_cast<size_t>(y0) * row_floats;
  weighted_.resize(static_cast<size_t>(y1 - y0) * row_floats);
  const float* weight = &pi_over_albedo_[0].x;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, weighted_.size(), 3 * 16384), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) weighted_[k] = rgb[offset + k] * weight[offset + k];
  });
  tbb::parallel_for(tbb::blocked_range<int>(first_row, last_row + 1, 8), [&](const tbb::blocked_range<int>& rows) {
    // Per row, the sums over five rows: where all 25 neighbours are on the pixel's surface (most
    // pixels), B is five of them.
    thread_local std::vector<float> column;
    column.resize(row_floats);
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const uint32_t i0 = row_begin_[static_cast<size_t>(y)], i1 = row_begin_[static_cast<size_t>(y) + 1];
      if (i0 == i1) continue;
      if (y >= 2 && y + 2 < h) {
        const float* r = weighted_.data() + static_cast<size_t>(y - 2 - y0) * row_floats;
        for (size_t k = 0; k < row_floats; ++k) {
          column[k] = r[k] + r[k + row_floats] + r[k + 2 * row_floats] + r[k + 3 * row_floats] + r[k + 4 * row_floats];
        }
      }
      for (uint32_t i = i0; i < i1; ++i) {
        const Loss& a = loss_[i];
        glm::vec3 b(0.0f);
        if (a.neighbours == kAllNeighbours) {
          const float* c = column.data() + 3 * static_cast<size_t>(a.pixel % static_cast<uint32_t>(w) - 2);
          for (int k = 0; k < 3; ++k) b[k] = (c[k] + c[k + 3] + c[k + 6] + c[k + 9] + c[k + 12]) * (1.0f / 25.0f);
        } else {
          int n = 0;
          for (uint32_t bits = a.neighbours; bits != 0; bits &= bits - 1) {
            const int bit = std::countr_zero(bits);
            const float* q = weighted_.data() + 3 * static_cast<size_t>(static_cast<ptrdiff_t>(a.pixel) + (bit / 5 - 2) * w + (bit % 5 - 2)) - offset;
            b += glm::vec3(q[0], q[1], q[2]);
            ++n;
          }
          b /= static_cast<float>(std::max(n, 1));
        }
        const glm::vec3 lost = estimation::Irradiance(e, a.sun, a.clear, a.overcast);
        float* p = rgb + 3 * static_cast<size_t>(a.pixel);
        for (int c = 0; c < 3; ++c) p[c] *= b[c] > 0.0f ? std::clamp(1.0f - lost[c] / b[c], 0.0f, kMostGain) : 1.0f;
      }
    }
  });
}

size_t ObjectShadows::SkyLossPixels() const {
  return static_cast<size_t>(std::count_if(affected_.begin(), affected_.end(), [](const Affected& a) { return a.covers; }));
}

size_t ObjectShadows::ShadowPixels() const {
  return static_cast<size_t>(std::count_if(affected_.begin(), affected_.end(), [](const Affected& a) { return a.sun_lost > 0.0f; }));
}

std::string ObjectShadowOptions::Check() const {
  return FirstProblem({InClosed("sky_rays", sky_rays, 16, 65536), InOpenClosed("reach_radii", reach_radii, 0.0f, 1000.0f),
                       InOpenClosed("offset_m", offset_m, 0.0f, 0.1f), InClosed("sun_rays", sun_rays, 1, 1024)});
}

}  // namespace daylit::composite
