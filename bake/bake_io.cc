// Storing and loading the bake: the cache key, multi-layer EXRs, bake.json, albedo.csv, previews.
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "bake/bake.h"
#include "bake/bake_code_hash.h"  // generated: DAYLIT_BAKE_CODE_HASH (bake/CMakeLists.txt)
#include "bake/sampling.h"
#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"
#include "base/files.h"
#include "base/log.h"
#include "base/version.h"
#include "capture/response.h"
#include "report/plot.h"
#include "scene/hdr_image.h"

namespace daylit::bake {
namespace {

namespace fs = std::filesystem;

struct Fnv1a {
  uint64_t state = 14695981039346656037ull;
  void Add(std::string_view bytes) {
    for (const char c : bytes) state = (state ^ static_cast<uint8_t>(c)) * 1099511628211ull;
  }
  void AddFile(const fs::path& path) {
    Add(path.filename().string());
    Add(ReadTextFile(path));
  }
};

// Planar copies of one component of a vector field, for EXR slices.
std::vector<float> Component(const std::vector<glm::vec3>& v, int c) {
  std::vector<float> out(v.size());
  for (size_t i = 0; i < v.size(); ++i) out[i] = v[i][c];
  return out;
}

std::vector<glm::vec3> Gather3(const scene::ExrChannels& ch, size_t first) {
  std::vector<glm::vec3> out(ch.planes[first].size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = {ch.planes[first][i], ch.planes[first + 1][i], ch.planes[first + 2][i]};
  return out;
}

// Writes `fields` (name prefix -> RGB/XYZ vectors) plus scalars as one multi-layer EXR.
struct Layers {
  std::vector<std::vector<float>> storage;
  std::vector<scene::ExrChannel> channels;
  void Vec3(const std::string& prefix, const char* suffixes, const std::vector<glm::vec3>& v, scene::ExrPixelType type) {
    for (int c = 0; c < 3; ++c) {
      storage.push_back(Component(v, c));
      channels.push_back({prefix + "." + suffixes[c], type, nullptr, nullptr});
    }
  }
  void Scalar(const std::string& name, const std::vector<float>& v, scene::ExrPixelType type) {
    storage.push_back(v);
    channels.push_back({name, type, nullptr, nullptr});
  }
  void Uint(const std::string& name, const std::vector<uint32_t>& v) {
    channels.push_back({name, scene::ExrPixelType::kUint, nullptr, v.data()});
  }
  void Write(const fs::path& path, int width, int height) {
    size_t k = 0;
    for (scene::ExrChannel& c : channels) {
      if (c.type != scene::ExrPixelType::kUint) c.floats = storage[k++].data();
    }
    scene::WriteExr(path, width, height, channels);
  }
};

cv::Mat ToPreview(int width, int height, const std::function<glm::vec3(size_t)>& rgb_linear, bool encode_srgb) {
  cv::Mat image(height, width, CV_8UC3);
  const capture::CameraResponse srgb;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const glm::vec3 c = rgb_linear(static_cast<size_t>(y) * width + x);
      cv::Vec3b& p = image.at<cv::Vec3b>(y, x);
      for (int k = 0; k < 3; ++k) {
        const double v = encode_srgb ? srgb.ToEncoded(c[k]) : std::clamp(static_cast<double>(c[k]), 0.0, 1.0);
        p[2 - k] = static_cast<uint8_t>(std::lround(255.0 * v));
      }
    }
  }
  return image;
}

glm::vec3 SurfaceColor(uint32_t surface) {
  if (surface == kNoSurface) return glm::vec3(0.55f, 0.75f, 1.0f);
  const std::array<int, 3> c = report::SeriesColor(static_cast<int>(surface));
  return glm::vec3(c[0], c[1], c[2]) / 255.0f;
}

void WritePreviews(const SceneBake& bake, const fs::path& dir) {
  const EnvMapMaps& e = bake.env;
  const CameraGBuffer& g = bake.camera;
  const auto png = [&](const char* name, const cv::Mat& image) { report::WritePng(dir / name, {image}); };
  png("env_albedo.png", ToPreview(e.width, e.height, [&](size_t i) { return e.albedo[i]; }, true));
  png("env_sky_visibility.png", ToPreview(e.width, e.height, [&](size_t i) { return glm::vec3(e.sky_visibility[i]); }, false));
  png("env_surfaces.png", ToPreview(e.width, e.height, [&](size_t i) { return SurfaceColor(e.surface[i]); }, false));
  png("env_normals.png", ToPreview(e.width, e.height, [&](size_t i) { return 0.5f * e.normal[i] + 0.5f; }, false));
  png("camera_albedo.png", ToPreview(g.width, g.height, [&](size_t i) { return g.albedo[i]; }, true));
  png("camera_sky_visibility.png", ToPreview(g.width, g.height, [&](size_t i) { return glm::vec3(g.sky_visibility[i]); }, false));
  png("camera_surfaces.png", ToPreview(g.width, g.height, [&](size_t i) { return SurfaceColor(g.surface[i]); }, false));
  png("camera_diffuse.png", ToPreview(g.width, g.height, [&](size_t i) {
        return g.diffuse[i] ? glm::vec3(1.0f) : g.surface[i] == kNoSurface ? glm::vec3(0.0f) : glm::vec3(0.3f);
      }, false));
}

nlohmann::json Vec(const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }
// at(), never operator[], on what is read: a missing key or index in a const json is an assertion
// (or undefined behaviour), at() throws.
glm::vec3 Vec(const nlohmann::json& j) { return {j.at(0).get<float>(), j.at(1).get<float>(), j.at(2).get<float>()}; }

}  // namespace

