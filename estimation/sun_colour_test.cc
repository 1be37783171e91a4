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
  // Ten hours later (a new episode) at air mass 1.34 (48°): the prior and the fifty frames' episode
  // (worth its best frame) were measured at 1.8, so their error gains the transmittance's across
  // 0.46: worth 1 / (1/1.25 + (0.05 · 0.46 / 0.02)²).
  const auto worth = [](double weight, double moved) { return 1.0 / (1.0 / weight + std::pow(0.05 * moved / 0.02, 2.0)); };
  const SunColourMemory::Colour near = memory.At(At(36000.0), 1.34);
  EXPECT_NEAR(near.weight, worth(1.25, 0.46), 1e-9);
  // And then at air mass 5.2 (11°): far less, carried from 1.8, where it was measured.
  const SunColourMemory::Colour far = memory.At(At(72000.0), 5.2);
  EXPECT_NEAR(far.weight, worth(1.25, 5.2 - 1.8), 1e-9);
  EXPECT_NEAR(far.above.z, 0.7, 1e-9);  // the colour itself is carried unchanged
  // Back at 1.8 it is worth what it was.
  EXPECT_NEAR(memory.At(At(80000.0), 1.8).weight, 1.25, 1e-9);
}

TEST(SunColourTest, AColourCarriedAMinuteAtATimeIsWorthWhatItsWholeDriftAllows) {
  // A clear episode at air mass 1.2, then three hours of frames every second under cloud that
  // measure nothing, the sun sinking to air mass 4: a new episode every minute, each a small step
  // of air mass. Carried from 1.2 to 4, the colour is worth what the transmittance gets right
  // across 2.8, not what it gets right across one minute's step.
  SunColourOptions options;
  SunColourMemory memory(options);
  memory.At(At(0.0), 1.2);
  memory.Measure(At(0.0), glm::dvec3(1.3, 1.0, 0.7), 1.0);
  SunColourMemory::Colour last;
  const int seconds = 3 * 3600;
  for (int s = 1; s <= seconds; ++s) last = memory.At(At(s), 1.2 + 2.8 * s / seconds);
  EXPECT_NEAR(last.weight, 1.0 / (1.0 + std::pow(0.05 * 2.8 / 0.02, 2.0)), 1e-6);
  EXPECT_NEAR(last.above.x, 1.3, 1e-9);
}

TEST(SunColourTest, MeasurementsNearTheSunAtHandCountMoreThanFarOnes) {
  // A colour measured at air mass 1.2 and another at 4, each worth one frame: at air mass 4 the
  // second dominates, and the two together are worth more than either alone.
  SunColourMemory memory;
  memory.At(At(0.0), 1.2);
  memory.Measure(At(0.0), glm::dvec3(1.3, 1.0, 0.7), 1.0);
  memory.At(At(3600.0), 4.0);
  memory.Measure(At(3600.0), glm::dvec3(1.1, 1.0, 0.8), 1.0);
  const SunColourMemory::Colour c = memory.At(At(7200.0), 4.0);
  EXPECT_NEAR(c.above.z, 0.8, 0.01);
  EXPECT_GT(c.weight, 1.0);
  EXPECT_LT(c.weight, 1.1);
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
