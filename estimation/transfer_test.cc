#include "estimation/transfer.h"

#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/constants.hpp>

#include "bake/synthetic_recording.h"
#include "base/log.h"

namespace daylit::estimation {
namespace {

// An open ground and a 3 m high, 200 m long wall at x = 1 facing −X, seen by a camera at
// (−3, 0, 1.5) looking along +X: the wall fills the middle of the image, the ground in front of it
// the bottom.
struct WallView {
  bake::testing::SyntheticRecording rec{"transfer"};
  scene::Scene scene;
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;

  explicit WallView(std::function<glm::vec3(const glm::dvec3&)> env = nullptr) {
    SetLogVerbosity(0);
    if (env) rec.env = std::move(env);
    rec.obj += "o wall\nv 1 -100 0\nv 1 100 0\nv 1 100 3\nv 1 -100 3\nf 5 6 7 8\n";
    rec.scene["diffuse_surfaces"] = {"ground", "wall"};
    rec.scene["camera"]["world_to_camera"] = {{"rotation", {{0, -1, 0}, {0, 0, -1}, {1, 0, 0}}},
                                              {"translation", {0, 1.5, 3}}};
    // Noon at (0°, 0°) on the solstice: the sun is up at capture time (its DNI given as 0).
    rec.scene["envmap"]["time_utc"] = "2026-06-21T12:00:00Z";
    scene = scene::LoadScene(rec.Write());
    bake = bake::RunBake(scene, bake::BakeOptions{});
    caster = std::make_unique<scene::RayCaster>(scene.model);
  }

