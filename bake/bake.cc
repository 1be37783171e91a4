#include "bake/bake.h"
#include "bake/parallax.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <glm/gtc/constants.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bake/sampling.h"
#include "base/error.h"
#include "base/options_check.h"
#include "base/statistics.h"
#include "base/log.h"
#include "base/latlong.h"
#include "scene/raycaster.h"

namespace daylit::bake {
namespace {

// Rays from the capture point: if none reaches the sky and most hit the back of a face, the
// point is inside closed geometry.
constexpr double kInsideBackFaceShare = 0.5;

glm::dvec3 SunAtCapture(const scene::Scene& scene) { return scene::SunAt(scene, scene.envmap->time_utc).dir; }

void CheckCapturePosition(const scene::Scene& scene, const std::vector<scene::RayHit>& hits) {
  size_t sky = 0, back = 0;
  for (const scene::RayHit& h : hits) {
    sky += h.IsHit() ? 0 : 1;
    back += h.IsHit() && h.back_face ? 1 : 0;
  }
  const double back_share = static_cast<double>(back) / static_cast<double>(hits.size());
  if (sky == 0 && back_share > kInsideBackFaceShare) {
    const glm::dvec3& p = scene.envmap->position;
    ThrowInputError("{}: envmap.position ({}, {}, {}) is inside the model: no ray from it reaches the sky and {:.0f}% "
                    "hit the back of a surface",
                    scene.file.string(), p.x, p.y, p.z, 100.0 * back_share);
  }
}

// Per surface: median albedo π·L/E and median indirect irradiance E − E_sun over its texels.
HiddenSurfaceModel SurfaceModelFrom(const scene::SceneModel& model, const std::vector<glm::vec3>& radiance,
                                    const std::vector<size_t>& texels, const std::vector<uint32_t>& surface,
                                    const std::vector<glm::vec3>& irradiance, const std::vector<glm::vec3>& direct) {
  const size_t surfaces = model.surface_names.size();
  std::vector<std::array<std::vector<float>, 6>> values(surfaces);
  for (size_t i = 0; i < texels.size(); ++i) {
    auto& v = values[surface[texels[i]]];
    for (int c = 0; c < 3; ++c) {
      if (irradiance[i][c] > 1e-6f) v[static_cast<size_t>(c)].push_back(glm::pi<float>() * radiance[texels[i]][c] / irradiance[i][c]);
      v[3 + static_cast<size_t>(c)].push_back(irradiance[i][c] - direct[i][c]);
    }
  }
  HiddenSurfaceModel hidden;
  hidden.albedo.assign(surfaces, glm::vec3(0.0f));
  hidden.indirect.assign(surfaces, glm::vec3(0.0f));
  for (size_t s = 0; s < surfaces; ++s) {
    for (int c = 0; c < 3; ++c) {
      hidden.albedo[s][c] = MedianInPlace(values[s][static_cast<size_t>(c)], 0.0f);
      hidden.indirect[s][c] = MedianInPlace(values[s][3 + static_cast<size_t>(c)], 0.0f);
    }
  }
  return hidden;
}

EnvMapMaps ComputeEnvMapMaps(const scene::Scene& scene, const scene::RayCaster& caster, const BakeOptions& options,
                             HdrImage* env, CaptureSun* sun) {
  const std::string name = scene.envmap->file.string();
  scene::CheckEnvMap(*env, name);
  *sun = ExtractSun(env, SunAtCapture(scene), scene.envmap->sun_irradiance_rgb, name);
  EnvMapMaps maps;
  maps.width = env->width;
  maps.height = env->height;
  const size_t n = static_cast<size_t>(env->width) * env->height;
  const glm::vec3 capture(scene.envmap->position);
  std::vector<glm::vec3> origins(n, capture), dirs(n);
  for (size_t t = 0; t < n; ++t) {
    dirs[t] = glm::vec3(LatLongDirection(static_cast<double>(t % maps.width), static_cast<double>(t / maps.width), maps.width, maps.height));
  }
  std::vector<scene::RayHit> hits(n);
  caster.IntersectMany(origins.data(), dirs.data(), n, 0.0f, hits.data());
  CheckCapturePosition(scene, hits);

  maps.point.resize(n);
  maps.normal.assign(n, glm::vec3(0.0f));
  maps.surface.assign(n, kNoSurface);
  maps.sky_visibility.assign(n, 1.0f);
  maps.irradiance.assign(n, glm::vec3(0.0f));
  maps.albedo.assign(n, glm::vec3(0.0f));
  maps.radiance.resize(n);
  std::vector<uint8_t> is_sky(n);
  std::vector<size_t> surface_texels;
  for (size_t t = 0; t < n; ++t) {
    const float* l = &env->rgb[t * 3];
    maps.radiance[t] = glm::vec3(l[0], l[1], l[2]);
    is_sky[t] = hits[t].IsHit() ? 0 : 1;
    if (!hits[t].IsHit()) {
      maps.point[t] = dirs[t];
      continue;
    }
    maps.point[t] = capture + hits[t].t * dirs[t];
    maps.normal[t] = hits[t].normal;
    maps.surface[t] = hits[t].surface;
    surface_texels.push_back(t);
  }
  const HdrImage sky = sky::SkyOnly(*env, is_sky, sun->dir);
  std::vector<float> env_distance(n, -1.0f);
  for (size_t t = 0; t < n; ++t) env_distance[t] = hits[t].IsHit() ? hits[t].t : -1.0f;
  std::vector<glm::vec3> points(surface_texels.size()), normals(surface_texels.size()), e(surface_texels.size()),
      direct(surface_texels.size());
  std::vector<float> v(surface_texels.size());
  for (size_t i = 0; i < surface_texels.size(); ++i) {
    points[i] = maps.point[surface_texels[i]];
    normals[i] = maps.normal[surface_texels[i]];
  }
  // Pass 1, coarse: each surface's albedo and typical indirect light, for the points that the
  // capture point cannot see (pass 2 needs their radiance and the map shows what hides them).
  CaptureScene capture_scene{&caster, env, &sky, &env_distance, &maps.surface, &maps.normal, nullptr, capture, *sun};
  RayOptions coarse = options.rays;
  coarse.hemisphere_rays = std::max(16, options.rays.hemisphere_rays / 4);
  {
    Progress progress("bake: env light, 1/2 ", points.size());
    IntegrateCaptureIrradiance(capture_scene, coarse, points.data(), normals.data(), points.size(), v.data(), e.data(),
                               direct.data(), &progress);
  }
  HiddenSurfaceModel hidden = SurfaceModelFrom(scene.model, maps.radiance, surface_texels, maps.surface, e, direct);
  capture_scene.hidden = &hidden;
  {
    Progress progress("bake: hidden cells ", points.size());
    GatherHiddenCells(capture_scene, coarse, points.data(), normals.data(), points.size(), &hidden, &progress);
  }
  {
    Progress progress("bake: env light, 2/2 ", points.size());
    IntegrateCaptureIrradiance(capture_scene, options.rays, points.data(), normals.data(), points.size(), v.data(),
                               e.data(), nullptr, &progress);
  }
  for (size_t i = 0; i < surface_texels.size(); ++i) {
    const size_t t = surface_texels[i];
    maps.sky_visibility[t] = v[i];
    maps.irradiance[t] = e[i];
    maps.albedo[t] = glm::vec3(0.0f);
    for (int c = 0; c < 3; ++c) {
      // Where nothing lit the point at capture (E ≈ 0) its albedo cannot be known.
      if (e[i][c] > 1e-6f) maps.albedo[t][c] = glm::pi<float>() * maps.radiance[t][c] / e[i][c];
    }
  }
  return maps;
}

std::vector<SurfaceAlbedo> AlbedoTable(const scene::SceneModel& model, const EnvMapMaps& env) {
  std::vector<std::array<std::vector<float>, 3>> values(model.surface_names.size());
  for (size_t t = 0; t < env.surface.size(); ++t) {
    if (env.IsSky(t) || env.irradiance[t].x <= 1e-6f) continue;
    for (int c = 0; c < 3; ++c) values[env.surface[t]][static_cast<size_t>(c)].push_back(env.albedo[t][c]);
  }
  std::vector<SurfaceAlbedo> table;
  for (size_t s = 0; s < model.surface_names.size(); ++s) {
    SurfaceAlbedo row{model.surface_names[s], glm::vec3(0.0f), values[s][0].size()};
    for (size_t c = 0; c < 3; ++c) row.albedo[static_cast<int>(c)] = MedianInPlace(values[s][c], 0.0f);
    table.push_back(row);
  }
  return table;
}

// Albedo of camera point x seen through env texel coordinates uv: bilinear among the four
// nearest texels of the same surface (textures are finer than the map), nearest if none.
glm::vec3 EnvAlbedoAt(const EnvMapMaps& env, const glm::dvec2& uv, uint32_t surface) {
  const int u0 = static_cast<int>(std::floor(uv.x)), v0 = static_cast<int>(std::floor(uv.y));
  const double fu = uv.x - u0, fv = uv.y - v0;
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int dv = 0; dv <= 1; ++dv) {
    for (int du = 0; du <= 1; ++du) {
      const int v = std::clamp(v0 + dv, 0, env.height - 1);
      const int u = ((u0 + du) % env.width + env.width) % env.width;
      const size_t t = static_cast<size_t>(v) * env.width + u;
      if (env.surface[t] != surface || env.irradiance[t].x <= 1e-6f) continue;
      const double w = (du ? fu : 1.0 - fu) * (dv ? fv : 1.0 - fv);
      sum += w * glm::dvec3(env.albedo[t]);
      weight += w;
    }
  }
  if (weight > 1e-9) return glm::vec3(sum / weight);
  const int t = LatLongTexel(LatLongDirection(uv.x, uv.y, env.width, env.height), env.width, env.height);
  return env.albedo[static_cast<size_t>(t)];
}

CameraGBuffer ComputeCameraGBuffer(const scene::Scene& scene, const scene::RayCaster& caster, const BakeOptions& options,
                                   const EnvMapMaps& env, const std::vector<SurfaceAlbedo>& albedo_table,
                                   const cv::Mat& diffuse_mask) {
  CameraGBuffer g;
  g.width = scene.intrinsics.width;
  g.height = scene.intrinsics.height;
  const size_t n = static_cast<size_t>(g.width) * g.height;
  const scene::CameraModel camera = scene.Camera();
  std::vector<glm::dvec2> pixels(n);
  for (size_t i = 0; i < n; ++i) pixels[i] = {static_cast<double>(i % g.width), static_cast<double>(i / g.width)};
  const std::vector<glm::dvec3> rays = camera.UnprojectToWorldRays(pixels);
  const glm::vec3 center(camera.CenterInWorld());
  std::vector<glm::vec3> origins(n, center), dirs(n);
  for (size_t i = 0; i < n; ++i) dirs[i] = glm::vec3(rays[i]);
  std::vector<scene::RayHit> hits(n);
  caster.IntersectMany(origins.data(), dirs.data(), n, 0.0f, hits.data());

  g.point.assign(n, glm::vec3(0.0f));
  g.normal.assign(n, glm::vec3(0.0f));
  g.surface.assign(n, kNoSurface);
  g.sky_visibility.assign(n, 1.0f);
  g.albedo.assign(n, glm::vec3(0.0f));
  g.env_texel.assign(n, kNoSurface);
  g.diffuse.assign(n, 0);
  std::vector<size_t> hit_pixels;
  for (size_t i = 0; i < n; ++i) {
    if (!hits[i].IsHit()) continue;
    g.point[i] = center + hits[i].t * dirs[i];
    g.normal[i] = hits[i].normal;
    g.surface[i] = hits[i].surface;
    hit_pixels.push_back(i);
  }
  std::vector<glm::vec3> points(hit_pixels.size()), normals(hit_pixels.size());
  std::vector<float> v(hit_pixels.size());
  for (size_t k = 0; k < hit_pixels.size(); ++k) points[k] = g.point[hit_pixels[k]], normals[k] = g.normal[hit_pixels[k]];
  {
    Progress progress("bake: camera sky V   ", points.size());
    SkyVisibility(caster, options.rays, points.data(), normals.data(), points.size(), v.data(), &progress);
  }
  // Is each point visible from the capture position? It must face it, and a ray back to it must
  // be free.
  const glm::vec3 capture(scene.envmap->position);
  std::vector<uint8_t> seen(hit_pixels.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, hit_pixels.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) {
      const glm::vec3 d = capture - points[k];
      const float distance = glm::length(d);
      seen[k] = glm::dot(normals[k], d) > 0.0f &&
                        !caster.Occluded(points[k] + options.rays.offset_m * normals[k], d / distance, 0.0f, distance - 2e-3f)
                    ? 1
                    : 0;
    }
  });
  std::vector<uint8_t> has_point(n, 0);
  for (const size_t i : hit_pixels) has_point[i] = 1;
  const std::vector<glm::vec3> detail = CameraTextureDetail(scene, g.point, g.surface, has_point, env.height, options.detail);
  std::vector<uint8_t> is_diffuse_surface(scene.model.surface_names.size(), 0);
  for (const int s : scene.diffuse_surfaces) is_diffuse_surface[static_cast<size_t>(s)] = 1;
  for (size_t k = 0; k < hit_pixels.size(); ++k) {
    const size_t i = hit_pixels[k];
    g.sky_visibility[i] = v[k];
    const glm::dvec3 toward = glm::dvec3(points[k]) - glm::dvec3(capture);
    if (seen[k]) {
      const glm::dvec2 uv = LatLongCoordinates(toward, env.width, env.height);
      g.env_texel[i] = static_cast<uint32_t>(LatLongTexel(toward, env.width, env.height));
      g.albedo[i] = EnvAlbedoAt(env, uv, g.surface[i]) * detail[i];
    } else {
      g.albedo[i] = albedo_table[g.surface[i]].albedo * detail[i];
    }
    bool usable = is_diffuse_surface[g.surface[i]] != 0;
    if (!diffuse_mask.empty()) {
      usable = seen[k] && diffuse_mask.at<uint8_t>(static_cast<int>(g.env_texel[i] / env.width),
                                                static_cast<int>(g.env_texel[i] % env.width)) >= 128;
    }
    g.diffuse[i] = usable ? 1 : 0;
  }
  return g;
}

