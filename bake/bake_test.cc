#include "bake/bake.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "bake/synthetic_recording.h"
#include "bake/texture_detail.h"
#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"
#include "base/latlong.h"
#include "scene/hdr_image.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::bake {
namespace {

using testing::SyntheticRecording;

scene::SceneModel GroundAndLongWall() {
  // Ground, and a wall 400 m long and 200 m tall standing at x = 1: practically infinite for V.
  scene::SceneModel m;
  m.surface_names = {"ground", "wall"};
  m.vertices = {{-500, -500, 0}, {500, -500, 0}, {500, 500, 0}, {-500, 500, 0},
                {1, -200, 0},    {1, 200, 0},    {1, 200, 200}, {1, -200, 200}};
  m.triangles = {{{0, 1, 2}, 0}, {{0, 2, 3}, 0}, {{4, 6, 5}, 1}, {{4, 7, 6}, 1}};
  return m;
}

TEST(BakeTest, SkyVisibilityMatchesAnalyticValues) {
  const scene::SceneModel model = GroundAndLongWall();
  const scene::RayCaster caster(model);
  // Ground at the foot of the wall, and the wall's face 2 m up: the vertical plane cuts the
  // cosine-weighted hemisphere in half, so 0.5 (the ground's edge 500 m away hides 0.2° of the
  // wall's lower half). Open ground, far behind the wall's end: 1. The 0.01 bar is the issue's.
  const std::vector<glm::vec3> points = {{0, 495, 0}, {0.999f, 0, 0}, {1, 0, 2}};
  const std::vector<glm::vec3> normals = {{0, 0, 1}, {0, 0, 1}, {-1, 0, 0}};
  std::vector<float> v(points.size());
  SkyVisibility(caster, RayOptions{}, points.data(), normals.data(), points.size(), v.data(), nullptr);
  EXPECT_NEAR(v[0], 1.0f, 0.01f);
  EXPECT_NEAR(v[1], 0.5f, 0.01f);
  EXPECT_NEAR(v[2], 0.5f, 0.01f);
  // Many random points on the foot line: each within 0.01 (stratified rays, per-point rotation).
  std::vector<glm::vec3> foot, up;
  for (int i = 0; i < 200; ++i) foot.emplace_back(0.999f, -50.0f + 0.5f * static_cast<float>(i), 0.0f), up.emplace_back(0, 0, 1);
  std::vector<float> vf(foot.size());
  SkyVisibility(caster, RayOptions{}, foot.data(), up.data(), foot.size(), vf.data(), nullptr);
  for (const float x : vf) ASSERT_NEAR(x, 0.5f, 0.01f);
}

TEST(BakeTest, SunVisibilityCastsTheWallsShadow) {
  const scene::SceneModel model = GroundAndLongWall();
  const scene::RayCaster caster(model);
  const glm::vec3 sun = glm::normalize(glm::vec3(1.0f, 0.0f, 1.0f));  // 45° high, behind the wall
  const std::vector<glm::vec3> points = {{-100, 0, 0}, {-300, 0, 0}, {2, 0, 0}, {0, 0, 0}};
  const std::vector<glm::vec3> normals(points.size(), glm::vec3(0, 0, 1));
  std::vector<uint8_t> lit(points.size());
  SunVisibility(caster, points.data(), normals.data(), points.size(), sun, 2e-3f, lit.data());
  // The 200 m wall shades 200 m of ground west of it; beyond and east of it is sunlit.
  EXPECT_EQ(lit, (std::vector<uint8_t>{0, 1, 1, 0}));
  const glm::vec3 down(0, 0, -1);
  SunVisibility(caster, points.data(), &down, 1, sun, 2e-3f, lit.data());
  EXPECT_EQ(lit[0], 0);  // facing away
}

TEST(BakeTest, SunDiscIsMeasuredAndRemoved) {
  HdrImage env{1024, 512, std::vector<float>(1024 * 512 * 3, 2.0f)};
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.3, 0.5, 0.6));
  double dni = 0.0;
  for (int v = 0; v < env.height; ++v) {
    for (int u = 0; u < env.width; ++u) {
      if (glm::dot(LatLongDirection(u, v, env.width, env.height), sun) < std::cos(glm::radians(0.6))) continue;
      float* p = env.Pixel(u, v);
      p[0] = 5002.0f, p[1] = 4002.0f, p[2] = 3002.0f;
      dni += 5000.0 * LatLongTexelSolidAngle(v, env.width, env.height);
    }
  }
  const CaptureSun found = ExtractSun(&env, sun, std::nullopt, "test");
  EXPECT_NEAR(found.dni_from_map_rgb.x, dni, dni * 1e-4);
  EXPECT_NEAR(found.dni_rgb.z, dni * 0.6, dni * 1e-4);  // no given DNI: the map's own
  EXPECT_LT(found.brightest_offset_deg, 0.6);
  float peak = 0.0f;
  for (const float x : env.rgb) peak = std::max(peak, x);
  EXPECT_FLOAT_EQ(peak, 2.0f);  // the disc is gone, the sky behind it restored
  const CaptureSun given = ExtractSun(&env, sun, glm::dvec3(80, 60, 40), "test");
  EXPECT_FLOAT_EQ(given.dni_rgb.y, 60.0f);
  const CaptureSun night = ExtractSun(&env, -sun, glm::dvec3(80, 60, 40), "test");
  EXPECT_EQ(night.dni_rgb, glm::vec3(0.0f));
}

