#include "estimation/transfer.h"

#include "base/options_check.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtx/component_wise.hpp>

#include "bake/sampling.h"
#include "bake/surface_light.h"
#include "base/latlong.h"

namespace daylit::estimation {
namespace {

constexpr size_t kGrain = 32;  // pixels per task

HdrImage ImageOf(const bake::EnvMapMaps& env) {
  HdrImage image{env.width, env.height, std::vector<float>(env.radiance.size() * 3)};
  for (size_t t = 0; t < env.radiance.size(); ++t) {
    for (int c = 0; c < 3; ++c) image.rgb[t * 3 + static_cast<size_t>(c)] = env.radiance[t][c];
  }
  return image;
}

}  // namespace

std::string TransferOptions::Check() const {
  return FirstProblem({InClosed("rays", rays, 8, 65536), InClosed("hidden_sky_rays", hidden_sky_rays, 8, 65536),
                       InOpenClosed("offset_m", offset_m, 0.0f, 0.1f), InClosed("bounces", bounces, 1, 8)});
}

TransferPoints TransferPoints::Camera(const bake::CameraGBuffer& g) {
  return {g.point.data(), g.normal.data(), g.sky_visibility.data(), g.surface.data(), g.surface.size()};
}

TransferPoints TransferPoints::Env(const bake::EnvMapMaps& env) {
  return {env.point.data(), env.normal.data(), env.sky_visibility.data(), env.surface.data(), env.surface.size()};
}

LightTransfer::LightTransfer(const bake::SceneBake& bake, TransferPoints points, const glm::vec3& capture_position,
                             const scene::RayCaster& caster, TransferOptions options)
    : bake_(bake), points_(points), capture_position_(capture_position), caster_(caster), options_(options),
      hemisphere_(bake::CosineHemisphere(options.rays)),
      slot_(points.count, -1) {
  // The captured sky's shape only means something with the sun up at capture time: the (θ, γ)
  // table is relative to that sun.
  if (options.sky_distribution && bake.capture_sun.above_horizon && !bake.env.radiance.empty()) {
    std::vector<uint8_t> is_sky(bake.env.surface.size());
    for (size_t t = 0; t < is_sky.size(); ++t) is_sky[t] = bake.env.IsSky(t) ? 1 : 0;
    sky_ = bake::SkyDistribution(ImageOf(bake.env), is_sky, bake.capture_sun.dir);
  }
}

void LightTransfer::Trace(const std::vector<uint32_t>& pixels) {
  std::vector<uint32_t> fresh;
  for (const uint32_t p : pixels) {
    if (slot_[p] != -1) continue;
    slot_[p] = -2;  // listed once even if `pixels` repeats it
    fresh.push_back(p);
  }
  if (fresh.empty()) return;
  std::vector<TracedPixel> traced(fresh.size());
  TraceHemispheres(fresh, &traced);
  FillHiddenSkyVisibility(&traced);
  StorePaths(fresh, traced);
}

// Albedo and V of a bounce point: the env maps' where the capture point sees it; else the
// surface's median albedo, and V marked (−1) for FillHiddenSkyVisibility.
LightTransfer::Bounce LightTransfer::BounceAt(const glm::vec3& y, const scene::RayHit& hit) const {
  const bake::EnvMapMaps& env = bake_.env;
  Bounce b{y + options_.offset_m * hit.normal, hit.normal, glm::vec3(0.0f), -1.0f, hit.surface, 0};
  if (env.width > 0) {
    const glm::vec3 toward = y - capture_position_;
    const size_t texel = static_cast<size_t>(LatLongTexel(glm::dvec3(toward), env.width, env.height));
    const float seen = env.IsSky(texel) ? -1.0f : glm::length(env.point[texel] - capture_position_);
    if (bake::CaptureSees(toward, hit.normal, hit.surface, seen, env.surface[texel], env.height) &&
        glm::compMax(env.albedo[texel]) > 0.0f) {
      b.albedo = env.albedo[texel];
      b.sky_visibility = env.sky_visibility[texel];
      return b;
    }
  }
  b.albedo = hit.surface < bake_.albedo_table.size() ? bake_.albedo_table[hit.surface].albedo : glm::vec3(0.0f);
  return b;
}

void LightTransfer::TraceHemispheres(const std::vector<uint32_t>& fresh, std::vector<TracedPixel>* traced) const {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, fresh.size(), kGrain), [&](const tbb::blocked_range<size_t>& range) {
    thread_local std::vector<glm::vec3> dirs;
    thread_local std::vector<scene::RayHit> hits;
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const uint32_t p = fresh[k];
      TracedPixel& pixel = (*traced)[k];
      const glm::vec3 origin = points_.point[p] + options_.offset_m * points_.normal[p];
      const glm::mat3 frame = bake::HemisphereFrame(points_.normal[p], p);
      dirs.resize(hemisphere_.size()), hits.resize(hemisphere_.size());
      for (size_t r = 0; r < dirs.size(); ++r) dirs[r] = frame * hemisphere_[r];
      caster_.IntersectFrom(origin, dirs.data(), dirs.size(), 0.0f, hits.data());
      size_t low_sky = 0, blocked = 0, bounces = 0;  // sized once
      for (size_t r = 0; r < dirs.size(); ++r) {
        low_sky += !hits[r].IsHit() && dirs[r].z <= 0.0f, blocked += hits[r].IsHit() && dirs[r].z > 0.0f;
        bounces += hits[r].IsHit() && options_.interreflection;
      }
      pixel.low_sky.reserve(low_sky), pixel.blocked.reserve(blocked), pixel.bounces.reserve(bounces);
      for (size_t r = 0; r < dirs.size(); ++r) {
        const glm::vec3& dir = dirs[r];
        const scene::RayHit& hit = hits[r];
        if (!hit.IsHit()) {
          if (dir.z <= 0.0f) pixel.low_sky.push_back(dir);
          continue;
        }
        if (dir.z > 0.0f) pixel.blocked.push_back(dir);
        if (options_.interreflection) pixel.bounces.push_back(BounceAt(origin + hit.t * dir, hit));
      }
    }
  });
}