std::string BakeHash(const scene::Scene& scene, const BakeOptions& options) {
  Fnv1a h;
  h.Add(kBakeFormat);
  h.Add(DAYLIT_BAKE_CODE_HASH);  // another build's code: another bake
  h.Add(options.Describe());
  h.AddFile(scene.file);
  h.AddFile(scene.model.file);
  if (scene.envmap) h.AddFile(scene.envmap->file);
  if (scene.diffuse_mask) h.AddFile(*scene.diffuse_mask);
  if (options.detail.frames > 0 && scene.frames.kind == scene::FrameSourceKind::kVideo) h.AddFile(scene.frames.video);
  if (scene.frame_times) h.AddFile(scene.frame_times->file);
  return fmt::format("{:016x}", h.state);
}

std::string AlbedoCsv(const std::vector<SurfaceAlbedo>& table) {
  std::string out = "surface,r,g,b,pixels\n";
  for (const SurfaceAlbedo& row : table) {
    out += fmt::format("{},{:.4f},{:.4f},{:.4f},{}\n", CsvField(row.surface), row.albedo.x, row.albedo.y, row.albedo.z,
                       row.texels);
  }
  return out;
}

std::string CacheFolderName(const std::string& scene_name) {
  // A name never becomes a path: separators, "..", a leading "/", control and other characters
  // are replaced, so the folder is always one level under the cache root.
  std::string out;
  for (const char c : scene_name) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                      c == '_' || c == '.';
    out += safe ? c : '_';
  }
  if (out.size() > 100) out.resize(100);
  if (out.find_first_not_of('.') == std::string::npos) out = "unnamed" + out;  // "", ".", ".."
  return out;
}