TEST(BakeTest, SkyFillFollowsZenithAngleAndSunAngle) {
  // A sky that brightens toward the horizon (radiance 1 + 9·(1 − cos θ)), with the lower half of
  // the azimuths hidden (is_sky = 0): the fill must restore the same law there.
  HdrImage env{360, 180, std::vector<float>(360 * 180 * 3, 0.0f)};
  std::vector<uint8_t> is_sky(360 * 180, 0);
  for (int v = 0; v < 90; ++v) {
    for (int u = 0; u < 360; ++u) {
      const glm::dvec3 d = LatLongDirection(u, v, 360, 180);
      float* p = env.Pixel(u, v);
      const float l = static_cast<float>(1.0 + 9.0 * (1.0 - d.z));
      if (u < 180) {
        p[0] = p[1] = p[2] = l;
        is_sky[static_cast<size_t>(v) * 360 + u] = 1;
      }
    }
  }
  const HdrImage sky = sky::SkyOnly(env, is_sky, glm::vec3(0, 0, 1));  // sun at the zenith: γ = θ
  for (int v = 0; v < 90; v += 7) {
    const float expected = static_cast<float>(1.0 + 9.0 * (1.0 - LatLongDirection(270, v, 360, 180).z));
    EXPECT_NEAR(sky.Pixel(270, v)[0], expected, 0.2f) << v;  // within a 1° bin's spread
  }
}

TEST(BakeTest, UniformSkyGivesBackTheGroundAlbedo) {
  SyntheticRecording rec("albedo");
  const scene::Scene scene = scene::LoadScene(rec.Write());
  const SceneBake bake = RunBake(scene, BakeOptions{});
  ASSERT_EQ(bake.albedo_table[0].surface, "ground");
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(bake.albedo_table[0].albedo[c], 0.4f, 0.4f * 0.01f);
  // Every camera pixel sees the ground, diffuse, V = 1, albedo 0.4 (the one frame is flat).
  EXPECT_EQ(bake.camera.DiffuseCount(), 64u * 48u);
  for (size_t i = 0; i < bake.camera.albedo.size(); i += 97) {
    ASSERT_NEAR(bake.camera.sky_visibility[i], 1.0f, 0.01f);
    ASSERT_NEAR(bake.camera.albedo[i].y, 0.4f, 0.4f * 0.02f);
  }
  // Gather tables: 8 probes × 256 directions; ground directions take the texel that shows their
  // hit point from the capture position (parallax), sky directions the sky layer's texel in their
  // direction, after the map's W·H texels (bake/parallax.h).
  ASSERT_EQ(bake.gather.ProbeCount(), 8u);
  const sh::GatherTables& g = bake.gather;
  const size_t map_texels = static_cast<size_t>(bake.env.width) * static_cast<size_t>(bake.env.height);
  ASSERT_EQ(g.map_texels, map_texels);
  const glm::vec3 capture(0.0f, 0.0f, 1.5f);
  for (size_t d = 0; d < g.directions.size(); ++d) {
    const glm::vec3 probe = g.ProbePosition(1, 1, 0);  // (1, 1, 0.5)
    const size_t probe_index = (0 * 2 + 1) * 2 + 1;
    const glm::vec3 dir = g.directions[d];
    const glm::vec3 ground = probe + (-probe.z / dir.z) * dir;  // the ground ends 100 m out
    const bool hits = dir.z < 0.0f && std::abs(ground.x) <= 100.0f && std::abs(ground.y) <= 100.0f;
    const uint32_t want = hits ? static_cast<uint32_t>(LatLongTexel(glm::dvec3(ground - capture), bake.env.width, bake.env.height))
                                       : static_cast<uint32_t>(map_texels) +
                                             static_cast<uint32_t>(LatLongTexel(glm::dvec3(dir), bake.env.width, bake.env.height));
    EXPECT_EQ(g.texel[probe_index * g.directions.size() + d], want);
  }
}

