#include <gtest/gtest.h>

#include <cmath>

#include "estimation/sun_colour.h"

namespace daylit::estimation {
namespace {

UtcTime At(double seconds) { return UtcFromUnixSeconds(1.78e9 + seconds); }

TEST(SunColourTest, AnEpisodeOfWeakSunsIsWorthItsBestFrameNotTheirSum) {
  // Carried: a clear burst's colour (1.3, 1, 0.7), worth one frame of weight 1. Then a hundred weak
  // suns 0.1 s apart, each of weight 0.1, measuring (1.2, 1, 0.75): they share their model's
  // errors, so together they are worth one of them.
  SunColourOptions options;
  SunColourMemory memory(options, glm::dvec3(1.3, 1.0, 0.7), 1.5);
  const double prior = options.prior_weight;
  for (int i = 0; i < 100; ++i) {
    const SunColourMemory::Colour c = memory.At(At(0.1 * i), 1.5);
    EXPECT_NEAR(c.weight, i == 0 ? prior : prior + 0.1, 1e-9);
    memory.Measure(At(0.1 * i), glm::dvec3(1.2, 1.0, 0.75), 0.1);
  }
  const SunColourMemory::Colour last = memory.At(At(10.0), 1.5);
  const double w = 0.1 / (prior + 0.1);
  EXPECT_NEAR(std::log(last.above.x), (1.0 - w) * std::log(1.3) + w * std::log(1.2), 1e-9);
  EXPECT_NEAR(last.above.y, 1.0, 1e-12);
}

TEST(SunColourTest, AColourCarriedAcrossAirMassIsWorthWhatTheAtmosphereGetsRight) {
  SunColourOptions options;
  SunColourMemory memory(options, glm::dvec3(1.3, 1.0, 0.7), 1.8);
  // Fifty clear frames at air mass 1.8 (34°), each of weight 1, in episodes of a minute.
  for (int i = 0; i < 50; ++i) {
    memory.At(At(i * 0.1), 1.8);
    memory.Measure(At(i * 0.1), glm::dvec3(1.3, 1.0, 0.7), 1.0);
  }
  // Ten hours later (a new episode) at air mass 1.34 (48°): worth at most (0.02 / (0.05 · 0.46))².
  const SunColourMemory::Colour near = memory.At(At(36000.0), 1.34);
  EXPECT_NEAR(near.weight, std::pow(0.02 / (0.05 * 0.46), 2.0), 1e-9);
  // And then at air mass 5.2 (11°): far less.
  const SunColourMemory::Colour far = memory.At(At(72000.0), 5.2);
  EXPECT_NEAR(far.weight, std::pow(0.02 / (0.05 * (5.2 - 1.34)), 2.0), 1e-9);
  EXPECT_NEAR(far.above.z, 0.7, 1e-9);  // the colour itself is carried unchanged
}

TEST(SunColourTest, NothingKnownWithoutAPriorUntilAFrameIsMeasured) {
  SunColourMemory memory;
  EXPECT_EQ(memory.At(At(0.0), 2.0).weight, 0.0);
  memory.Measure(At(0.0), glm::dvec3(2.6, 2.0, 1.4), 0.5);
  const SunColourMemory::Colour c = memory.At(At(0.1), 2.0);
  EXPECT_NEAR(c.weight, 0.5, 1e-12);
  EXPECT_NEAR(c.above.x, 1.3, 1e-9);
  // A bad measurement (a zero channel) is ignored.
  memory.Measure(At(0.2), glm::dvec3(0.0, 2.0, 1.4), 1.0);
  EXPECT_NEAR(memory.At(At(0.3), 2.0).above.x, 1.3, 1e-9);
}

}  // namespace
}  // namespace daylit::estimation
