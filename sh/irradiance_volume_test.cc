#include "sh/irradiance_volume.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include "bake/bake.h"
#include "bake/sampling.h"
#include "bake/synthetic_recording.h"
#include "base/latlong.h"
#include "base/log.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::sh {
namespace {

// An open ground under a uniform sky of radiance 1 (the ground then has radiance 0.4), probes
// 2×2×2 over [-1, 1]² × [0.5, 1.5].
struct OpenGround {
  bake::testing::SyntheticRecording rec;
  scene::Scene scene;
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;

  explicit OpenGround(const std::string& name, const std::string& extra_obj = "") : rec(name) {
    SetLogVerbosity(0);
    rec.obj += extra_obj;
    scene = scene::LoadScene(rec.Write());
    bake = bake::RunBake(scene, bake::BakeOptions{});
    caster = std::make_unique<scene::RayCaster>(scene.model);
  }
};

// `map` (W×H) stacked on its sky layer (bake/parallax.h): the synthetic recordings' sky, 1 above
// the horizon and 0.4 below (what their maps show where the ground ends).
std::vector<glm::vec3> Stacked(const std::vector<glm::vec3>& map, int width, int height) {
  std::vector<glm::vec3> stacked = map;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) stacked.push_back(glm::vec3(LatLongDirection(u, v, width, height).z > 0.0 ? 1.0f : 0.4f));
  }
  return stacked;
}

std::vector<glm::vec3> CapturedStacked(const bake::SceneBake& bake) {
  return Stacked(bake.env.radiance, bake.env.width, bake.env.height);
}

TEST(IrradianceVolumeTest, OpenGroundGivesTheHemispheresIrradiance) {
  const OpenGround w("volume_open");
  IrradianceVolume volume(w.bake.gather, bake::ProbesInsideModel(w.bake.gather, *w.caster));
  EXPECT_EQ(volume.InsideCount(), 0u);
  volume.Update(CapturedStacked(w.bake));
  // Sky 1 above, ground 0.4 below: facing up π, facing down 0.4π, sideways 0.7π (SH9 is exact
  // for these three on a two-level sphere; what is left is the 256-direction quadrature).
  const glm::vec3 up(0, 0, 1), down(0, 0, -1), side(1, 0, 0);
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 2; ++j) {
      for (int i = 0; i < 2; ++i) {
        EXPECT_NEAR(volume.ProbeIrradiance(i, j, k, up).x, glm::pi<float>(), 0.02f * glm::pi<float>());
        EXPECT_NEAR(volume.ProbeIrradiance(i, j, k, down).y, 0.4f * glm::pi<float>(), 0.02f * glm::pi<float>());
        EXPECT_NEAR(volume.ProbeIrradiance(i, j, k, side).z, 0.7f * glm::pi<float>(), 0.02f * glm::pi<float>());
      }
    }
  }
  // Between probes and outside the box (clamped): the same field.
  EXPECT_NEAR(volume.Irradiance(glm::vec3(0.3f, -0.2f, 1.0f), up).x, glm::pi<float>(), 0.02f * glm::pi<float>());
  EXPECT_NEAR(volume.Irradiance(glm::vec3(5.0f, 5.0f, 9.0f), down).x, 0.4f * glm::pi<float>(), 0.02f * glm::pi<float>());
}

