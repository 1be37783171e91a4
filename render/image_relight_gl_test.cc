// The GPU path of image relighting (llvmpipe here) against the CPU path, pixel for pixel, on
// terms that exercise every branch: model pixels (some below the floor), sky pixels, kept pixels.
#include "render/image_relight_gl.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "render/gl_context.h"

namespace daylit::render {
namespace {

TEST(ImageRelightGlTest, MatchesTheCpuPath) {
  std::string why;
  const std::unique_ptr<HeadlessGlContext> gl = HeadlessGlContext::Create(&why);
  ASSERT_NE(gl, nullptr) << why;
  relight::RatioTerms t;
  t.width = 67, t.height = 45;  // odd sizes: row alignment
  const size_t n = static_cast<size_t>(t.width) * static_cast<size_t>(t.height);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const auto terms = [&](relight::PixelTerms* p) {
    for (auto* v : {&p->sun, &p->clear, &p->overcast}) {
      v->resize(n);
      for (glm::vec3& x : *v) x = glm::vec3(unit(random), unit(random), unit(random));
    }
  };
  terms(&t.now), terms(&t.next);
  t.kind.resize(n);
  for (size_t p = 0; p < n; ++p) {
    t.kind[p] = static_cast<uint8_t>(p % 7 == 0 ? relight::kSkyPixel : p % 11 == 0 ? relight::kKeptPixel : relight::kModelPixel);
    if (p % 5 == 0) t.now.sun[p] = t.now.clear[p] = t.now.overcast[p] = glm::vec3(0.001f);  // deep shadow
  }
  t.now_sun = glm::normalize(glm::vec3(0.2f, 0.3f, 0.7f));
  estimation::LightParts now{glm::vec3(80, 60, 40), glm::vec3(8, 9, 10), glm::vec3(2)};
  estimation::LightParts next{glm::vec3(30, 25, 20), glm::vec3(5, 6, 7), glm::vec3(9)};
  std::vector<float> cpu(3 * n);
  for (float& x : cpu) x = unit(random);
  std::vector<float> gpu = cpu;
  const relight::RelightStats a = relight::ApplyRatio(t, now, next, cpu.data());
  ImageRelightGl relighter(t.width, t.height);
  relighter.SetTerms(t);
  const relight::RelightStats b = relighter.Apply(t, now, next, gpu.data());
  EXPECT_EQ(a.model_pixels, b.model_pixels);
  EXPECT_EQ(a.clamped, b.clamped);
  EXPECT_GT(a.clamped, n / 10);
  float worst = 0.0f;
  for (size_t i = 0; i < cpu.size(); ++i) worst = std::max(worst, std::abs(gpu[i] - cpu[i]) / std::max(cpu[i], 1e-6f));
  EXPECT_LT(worst, 1e-5f);
}

}  // namespace
}  // namespace daylit::render
