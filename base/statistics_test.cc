#include "base/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace daylit {
namespace {

TEST(StatisticsTest, PercentilesOfAShuffledRange) {
  // 0..99 in a scrambled order: the value at fraction q is floor(100 q), the last at q = 1.
  std::vector<double> v;
  for (int i = 0; i < 100; ++i) v.push_back((i * 37) % 100);
  std::vector<double> a = v, b = v, c = v, d = v;
  EXPECT_EQ(PercentileInPlace(a, 0.5, -1.0), 50.0);
  EXPECT_EQ(MedianInPlace(b, -1.0), 50.0);
  EXPECT_EQ(PercentileInPlace(c, 0.95, -1.0), 95.0);
  EXPECT_EQ(PercentileInPlace(d, 1.0, -1.0), 99.0);
  std::vector<double> none;
  EXPECT_TRUE(std::isnan(PercentileInPlace(none, 0.95, static_cast<double>(NAN))));
  std::vector<int> one = {7};
  EXPECT_EQ(PercentileInPlace(one, 0.0, 0), 7);
}

}  // namespace
}  // namespace daylit