// V of the bounce points the capture point does not see (~5% of them on courtyard-a), by ray
// casting, once per 25 cm cell of a surface side: V is smooth, and tracing each point alone
// cost more rays than the primary ones.
void LightTransfer::FillHiddenSkyVisibility(std::vector<TracedPixel>* traced) {
  std::vector<Bounce*> hidden;
  for (TracedPixel& pixel : *traced) {
    for (Bounce& b : pixel.bounces) {
      if (b.sky_visibility < 0.0f) hidden.push_back(&b);
    }
  }
  std::vector<uint64_t> keys(hidden.size());
  std::vector<std::pair<uint64_t, Bounce*>> missing;
  for (size_t i = 0; i < hidden.size(); ++i) {
    keys[i] = CellOf(*hidden[i]);
    if (hidden_cells_.emplace(keys[i], -1.0f).second) missing.emplace_back(keys[i], hidden[i]);
  }
  const std::vector<glm::vec3> cell_hemisphere = bake::CosineHemisphere(options_.hidden_sky_rays);
  std::vector<float> cell_v(missing.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, missing.size(), kGrain), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      // The cell's centre dropped onto the bounce point's plane: the same point for every bounce
      // in the cell, so the result does not depend on which one came first.
      const Bounce& b = *missing[i].second;
      const glm::vec3 centre = (glm::floor(b.point / kCellSize) + 0.5f) * kCellSize;
      const glm::vec3 origin = centre - glm::dot(centre - b.point, b.normal) * b.normal;
      const glm::mat3 frame = bake::HemisphereFrame(b.normal, static_cast<uint32_t>(missing[i].first));
      int open = 0;
      for (const glm::vec3& d : cell_hemisphere) open += caster_.Occluded(origin, frame * d) ? 0 : 1;
      cell_v[i] = static_cast<float>(open) / static_cast<float>(cell_hemisphere.size());
    }
  });
  for (size_t i = 0; i < missing.size(); ++i) hidden_cells_[missing[i].first] = cell_v[i];
  for (size_t i = 0; i < hidden.size(); ++i) hidden[i]->sky_visibility = hidden_cells_[keys[i]];
}

