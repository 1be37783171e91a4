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
constexpr float kDeepCellScale = 4.0f;  // deeper cells are this many times a level-1 cell's edge

// Unit directions as three signed bytes (0.5° at worst): a cell keeps those of its rays that
// reach the sky.
uint32_t PackDirection(const glm::vec3& d) {
  const glm::ivec3 q(glm::round(glm::clamp(d, -1.0f, 1.0f) * 127.0f));
  return static_cast<uint32_t>(q.x + 128) | (static_cast<uint32_t>(q.y + 128) << 8) | (static_cast<uint32_t>(q.z + 128) << 16);
}
glm::vec3 UnpackDirection(uint32_t p) {
  const glm::vec3 q(static_cast<float>(p & 0xff) - 128.0f, static_cast<float>((p >> 8) & 0xff) - 128.0f,
                    static_cast<float>((p >> 16) & 0xff) - 128.0f);
  return glm::normalize(q);
}


}  // namespace

std::string TransferOptions::Check() const {
  return FirstProblem({InClosed("rays", rays, 8, 65536), InClosed("cell_rays", cell_rays, 8, 65536),
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
    sky_ = bake::CapturedSky(bake);
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
  const size_t first_block = blocks_.size();
  TraceHemispheres(fresh);
  TraceCells(first_block);
}

// Albedo and V of a bounce point: the env maps' where the capture point sees it; else the
// surface's median albedo, and V marked (−1) for FillHiddenSkyVisibility.
LightTransfer::Bounce LightTransfer::BounceAt(const glm::vec3& y, const scene::RayHit& hit) const {
  const bake::EnvMapMaps& env = bake_.env;
  Bounce b{y + options_.offset_m * hit.normal, hit.normal, glm::vec3(0.0f), -1.0f, hit.surface, 0, kNoCell};
  if (env.width > 0) {
    const glm::vec3 toward = y - capture_position_;
    const size_t texel = static_cast<size_t>(LatLongTexel(glm::dvec3(toward), env.width, env.height));
    const float seen = env.IsSky(texel) ? -1.0f : glm::length(env.point[texel] - capture_position_);
    if (bake::CaptureSees(toward, hit.normal, hit.surface, seen, env.surface[texel], env.normal[texel], env.height) &&
        glm::compMax(env.albedo[texel]) > 0.0f) {
      b.albedo = env.albedo[texel];
      b.sky_visibility = env.sky_visibility[texel];
      return b;
    }
  }
  b.albedo = hit.surface < bake_.albedo_table.size() ? bake_.albedo_table[hit.surface].albedo : glm::vec3(0.0f);
  return b;
}

// Each block of kBlockPixels fresh pixels on one thread: its rays into that thread's scratch
// lists, then into the block's own, sized once. The store grows by blocks, so what earlier sun
// moves traced is never copied again.
void LightTransfer::TraceHemispheres(const std::vector<uint32_t>& fresh) {
  const size_t first_block = blocks_.size(), first_path = paths_.size();
  const size_t blocks = (fresh.size() + kBlockPixels - 1) / kBlockPixels;
  blocks_.resize(first_block + blocks);
  paths_.resize(first_path + fresh.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks, 1), [&](const tbb::blocked_range<size_t>& range) {
    thread_local std::vector<glm::vec3> dirs, low_sky, blocked;
    thread_local std::vector<scene::RayHit> hits;
    thread_local std::vector<Bounce> bounces;
    for (size_t k = range.begin(); k != range.end(); ++k) {
      low_sky.clear(), blocked.clear(), bounces.clear();
      const uint32_t block = static_cast<uint32_t>(first_block + k);
      for (size_t f = k * kBlockPixels; f < std::min(fresh.size(), (k + 1) * kBlockPixels); ++f) {
        const uint32_t p = fresh[f];
        Paths& paths = paths_[first_path + f];
        paths.block = block;
        paths.low_sky_begin = static_cast<uint32_t>(low_sky.size());
        paths.blocked_begin = static_cast<uint32_t>(blocked.size());
        paths.bounce_begin = static_cast<uint32_t>(bounces.size());
        const glm::vec3 origin = points_.point[p] + options_.offset_m * points_.normal[p];
        const glm::mat3 frame = bake::HemisphereFrame(points_.normal[p], p);
        dirs.resize(hemisphere_.size()), hits.resize(hemisphere_.size());
        for (size_t r = 0; r < dirs.size(); ++r) dirs[r] = frame * hemisphere_[r];
        caster_.IntersectFrom(origin, dirs.data(), dirs.size(), 0.0f, hits.data());
        for (size_t r = 0; r < dirs.size(); ++r) {
          const glm::vec3& dir = dirs[r];
          const scene::RayHit& hit = hits[r];
          if (!hit.IsHit()) {
            if (dir.z <= 0.0f) low_sky.push_back(dir);
            continue;
          }
          if (dir.z > 0.0f) blocked.push_back(dir);
          if (options_.interreflection) {
            bounces.push_back(BounceAt(origin + hit.t * dir, hit));
            bounces.back().orientation = OrientationKey(hit.normal);  // made an index below
          }
        }
        paths.low_sky_end = static_cast<uint32_t>(low_sky.size());
        paths.blocked_end = static_cast<uint32_t>(blocked.size());
        paths.bounce_end = static_cast<uint32_t>(bounces.size());
      }
      PathBlock& out = blocks_[block];
      out.low_sky.assign(low_sky.begin(), low_sky.end());
      out.blocked.assign(blocked.begin(), blocked.end());
      out.bounces.assign(bounces.begin(), bounces.end());
    }
  });
  // The tables shared by all blocks grow here, in order.
  uint32_t last_key = UINT32_MAX, last_index = 0;  // neighbouring hits mostly share a plane
  for (size_t k = first_block; k < blocks_.size(); ++k) {
    for (Bounce& b : blocks_[k].bounces) {
      if (b.orientation != last_key) last_key = b.orientation, last_index = OrientationOfKey(last_key);
      b.orientation = last_index;
    }
  }
  for (size_t f = 0; f < fresh.size(); ++f) {
    paths_[first_path + f].orientation = OrientationOf(points_.normal[fresh[f]]);
    slot_[fresh[f]] = static_cast<int32_t>(first_path + f);
  }
}

// The cells of the points' bounce points, and theirs in turn down to the level the bounces need
// (level L's hits get cells while L < bounces − 1; level 1 is always traced, for V). A cell first
// met deeper and later by a point keeps its trace and gets its hits' cells then.
void LightTransfer::TraceCells(size_t first_block) {
  const uint32_t deepest = static_cast<uint32_t>(std::max(1, options_.bounces - 1));
  for (size_t k = first_block; k < blocks_.size(); ++k) {
    for (Bounce& b : blocks_[k].bounces) b.cell = CellFor(b, 1);
  }
  for (uint32_t depth = 1; depth <= deepest; ++depth) {
    std::vector<uint32_t> untraced, unexpanded;
    for (uint32_t c = 0; c < cells_.size(); ++c) {
      if (cells_[c].level != depth) continue;
      if (!cells_[c].traced) untraced.push_back(c);
      if (!cells_[c].expanded && depth < deepest) unexpanded.push_back(c);
    }
    TraceNewCells(untraced);
    for (const uint32_t c : unexpanded) {
      cells_[c].expanded = true;
      for (uint32_t i = cells_[c].bounce_begin; i < cells_[c].bounce_end; ++i) {
        cell_bounces_[i].cell = CellFor(cell_bounces_[i], depth + 1);
      }
    }
  }
  FillHiddenSkyVisibility(first_block);
}

uint32_t LightTransfer::CellFor(const Bounce& b, uint32_t level) {
  const auto [it, inserted] = cell_of_.try_emplace(CellKey(b, std::min(level, 2u)), static_cast<uint32_t>(cells_.size()));
  if (inserted) {
    cells_.push_back({bake::SurfaceCellOrigin(b.point, b.normal, CellEdge(level)), b.normal, level});
  } else if (cells_[it->second].level > level) {
    cells_[it->second].level = level;
  }
  return it->second;
}

// Each new cell's hemisphere from its origin: V (the share of rays that escape) and its hits.
void LightTransfer::TraceNewCells(const std::vector<uint32_t>& cells) {
  const std::vector<glm::vec3> hemisphere = bake::CosineHemisphere(options_.cell_rays);
  std::vector<std::vector<Bounce>> hits(cells.size());
  std::vector<std::vector<uint32_t>> open_dirs(cells.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells.size(), 8), [&](const tbb::blocked_range<size_t>& range) {
    thread_local std::vector<glm::vec3> dirs;
    thread_local std::vector<scene::RayHit> ray_hits;
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Cell& cell = cells_[cells[i]];
      const glm::mat3 frame = bake::HemisphereFrame(cell.normal, cells[i]);
      dirs.resize(hemisphere.size()), ray_hits.resize(hemisphere.size());
      for (size_t r = 0; r < dirs.size(); ++r) dirs[r] = frame * hemisphere[r];
      caster_.IntersectFrom(cell.origin, dirs.data(), dirs.size(), 0.0f, ray_hits.data());
      size_t open = 0;
      for (size_t r = 0; r < dirs.size(); ++r) open += !ray_hits[r].IsHit();
      open_dirs[i].reserve(open), hits[i].reserve(options_.interreflection ? dirs.size() - open : 0);
      for (size_t r = 0; r < dirs.size(); ++r) {
        if (!ray_hits[r].IsHit()) {
          open_dirs[i].push_back(PackDirection(dirs[r]));
        } else if (options_.interreflection) {
          hits[i].push_back(BounceAt(cell.origin + ray_hits[r].t * dirs[r], ray_hits[r]));
          hits[i].back().orientation = OrientationKey(ray_hits[r].normal);  // made an index below
        }
      }
      cell.sky_visibility = static_cast<float>(open) / static_cast<float>(dirs.size());
    }
  });
  size_t bounces = cell_bounces_.size(), sky = cell_sky_.size();
  for (size_t i = 0; i < cells.size(); ++i) bounces += hits[i].size(), sky += open_dirs[i].size();
  // Grown by half at least: each depth of a trace appends, and a move copies all before it.
  if (bounces > cell_bounces_.capacity()) cell_bounces_.reserve(bounces + bounces / 2);
  if (sky > cell_sky_.capacity()) cell_sky_.reserve(sky + sky / 2);
  uint32_t last_key = UINT32_MAX, last_index = 0;  // a cell's hits mostly share a plane
  for (size_t i = 0; i < cells.size(); ++i) {
    Cell& cell = cells_[cells[i]];
    cell.traced = true;
    cell.bounce_begin = static_cast<uint32_t>(cell_bounces_.size());
    for (Bounce b : hits[i]) {
      if (b.orientation != last_key) last_key = b.orientation, last_index = OrientationOfKey(last_key);
      b.orientation = last_index;
      cell_bounces_.push_back(b);
    }
    cell.bounce_end = static_cast<uint32_t>(cell_bounces_.size());
    cell.sky_begin = static_cast<uint32_t>(cell_sky_.size());
    cell_sky_.insert(cell_sky_.end(), open_dirs[i].begin(), open_dirs[i].end());
    cell.sky_end = static_cast<uint32_t>(cell_sky_.size());
  }
}

