// The pieces of the options structs' Check(): ranges, the first problem, nested names; and one
// composed Check() (the pipeline's) naming the nested field that is wrong.
#include <gtest/gtest.h>

#include "base/options_check.h"

namespace daylit {
namespace {

TEST(OptionsCheckTest, RangesNameTheFieldAndTheValue) {
  EXPECT_EQ(InClosed("samples", 100, 100, 200), "");
  EXPECT_EQ(InClosed("samples", 99, 100, 200), "samples: 99 is outside [100, 200]");
  EXPECT_EQ(InOpenClosed("floor", 0.0, 0.0, 1.0), "floor: 0 is outside (0, 1]");
  EXPECT_EQ(InOpenClosed("floor", 1.0, 0.0, 1.0), "");
  EXPECT_NE(InClosed("x", std::nan(""), 0.0, 1.0), "");  // NaN is never in range
}

TEST(OptionsCheckTest, TheFirstProblemUnderItsNestedName) {
  EXPECT_EQ(FirstProblem({"", "b: bad", "c: worse"}), "b: bad");
  EXPECT_EQ(FirstProblem({"", ""}), "");
  EXPECT_EQ(Nested("sampler", "samples: 5 is outside [100, 1000000]"), "sampler.samples: 5 is outside [100, 1000000]");
  EXPECT_EQ(Nested("sampler", ""), "");
}

}  // namespace
}  // namespace daylit