void LightTransfer::StorePaths(const std::vector<uint32_t>& fresh, const std::vector<TracedPixel>& traced) {
  for (size_t k = 0; k < fresh.size(); ++k) {
    const TracedPixel& pixel = traced[k];
    Paths paths;
    paths.orientation = OrientationOf(points_.normal[fresh[k]]);
    paths.low_sky_begin = static_cast<uint32_t>(low_sky_.size());
    low_sky_.insert(low_sky_.end(), pixel.low_sky.begin(), pixel.low_sky.end());
    paths.low_sky_end = static_cast<uint32_t>(low_sky_.size());
    paths.blocked_begin = static_cast<uint32_t>(blocked_.size());
    blocked_.insert(blocked_.end(), pixel.blocked.begin(), pixel.blocked.end());
    paths.blocked_end = static_cast<uint32_t>(blocked_.size());
    paths.bounce_begin = static_cast<uint32_t>(bounces_.size());
    for (Bounce b : pixel.bounces) {
      b.orientation = OrientationOf(b.normal);
      bounces_.push_back(b);
    }
    paths.bounce_end = static_cast<uint32_t>(bounces_.size());
    slot_[fresh[k]] = static_cast<int32_t>(paths_.size());
    paths_.push_back(paths);
  }
}

uint64_t LightTransfer::CellOf(const Bounce& b) {
  const glm::ivec3 cell(glm::floor(b.point / kCellSize));
  const glm::ivec3 side(glm::round(b.normal * 8.0f));
  uint64_t key = b.surface;
  for (const int v : {cell.x, cell.y, cell.z}) key = key * 0x100000001b3ull ^ static_cast<uint64_t>(static_cast<uint32_t>(v));
  for (const int v : {side.x, side.y, side.z}) key = key * 0x100000001b3ull ^ static_cast<uint64_t>(v + 8);
  return key;
}

uint32_t LightTransfer::OrientationOf(const glm::vec3& normal) {
  const glm::ivec3 q(glm::round(normal * 64.0f));
  const uint64_t key = (static_cast<uint64_t>(q.x + 64) << 16) | (static_cast<uint64_t>(q.y + 64) << 8) |
                       static_cast<uint64_t>(q.z + 64);
  const auto [it, inserted] = orientation_of_.emplace(key, static_cast<uint32_t>(orientations_.size()));
  if (inserted) orientations_.push_back(glm::normalize(glm::vec3(q)));
  return it->second;
}

std::vector<LightTransfer::OpenSky> LightTransfer::OpenSkyIntegrals(const glm::vec3& sun_dir,
                                                                      const glm::vec3& inv_dhi) const {
  // Midpoint rule on a 1° × 2° grid of the upper hemisphere.
  constexpr int kRows = 90, kColumns = 180;
  std::vector<glm::vec3> dirs, radiance;
  std::vector<float> solid_angle;
  for (int r = 0; r < kRows; ++r) {
    const float theta = 0.5f * glm::pi<float>() * (static_cast<float>(r) + 0.5f) / kRows;
    for (int c = 0; c < kColumns; ++c) {
      const float phi = 2.0f * glm::pi<float>() * (static_cast<float>(c) + 0.5f) / kColumns;
      dirs.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      radiance.push_back(sky_.Radiance(dirs.back(), sun_dir) * inv_dhi);
      solid_angle.push_back(std::sin(theta) * (0.5f * glm::pi<float>() / kRows) * (2.0f * glm::pi<float>() / kColumns));
    }
  }
  std::vector<OpenSky> open(orientations_.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, orientations_.size()), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t o = range.begin(); o != range.end(); ++o) {
      for (size_t d = 0; d < dirs.size(); ++d) {
        const float c = std::max(0.0f, glm::dot(orientations_[o], dirs[d])) * solid_angle[d];
        open[o].clear += radiance[d] * c, open[o].uniform += glm::one_over_pi<float>() * c;
      }
    }
  });
  return open;
}

