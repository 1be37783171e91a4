// Line plots written as PNG: lighting over time, error curves, the sun's path. Drawn with
// OpenCV, so they need no display and no plotting package.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace daylit::report {

struct Series {
  std::string name;
  std::vector<double> x, y;  // same length; a NaN y breaks the line
  std::array<int, 3> rgb{31, 119, 180};
  bool dashed = false;
  bool markers_only = false;  // dots at the points, no line
};

struct PlotOptions {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width = 1200;   // pixels
  int height = 420;   // pixels
  bool y_from_zero = false;  // include 0 in the y range
  bool x_log = false;        // logarithmic axes (values ≤ 0 are left out), ticks at 1, 2, 5 × 10^k
  bool y_log = false;
};

class LinePlot {
 public:
  explicit LinePlot(PlotOptions options) : options_(std::move(options)) {}
  void Add(Series series) { series_.push_back(std::move(series)); }

  // The plot as an 8-bit BGR image; an empty plot gets axes and "no data".
  cv::Mat Render() const;

 private:
  PlotOptions options_;
  std::vector<Series> series_;
};

// A horizontal bar chart: one row per label, one bar per value in the row (e.g. R, G, B), from
// `origin` (the reference, drawn as a line) to the value, in the values' colours.
struct BarRow {
  std::string label;
  std::vector<double> values;  // NaN: no bar
};
struct BarChartOptions {
  std::string title;
  std::string x_label;
  double origin = 0.0;
  std::vector<std::array<int, 3>> colors;  // per value in a row
  int width = 1200;                        // pixels; the height follows the rows
};
cv::Mat RenderBarChart(const BarChartOptions& options, const std::vector<BarRow>& rows);

// Stacks images (same width) top to bottom and writes them as one PNG, atomically.
void WritePng(const std::filesystem::path& path, const std::vector<cv::Mat>& panels);

// "Nice" tick positions (1, 2, 5 × 10^k steps) covering [lo, hi], about `target` of them.
std::vector<double> NiceTicks(double lo, double hi, int target);

// Standard series colours (matplotlib's tab10 order).
std::array<int, 3> SeriesColor(int index);

}  // namespace daylit::report