TEST(BakeTest, DiffuseMaskOverTheEnvMapSelectsPixels) {
  // A mask that allows only the env-map texels west of the capture point (x < 0): exactly the
  // camera pixels that see ground with x < 0 become diffuse.
  SyntheticRecording rec("mask");
  cv::Mat mask(rec.env_width / 2, rec.env_width, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      if (LatLongDirection(u, v, mask.cols, mask.rows).x < 0.0) mask.at<uint8_t>(v, u) = 255;
    }
  }
  rec.Write();
  cv::imwrite((rec.dir / "mask.png").string(), mask);
  rec.scene.erase("diffuse_surfaces");
  rec.scene["diffuse_mask"] = "mask.png";
  const SceneBake bake = RunBake(scene::LoadScene(rec.Write()), BakeOptions{});
  size_t mismatches = 0, diffuse = 0;
  for (size_t i = 0; i < bake.camera.diffuse.size(); ++i) {
    const float x = bake.camera.point[i].x;
    if (std::abs(x) < 0.05f) continue;  // the texel column on the boundary
    mismatches += (bake.camera.diffuse[i] != 0) != (x < 0.0f);
    diffuse += bake.camera.diffuse[i];
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_NEAR(static_cast<double>(diffuse), 64.0 * 48.0 / 2.0, 64.0 * 2.0);
}