std::vector<glm::vec3> LightTransfer::ClearSkyPerUnitDhi(const glm::vec3& sun_dir,
                                                         const std::vector<glm::vec3>& dirs) const {
  std::vector<glm::vec3> out(dirs.size(), glm::vec3(glm::one_over_pi<float>()));
  if (sun_dir.z <= 0.0f || sky_.empty()) return out;
  const glm::dvec3 dhi = sky_.HorizontalIrradiance(sun_dir);
  if (!(glm::compMin(dhi) > 0.0)) return out;
  const glm::vec3 inv_dhi(1.0 / dhi);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, dirs.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) out[i] = sky_.Radiance(dirs[i], sun_dir) * inv_dhi;
  });
  return out;
}

void LightTransfer::Compute(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir, const float* direct,
                            Transfer* out, Transfer* reflected_out) {
  Trace(pixels);
  const ClearSky sky = ClearSkyUnder(sun_dir);
  // The first bounce is kept apart from the direct terms for the per-surface means of the second.
  std::vector<Transfer> reflected(pixels.size());
  DirectAndFirstBounce(pixels, sun_dir, direct, sky, out, &reflected);
  if (!options_.interreflection) {
    if (reflected_out != nullptr) std::fill(reflected_out, reflected_out + pixels.size(), Transfer{});
    return;
  }
  AddFurtherBounces(pixels, reflected, out, reflected_out);
}

LightTransfer::ClearSky LightTransfer::ClearSkyUnder(const glm::vec3& sun_dir) const {
  ClearSky sky;
  if (sun_dir.z <= 0.0f || sky_.empty()) return sky;
  const glm::dvec3 dhi = sky_.HorizontalIrradiance(sun_dir);
  if (!(glm::compMin(dhi) > 0.0)) return sky;
  sky.on = true;
  sky.inv_dhi = glm::vec3(1.0 / dhi);
  sky.open = OpenSkyIntegrals(sun_dir, sky.inv_dhi);
  return sky;
}

void LightTransfer::DirectAndFirstBounce(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir,
                                         const float* direct, const ClearSky& sky, Transfer* out,
                                         std::vector<Transfer>* reflected) const {
  const bool day = sun_dir.z > 0.0f;
  // How much more of the clear sky than of a uniform one an open surface of each orientation gets.
  const auto clear_weight = [&](uint32_t o) {
    return sky.open[o].uniform > 1e-3f ? sky.open[o].clear / sky.open[o].uniform : glm::vec3(1.0f);
  };
  const float inv_rays = 1.0f / static_cast<float>(hemisphere_.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels.size(), kGrain), [&](const tbb::blocked_range<size_t>& range) {
    // The bounce points' shadow rays all run along the sun: traced per pixel as packets.
    thread_local std::vector<glm::vec3> origins;
    thread_local std::vector<uint32_t> facing;
    thread_local std::vector<uint8_t> occluded;
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const uint32_t p = pixels[k];
      const Paths& paths = paths_[static_cast<size_t>(slot_[p])];
      Transfer t, r;
      origins.clear(), facing.clear();
      for (uint32_t i = paths.bounce_begin; day && i < paths.bounce_end; ++i) {
        if (glm::dot(bounces_[i].normal, sun_dir) > 0.0f) origins.push_back(bounces_[i].point), facing.push_back(i);
      }
      occluded.resize(origins.size());
      caster_.OccludedAlong(origins.data(), origins.size(), sun_dir, 0.0f, occluded.data());
      for (size_t j = 0; j < facing.size(); ++j) {
        const Bounce& b = bounces_[facing[j]];
        if (!occluded[j]) r.sun += b.albedo * glm::dot(b.normal, sun_dir);
      }
      for (uint32_t i = paths.bounce_begin; i < paths.bounce_end; ++i) {
        const Bounce& b = bounces_[i];
        r.overcast += b.albedo * b.sky_visibility;
        r.clear += b.albedo * b.sky_visibility * (sky.on ? clear_weight(b.orientation) : glm::vec3(1.0f));
      }
      r.sun *= inv_rays, r.clear *= inv_rays, r.overcast *= inv_rays;
      // The direct sky: V from the bake's many rays for the uniform sky. For the clear one, what
      // the open hemisphere would give (exact) less what the model blocks above the horizon, plus
      // what escapes below it: only the blocked part is sampled, which keeps the noise of a sky
      // ten times brighter at the horizon than at the zenith off open points.
      const float v = points_.sky_visibility[p];
      t.sun = glm::vec3(day ? direct[p] : 0.0f);
      t.overcast = glm::vec3(v);
      t.clear = glm::vec3(v);
      if (sky.on) {
        glm::vec3 blocked(0.0f), low(0.0f);
        for (uint32_t d = paths.blocked_begin; d < paths.blocked_end; ++d) blocked += sky_.Radiance(blocked_[d], sun_dir);
        for (uint32_t d = paths.low_sky_begin; d < paths.low_sky_end; ++d) low += sky_.Radiance(low_sky_[d], sun_dir);
        t.clear = glm::max(sky.open[paths.orientation].clear + (low - blocked) * glm::pi<float>() * sky.inv_dhi * inv_rays,
                           glm::vec3(0.0f));
      }
      out[k] = t;
      (*reflected)[k] = r;
    }
  });
}