// V of the bounce points the capture point does not see (~5% of them on courtyard-a): their
// cell's (V is smooth). Hits of the deepest cells have no cell of their own: a traced cell of their
// square if there is one, else the mean V of their surface's cells.
void LightTransfer::FillHiddenSkyVisibility(size_t first_block) {
  for (size_t k = first_block; k < blocks_.size(); ++k) {
    for (Bounce& b : blocks_[k].bounces) {
      if (b.sky_visibility < 0.0f) b.sky_visibility = cells_[b.cell].sky_visibility;
    }
  }
  std::unordered_map<uint32_t, std::pair<double, int>> by_surface;
  for (Bounce& b : cell_bounces_) {
    if (b.sky_visibility < 0.0f && b.cell != kNoCell && cells_[b.cell].traced) b.sky_visibility = cells_[b.cell].sky_visibility;
  }
  for (const Bounce& b : cell_bounces_) {
    if (b.cell != kNoCell && cells_[b.cell].traced) {
      auto& [sum, n] = by_surface[b.surface];
      sum += cells_[b.cell].sky_visibility, ++n;
    }
  }
  for (Bounce& b : cell_bounces_) {
    if (b.sky_visibility >= 0.0f) continue;
    // A cell of its square traced for another path (a slab's underside is not its top).
    for (const uint32_t level : {2u, 1u}) {
      const auto cell = cell_of_.find(CellKey(b, level));
      if (b.sky_visibility < 0.0f && cell != cell_of_.end() && cells_[cell->second].traced) {
        b.sky_visibility = cells_[cell->second].sky_visibility;
      }
    }
    if (b.sky_visibility >= 0.0f) continue;
    const auto it = by_surface.find(b.surface);
    b.sky_visibility = it == by_surface.end() ? 0.5f : static_cast<float>(it->second.first / it->second.second);
  }
}

