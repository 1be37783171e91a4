#include "report/plot.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

namespace daylit::report {
namespace {

TEST(PlotTest, NiceTicksCoverTheRangeWithRoundSteps) {
  EXPECT_EQ(NiceTicks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  // (56.3 − 16.6) / 6 = 6.6: the smallest 1-2-5 step at least that is 10.
  EXPECT_EQ(NiceTicks(16.6, 56.3, 6), (std::vector<double>{20, 30, 40, 50}));
  EXPECT_EQ(NiceTicks(-0.013, 0.011, 5), (std::vector<double>{-0.01, -0.005, 0, 0.005, 0.01}));
}

TEST(PlotTest, SeriesAreDrawnWhereTheirValuesAre) {
  LinePlot plot({"t", "x", "y", 400, 300, true});
  plot.Add({"rising", {0, 1}, {0, 1}, {255, 0, 0}, false});  // pure red, BGR (0, 0, 255)
  const cv::Mat image = plot.Render();
  ASSERT_EQ(image.size(), cv::Size(400, 300));
  // The line runs from the bottom-left to the top-right of the plot area, so red pixels exist
  // in the lower-left quadrant and the upper-right quadrant but not in the upper-left one.
  const auto red_in = [&](cv::Rect r) {
    cv::Mat mask;
    cv::inRange(image(r), cv::Scalar(0, 0, 200), cv::Scalar(80, 80, 255), mask);
    return cv::countNonZero(mask);
  };
  EXPECT_GT(red_in({80, 150, 120, 100}), 20);
  EXPECT_GT(red_in({260, 40, 110, 100}), 20);
  EXPECT_EQ(red_in({85, 40, 100, 80}), 0);
}

TEST(PlotTest, LogAxisPutsEachDecadeTheSameDistanceApart) {
  PlotOptions options{"t", "x", "y", 400, 300};
  options.y_log = true;
  LinePlot plot(options);
  Series decades{"decades", {0, 1, 2}, {1, 10, 100}, {255, 0, 0}};
  decades.markers_only = true;
  plot.Add(decades);
  const cv::Mat image = plot.Render();
  const auto red_in = [&](cv::Rect r) {
    cv::Mat mask;
    cv::inRange(image(r), cv::Scalar(0, 0, 200), cv::Scalar(80, 80, 255), mask);
    return cv::countNonZero(mask);
  };
  // The plot area spans rows 50-252 and columns 80-380; 10 is half way up on a log axis (at
  // 10% of the height on a linear one).
  EXPECT_GT(red_in({224, 145, 12, 12}), 5);
  EXPECT_EQ(red_in({224, 225, 12, 12}), 0);
}

TEST(PlotTest, WritesAReadablePng) {
  const auto path = std::filesystem::temp_directory_path() / ("daylit_plot_" + std::to_string(::getpid()) + ".png");
  LinePlot a({"a", "", "", 300, 200, false}), b({"b", "", "", 300, 100, false});
  WritePng(path, {a.Render(), b.Render()});
  const cv::Mat back = cv::imread(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(back.size(), cv::Size(300, 300));
}

}  // namespace
}  // namespace daylit::report
