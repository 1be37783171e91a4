// The light transport against independent computations, per surface and per sunlit/shadowed
// stratum (issue 18): a brute-force path tracer here (Embree rays, 6 bounces, sun by next-event
// estimation, the bake's captured sky table) and the recordings' path-traced truth. On the clear
// truth frames, with the true E_sun and E_sky, the truth's irradiance π·L/ρ (the noise-free
// render over its Diffuse Color pass) is compared with daylit's E_sun·T_sun + E_sky·T_clear
// (estimation::LightTransfer), and the bake's capture-time irradiance of the env texels (what the
// albedo divides by) with the path tracer's. These caught the per-surface means that put a
// slab's sunlit light on its underside (+25% on courtyard-c's arcade wall) and the whole
// hemisphere's sky on bounce points that see only the low sky.
#include <gtest/gtest.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "bake/capture_light.h"
#include "bake/sampling.h"
#include "bake/surface_light.h"
#include "base/csv.h"
#include "estimation/testing/reference_path_tracer.h"
#include "estimation/transfer.h"
#include "scene/hdr_image.h"
#include "scene/raycaster.h"
#include "scene/sun_tracker.h"
#include "tests/courtyard_fixture.h"

namespace daylit {
namespace {

struct Stratum {
  std::vector<float> ratio[3], brute_truth[3], brute_daylit[3];
};

float Median(std::vector<float> v) {
  if (v.empty()) return 0.0f;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The path tracer's irradiance at (x, n) with the sky table scaled by `sky_scale`, less the
// direct sun at x.
glm::vec3 BruteIrradiance(const scene::RayCaster& caster, const glm::vec3& x, const glm::vec3& n,
                          const std::vector<glm::vec3>& albedo, const sky::SkyDistribution& sky, const glm::vec3& sky_scale,
                          const glm::vec3& sun, const glm::vec3& e_sun, int paths, int depth, std::mt19937& rng) {
  const estimation::testing::ReferenceLight light{
      sun, e_sun, [&](const glm::vec3& d) { return sky.Radiance(d) * sky_scale; }, albedo};
  return estimation::testing::PathTracedIndirectAndSky(caster, light, x, n, paths, depth, rng);
}

void CaptureIrradianceAgainstAPathTracer(const testing::BundledCourtyard& c, const std::string& recording) {
  const scene::RayCaster caster(c.scene.model);
  const bake::EnvMapMaps& e = c.bake.env;
  const sky::SkyDistribution sky = bake::CapturedSky(c.bake);
  std::vector<glm::vec3> rho(c.scene.model.surface_names.size(), glm::vec3(0.3f));
  for (size_t s = 0; s < c.bake.albedo_table.size(); ++s) rho[s] = c.bake.albedo_table[s].albedo;
  const std::string dir = DAYLIT_SOURCE_DIR "/recordings/" + recording + "/";
  std::ifstream in(dir + "groundtruth/albedo.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  for (auto& [name, v] : j.items()) {
    const int s = c.scene.model.SurfaceIndex(name);
    if (s >= 0) rho[static_cast<size_t>(s)] = glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
  }
  std::vector<size_t> texels;
  for (size_t t = 0; t < e.surface.size(); t += 7) if (!e.IsSky(t) && e.irradiance[t].x > 0) texels.push_back(t);
  std::vector<glm::vec3> brute(texels.size());
  const glm::vec3 sun = c.bake.capture_sun.dir, dni = c.bake.capture_sun.dni_rgb;
  tbb::parallel_for(size_t{0}, texels.size(), [&](size_t k) {
    std::mt19937 rng(static_cast<uint32_t>(k * 7919 + 1));
    const size_t t = texels[k];
    const glm::vec3 o = e.point[t] + 2e-3f * e.normal[t];
    const float cs = glm::dot(e.normal[t], sun);
    const glm::vec3 d = cs > 0 && !caster.Occluded(o, sun) ? dni * cs : glm::vec3(0.0f);
    brute[k] = d + BruteIrradiance(caster, e.point[t], e.normal[t], rho, sky, glm::vec3(1.0f), sun, dni, 256, 6, rng);
  });
  std::map<uint32_t, Stratum> by;
  for (size_t k = 0; k < texels.size(); ++k) {
    const size_t t = texels[k];
    Stratum& s = by[e.surface[t]];
    for (int ch = 0; ch < 3; ++ch) {
      s.ratio[ch].push_back(e.irradiance[t][ch] / brute[k][ch]);
      s.brute_truth[ch].push_back(glm::pi<float>() * e.radiance[t][ch] / brute[k][ch] / rho[e.surface[t]][ch]);
    }
  }
  for (auto& [surface, s] : by) {
    if (s.ratio[0].size() >= 80) {
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(Median(s.ratio[ch]), 1.0, 0.04) << c.scene.model.surface_names[surface] << " channel " << ch;
      }
    }
    std::printf("  %-20s %5zu bake/brute %.3f %.3f %.3f | albedo(brute)/truth %.3f %.3f %.3f\n",
                c.scene.model.surface_names[surface].c_str(), s.ratio[0].size(), Median(s.ratio[0]), Median(s.ratio[1]),
                Median(s.ratio[2]), Median(s.brute_truth[0]), Median(s.brute_truth[1]), Median(s.brute_truth[2]));
  }
}

TEST(TransferTruthRecordingTest, BakeCaptureIrradianceMatchesAPathTracerOnCourtyardC) {
  CaptureIrradianceAgainstAPathTracer(testing::CourtyardC(), "courtyard-c");
}

// A stratum held to its own bar: frame, surface, sunlit, and the bar on truth / daylit.
struct WiderBar {
  int frame;
  std::string surface;
  bool sunlit;
  double bar;
};

void ClearFrames(const testing::BundledCourtyard& c, const std::string& recording, std::vector<int> frames,
                 const std::vector<WiderBar>& wider = {}) {
  const scene::RayCaster caster(c.scene.model);
  const std::string dir = DAYLIT_SOURCE_DIR "/recordings/" + recording + "/";
  const HdrImage albedo = scene::ReadHdrImage(dir + "groundtruth/albedo_camera.exr");
  const bake::CameraGBuffer& g = c.bake.camera;
  const CsvTable truth = ReadCsvFile(dir + "groundtruth.csv");
  std::vector<glm::vec3> daylit_albedo(c.scene.model.surface_names.size(), glm::vec3(0.3f)), true_albedo;
  for (size_t s = 0; s < c.bake.albedo_table.size(); ++s) daylit_albedo[s] = c.bake.albedo_table[s].albedo;
  true_albedo = daylit_albedo;
  {
    std::ifstream in(dir + "groundtruth/albedo.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    for (auto& [name, v] : j.items()) {
      const int s = c.scene.model.SurfaceIndex(name);
      if (s >= 0) true_albedo[static_cast<size_t>(s)] = glm::vec3(v[0].get<float>(), v[1].get<float>(), v[2].get<float>());
    }
  }
  const sky::SkyDistribution captured_sky = bake::CapturedSky(c.bake);
  for (const int frame : frames) {
    const HdrImage L = scene::ReadHdrImage(fmt::format("{}groundtruth/without_objects/{:06d}.exr", dir, frame));
    scene::SunTracker tracker(c.scene);
    const scene::TrackedSun& sun = tracker.Update(c.scene.frame_times->frames[static_cast<size_t>(frame)].utc);
    std::vector<uint32_t> pixels;
    for (size_t i = 0; i < g.surface.size(); i += 37) {
      if (g.diffuse[i]) pixels.push_back(static_cast<uint32_t>(i));
    }
    std::vector<float> direct(g.surface.size(), 0.0f);
    std::vector<uint8_t> lit(g.surface.size(), 0);
    bake::DirectSun(caster, g.point.data(), g.normal.data(), pixels, sun.dir_in_scene, 2e-3f, direct.data(), lit.data());
    estimation::LightTransfer transfer(c.bake, estimation::TransferPoints::Camera(g), glm::vec3(c.scene.envmap->position),
                                       caster);
    std::vector<estimation::Transfer> t(pixels.size());
    transfer.Compute(pixels, sun.dir_in_scene, direct.data(), t.data());
    const auto row = truth.rows[static_cast<size_t>(frame)];
    const glm::vec3 e_sun(std::stof(row[1]), std::stof(row[2]), std::stof(row[3]));
    const glm::vec3 e_sky(std::stof(row[4]), std::stof(row[5]), std::stof(row[6]));
    const sky::SkyDistribution sky = captured_sky.Under(sun.dir_in_scene);
    const glm::vec3 sky_scale = e_sky / glm::vec3(sky.HorizontalIrradiance());
    std::vector<glm::vec3> brute(pixels.size()), brute_true(pixels.size());
    tbb::parallel_for(size_t{0}, pixels.size(), [&](size_t k) {
      std::mt19937 rng(static_cast<uint32_t>(k * 7919 + 1));
      const uint32_t p = pixels[k];
      const glm::vec3 direct_sun = e_sun * direct[p];
      brute[k] = direct_sun + BruteIrradiance(caster, g.point[p], g.normal[p], daylit_albedo, sky, sky_scale,
                                              sun.dir_in_scene, e_sun, 512, 6, rng);
      brute_true[k] = direct_sun + BruteIrradiance(caster, g.point[p], g.normal[p], true_albedo, sky, sky_scale,
                                                   sun.dir_in_scene, e_sun, 512, 6, rng);
    });
    std::map<std::pair<uint32_t, int>, Stratum> strata;
    for (size_t k = 0; k < pixels.size(); ++k) {
      const uint32_t p = pixels[k];
      const glm::vec3 predicted = e_sun * t[k].sun + e_sky * t[k].clear;
      Stratum& s = strata[{g.surface[p], lit[p]}];
      for (int ch = 0; ch < 3; ++ch) {
        const float rho = albedo.rgb[p * 3 + ch];
        if (rho < 0.02f || predicted[ch] <= 0.0f) continue;
        const float e_true = glm::pi<float>() * L.rgb[p * 3 + ch] / rho;
        s.ratio[ch].push_back(e_true / predicted[ch]);
        s.brute_truth[ch].push_back(e_true / brute_true[k][ch]);
        s.brute_daylit[ch].push_back(brute[k][ch] / predicted[ch]);
      }
    }
    std::printf("%s frame %d (sun %.1f deg), %zu cells\n", recording.c_str(), frame, sun.position.ApparentElevationDeg(), transfer.Cells());
    for (auto& [key, s] : strata) {
      if (s.ratio[0].size() < 30) continue;
      // Strata of 200+ sampled pixels: smaller ones are slivers along shadow edges, where a
      // pixel's footprint straddles the edge.
      for (int ch = 0; s.ratio[0].size() >= 200 && ch < 3; ++ch) {
        const std::string what = fmt::format("{} frame {} {} {} channel {}", recording, frame,
                                             c.scene.model.surface_names[key.first], key.second ? "sunlit" : "shadowed", ch);
        double bar = 0.05;
        for (const WiderBar& w : wider) {
          if (w.frame == frame && w.surface == c.scene.model.surface_names[key.first] && w.sunlit == (key.second != 0)) bar = w.bar;
        }
        EXPECT_NEAR(Median(s.ratio[ch]), 1.0, bar) << what << ": truth / daylit";
        // The path tracer here gives each surface one albedo (the truth's per-surface median, the
        // bake's where the truth has none) and the bake's sky table: 7% off on courtyard-c's
        // arcade wall under the lowest sun, so its bar is wider.
        EXPECT_NEAR(Median(s.brute_truth[ch]), 1.0, 0.08) << what << ": truth / path tracer";
        EXPECT_NEAR(Median(s.brute_daylit[ch]), 1.0, 0.08) << what << ": path tracer / daylit";
      }
      std::printf("  %-20s %-6s %5zu truth/daylit %.3f %.3f %.3f | truth/brute(true rho) %.3f %.3f %.3f | brute(daylit rho)/daylit %.3f %.3f %.3f\n",
                  c.scene.model.surface_names[key.first].c_str(), key.second ? "sunlit" : "shadow", s.ratio[0].size(),
                  Median(s.ratio[0]), Median(s.ratio[1]), Median(s.ratio[2]), Median(s.brute_truth[0]),
                  Median(s.brute_truth[1]), Median(s.brute_truth[2]), Median(s.brute_daylit[0]), Median(s.brute_daylit[1]),
                  Median(s.brute_daylit[2]));
    }
  }
}

TEST(TransferTruthRecordingTest, ClearFramesOfCourtyardCPerSurfaceAndStratumWithinFivePercent) {
  // Frame 462 (the sun 11.9° up, 17° below the capture's): the arcade wall's shadow, which faces
  // the low sky opposite the sun, is 5.2% darker in blue than daylit's transfer. The path tracer
  // given the same sky table is 7.2% off there too: it is the captured sky re-aimed at a sun far
  // below the capture's (the table's bins past the angles the capture saw), not the transfer.
  ClearFrames(testing::CourtyardC(), "courtyard-c", {59, 156, 351, 462}, {{462, "building_arcade", false, 0.06}});
}
TEST(TransferTruthRecordingTest, ClearFramesOfCourtyardAPerSurfaceAndStratumWithinFivePercent) {
  ClearFrames(testing::Courtyard(), "courtyard-a", {50, 152, 250, 452, 550});
}

}  // namespace
}  // namespace daylit