float LightTransfer::CellEdge(uint32_t level) { return level == 1 ? kCellSize : kDeepCellScale * kCellSize; }

uint64_t LightTransfer::CellKey(const Bounce& b, uint32_t level) {
  return bake::SurfaceCellKey(b.point, b.normal, b.surface * 4ull + level, CellEdge(level));
}

uint32_t LightTransfer::OrientationKey(const glm::vec3& normal) {
  const glm::ivec3 q = glm::clamp(glm::ivec3(glm::round(normal * 64.0f)), -64, 64);
  return (static_cast<uint32_t>(q.x + 64) << 16) | (static_cast<uint32_t>(q.y + 64) << 8) | static_cast<uint32_t>(q.z + 64);
}

uint32_t LightTransfer::OrientationOfKey(uint32_t key) {
  const auto [it, inserted] = orientation_of_.emplace(key, static_cast<uint32_t>(orientations_.size()));
  if (inserted) {
    const glm::vec3 q(static_cast<float>(static_cast<int>(key >> 16) - 64), static_cast<float>(static_cast<int>((key >> 8) & 0xFF) - 64),
                      static_cast<float>(static_cast<int>(key & 0xFF) - 64));
    orientations_.push_back(glm::normalize(q));
  }
  return it->second;
}

uint32_t LightTransfer::OrientationOf(const glm::vec3& normal) { return OrientationOfKey(OrientationKey(normal)); }