fs::path CacheDir(const scene::Scene& scene, const fs::path& dir) {
  if (!dir.empty()) {
    // Inside the recording, the bake's files must not replace the recording's (a texture named
    // camera_albedo.png): its folder of its own there is new, empty or a bake already.
    if (IsWithin(dir, scene.folder)) {
      if (ResolvedPath(dir) == ResolvedPath(scene.folder)) {
        ThrowInputError("--cache: {} is the recording's folder: a bake cache goes in a folder of its own (name another "
                        "folder)",
                        dir.string());
      }
      std::error_code ec;
      const bool holds_files = fs::is_directory(dir, ec) && !fs::is_empty(dir, ec);
      if (holds_files && !fs::exists(dir / "bake.json", ec)) {
        ThrowInputError("--cache: {} lies in the recording and holds files that are not a bake's: the bake would replace "
                        "them (name another folder)",
                        dir.string());
      }
    }
    return dir;
  }
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  const char* home = std::getenv("HOME");
  const fs::path base = xdg != nullptr && *xdg != '\0' ? fs::path(xdg)
                        : home != nullptr && *home != '\0' ? fs::path(home) / ".cache"
                                                            : fs::temp_directory_path();
  return base / "daylit" / CacheFolderName(scene.name);
}

void SaveBake(const SceneBake& bake, const scene::Scene& scene, const BakeOptions& options, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) ThrowInputError("{}: cannot create the cache folder: {}", dir.string(), ec.message());
  fs::remove(dir / "bake.json", ec);  // stale until the new one is complete
  using T = scene::ExrPixelType;
  {
    const EnvMapMaps& e = bake.env;
    Layers layers;
    layers.Vec3("point", "XYZ", e.point, T::kFloat);
    layers.Vec3("normal", "XYZ", e.normal, T::kHalf);
    layers.Uint("surface", e.surface);
    layers.Scalar("V.Y", e.sky_visibility, T::kHalf);
    layers.Vec3("E", "RGB", e.irradiance, T::kFloat);
    layers.Vec3("albedo", "RGB", e.albedo, T::kHalf);
    layers.Vec3("L", "RGB", e.radiance, T::kFloat);
    layers.Write(dir / "env_maps.exr", e.width, e.height);
  }
  {
    const CameraGBuffer& g = bake.camera;
    Layers layers;
    layers.Vec3("point", "XYZ", g.point, T::kFloat);
    layers.Vec3("normal", "XYZ", g.normal, T::kHalf);
    layers.Uint("surface", g.surface);
    layers.Scalar("V.Y", g.sky_visibility, T::kHalf);
    layers.Vec3("albedo", "RGB", g.albedo, T::kHalf);
    layers.Uint("env_texel", g.env_texel);
    layers.Scalar("diffuse.Y", std::vector<float>(g.diffuse.begin(), g.diffuse.end()), T::kHalf);
    layers.Write(dir / "camera_gbuffer.exr", g.width, g.height);
  }
  if (!bake.gather.texel.empty()) {
    Layers layers;
    layers.Uint("texel", bake.gather.texel);
    layers.Write(dir / "gather.exr", static_cast<int>(bake.gather.directions.size()), static_cast<int>(bake.gather.ProbeCount()));
  }
  WriteFileAtomically(dir / "albedo.csv", AlbedoCsv(bake.albedo_table));
  WritePreviews(bake, dir);
  nlohmann::json j;
  j["format"] = kBakeFormat;
  j["hash"] = bake.hash;
  j["scene"] = fs::absolute(scene.file).string();
  j["options"] = options.Describe();
  j["capture_sun"] = {{"direction", Vec(bake.capture_sun.dir)},
                      {"above_horizon", bake.capture_sun.above_horizon},
                      {"dni_rgb", Vec(bake.capture_sun.dni_rgb)},
                      {"dni_from_map_rgb", Vec(bake.capture_sun.dni_from_map_rgb)},
                      {"disc_texels", bake.capture_sun.disc_texels},
                      {"brightest_offset_deg", bake.capture_sun.brightest_offset_deg}};
  j["surfaces"] = scene.model.surface_names.size();
  j["daylit"] = kVersion;
  j["camera"] = {{"width", bake.camera.width}, {"height", bake.camera.height}, {"diffuse_pixels", bake.camera.DiffuseCount()}};
  j["gather"] = {{"min", Vec(bake.gather.min)},
                 {"max", Vec(bake.gather.max)},
                 {"resolution", {bake.gather.resolution.x, bake.gather.resolution.y, bake.gather.resolution.z}},
                 {"directions", bake.gather.directions.size()}};
  WriteFileAtomically(dir / "bake.json", j.dump(1) + "\n");
}