  std::vector<uint32_t> PixelsOf(uint32_t surface) const {
    std::vector<uint32_t> pixels;
    for (size_t i = 0; i < bake.camera.surface.size(); ++i) {
      if (bake.camera.surface[i] == surface) pixels.push_back(static_cast<uint32_t>(i));
    }
    return pixels;
  }
};

// View factor from an upward-facing point to an infinitely long vertical wall of height h at
// horizontal distance d: (1 − d/√(d² + h²)) / 2.
double WallViewFactor(double d, double h) { return 0.5 * (1.0 - d / std::sqrt(d * d + h * h)); }

TEST(TransferTest, OneBounceOffASunlitWallMatchesItsViewFactor) {
  WallView w;
  // Known albedos instead of the map's (whose "wall" texels show sky): wall 0.5, ground 0, and no
  // env maps, so every bounce point takes its surface's albedo and a ray-cast V.
  w.bake.albedo_table[0].albedo = glm::vec3(0.0f);
  w.bake.albedo_table[1].albedo = glm::vec3(0.5f, 0.3f, 0.1f);
  w.bake.env = {};
  TransferOptions options;
  options.rays = 1024;
  options.cell_rays = 256;
  options.bounces = 1;  // the analytic figure is for one bounce
  LightTransfer transfer(w.bake, TransferPoints::Camera(w.bake.camera), glm::vec3(w.scene.envmap->position), *w.caster, options);
  // The sun 45° high behind the camera lights the ground and the wall's face toward it.
  const glm::vec3 sun = glm::normalize(glm::vec3(-1.0f, 0.0f, 1.0f));
  const float cos45 = std::sqrt(0.5f);
  const std::vector<uint32_t> ground = w.PixelsOf(0);
  ASSERT_GT(ground.size(), 100u);
  std::vector<float> direct(w.bake.camera.surface.size(), cos45);
  std::vector<Transfer> t(ground.size());
  transfer.Compute(ground, sun, direct.data(), t.data());
  size_t checked = 0;
  for (size_t k = 0; k < ground.size(); ++k) {
    const glm::vec3& p = w.bake.camera.point[ground[k]];
    if (std::abs(p.y) > 2.0f || p.x > 0.9f) continue;  // the wall's far ends and its foot are ignored
    const double f = WallViewFactor(1.0 - p.x, 3.0);
    for (int c = 0; c < 3; ++c) {
      const double rho = w.bake.albedo_table[1].albedo[c];
      // Reflected: the wall's albedo × its irradiance per unit DNI (cos 45°) × view factor, and
      // for the sky its V (0.5: a vertical face sees half the sky) likewise, on top of the
      // point's own V (1 − f, as the bake measured it).
      const double v = w.bake.camera.sky_visibility[ground[k]];
      EXPECT_NEAR(t[k].sun[c], cos45 * (1.0 + rho * f), 0.01) << p.x << " channel " << c;
      EXPECT_NEAR(t[k].overcast[c], v + rho * 0.5 * f, 0.01) << p.x << " channel " << c;
    }
    ++checked;
  }
  EXPECT_GT(checked, 50u);

  // Without interreflection the terms are seed 001's: s·max(0, n·l) and V.
  options.interreflection = false;
  LightTransfer plain(w.bake, TransferPoints::Camera(w.bake.camera), glm::vec3(w.scene.envmap->position), *w.caster, options);
  plain.Compute(ground, sun, direct.data(), t.data());
  for (size_t k = 0; k < ground.size(); ++k) {
    EXPECT_EQ(t[k].sun, glm::vec3(cos45));
    EXPECT_EQ(t[k].overcast, glm::vec3(w.bake.camera.sky_visibility[ground[k]]));
  }
  // The sun below the horizon: no sun term.
  plain.Compute(ground, glm::vec3(0.0f, 0.0f, -1.0f), direct.data(), t.data());
  EXPECT_EQ(t.front().sun, glm::vec3(0.0f));
}

TEST(TransferTest, AWallSeesTheSkyInItsDistribution) {
  // A sky brightest at the zenith, L = cos θ: per unit DHI (2π/3) a vertical wall receives
  // ∫ cos θ · cos(n, ω) dω / (2π/3) = (2/3) / (2π/3) = 1/π, not the uniform sky's V = 0.5.
  WallView w([](const glm::dvec3& d) { return d.z > 0.0 ? glm::vec3(static_cast<float>(d.z)) : glm::vec3(0.0f); });
  TransferOptions options;
  options.rays = 1024;
  options.interreflection = false;
  LightTransfer transfer(w.bake, TransferPoints::Camera(w.bake.camera), glm::vec3(w.scene.envmap->position), *w.caster, options);
  const std::vector<uint32_t> wall = w.PixelsOf(1);
  ASSERT_GT(wall.size(), 100u);
  const std::vector<float> direct(w.bake.camera.surface.size(), 0.0f);
  std::vector<Transfer> t(wall.size());
  for (const glm::vec3& sun : {glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f)), glm::normalize(glm::vec3(-1.0f, 0.0f, 0.5f))}) {
    transfer.Compute(wall, sun, direct.data(), t.data());
    for (size_t k = 0; k < wall.size(); ++k) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(t[k].clear[c], glm::one_over_pi<double>(), 0.01) << k;
    }
  }
}

TEST(TransferTest, SkyDistributionIntegratesToItsHorizontalIrradiance) {
  // L = 1 + 2·cos γ⁺ (brighter toward the sun): DHI = π + 2 ∫ max(0, cos γ) cos θ dω, which for
  // the sun at the zenith is π + 4π/3.
  const int w = 512, h = 256;
  HdrImage env{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  const glm::vec3 zenith(0.0f, 0.0f, 1.0f);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const glm::dvec3 d = LatLongDirection(u, v, w, h);
      for (int c = 0; c < 3; ++c) env.Pixel(u, v)[c] = static_cast<float>(1.0 + 2.0 * std::max(0.0, d.z));
    }
  }
  const bake::SkyDistribution sky(env, std::vector<uint8_t>(static_cast<size_t>(w) * h, 1), zenith);
  EXPECT_NEAR(sky.HorizontalIrradiance(zenith).x, glm::pi<double>() + 4.0 * glm::pi<double>() / 3.0, 0.02);
}

}  // namespace
}  // namespace daylit::estimation