std::vector<LightTransfer::OpenSky> LightTransfer::OpenSkyIntegrals(const sky::SkyDistribution& table,
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
      radiance.push_back(table.Radiance(dirs.back()) * inv_dhi);
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
  const sky::SkyDistribution table = sky_.Under(sun_dir, options_.reaim_sky);
  const glm::dvec3 dhi = table.HorizontalIrradiance();
  if (!(glm::compMin(dhi) > 0.0)) return out;
  const glm::vec3 inv_dhi(1.0 / dhi);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, dirs.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) out[i] = table.Radiance(dirs[i]) * inv_dhi;
  });
  return out;
}

void LightTransfer::Compute(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir, const float* direct,
                            Transfer* out, Transfer* reflected_out) {
  Trace(pixels);
  const ClearSky sky = ClearSkyUnder(sun_dir);
  const std::vector<Transfer> cell_light = options_.interreflection && options_.bounces > 1
                                               ? SolveCells(sun_dir, sky)
                                               : std::vector<Transfer>(cells_.size());
  DirectAndReflected(pixels, sun_dir, direct, sky, cell_light, out, reflected_out);
}

LightTransfer::ClearSky LightTransfer::ClearSkyUnder(const glm::vec3& sun_dir) const {
  ClearSky sky;
  if (sun_dir.z <= 0.0f || sky_.empty()) return sky;
  sky.table = sky_.Under(sun_dir, options_.reaim_sky);
  const glm::dvec3 dhi = sky.table.HorizontalIrradiance();
  if (!(glm::compMin(dhi) > 0.0)) return sky;
  sky.on = true;
  sky.inv_dhi = glm::vec3(1.0 / dhi);
  sky.open = OpenSkyIntegrals(sky.table, sky.inv_dhi);
  // π·L/DHI averaged over each cell's open rays: 1 for a uniform sky.
  sky.cell_weight.assign(cells_.size(), glm::vec3(1.0f));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t c = range.begin(); c != range.end(); ++c) {
      const Cell& cell = cells_[c];
      if (cell.sky_begin == cell.sky_end) continue;
      glm::vec3 sum(0.0f);
      for (uint32_t d = cell.sky_begin; d < cell.sky_end; ++d) sum += sky.table.Radiance(UnpackDirection(cell_sky_[d]));
      sky.cell_weight[c] = sum * sky.inv_dhi * glm::pi<float>() / static_cast<float>(cell.sky_end - cell.sky_begin);
    }
  });
  return sky;
}