// Where a probe gathers from. A probe on a surface (the volume's floor lying on the ground) would
// send half its rays along that surface, through it or not by rounding, and read the map through
// it; it gathers from 2 cm in front of the surface instead.
glm::vec3 GatherOrigin(const scene::RayCaster& caster, const glm::vec3& probe) {
  constexpr float kClearance = 0.02f;
  for (const glm::vec3& d : {glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0),
                             glm::vec3(0, 1, 0), glm::vec3(0, -1, 0)}) {
    // From 2 cm out along d back toward the probe and 2 cm past it: a front face there is a
    // surface through or next to the probe.
    const glm::vec3 start = probe + kClearance * d;
    const scene::RayHit hit = caster.Intersect(start, -d, 0.0f, 2.0f * kClearance);
    if (hit.IsHit() && !hit.back_face) return start - hit.t * d + kClearance * hit.normal;
  }
  return probe;
}

sh::GatherTables ComputeGatherTables(const scene::Scene& scene, const scene::RayCaster& caster, const BakeOptions& options,
                                 const EnvMapMaps& env) {
  sh::GatherTables gather;
  if (!scene.volume) return gather;
  gather.min = glm::vec3(scene.volume->min);
  gather.max = glm::vec3(scene.volume->max);
  gather.resolution = scene.volume->resolution;
  gather.directions = SphericalFibonacci(options.gather_directions);
  const size_t dirs = gather.directions.size();
  const size_t n = gather.ProbeCount() * dirs;
  std::vector<glm::vec3> origins(n), rays(n);
  size_t probe = 0;
  for (int k = 0; k < gather.resolution.z; ++k) {
    for (int j = 0; j < gather.resolution.y; ++j) {
      for (int i = 0; i < gather.resolution.x; ++i, ++probe) {
        const glm::vec3 origin = GatherOrigin(caster, gather.ProbePosition(i, j, k));
        for (size_t d = 0; d < dirs; ++d) {
          origins[probe * dirs + d] = origin;
          rays[probe * dirs + d] = gather.directions[d];
        }
      }
    }
  }
  std::vector<scene::RayHit> hits(n);
  caster.IntersectMany(origins.data(), rays.data(), n, 0.0f, hits.data());
  const glm::vec3 capture(scene.envmap->position);
  gather.texel.resize(n);
  gather.map_texels = static_cast<size_t>(env.width) * static_cast<size_t>(env.height);
  for (size_t r = 0; r < n; ++r) gather.texel[r] = ParallaxTexel(origins[r], rays[r], hits[r], capture, env.width, env.height);
  return gather;
}