// A direction that escapes from a probe reads the sky, also where the capture point sees the
// model that way. Here the capture point stands 3 m in front of a bright wall 3 m high (radiance
// 10, as a sunlit terracotta wall), so the map shows the wall up to 27° above the horizon toward
// +Y; probes 10 m from the wall, just under its top, see it only below the horizon and sky above.
// Their irradiance facing the wall is checked against a brute-force integral of the same scene
// (Embree, 20 000 cosine-weighted rays, the radiance of what each ray meets).
TEST(IrradianceVolumeTest, ADirectionThatEscapesReadsTheSkyNotWhatTheCapturePointSeesThatWay) {
  bake::testing::SyntheticRecording rec("volume_sky_parallax");
  rec.obj += "o wall\nv -50 3 0\nv 50 3 0\nv 50 3 3\nv -50 3 3\nf 5 8 7 6\n";
  rec.env_width = 512;
  const glm::dvec3 capture(0.0, 0.0, 1.5);
  const auto radiance = [](bool wall, const glm::dvec3& d) { return wall ? 10.0f : d.z > 0.0 ? 1.0f : 0.4f; };
  rec.env = [&](const glm::dvec3& d) {
    const double t = d.y > 0.0 ? (3.0 - capture.y) / d.y : -1.0;
    const glm::dvec3 p = capture + t * d;
    return glm::vec3(radiance(t > 0.0 && std::abs(p.x) <= 50.0 && p.z >= 0.0 && p.z <= 3.0, d));
  };
  rec.scene["volume"] = {{"min", {-1, -8, 2.5}}, {"max", {1, -7, 2.9}}, {"resolution", {2, 2, 2}}};
  SetLogVerbosity(0);
  const scene::Scene scene = scene::LoadScene(rec.Write());
  const bake::SceneBake baked = bake::RunBake(scene, bake::BakeOptions{});
  const scene::RayCaster caster(scene.model);
  const int wall = scene.model.SurfaceIndex("wall");
  ASSERT_GE(wall, 0);
  IrradianceVolume volume(baked.gather);
  volume.Update(CapturedStacked(baked));
  const glm::vec3 toward_wall(0.0f, 1.0f, 0.0f);
  const std::vector<glm::vec3> hemisphere = bake::CosineHemisphere(20000);
  for (int j = 0; j < 2; ++j) {
    const glm::vec3 probe = baked.gather.ProbePosition(0, j, 1);
    const glm::mat3 frame = bake::HemisphereFrame(toward_wall, 1u);
    double right = 0.0, straight = 0.0;
    for (const glm::vec3& local : hemisphere) {
      const glm::vec3 dir = frame * local;
      const scene::RayHit hit = caster.Intersect(probe, dir);
      const bool meets_wall = hit.IsHit() && static_cast<int>(hit.surface) == wall;
      right += radiance(meets_wall, glm::dvec3(dir));
      // What reading the map straight in an escaping direction would give.
      straight += hit.IsHit() ? radiance(meets_wall, glm::dvec3(dir)) : rec.env(glm::dvec3(dir)).x;
    }
    right *= glm::pi<double>() / static_cast<double>(hemisphere.size());
    straight *= glm::pi<double>() / static_cast<double>(hemisphere.size());
    const double got = volume.ProbeIrradiance(0, j, 1, toward_wall).x;
    std::printf("probe %d m from the wall: volume %.3f, brute force %.3f (the map read straight: %.3f)\n",
                static_cast<int>(std::lround(3.0f - probe.y)), got, right, straight);
    EXPECT_NEAR(got, right, 0.03 * right);
    EXPECT_GT(straight, 1.5 * right);  // the error this guards against
  }
}

TEST(IrradianceVolumeTest, InterpolationIsTrilinearBetweenProbes) {
  const OpenGround w("volume_lerp");
  IrradianceVolume volume(w.bake.gather);
  // A made-up map: texel radiance grows with the texel index, so that probes differ (their
  // gather directions read different texels through parallax).
  std::vector<glm::vec3> radiance(2 * w.bake.env.radiance.size());
  for (size_t t = 0; t < radiance.size(); ++t) radiance[t] = glm::vec3(static_cast<float>(t % 97) / 97.0f);
  volume.Update(radiance);
  const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(volume.Irradiance(w.bake.gather.ProbePosition(i, 1, 0), n).x, volume.ProbeIrradiance(i, 1, 0, n).x, 1e-5f);
  }
  // Midway along x: the mean of the two probes (the coefficients are linear in the weights).
  const glm::vec3 mid = 0.5f * (w.bake.gather.ProbePosition(0, 1, 1) + w.bake.gather.ProbePosition(1, 1, 1));
  EXPECT_NEAR(volume.Irradiance(mid, n).x,
              0.5f * (volume.ProbeIrradiance(0, 1, 1, n).x + volume.ProbeIrradiance(1, 1, 1, n).x), 1e-4f);
}

