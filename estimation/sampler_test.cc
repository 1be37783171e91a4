#include "estimation/sampler.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include "bake/synthetic_recording.h"
#include "base/log.h"

namespace daylit::estimation {
namespace {

// A ground seen from 5 m above and a 3 m wall at x = 1; the sun 45° high in the +X direction
// shades the ground for x in [-2, 1].
struct WallScene {
  bake::testing::SyntheticRecording rec{"sampler"};
  scene::Scene scene;
  bake::SceneBake bake;
  std::unique_ptr<scene::RayCaster> caster;
  const glm::vec3 sun = glm::normalize(glm::vec3(1.0f, 0.0f, 1.0f));

  WallScene() {
    SetLogVerbosity(0);
    rec.obj += "o wall\nv 1 -10 0\nv 1 10 0\nv 1 10 3\nv 1 -10 3\nf 5 6 7 8\n";
    scene = scene::LoadScene(rec.Write());
    bake = bake::RunBake(scene, bake::BakeOptions{});
    caster = std::make_unique<scene::RayCaster>(scene.model);
  }

  // The model of seed 001 (no interreflection, a uniform sky): what Render draws.
  static SamplerOptions SeedModel() {
    SamplerOptions options;
    options.transfer.interreflection = false;
    options.transfer.sky_distribution = false;
    return options;
  }
  glm::vec3 Capture() const { return glm::vec3(scene.envmap->position); }

  // Whether the sun reaches point p, worked out by hand rather than with the sampler's ray
  // casting (so that its shadow errors show): the wall is the plane x = 1, |y| ≤ 10, 0 ≤ z ≤ 3,
  // the sun along (1, 0, 1)/√2. A ground point's ray toward it meets x = 1 at height 1 − x, so
  // it is shadowed for −2 ≤ x < 1 and |y| ≤ 10; the wall's own faces: the one facing +x is lit.
  static bool SunReaches(const glm::vec3& p, const glm::vec3& normal) {
    if (glm::dot(normal, glm::vec3(1.0f, 0.0f, 1.0f)) <= 0.0f) return false;
    if (std::abs(p.z) > 1e-3f) return true;  // on the wall, facing the sun
    return !(p.x >= -2.0f && p.x < 1.0f && std::abs(p.y) <= 10.0f);
  }

  // The frame the model predicts for `light`, as linear RGB floats times `exposure`.
  cv::Mat Render(const SunSky& light, double exposure) const {
    const bake::CameraGBuffer& g = bake.camera;
    cv::Mat frame(g.height, g.width, CV_32FC3, cv::Scalar(0, 0, 0));
    for (size_t i = 0; i < g.surface.size(); ++i) {
      if (g.surface[i] == bake::kNoSurface) continue;
      const float a = SunReaches(g.point[i], g.normal[i]) ? std::max(0.0f, glm::dot(g.normal[i], sun)) : 0.0f;
      // Seed 001's model: a uniform sky without interreflection (lighting_model.h).
      const Transfer t{glm::vec3(a), glm::vec3(g.sky_visibility[i]), glm::vec3(g.sky_visibility[i])};
      const glm::dvec3 l = exposure * glm::dvec3(g.albedo[i] * glm::one_over_pi<float>() * Irradiance(SplitLight(light, 0.0), t));
      frame.at<cv::Vec3f>(static_cast<int>(i / g.width), static_cast<int>(i % g.width)) =
          cv::Vec3f(static_cast<float>(l.x), static_cast<float>(l.y), static_cast<float>(l.z));
    }
    return frame;
  }
};

TEST(SamplerTest, ExactSyntheticFrameIsRecoveredTo0_1Percent) {
  const WallScene w;
  Sampler sampler(w.bake, w.Capture(), *w.caster, WallScene::SeedModel());
  ASSERT_TRUE(sampler.SetSun(w.sun));
  EXPECT_EQ(sampler.StratumCount(), 2u);  // ground sunlit, ground shadowed
  const SunSky light{{86.0, 63.0, 37.0}, {9.9, 9.7, 10.0}};
  const double exposure = 0.004;  // keeps sunlit ground (0.4/π·(86·0.71 + 9.9) ≈ 9) below clipping
  const std::vector<Sample> samples = sampler.Draw(w.Render(light, exposure), exposure);
  EXPECT_GT(samples.size(), 1500u);  // of 3072 pixels, less the shadow-edge and silhouette margins
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  ASSERT_EQ(fit.status, SunSkyFitStatus::kConverged) << fit.message;
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(fit.light.sun_rgb[c], light.sun_rgb[c], 1e-3 * light.sun_rgb[c]) << c;
    EXPECT_NEAR(fit.light.sky_rgb[c], light.sky_rgb[c], 1e-3 * light.sky_rgb[c]) << c;
  }
}

TEST(SamplerTest, AnEncodedFrameIsLinearisedWhereRead) {
  const WallScene w;
  Sampler sampler(w.bake, w.Capture(), *w.caster, WallScene::SeedModel());
  sampler.SetSun(w.sun);
  const SunSky light{{86.0, 63.0, 37.0}, {9.9, 9.7, 10.0}};
  const cv::Mat linear = w.Render(light, 0.004);
  const capture::CameraResponse srgb;
  cv::Mat encoded = linear.clone();
  for (auto it = encoded.begin<cv::Vec3f>(); it != encoded.end<cv::Vec3f>(); ++it) {
    for (int c = 0; c < 3; ++c) (*it)[c] = static_cast<float>(srgb.ToEncoded((*it)[c]));
  }
  const capture::Linearizer linearizer(srgb);
  const std::vector<Sample> want = sampler.Draw(linear, 0.004);
  const std::vector<Sample> got = sampler.Draw(encoded, 0.004, &linearizer);
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[i].radiance[c], want[i].radiance[c], 1e-4 * want[i].radiance[c]) << i;
  }
}