std::string BakeErrorOf(SyntheticRecording& rec, int env_height = 0) {
  try {
    RunBake(scene::LoadScene(rec.Write(env_height)), BakeOptions{});
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(BakeTest, ASceneNameNeverBecomesAPath) {
  for (const std::string name : {"../../escaped", "/etc/cron.d", "", ".", "..", "a/b\\c", "x\ny", "courtyard-a"}) {
    const std::string folder = CacheFolderName(name);
    EXPECT_FALSE(folder.empty()) << name;
    EXPECT_EQ(folder.find('/'), std::string::npos) << name;
    EXPECT_NE(folder, ".");
    EXPECT_NE(folder, "..");
    EXPECT_EQ(std::filesystem::path(folder).filename().string(), folder) << name;
    scene::Scene scene;
    scene.name = name;
    EXPECT_EQ(CacheDir(scene, {}).parent_path().filename(), "daylit") << name;
  }
  EXPECT_EQ(CacheFolderName("courtyard-a"), "courtyard-a");
  EXPECT_EQ(CacheFolderName("../../escaped"), ".._.._escaped");
  EXPECT_EQ(CacheFolderName(".."), "unnamed..");
  EXPECT_EQ(CacheFolderName(std::string(300, 'a')).size(), 100u);
}

TEST(BakeTest, BadInputsAreNamed) {
  {
    SyntheticRecording rec("nan");
    rec.env = [](const glm::dvec3& d) { return d.z > 0.99 ? glm::vec3(NAN) : glm::vec3(1.0f); };
    EXPECT_NE(BakeErrorOf(rec).find("are NaN or infinite"), std::string::npos);
  }
  {
    SyntheticRecording rec("negative");
    rec.env = [](const glm::dvec3& d) { return d.z < -0.99 ? glm::vec3(-1.0f) : glm::vec3(1.0f); };
    EXPECT_NE(BakeErrorOf(rec).find("are negative"), std::string::npos);
  }
  {
    SyntheticRecording rec("ratio");
    EXPECT_NE(BakeErrorOf(rec, 100).find("is not a 2:1 latitude-longitude map"), std::string::npos);
  }
  {
    SyntheticRecording rec("inside");  // a closed box (outward faces) around the capture point
    rec.obj += "o box\nv -1 -1 0.5\nv 1 -1 0.5\nv 1 1 0.5\nv -1 1 0.5\nv -1 -1 2.5\nv 1 -1 2.5\nv 1 1 2.5\nv -1 1 2.5\n"
               "f 9 10 11 12\nf 9 12 8 5\nf 8 7 6 5\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\n";
    EXPECT_NE(BakeErrorOf(rec).find("envmap.position (0, 0, 1.5) is inside the model"), std::string::npos)
        << BakeErrorOf(rec);
  }
  {
    SyntheticRecording rec("nodiffuse");  // the only diffuse surface lies behind the camera
    rec.obj += "o roof\nv -1 -1 9\nv 1 -1 9\nv 1 1 9\nf 1 2 3\n";
    rec.obj.replace(rec.obj.find("f 1 2 3\n"), 8, "f 5 6 7\n");
    rec.scene["diffuse_surfaces"] = {"roof"};
    EXPECT_NE(BakeErrorOf(rec).find("the camera sees no diffuse surface (diffuse_surfaces: roof)"), std::string::npos)
        << BakeErrorOf(rec);
  }
  {
    SyntheticRecording rec("degenerate");  // a zero-area triangle is left out, with a warning
    rec.obj += "o sliver\nv 0 0 3\nv 1 0 3\nv 2 0 3\nf 5 6 7\n";
    const scene::Scene scene = scene::LoadScene(rec.Write());
    EXPECT_EQ(scene::RayCaster(scene.model).degenerate_triangles(), 1u);
    EXPECT_NO_THROW(RunBake(scene, BakeOptions{}));
  }
}

// A cached gather table whose entries reach past the map and its sky layer (a damaged or hostile
// cache) is not loaded, so the volume never reads outside the map; the bake is then made again.
TEST(BakeTest, ACachedGatherTableOutsideTheMapIsBakedAgain) {
  SyntheticRecording rec("gather_cache");
  const scene::Scene scene = scene::LoadScene(rec.Write());
  const BakeOptions options;
  const SceneBake bake = RunBake(scene, options);
  const std::filesystem::path dir = rec.dir / "cache";
  SaveBake(bake, scene, options, dir);
  const std::string hash = BakeHash(scene, options);
  ASSERT_TRUE(LoadBake(dir, hash).has_value());
  std::vector<uint32_t> texel = bake.gather.texel;
  texel[17] = static_cast<uint32_t>(2 * bake.gather.map_texels);  // one past the sky layer's last texel
  scene::WriteExr(dir / "gather.exr", static_cast<int>(bake.gather.directions.size()), static_cast<int>(bake.gather.ProbeCount()),
                  {{"texel", scene::ExrPixelType::kUint, nullptr, texel.data()}});
  EXPECT_FALSE(LoadBake(dir, hash).has_value());
  texel[17] = static_cast<uint32_t>(2 * bake.gather.map_texels - 1);  // the last one is fine
  scene::WriteExr(dir / "gather.exr", static_cast<int>(bake.gather.directions.size()), static_cast<int>(bake.gather.ProbeCount()),
                  {{"texel", scene::ExrPixelType::kUint, nullptr, texel.data()}});
  EXPECT_TRUE(LoadBake(dir, hash).has_value());
}

// A bake.json with the right format and hash but a field missing, of the wrong type or out of
// range is a damaged cache: baked again, never read past (fuzz/regressions/bake_cache).
TEST(BakeTest, ABakeJsonWithAFieldMissingOrOutOfRangeIsBakedAgain) {
  SyntheticRecording rec("bake_json_fields");
  const scene::Scene scene = scene::LoadScene(rec.Write());
  const BakeOptions options;
  const std::filesystem::path dir = rec.dir / "cache";
  SaveBake(RunBake(scene, options), scene, options, dir);
  const std::string hash = BakeHash(scene, options);
  const nlohmann::json pristine = nlohmann::json::parse(ReadTextFile(dir / "bake.json"));
  ASSERT_TRUE(LoadBake(dir, hash).has_value());
  const std::vector<std::pair<std::string, std::function<void(nlohmann::json&)>>> damage = {
      {"no capture_sun", [](auto& j) { j.erase("capture_sun"); }},
      {"no capture sun direction", [](auto& j) { j["capture_sun"].erase("direction"); }},
      {"a two-element direction", [](auto& j) { j["capture_sun"]["direction"] = {0, 1}; }},
      {"no camera", [](auto& j) { j.erase("camera"); }},
      {"no gather", [](auto& j) { j.erase("gather"); }},
      {"no gather resolution", [](auto& j) { j["gather"].erase("resolution"); }},
      {"a gather resolution of zero", [](auto& j) { j["gather"]["resolution"][1] = 0; }},
      {"two billion gather directions", [](auto& j) { j["gather"]["directions"] = 2000000000; }},
      {"a string for directions", [](auto& j) { j["gather"]["directions"] = "many"; }},
  };
  for (const auto& [name, change] : damage) {
    nlohmann::json j = pristine;
    change(j);
    WriteFileAtomically(dir / "bake.json", j.dump(1));
    EXPECT_FALSE(LoadBake(dir, hash).has_value()) << name;
  }
  WriteFileAtomically(dir / "bake.json", pristine.dump(1));
  EXPECT_TRUE(LoadBake(dir, hash).has_value());
}

// Texture detail D = I / blur(I) is relative to the pixel's own surface: a box reaching over an
// edge into a brighter surface made D, and the camera albedo, too low along the edge
// (courtyard-c's far ground, a strip under a white building: −7.2% in green). Hand-built: a
// striped surface (rows alternating between two codes) beside a bright one, seen straight down;
// at the edge and in the interior, D is the stripes' own ratio 5a / (3a + 2b) for the 5-pixel box
// both use there (a texel of π/12 at 1.5–1.7 m from the capture point, ×1.5, seen from 5 m).
TEST(BakeTest, TextureDetailIsRelativeToThePixelsOwnSurface) {
  SyntheticRecording rec("detail_edge");
  rec.env_width = 24;
  rec.obj = "o striped\nv -100 -100 0\nv 0 -100 0\nv 0 100 0\nv -100 100 0\nf 1 2 3 4\n"
            "o bright\nv 0 -100 0\nv 100 -100 0\nv 100 100 0\nv 0 100 0\nf 1 2 3 4\n";
  rec.scene["diffuse_surfaces"] = {"striped", "bright"};
  const scene::Scene scene = scene::LoadScene(rec.Write());
  // Camera x is world x (cx = 31.5): columns 0–31 see the striped surface, 32–63 the bright one.
  constexpr uint8_t kA = 100, kB = 60, kBright = 230;
  cv::Mat frame(48, 64, CV_8UC3);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) frame.at<cv::Vec3b>(v, u) = cv::Vec3b::all(u >= 32 ? kBright : (v % 2 ? kB : kA));
  }
  ASSERT_TRUE(cv::imwrite((rec.dir / "frames" / "000000.png").string(), frame));
  std::vector<glm::vec3> points(64 * 48);
  std::vector<uint32_t> surface(points.size());
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {  // the ground point under pixel (u, v), 5 m below the camera
      const size_t i = static_cast<size_t>(v) * 64 + u;
      points[i] = glm::vec3(5.0f * (static_cast<float>(u) - 31.5f) / 40.0f, -5.0f * (static_cast<float>(v) - 23.5f) / 40.0f, 0.0f);
      surface[i] = u >= 32 ? 1 : 0;
    }
  }
  const std::vector<glm::vec3> d = CameraTextureDetail(scene, points, surface, std::vector<uint8_t>(points.size(), 1), 12, DetailOptions{});
  const std::array<float, 256> lut = scene.response.LinearLut8(1);
  for (int v = 18; v < 30; ++v) {  // the rows where both columns use the 5-pixel box
    const size_t row = static_cast<size_t>(v) * 64;
    const float a = lut[v % 2 ? kB : kA], b = lut[v % 2 ? kA : kB];
    const float expected = 5.0f * a / (3.0f * a + 2.0f * b);
    for (const int u : {28, 31}) {  // interior, and the column next to the bright surface
      EXPECT_NEAR(d[row + static_cast<size_t>(u)].y, expected, 0.01f * expected) << "row " << v << " column " << u;
    }
    EXPECT_NEAR(d[row + 32].y, 1.0f, 0.01f) << "row " << v;  // the bright side's edge: flat
  }
}

}  // namespace
}  // namespace daylit::bake