TEST(IrradianceVolumeTest, AProbeInsideAWallTakesItsNeighboursValues) {
  // A closed 0.4 m box around probe (0, 0, 0) at (-1, -1, 0.5), its faces facing outward.
  const std::string faces =
      "o block\n"
      "v -1.2 -1.2 0.3\nv -0.8 -1.2 0.3\nv -0.8 -0.8 0.3\nv -1.2 -0.8 0.3\n"
      "v -1.2 -1.2 0.7\nv -0.8 -1.2 0.7\nv -0.8 -0.8 0.7\nv -1.2 -0.8 0.7\n"
      "f 5 8 7 6\nf 9 10 11 12\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 8 5 9 12\n";
  const OpenGround w("volume_inside", faces);
  const std::vector<uint8_t> inside = bake::ProbesInsideModel(w.bake.gather, *w.caster);
  ASSERT_EQ(inside.size(), 8u);
  EXPECT_EQ(inside[0], 1);
  for (size_t p = 1; p < 8; ++p) EXPECT_EQ(inside[p], 0) << p;
  IrradianceVolume volume(w.bake.gather, inside);
  volume.Update(CapturedStacked(w.bake));
  const glm::vec3 up(0, 0, 1);
  const float want = (volume.ProbeIrradiance(1, 0, 0, up).x + volume.ProbeIrradiance(0, 1, 0, up).x +
                      volume.ProbeIrradiance(0, 0, 1, up).x) / 3.0f;
  EXPECT_NEAR(volume.ProbeIrradiance(0, 0, 0, up).x, want, 1e-4f);
  EXPECT_GT(want, 2.0f);  // not black
}

// The renderer's shortcut: the volume of a combination of maps is the combination of their
// volumes, inside probes included (their neighbours' mean is linear too).
TEST(IrradianceVolumeTest, CombiningUpdatesEqualsUpdatingTheCombinedMap) {
  const std::string faces =
      "o block\n"
      "v -1.2 -1.2 0.3\nv -0.8 -1.2 0.3\nv -0.8 -0.8 0.3\nv -1.2 -0.8 0.3\n"
      "v -1.2 -1.2 0.7\nv -0.8 -1.2 0.7\nv -0.8 -0.8 0.7\nv -1.2 -0.8 0.7\n"
      "f 5 8 7 6\nf 9 10 11 12\nf 5 6 10 9\nf 6 7 11 10\nf 7 8 12 11\nf 8 5 9 12\n";
  const OpenGround w("volume_combine", faces);
  IrradianceVolume volume(w.bake.gather, bake::ProbesInsideModel(w.bake.gather, *w.caster));
  ASSERT_EQ(volume.InsideCount(), 1u);
  const size_t texels = 2 * w.bake.env.radiance.size();  // the map and its sky layer
  std::array<std::vector<glm::vec3>, 3> maps;
  std::array<std::vector<float>, 3> parts;
  for (size_t i = 0; i < 3; ++i) {
    maps[i].resize(texels);
    for (size_t t = 0; t < texels; ++t) maps[i][t] = glm::vec3(static_cast<float>((t * (i + 3)) % 101) / 101.0f, 0.2f * static_cast<float>(i), 1.0f);
    volume.Update(maps[i]);
    parts[i] = volume.coefficients();
  }
  const std::array<glm::vec3, 3> weights = {glm::vec3(2.0f, 0.5f, 1.0f), glm::vec3(0.3f, 4.0f, 0.0f), glm::vec3(1.5f)};
  std::vector<glm::vec3> combined(texels);
  for (size_t t = 0; t < texels; ++t) combined[t] = weights[0] * maps[0][t] + weights[1] * maps[1][t] + weights[2] * maps[2][t];
  volume.Update(combined);
  const std::vector<float> direct = volume.coefficients();
  volume.SetCombination({&parts[0], &parts[1], &parts[2]}, weights);
  ASSERT_EQ(volume.coefficients().size(), direct.size());
  for (size_t i = 0; i < direct.size(); ++i) EXPECT_NEAR(volume.coefficients()[i], direct[i], 1e-4f * (1.0f + std::abs(direct[i]))) << i;
}

}  // namespace
}  // namespace daylit::sh