namespace {

// Reads a cache whose bake.json matches; throws InputError if one of its files is damaged.
SceneBake ReadBake(const fs::path& dir, const std::string& hash, const nlohmann::json& j);

}  // namespace

std::optional<SceneBake> LoadBake(const fs::path& dir, const std::string& hash) {
  if (!fs::is_regular_file(dir / "bake.json")) return std::nullopt;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ReadTextFile(dir / "bake.json"));
    if (j.value("format", "") != kBakeFormat || j.value("hash", "") != hash) return std::nullopt;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
  try {
    return ReadBake(dir, hash, j);
  } catch (const std::exception& e) {  // a damaged cache is re-baked, not an error
    Log().warn("{}: the cached bake cannot be read ({}); baking again", dir.string(), e.what());
    return std::nullopt;
  }
}

namespace {

[[noreturn]] void Damaged(const std::string& what) { throw std::runtime_error(what); }

// Every value the online stages index with or divide by, as the bake makes them: sizes that
// agree, indices inside what they index, finite numbers. A cache that fails is baked again
// (LoadBake), never used: an index past the map read outside it, a NaN point or albedo gave
// all-zero estimates or a NaN replay with exit 0.
bool Finite(float v) { return std::isfinite(v); }
bool Finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

template <typename T>
void CheckFinite(const std::vector<T>& values, const char* file, const char* what) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!Finite(values[i])) Damaged(fmt::format("{}: {} of element {} is not finite", file, what, i));
  }
}

void CheckLoadedBake(const SceneBake& bake, const nlohmann::json& j) {
  const EnvMapMaps& e = bake.env;
  const size_t texels = static_cast<size_t>(e.width) * static_cast<size_t>(e.height);
  if (e.width <= 0 || e.width != 2 * e.height) Damaged(fmt::format("env_maps.exr: {}x{} is not a 2:1 map", e.width, e.height));
  const size_t surfaces = j.value("surfaces", size_t{0});
  for (const auto* v : {&e.point, &e.normal, &e.irradiance, &e.albedo, &e.radiance}) {
    if (v->size() != texels) Damaged(fmt::format("env_maps.exr: {} values for {} texels", v->size(), texels));
  }
  if (e.sky_visibility.size() != texels || e.surface.size() != texels) Damaged("env_maps.exr: a layer of the wrong size");
  CheckFinite(e.point, "env_maps.exr", "point"), CheckFinite(e.normal, "env_maps.exr", "normal");
  CheckFinite(e.irradiance, "env_maps.exr", "E"), CheckFinite(e.albedo, "env_maps.exr", "albedo");
  CheckFinite(e.radiance, "env_maps.exr", "L"), CheckFinite(e.sky_visibility, "env_maps.exr", "V");
  for (size_t t = 0; t < texels; ++t) {
    if (e.surface[t] != kNoSurface && e.surface[t] >= surfaces) Damaged(fmt::format("env_maps.exr: surface {} of texel {}", e.surface[t], t));
  }
  const CameraGBuffer& g = bake.camera;
  const size_t pixels = static_cast<size_t>(g.width) * static_cast<size_t>(g.height);
  const auto& camera = j.at("camera");
  if (g.width != camera.value("width", -1) || g.height != camera.value("height", -1)) {
    Damaged(fmt::format("camera_gbuffer.exr: {}x{}, not the camera's", g.width, g.height));
  }
  for (const auto* v : {&g.point, &g.normal, &g.albedo}) {
    if (v->size() != pixels) Damaged(fmt::format("camera_gbuffer.exr: {} values for {} pixels", v->size(), pixels));
  }
  if (g.sky_visibility.size() != pixels || g.surface.size() != pixels || g.env_texel.size() != pixels || g.diffuse.size() != pixels) {
    Damaged("camera_gbuffer.exr: a layer of the wrong size");
  }
  CheckFinite(g.point, "camera_gbuffer.exr", "point"), CheckFinite(g.normal, "camera_gbuffer.exr", "normal");
  CheckFinite(g.albedo, "camera_gbuffer.exr", "albedo"), CheckFinite(g.sky_visibility, "camera_gbuffer.exr", "V");
  for (size_t p = 0; p < pixels; ++p) {
    if (g.surface[p] != kNoSurface && g.surface[p] >= surfaces) Damaged(fmt::format("camera_gbuffer.exr: surface {} of pixel {}", g.surface[p], p));
    if (g.env_texel[p] != kNoSurface && g.env_texel[p] >= texels) Damaged(fmt::format("camera_gbuffer.exr: env texel {} of pixel {}", g.env_texel[p], p));
  }
  // The gather table: every entry indexes the env map or its sky layer (bake/parallax.h).
  const sh::GatherTables& t = bake.gather;
  if (!t.directions.empty()) {
    if (t.texel.size() != t.ProbeCount() * t.directions.size()) {
      Damaged(fmt::format("gather.exr: {} entries for {} probes × {} directions", t.texel.size(), t.ProbeCount(), t.directions.size()));
    }
    for (const uint32_t texel : t.texel) {
      if (texel >= 2 * t.map_texels) Damaged(fmt::format("gather.exr: texel {} outside the {}-texel map and its sky layer", texel, t.map_texels));
    }
  }
  const glm::vec3 sun[3] = {bake.capture_sun.dir, bake.capture_sun.dni_rgb, bake.capture_sun.dni_from_map_rgb};
  for (const glm::vec3& v : sun) {
    if (!Finite(v)) Damaged("bake.json: capture_sun is not finite");
  }
}