TEST(SamplerTest, ShadowEdgesClippedAndDarkPixelsAreLeftOut) {
  const WallScene w;
  Sampler sampler(w.bake, w.Capture(), *w.caster, WallScene::SeedModel());
  sampler.SetSun(w.sun);
  // The shadow edge at x = -2 runs across the image, and the wall's silhouette from x = 1 (its foot)
  // to x = 2.5 (where its top hides the ground): only ground near those is excluded (3 px at
  // 40 px per 5 m is 0.375 m).
  size_t at_shadow = 0, at_wall = 0;
  for (size_t i = 0; i < sampler.near_boundary().size(); ++i) {
    if (!sampler.near_boundary()[i] || w.bake.camera.surface[i] != 0) continue;
    const float x = w.bake.camera.point[i].x;
    const bool shadow_edge = std::abs(x + 2.0f) < 0.5f, wall = x > 0.5f && x < 3.0f;
    EXPECT_TRUE(shadow_edge || wall) << x;
    at_shadow += shadow_edge, at_wall += wall;
  }
  EXPECT_GT(at_shadow, 48u * 4u);  // both sides of the edge, the whole image height
  EXPECT_GT(at_wall, 48u * 4u);
  // Clipped and black pixels are skipped.
  const SunSky light{{86.0, 63.0, 37.0}, {9.9, 9.7, 10.0}};
  cv::Mat frame = w.Render(light, 0.004);
  const size_t all = sampler.Draw(frame, 0.004).size();
  frame.setTo(cv::Scalar(1.0f, 1.0f, 1.0f), cv::Mat(frame.size(), CV_8UC1, cv::Scalar(0)));
  cv::Mat clipped = frame.clone();
  clipped.rowRange(0, 24).setTo(cv::Scalar(1.0f, 1.0f, 1.0f));  // half the image clipped
  EXPECT_LT(sampler.Draw(clipped, 0.004).size(), all);
  EXPECT_TRUE(sampler.Draw(cv::Mat(frame.size(), CV_32FC3, cv::Scalar(0, 0, 0)), 0.004).empty());
}

// The pipeline's scene::SunTracker hands the same direction until the sun has moved; the sampler
// re-casts for any other direction, however close, and never for the same one.
TEST(SamplerTest, SunVisibilityIsRecastOnlyForAnotherSun) {
  const WallScene w;
  Sampler sampler(w.bake, w.Capture(), *w.caster, WallScene::SeedModel());
  EXPECT_TRUE(sampler.SetSun(w.sun));
  EXPECT_FALSE(sampler.SetSun(w.sun));
  const glm::vec3 tiny = glm::normalize(w.sun + glm::vec3(0.0f, 0.0005f, 0.0f));  // 0.02°
  EXPECT_TRUE(sampler.SetSun(tiny));
  EXPECT_FALSE(sampler.SetSun(tiny));
  const glm::vec3 moved = glm::normalize(w.sun + glm::vec3(0.0f, 0.005f, 0.0f));  // 0.2°
  EXPECT_TRUE(sampler.SetSun(moved));
  // Night: everything is shadowed, one stratum, and the fit is sky only.
  EXPECT_TRUE(sampler.SetSun(glm::vec3(0.0f, 0.0f, -1.0f)));
  EXPECT_EQ(sampler.StratumCount(), 1u);
  const SunSky night{{0, 0, 0}, {0.5, 0.6, 0.9}};
  const std::vector<Sample> samples = sampler.Draw(w.Render(night, 0.1), 0.1);
  const SunSkyFitSummary fit = FitSunSky({}, samples);
  EXPECT_EQ(fit.status, SunSkyFitStatus::kSkyOnly);
  EXPECT_NEAR(fit.light.sky_rgb.z, 0.9, 0.9e-3);
}

// The samples' shares: a stratum of a few pixels takes only those, and its coming or going moves
// the others' shares by at most the few pixels it takes (an equal split moved each by a quarter).
TEST(FairSharesTest, ASliverTakesOnlyItsPixelsAndBarelyMovesTheOthers) {
  EXPECT_EQ(FairShares({5000, 5000, 5000}, 8000), (std::vector<size_t>{2667, 2667, 2666}));
  const std::vector<size_t> with_sliver = FairShares({5000, 3, 5000, 5000}, 8000);
  EXPECT_EQ(with_sliver, (std::vector<size_t>{2666, 3, 2666, 2665}));
  size_t sum = 0;
  for (const size_t share : with_sliver) sum += share;
  EXPECT_EQ(sum, 8000u);
  EXPECT_EQ(FairShares({100, 200}, 8000), (std::vector<size_t>{100, 200}));  // fewer pixels than asked: all of them
  EXPECT_EQ(FairShares({100, 9000}, 8000), (std::vector<size_t>{100, 7900}));  // the rest to the large one
  EXPECT_TRUE(FairShares({}, 8000).empty());
}

}  // namespace
}  // namespace daylit::estimation
