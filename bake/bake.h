// The offline stage of the relighting pipeline (seed 001, its Fig. 5): from the model, the HDR
// env map and the calibrated camera, everything each frame needs, so that a frame only does cheap
// arithmetic. Computed once and cached on disk, keyed by a hash of the inputs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "bake/capture_light.h"
#include "bake/surface_light.h"
#include "bake/texture_detail.h"
#include "scene/scene.h"
#include "sh/gather_tables.h"

namespace daylit::bake {

inline constexpr uint32_t kNoSurface = 0xFFFFFFFFu;  // sky, or no point
// Bumped whenever the bake computes something differently, so that old caches are re-baked.
inline constexpr const char* kBakeFormat = "daylit-bake/8";
// The most gather directions per probe a bake makes (BakeOptions::Check) or a cache may claim.
inline constexpr int kMaxGatherDirections = 65536;

struct BakeOptions {
  RayOptions rays;
  int gather_directions = 512;  // per probe, spherical Fibonacci
  DetailOptions detail;         // camera albedo detail from the recording's frames

  std::string Check() const;  // empty when valid, else the first problem, naming the field
  std::string Describe() const;        // the values, for the cache key and bake.json
};

// One value per env-map texel (row-major, like the map).
struct EnvMapMaps {
  int width = 0, height = 0;
  std::vector<glm::vec3> point;       // where the texel's ray from the capture point hits the model
  std::vector<glm::vec3> normal;      // unit, facing the capture point; 0 for sky
  std::vector<uint32_t> surface;      // kNoSurface for sky
  std::vector<float> sky_visibility;  // V; 1 for sky
  std::vector<glm::vec3> irradiance;  // E at capture time (env map as the light)
  std::vector<glm::vec3> albedo;      // ρ = π·L / E; 0 for sky and where E ≈ 0
  std::vector<glm::vec3> radiance;    // the captured radiance L, sun disc removed

  bool IsSky(size_t texel) const { return surface[texel] == kNoSurface; }
};

// One value per camera pixel (row-major, row 0 at the top).
struct CameraGBuffer {
  int width = 0, height = 0;
  std::vector<glm::vec3> point;
  std::vector<glm::vec3> normal;      // facing the camera
  std::vector<uint32_t> surface;      // kNoSurface where the pixel sees no model
  std::vector<float> sky_visibility;  // V
  std::vector<glm::vec3> albedo;      // env map albedo × texture detail from the frames (the
                                      // surface's median × detail where hidden from the capture point)
  std::vector<uint32_t> env_texel;    // env texel showing this point, kNoSurface if hidden from the capture point
  std::vector<uint8_t> diffuse;       // 1: usable to estimate the lighting

  size_t DiffuseCount() const;
};


struct SurfaceAlbedo {
  std::string surface;
  glm::vec3 albedo{0.0f};  // per-channel median over the surface's env texels
  size_t texels = 0;
};

struct SceneBake {
  std::string hash;
  CaptureSun capture_sun;
  EnvMapMaps env;
  CameraGBuffer camera;
  sh::GatherTables gather;  // empty when the scene has no volume
  std::vector<SurfaceAlbedo> albedo_table;
};

// The cache key: inputs that change the bake (scene.json, model, env map, diffuse mask, the
// frames the detail comes from, options, format, and the SHA-256 of the code that bakes, made
// at build time), hashed (FNV-1a 64, hex).
std::string BakeHash(const scene::Scene& scene, const BakeOptions& options);

// Computes the whole bake, with a progress bar. Throws InputError for an env map that is not 2:1 or
// has NaN/Inf/negative texels, a capture point inside the model, or a camera that sees no diffuse
// surface; warns about degenerate triangles.
SceneBake RunBake(const scene::Scene& scene, const BakeOptions& options);

// The captured sky of `bake`'s env maps (their sky texels, the sun disc removed) as a (θ, γ)
// table about the capture sun (SkyDistribution::Under re-aims it at another).
sky::SkyDistribution CapturedSky(const SceneBake& bake);

// Writes the bake into `dir`: env_maps.exr, camera_gbuffer.exr, gather.exr (multi-layer OpenEXR),
// albedo.csv, bake.json and PNG previews. Each file is written to a temporary name and renamed;
// bake.json last, so an interrupted save is never taken for a complete one.
void SaveBake(const SceneBake& bake, const scene::Scene& scene, const BakeOptions& options,
              const std::filesystem::path& dir);

// Loads a bake from `dir` if its bake.json carries `hash`; nullopt when missing or stale.
std::optional<SceneBake> LoadBake(const std::filesystem::path& dir, const std::string& hash);

// `dir` unless empty, else $XDG_CACHE_HOME/daylit/<folder> (~/.cache/daylit/<folder>), where
// <folder> is CacheFolderName(scene name). A `dir` inside the recording's folder must be a folder
// of its own there, new, empty or holding a bake (bake.json): InputError "--cache: ..." otherwise.
std::filesystem::path CacheDir(const scene::Scene& scene, const std::filesystem::path& dir);
// A scene name as one folder name: characters other than letters, digits, '-', '_' and '.' become
// '_', at most 100 of them, and a name of dots only (or none) gets "unnamed" in front. Never a
// path: "../../x" is ".._.._x", "/etc" is "_etc".
std::string CacheFolderName(const std::string& scene_name);

// The cached bake when its hash matches, else a new one (saved). `loaded` tells which.
SceneBake BakeOrLoad(const scene::Scene& scene, const BakeOptions& options, const std::filesystem::path& dir,
                     bool* loaded);

// albedo.csv: `surface,r,g,b,pixels` (pixels: the env-map texels behind the median).
std::string AlbedoCsv(const std::vector<SurfaceAlbedo>& table);

// Probes inside the model: from inside, most gather rays leave through the back of a face; a
// probe is inside when more than a quarter of its rays do. (A probe exactly on a surface, such
// as the ground at the volume's floor, is not: it sees the surface as a black half.)
std::vector<uint8_t> ProbesInsideModel(const sh::GatherTables& gather, const scene::RayCaster& caster);

}  // namespace daylit::bake
