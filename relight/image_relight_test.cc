// Image relighting on a small synthetic scene whose camera sees the horizon: sky pixels keep their
// value or follow the sky's change, open ground follows the model exactly, and a sun below the
// horizon leaves the sky's light alone.
#include "relight/image_relight.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>

#include "bake/bake.h"
#include "bake/synthetic_recording.h"
#include "base/log.h"
#include "scene/scene.h"

namespace daylit::relight {
namespace {

struct Horizon {
  bake::testing::SyntheticRecording rec{"image_relight"};
  scene::Scene scene;
  bake::SceneBake baked;
  Horizon() {
    SetLogVerbosity(0);
    // The camera 1.5 m up, looking along +Y: ground below the horizon, sky above.
    rec.scene["camera"]["world_to_camera"] = {{"rotation", {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}}, {"translation", {0, 1.5, 0}}};
    rec.scene.erase("volume");
    scene = scene::LoadScene(rec.Write());
    baked = bake::RunBake(scene, bake::BakeOptions{});
  }
};

TEST(ImageRelightTest, SkyPixelsKeepOrFollowAndOpenGroundFollowsTheModel) {
  Horizon h;
  const scene::RayCaster caster(h.scene.model);
  const glm::vec3 now_sun = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  const glm::vec3 new_sun = glm::normalize(glm::vec3(-0.6f, 0.2f, 0.4f));
  LightParts now, next;
  now.sun = glm::vec3(50.0f, 40.0f, 30.0f), now.overcast = glm::vec3(10.0f);
  next.sun = glm::vec3(20.0f), next.overcast = glm::vec3(25.0f, 20.0f, 15.0f);
  for (const SkyPixels sky : {SkyPixels::kKeep, SkyPixels::kFollow}) {
    ImageRelightOptions options;
    options.sky = sky;
    ImageRelighter relighter(h.scene, h.baked, caster, options);
    relighter.SetSuns(now_sun, new_sun);
    const RatioTerms& t = relighter.terms();
    std::vector<float> ratio(3 * t.kind.size());
    RatioOf(t, now, next, ratio.data());
    size_t sky_pixels = 0, ground = 0;
    for (size_t p = 0; p < t.kind.size(); ++p) {
      if (h.baked.camera.surface[p] == bake::kNoSurface) {
        ++sky_pixels;
        // Uniform skies (no captured sky's shape here): the sky's radiance is E_sky/π.
        const float want = sky == SkyPixels::kKeep ? 1.0f : next.overcast.y / now.overcast.y;
        EXPECT_NEAR(ratio[3 * p + 1], want, 1e-5f) << p;
        continue;
      }
      // Open level ground: E = E_sun·l_z + E_sky, exactly (no walls to shade or reflect).
      const glm::vec3 e_now = now.sun * now_sun.z + now.overcast, e_new = next.sun * new_sun.z + next.overcast;
      if (h.baked.camera.sky_visibility[p] < 0.999f) continue;
      ++ground;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(ratio[3 * p + c], e_new[c] / e_now[c], 2e-3f * e_new[c] / e_now[c]) << p;
    }
    EXPECT_GT(sky_pixels, 1000u);
    EXPECT_GT(ground, 1000u);
    // The sun below the horizon: no sun light, only the sky's.
    relighter.SetSuns(now_sun, glm::normalize(glm::vec3(0.0f, 1.0f, -0.1f)));
    RatioOf(relighter.terms(), now, next, ratio.data());
    for (size_t p = 0; p < t.kind.size(); ++p) {
      if (h.baked.camera.surface[p] == bake::kNoSurface || h.baked.camera.sky_visibility[p] < 0.999f) continue;
      EXPECT_NEAR(ratio[3 * p + 1], next.overcast.y / (now.sun.y * now_sun.z + now.overcast.y), 1e-3f);
    }
  }
}

}  // namespace
}  // namespace daylit::relight