cv::Mat LoadDiffuseMask(const scene::Scene& scene, const EnvMapMaps& env) {
  if (!scene.diffuse_mask) return {};
  cv::Mat mask = cv::imread(scene.diffuse_mask->string(), cv::IMREAD_GRAYSCALE);
  if (mask.empty()) ThrowInputError("{}: diffuse_mask: '{}' is not a readable image", scene.file.string(), scene.diffuse_mask->string());
  if (mask.cols != env.width || mask.rows != env.height) {
    ThrowInputError("{}: diffuse_mask: {}x{} does not match the env map's {}x{}", scene.file.string(), mask.cols,
                    mask.rows, env.width, env.height);
  }
  return mask;
}

}  // namespace

std::string BakeOptions::Check() const {
  return FirstProblem({Nested("rays", rays.Check()), InClosed("gather_directions", gather_directions, 16, kMaxGatherDirections),
                       Nested("detail", detail.Check())});
}

std::string BakeOptions::Describe() const {
  return fmt::format("hemisphere_rays={} offset_m={} gather_directions={} detail_frames={} detail_footprint={}",
                     rays.hemisphere_rays, rays.offset_m, gather_directions, detail.frames, detail.footprint_scale);
}

size_t CameraGBuffer::DiffuseCount() const {
  return static_cast<size_t>(std::count(diffuse.begin(), diffuse.end(), uint8_t{1}));
}