Transfer LightTransfer::DirectReflected(const Bounce& b, float sun_cos, const ClearSky& sky) const {
  // How much more of the clear sky than of a uniform one b gets: the mean over its cell's rays that
  // reach the sky (under an arcade, the low sky toward the sun), else what an open surface of b's
  // orientation gets.
  const OpenSky* open = sky.on ? &sky.open[b.orientation] : nullptr;
  glm::vec3 clear_weight(1.0f);
  if (b.cell != kNoCell && sky.on && cells_[b.cell].sky_begin != cells_[b.cell].sky_end) {
    clear_weight = sky.cell_weight[b.cell];
  } else if (open != nullptr && open->uniform > 1e-3f) {
    clear_weight = open->clear / open->uniform;
  }
  return {b.albedo * sun_cos, b.albedo * b.sky_visibility * clear_weight, b.albedo * b.sky_visibility};
}

// Jacobi iteration from no reflected light: after k passes a cell holds what reaches it over k
// bounces, so bounces − 1 passes give the points their full count.
std::vector<Transfer> LightTransfer::SolveCells(const glm::vec3& sun_dir, const ClearSky& sky) {
  const bool day = sun_dir.z > 0.0f;
  std::vector<Transfer>& own = own_;  // each hit's reflected direct light; every one is written below
  own.resize(cell_bounces_.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
    thread_local std::vector<glm::vec3> origins;
    thread_local std::vector<uint32_t> facing;
    thread_local std::vector<uint8_t> occluded;
    for (size_t c = range.begin(); c != range.end(); ++c) {
      origins.clear(), facing.clear();
      for (uint32_t i = cells_[c].bounce_begin; day && i < cells_[c].bounce_end; ++i) {
        if (glm::dot(cell_bounces_[i].normal, sun_dir) > 0.0f) origins.push_back(cell_bounces_[i].point), facing.push_back(i);
      }
      occluded.resize(origins.size());
      caster_.OccludedAlong(origins.data(), origins.size(), sun_dir, 0.0f, occluded.data());
      for (uint32_t i = cells_[c].bounce_begin; i < cells_[c].bounce_end; ++i) own[i] = DirectReflected(cell_bounces_[i], 0.0f, sky);
      for (size_t j = 0; j < facing.size(); ++j) {
        if (!occluded[j]) own[facing[j]].sun = cell_bounces_[facing[j]].albedo * glm::dot(cell_bounces_[facing[j]].normal, sun_dir);
      }
    }
  });
  const float inv_rays = 1.0f / static_cast<float>(options_.cell_rays);
  std::vector<Transfer> light(cells_.size()), next(cells_.size()), before(cells_.size()), before2(cells_.size());
  for (int pass = 1; pass < options_.bounces; ++pass) {
    before2.swap(before), before = light;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_.size(), 64), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t c = range.begin(); c != range.end(); ++c) {
        Transfer sum;
        for (uint32_t i = cells_[c].bounce_begin; i < cells_[c].bounce_end; ++i) {
          const Bounce& b = cell_bounces_[i];
          Transfer t = own[i];
          if (b.cell != kNoCell) {
            const Transfer& further = light[b.cell];
            t.sun += b.albedo * further.sun, t.clear += b.albedo * further.clear, t.overcast += b.albedo * further.overcast;
          }
          sum.sun += t.sun, sum.clear += t.clear, sum.overcast += t.overcast;
        }
        next[c] = {sum.sun * inv_rays, sum.clear * inv_rays, sum.overcast * inv_rays};
      }
    });
    light.swap(next);
  }
  if (options_.close_series && options_.bounces >= 3) CloseGeometricSeries(before2, before, &light);
  return light;
}