SceneBake ReadBake(const fs::path& dir, const std::string& hash, const nlohmann::json& j) {
  SceneBake bake;
  bake.hash = hash;
  const auto& sun = j.at("capture_sun");
  bake.capture_sun.dir = Vec(sun.at("direction"));
  bake.capture_sun.above_horizon = sun.at("above_horizon").get<bool>();
  bake.capture_sun.dni_rgb = Vec(sun.at("dni_rgb"));
  bake.capture_sun.dni_from_map_rgb = Vec(sun.at("dni_from_map_rgb"));
  bake.capture_sun.disc_texels = sun.at("disc_texels").get<size_t>();
  bake.capture_sun.brightest_offset_deg = sun.at("brightest_offset_deg").get<double>();
  {
    scene::ExrChannels ch = scene::ReadExrChannels(
        dir / "env_maps.exr",
        {"point.X", "point.Y", "point.Z", "normal.X", "normal.Y", "normal.Z", "V.Y", "E.R", "E.G", "E.B", "albedo.R",
         "albedo.G", "albedo.B", "L.R", "L.G", "L.B"},
        {"surface"});
    EnvMapMaps& e = bake.env;
    e.width = ch.width, e.height = ch.height;
    e.point = Gather3(ch, 0), e.normal = Gather3(ch, 3), e.sky_visibility = ch.planes[6];
    e.irradiance = Gather3(ch, 7), e.albedo = Gather3(ch, 10), e.radiance = Gather3(ch, 13);
    e.surface = std::move(ch.uints[0]);
  }
  {
    scene::ExrChannels ch = scene::ReadExrChannels(
        dir / "camera_gbuffer.exr",
        {"point.X", "point.Y", "point.Z", "normal.X", "normal.Y", "normal.Z", "V.Y", "albedo.R", "albedo.G",
         "albedo.B", "diffuse.Y"},
        {"surface", "env_texel"});
    CameraGBuffer& g = bake.camera;
    g.width = ch.width, g.height = ch.height;
    g.point = Gather3(ch, 0), g.normal = Gather3(ch, 3), g.sky_visibility = ch.planes[6], g.albedo = Gather3(ch, 7);
    g.diffuse.resize(ch.planes[10].size());
    for (size_t i = 0; i < g.diffuse.size(); ++i) g.diffuse[i] = ch.planes[10][i] > 0.5f ? 1 : 0;
    g.surface = std::move(ch.uints[0]);
    g.env_texel = std::move(ch.uints[1]);
  }
  const auto& gather = j.at("gather");
  bake.gather.min = Vec(gather.at("min"));
  bake.gather.max = Vec(gather.at("max"));
  const auto& resolution = gather.at("resolution");
  bake.gather.resolution = {resolution.at(0).get<int>(), resolution.at(1).get<int>(), resolution.at(2).get<int>()};
  const int directions = gather.at("directions").get<int>();
  if (directions > kMaxGatherDirections) Damaged(fmt::format("bake.json: {} gather directions (at most {})", directions, kMaxGatherDirections));
  if (directions > 0) {
    for (int a = 0; a < 3; ++a) {  // the bounds scene.json's volume has
      if (bake.gather.resolution[a] < 1 || bake.gather.resolution[a] > scene::kMaxVolumeResolution) {
        Damaged(fmt::format("bake.json: gather resolution {}", resolution.dump()));
      }
    }
    bake.gather.directions = SphericalFibonacci(directions);
    bake.gather.texel = std::move(scene::ReadExrChannels(dir / "gather.exr", {}, {"texel"}).uints[0]);
    bake.gather.map_texels = static_cast<size_t>(bake.env.width) * static_cast<size_t>(bake.env.height);
  }
  const CsvTable albedo = ReadCsvFile(dir / "albedo.csv");
  size_t column[5];
  const char* names[5] = {"surface", "r", "g", "b", "pixels"};
  for (size_t k = 0; k < 5; ++k) column[k] = static_cast<size_t>(albedo.RequireColumn(names[k]));
  for (size_t r = 0; r < albedo.rows.size(); ++r) {
    const auto& row = albedo.rows[r];
    const auto number = [&](size_t k) { return ParseFiniteDouble(row[column[k]], albedo.Where(r)); };
    bake.albedo_table.push_back({row[column[0]], glm::vec3(number(1), number(2), number(3)),
                                 static_cast<size_t>(ParseCount(row[column[4]], albedo.Where(r), INT32_MAX))});
  }
  const auto start = std::chrono::steady_clock::now();
  CheckLoadedBake(bake, j);
  Log().debug("{}: the cached bake checked in {:.1f} ms", dir.string(),
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return bake;
}

}  // namespace

SceneBake BakeOrLoad(const scene::Scene& scene, const BakeOptions& options, const fs::path& dir, bool* loaded) {
  const std::string hash = BakeHash(scene, options);
  if (std::optional<SceneBake> cached = LoadBake(dir, hash)) {
    *loaded = true;
    return std::move(*cached);
  }
  *loaded = false;
  // The folder first: a cache that cannot be written is said before the bake, not after it.
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    ThrowInputError("{}: cannot create the cache folder: {}", dir.string(), ec ? ec.message() : "a file is in the way");
  }
  if (::access(dir.c_str(), W_OK) != 0) ThrowInputError("{}: the cache folder may not be written to", dir.string());
  SaveBake(RunBake(scene, options), scene, options, dir);
  // Read back: the run goes on with the bake as the cache holds it (normals, V and albedo in half
  // floats), so that it and every later run from the cache give the same figures to the last digit.
  if (std::optional<SceneBake> stored = LoadBake(dir, hash)) return std::move(*stored);
  ThrowInputError("{}: the bake just written there cannot be read back", dir.string());
}

}  // namespace daylit::bake