sky::SkyDistribution CapturedSky(const SceneBake& bake) {
  const EnvMapMaps& env = bake.env;
  HdrImage image{env.width, env.height, std::vector<float>(env.radiance.size() * 3)};
  std::vector<uint8_t> is_sky(env.surface.size());
  for (size_t t = 0; t < env.radiance.size(); ++t) {
    for (int c = 0; c < 3; ++c) image.rgb[t * 3 + static_cast<size_t>(c)] = env.radiance[t][c];
    is_sky[t] = env.IsSky(t) ? 1 : 0;
  }
  return sky::SkyDistribution(image, is_sky, bake.capture_sun.dir);
}

SceneBake RunBake(const scene::Scene& scene, const BakeOptions& options) {
  if (!scene.envmap) ThrowInputError("{}: envmap: missing (the bake needs the HDR environment map)", scene.file.string());
  if (const std::string why = options.Check(); !why.empty()) ThrowInputError("bake options: {}", why);
  SceneBake bake;
  bake.hash = BakeHash(scene, options);
  const scene::RayCaster caster(scene.model);
  if (caster.degenerate_triangles() > 0) {
    Log().warn("{}: {} degenerate triangles (zero area) left out of ray casting", scene.model.file.string(),
               caster.degenerate_triangles());
  }
  HdrImage env = scene::ReadHdrImage(scene.envmap->file);
  bake.env = ComputeEnvMapMaps(scene, caster, options, &env, &bake.capture_sun);
  bake.albedo_table = AlbedoTable(scene.model, bake.env);
  bake.camera = ComputeCameraGBuffer(scene, caster, options, bake.env, bake.albedo_table, LoadDiffuseMask(scene, bake.env));
  if (bake.camera.DiffuseCount() == 0) {
    ThrowInputError("{}: the camera sees no diffuse surface (diffuse_surfaces: {}): nothing to estimate the light from",
                    scene.file.string(), fmt::join(scene.diffuse_globs, ", "));
  }
  bake.gather = ComputeGatherTables(scene, caster, options, bake.env);
  return bake;
}