void CloseGeometricSeries(const std::vector<Transfer>& two_back, const std::vector<Transfer>& one_back,
                          std::vector<Transfer>* light) {
  glm::dvec3 last[3] = {}, previous[3] = {};
  for (size_t c = 0; c < light->size(); ++c) {
    const Transfer &l = (*light)[c], &b = one_back[c], &a = two_back[c];
    last[0] += l.sun - b.sun, last[1] += l.clear - b.clear, last[2] += l.overcast - b.overcast;
    previous[0] += b.sun - a.sun, previous[1] += b.clear - a.clear, previous[2] += b.overcast - a.overcast;
  }
  glm::vec3 gain[3];
  for (int part = 0; part < 3; ++part) {
    for (int ch = 0; ch < 3; ++ch) {
      const double r = previous[part][ch] > 1e-12 ? std::clamp(last[part][ch] / previous[part][ch], 0.0, 0.9) : 0.0;
      gain[part][ch] = static_cast<float>(r / (1.0 - r));
    }
  }
  for (size_t c = 0; c < light->size(); ++c) {
    Transfer& l = (*light)[c];
    const Transfer& b = one_back[c];
    l.sun += (l.sun - b.sun) * gain[0], l.clear += (l.clear - b.clear) * gain[1], l.overcast += (l.overcast - b.overcast) * gain[2];
  }
}

void LightTransfer::DirectAndReflected(const std::vector<uint32_t>& pixels, const glm::vec3& sun_dir, const float* direct,
                                       const ClearSky& sky, const std::vector<Transfer>& cell_light, Transfer* out,
                                       Transfer* reflected) const {
  const bool day = sun_dir.z > 0.0f;
  const float inv_rays = 1.0f / static_cast<float>(hemisphere_.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels.size(), kGrain), [&](const tbb::blocked_range<size_t>& range) {
    // The bounce points' shadow rays all run along the sun: traced per pixel as packets.
    thread_local std::vector<glm::vec3> origins;
    thread_local std::vector<uint32_t> facing;
    thread_local std::vector<uint8_t> occluded;
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const uint32_t p = pixels[k];
      const Paths& paths = paths_[static_cast<size_t>(slot_[p])];
      const PathBlock& block = blocks_[paths.block];
      Transfer t, r;
      origins.clear(), facing.clear();
      for (uint32_t i = paths.bounce_begin; day && i < paths.bounce_end; ++i) {
        if (glm::dot(block.bounces[i].normal, sun_dir) > 0.0f) origins.push_back(block.bounces[i].point), facing.push_back(i);
      }
      occluded.resize(origins.size());
      caster_.OccludedAlong(origins.data(), origins.size(), sun_dir, 0.0f, occluded.data());
      for (size_t j = 0; j < facing.size(); ++j) {
        const Bounce& b = block.bounces[facing[j]];
        if (!occluded[j]) r.sun += b.albedo * glm::dot(b.normal, sun_dir);
      }
      for (uint32_t i = paths.bounce_begin; i < paths.bounce_end; ++i) {
        const Bounce& b = block.bounces[i];
        const Transfer own = DirectReflected(b, 0.0f, sky);
        const Transfer& further = cell_light[b.cell];
        r.clear += own.clear + b.albedo * further.clear, r.overcast += own.overcast + b.albedo * further.overcast;
        r.sun += b.albedo * further.sun;
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
        for (uint32_t d = paths.blocked_begin; d < paths.blocked_end; ++d) blocked += sky.table.Radiance(block.blocked[d]);
        for (uint32_t d = paths.low_sky_begin; d < paths.low_sky_end; ++d) low += sky.table.Radiance(block.low_sky[d]);
        t.clear = glm::max(sky.open[paths.orientation].clear + (low - blocked) * glm::pi<float>() * sky.inv_dhi * inv_rays,
                           glm::vec3(0.0f));
      }
      out[k] = {t.sun + r.sun, t.clear + r.clear, t.overcast + r.overcast};
      if (reflected != nullptr) reflected[k] = r;
    }
  });
}

}  // namespace daylit::estimation
