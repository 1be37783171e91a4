#include <gtest/gtest.h>

#include "calibrate/shadow_calibration.h"

namespace daylit::calibrate {
namespace {

ShadowCheck Check(double kappa, double kappa_away) {
  ShadowCheck c;
  c.kappa = kappa, c.kappa_away = kappa_away;
  return c;
}

TEST(ShadowCheckTest, SunSkillIsKappaWithTheTurnedSunAsChance) {
  // The turned sun agrees 0.5 from the layout alone; the frames' sun 0.9: it adds 0.8 of the rest.
  EXPECT_NEAR(Check(0.9, 0.5).SunSkill(), 0.8, 1e-12);
  EXPECT_NEAR(Check(0.5, 0.5).SunSkill(), 0.0, 1e-12);
  EXPECT_LT(Check(0.3, 0.5).SunSkill(), 0.0);  // the turned sun fits better: not this footage's sun
  EXPECT_EQ(Check(1.0, 1.0).SunSkill(), 0.0);
}

TEST(ShadowCheckTest, ATurnedSunWorseThanChanceIsNoLowerBaselineThanChance) {
  // Taken as the baseline, a kappa_away of -0.2 lifted a kappa of 0.3 to a skill of 0.42, over the
  // 0.4 that says the model is the footage's. Against chance it is the kappa itself.
  EXPECT_NEAR(Check(0.3, -0.2).SunSkill(), 0.3, 1e-12);
  EXPECT_FALSE(Check(0.3, -0.2).ModelMatchesFootage());
  EXPECT_TRUE(Check(0.6, -0.2).ModelMatchesFootage());
}

}  // namespace
}  // namespace daylit::calibrate