std::vector<uint8_t> ProbesInsideModel(const sh::GatherTables& gather, const scene::RayCaster& caster) {
  const size_t dirs = gather.directions.size();
  const size_t probes = gather.ProbeCount();
  std::vector<glm::vec3> origins(probes * dirs), rays(probes * dirs);
  const glm::ivec3 n = gather.resolution;
  for (int k = 0; k < n.z; ++k) {
    for (int j = 0; j < n.y; ++j) {
      for (int i = 0; i < n.x; ++i) {
        const size_t p = (static_cast<size_t>(k) * n.y + j) * n.x + i;
        for (size_t d = 0; d < dirs; ++d) origins[p * dirs + d] = gather.ProbePosition(i, j, k), rays[p * dirs + d] = gather.directions[d];
      }
    }
  }
  std::vector<scene::RayHit> hits(origins.size());
  caster.IntersectMany(origins.data(), rays.data(), origins.size(), 0.0f, hits.data());
  std::vector<uint8_t> inside(probes, 0);
  for (size_t p = 0; p < probes; ++p) {
    size_t back = 0;
    for (size_t d = 0; d < dirs; ++d) {
      // A face through the probe itself (the ground under the volume's floor) says nothing.
      const scene::RayHit& hit = hits[p * dirs + d];
      back += hit.IsHit() && hit.back_face && hit.t > 1e-3f ? 1 : 0;
    }
    inside[p] = back * 4 > dirs ? 1 : 0;
  }
  return inside;
}

}  // namespace daylit::bake