// Further bounces: each bounce point's own reflected light, as its surface's mean over these
// pixels (surfaces without pixels here take the mean of all), iterated: the first pass gives the
// second bounce, the next the third.
void LightTransfer::AddFurtherBounces(const std::vector<uint32_t>& pixels, const std::vector<Transfer>& reflected,
                                      Transfer* out, Transfer* reflected_out) const {
  const float inv_rays = 1.0f / static_cast<float>(hemisphere_.size());
  const size_t surfaces = bake_.albedo_table.size();
  std::vector<Transfer> indirect = reflected;  // all reflected light found so far, per pixel
  for (int bounce = 2; bounce <= options_.bounces; ++bounce) {
    std::vector<Transfer> mean(surfaces + 1);
    std::vector<double> count(surfaces + 1, 0.0);
    for (size_t k = 0; k < pixels.size(); ++k) {
      for (const size_t s : {std::min<size_t>(points_.surface[pixels[k]], surfaces), surfaces}) {
        mean[s].sun += indirect[k].sun, mean[s].clear += indirect[k].clear, mean[s].overcast += indirect[k].overcast;
        count[s] += 1.0;
      }
    }
    for (size_t s = 0; s <= surfaces; ++s) {
      const size_t from = count[s] > 0.0 ? s : surfaces;
      const float scale = count[from] > 0.0 ? static_cast<float>(1.0 / count[from]) : 0.0f;
      mean[s] = {mean[from].sun * scale, mean[from].clear * scale, mean[from].overcast * scale};
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels.size(), kGrain), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t k = range.begin(); k != range.end(); ++k) {
        const Paths& paths = paths_[static_cast<size_t>(slot_[pixels[k]])];
        Transfer further;
        for (uint32_t i = paths.bounce_begin; i < paths.bounce_end; ++i) {
          const Bounce& b = bounces_[i];
          const Transfer& m = mean[std::min<size_t>(b.surface, surfaces)];
          further.sun += b.albedo * m.sun, further.clear += b.albedo * m.clear, further.overcast += b.albedo * m.overcast;
        }
        indirect[k] = {reflected[k].sun + further.sun * inv_rays, reflected[k].clear + further.clear * inv_rays,
                       reflected[k].overcast + further.overcast * inv_rays};
      }
    });
  }
  for (size_t k = 0; k < pixels.size(); ++k) {
    out[k].sun += indirect[k].sun, out[k].clear += indirect[k].clear, out[k].overcast += indirect[k].overcast;
    if (reflected_out != nullptr) reflected_out[k] = indirect[k];
  }
}

}  // namespace daylit::estimation
