#include "report/plot.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/atomic_file.h"
#include "base/error.h"

namespace daylit::report {
namespace {

constexpr int kLeft = 80, kRight = 20, kTop = 50, kBottom = 48;
const cv::Scalar kInk(40, 40, 40), kGrid(225, 225, 225);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

cv::Scalar Bgr(const std::array<int, 3>& rgb) { return cv::Scalar(rgb[2], rgb[1], rgb[0]); }

std::string TickLabel(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", std::abs(v) < step * 1e-6 ? 0.0 : v, decimals);
}

void DrawDashed(cv::Mat& image, cv::Point a, cv::Point b, const cv::Scalar& color) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  const int dashes = std::max(1, static_cast<int>(length / 6.0));
  for (int i = 0; i < dashes; i += 2) {
    const double t0 = static_cast<double>(i) / dashes, t1 = std::min(1.0, (i + 1.0) / dashes);
    cv::line(image, a + (b - a) * t0, a + (b - a) * t1, color, 2, cv::LINE_AA);
  }
}

// Tick positions on a log10 axis covering [lo, hi] (in log10 units): the decades, and 2 and 5
// times them when the range spans few decades.
std::vector<double> LogTicks(double lo, double hi) {
  std::vector<double> ticks;
  const bool fine = hi - lo < 3.0;
  for (int k = static_cast<int>(std::floor(lo)); k <= static_cast<int>(std::ceil(hi)); ++k) {
    for (const double m : {1.0, 2.0, 5.0}) {
      if (m != 1.0 && !fine) continue;
      const double t = k + std::log10(m);
      if (t >= lo - 1e-9 && t <= hi + 1e-9) ticks.push_back(t);
    }
  }
  return ticks;
}

}  // namespace

std::array<int, 3> SeriesColor(int index) {
  static constexpr std::array<std::array<int, 3>, 10> kTab10 = {{{31, 119, 180}, {255, 127, 14}, {44, 160, 44},
                                                                 {214, 39, 40}, {148, 103, 189}, {140, 86, 75},
                                                                 {227, 119, 194}, {127, 127, 127}, {188, 189, 34},
                                                                 {23, 190, 207}}};
  return kTab10[static_cast<size_t>(index) % kTab10.size()];
}

std::vector<double> NiceTicks(double lo, double hi, int target) {
  if (!(hi > lo)) return {lo};
  const double raw = (hi - lo) / std::max(1, target);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * magnitude;
    if (step >= raw) break;
  }
  std::vector<double> ticks;
  // Integer multiples of the step: no drift from repeated addition.
  const auto first = static_cast<long long>(std::ceil(lo / step - 1e-9));
  const auto last = static_cast<long long>(std::floor(hi / step + 1e-9));
  for (long long k = first; k <= last; ++k) ticks.push_back(static_cast<double>(k) * step);
  return ticks;
}

namespace {

// The plot's data range and its pixel area: where a value lands.
struct PlotArea {
  cv::Rect area;
  double x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0;
  bool has_data = false;

  cv::Point ToPixel(double x, double y) const {
    return cv::Point(area.x + static_cast<int>(std::lround((x - x0) / (x1 - x0) * area.width)),
                     area.y + area.height - static_cast<int>(std::lround((y - y0) / (y1 - y0) * area.height)));
  }
};

PlotArea AreaOf(const std::vector<Series>& plotted, const PlotOptions& options, int left, int right, int top, int bottom) {
  PlotArea p;
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const Series& s : plotted) {
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  }
  p.has_data = x0 <= x1;
  if (!p.has_data) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (options.y_from_zero && !options.y_log) y0 = std::min(y0, 0.0), y1 = std::max(y1, 0.0);
  if (x1 == x0) x0 -= 0.5, x1 += 0.5;
  if (y1 == y0) y0 -= 0.5, y1 += 0.5;
  const double pad = 0.05 * (y1 - y0);
  y0 -= options.y_from_zero && y0 == 0.0 ? 0.0 : pad;
  y1 += pad;
  p.x0 = x0, p.x1 = x1, p.y0 = y0, p.y1 = y1;
  p.area = cv::Rect(left, top, options.width - left - right, options.height - top - bottom);
  return p;
}

// Grid lines and tick labels on both axes, and the frame.
void DrawAxes(const PlotArea& p, const PlotOptions& options, cv::Mat* image) {
  const cv::Rect& area = p.area;
  const std::vector<double> xt = options.x_log ? LogTicks(p.x0, p.x1) : NiceTicks(p.x0, p.x1, 10);
  const std::vector<double> yt = options.y_log ? LogTicks(p.y0, p.y1) : NiceTicks(p.y0, p.y1, 6);
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0, ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  const auto x_label = [&](double t) { return options.x_log ? fmt::format("{:g}", std::pow(10.0, t)) : TickLabel(t, xstep); };
  const auto y_label = [&](double t) { return options.y_log ? fmt::format("{:g}", std::pow(10.0, t)) : TickLabel(t, ystep); };
  for (const double t : yt) {
    const cv::Point at = p.ToPixel(p.x0, t);
    cv::line(*image, at, {area.x + area.width, at.y}, kGrid, 1);
    const std::string label = y_label(t);
    int base = 0;
    const cv::Size size = cv::getTextSize(label, kFont, 0.45, 1, &base);
    cv::putText(*image, label, {area.x - size.width - 6, at.y + size.height / 2}, kFont, 0.45, kInk, 1, cv::LINE_AA);
  }
  for (const double t : xt) {
    const cv::Point at = p.ToPixel(t, p.y0);
    cv::line(*image, {at.x, area.y}, at, kGrid, 1);
    const std::string label = x_label(t);
    int base = 0;
    const cv::Size size = cv::getTextSize(label, kFont, 0.45, 1, &base);
    cv::putText(*image, label, {at.x - size.width / 2, area.y + area.height + 18}, kFont, 0.45, kInk, 1, cv::LINE_AA);
  }
  cv::rectangle(*image, area, kInk, 1);
}

void DrawSeries(const PlotArea& p, const std::vector<Series>& plotted, cv::Mat* image) {
  for (const Series& s : plotted) {
    const cv::Scalar color = Bgr(s.rgb);
    if (s.markers_only) {
      for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
        if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) cv::circle(*image, p.ToPixel(s.x[i], s.y[i]), 3, color, cv::FILLED, cv::LINE_AA);
      }
      continue;
    }
    for (size_t i = 1; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.y[i - 1]) || !std::isfinite(s.y[i]) || !std::isfinite(s.x[i - 1]) || !std::isfinite(s.x[i])) continue;
      if (s.dashed) {
        DrawDashed(*image, p.ToPixel(s.x[i - 1], s.y[i - 1]), p.ToPixel(s.x[i], s.y[i]), color);
      } else {
        cv::line(*image, p.ToPixel(s.x[i - 1], s.y[i - 1]), p.ToPixel(s.x[i], s.y[i]), color, 2, cv::LINE_AA);
      }
    }
  }
}

// The legend, top right inside the area: each series' line or marker and its name.
void DrawLegend(const cv::Rect& area, const std::vector<Series>& plotted, cv::Mat* image) {
  int legend_width = 0;
  for (const Series& s : plotted) {
    int base = 0;
    legend_width = std::max(legend_width, cv::getTextSize(s.name, kFont, 0.45, 1, &base).width);
  }
  int legend_y = area.y + 18;
  for (const Series& s : plotted) {
    const int x = area.x + area.width - legend_width - 44;
    if (s.markers_only) {
      cv::circle(*image, {x + 12, legend_y - 5}, 3, Bgr(s.rgb), cv::FILLED, cv::LINE_AA);
    } else {
      cv::line(*image, {x, legend_y - 5}, {x + 24, legend_y - 5}, Bgr(s.rgb), 2, cv::LINE_AA);
    }
    cv::putText(*image, s.name, {x + 30, legend_y}, kFont, 0.45, kInk, 1, cv::LINE_AA);
    legend_y += 18;
  }
}

}  // namespace

cv::Mat LinePlot::Render() const {
  cv::Mat image(options_.height, options_.width, CV_8UC3, cv::Scalar(255, 255, 255));
  // Log axes plot log10 of the values; a value ≤ 0 has none and becomes a gap.
  const auto log_of = [](double v) { return v > 0.0 ? std::log10(v) : NAN; };
  std::vector<Series> plotted = series_;
  for (Series& s : plotted) {
    if (options_.x_log) std::transform(s.x.begin(), s.x.end(), s.x.begin(), log_of);
    if (options_.y_log) std::transform(s.y.begin(), s.y.end(), s.y.begin(), log_of);
  }
  const PlotArea p = AreaOf(plotted, options_, kLeft, kRight, kTop, kBottom);
  const cv::Rect& area = p.area;
  DrawAxes(p, options_, &image);
  DrawSeries(p, plotted, &image);
  cv::putText(image, options_.title, {kLeft, 24}, kFont, 0.6, kInk, 1, cv::LINE_AA);
  cv::putText(image, options_.x_label, {area.x + area.width / 2 - 40, options_.height - 8}, kFont, 0.5, kInk, 1, cv::LINE_AA);
  cv::putText(image, options_.y_label, {6, kTop - 10}, kFont, 0.45, kInk, 1, cv::LINE_AA);
  DrawLegend(area, plotted, &image);
  if (!p.has_data) cv::putText(image, "no data", {area.x + area.width / 2 - 30, area.y + area.height / 2}, kFont, 0.6, kInk, 1);
  return image;
}

cv::Mat RenderBarChart(const BarChartOptions& options, const std::vector<BarRow>& rows) {
  constexpr int kRowHeight = 22, kLabelWidth = 260;
  const int height = kTop + kBottom + kRowHeight * std::max<int>(1, static_cast<int>(rows.size()));
  cv::Mat image(height, options.width, CV_8UC3, cv::Scalar(255, 255, 255));
  double lo = options.origin, hi = options.origin;
  for (const BarRow& row : rows) {
    for (const double v : row.values) {
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
  }
  if (hi == lo) lo -= 0.5, hi += 0.5;
  const double pad = 0.05 * (hi - lo);
  lo -= pad, hi += pad;
  const cv::Rect area(kLabelWidth, kTop, options.width - kLabelWidth - kRight, kRowHeight * std::max<int>(1, static_cast<int>(rows.size())));
  const auto to_x = [&](double v) { return area.x + static_cast<int>(std::lround((v - lo) / (hi - lo) * area.width)); };
  const std::vector<double> ticks = NiceTicks(lo, hi, 10);
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (const double t : ticks) {
    const int x = to_x(t);
    cv::line(image, {x, area.y}, {x, area.y + area.height}, kGrid, 1);
    const std::string label = TickLabel(t, step);
    int base = 0;
    const cv::Size size = cv::getTextSize(label, kFont, 0.45, 1, &base);
    cv::putText(image, label, {x - size.width / 2, area.y + area.height + 18}, kFont, 0.45, kInk, 1, cv::LINE_AA);
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    const int y = area.y + static_cast<int>(r) * kRowHeight;
    cv::putText(image, rows[r].label, {8, y + kRowHeight - 7}, kFont, 0.42, kInk, 1, cv::LINE_AA);
    const size_t n = std::max<size_t>(1, rows[r].values.size());
    const int bar = std::max(2, (kRowHeight - 6) / static_cast<int>(n));
    for (size_t k = 0; k < rows[r].values.size(); ++k) {
      const double v = rows[r].values[k];
      if (!std::isfinite(v)) continue;
      const std::array<int, 3> rgb = k < options.colors.size() ? options.colors[k] : SeriesColor(static_cast<int>(k));
      const int top = y + 3 + static_cast<int>(k) * bar;
      const int a = to_x(options.origin), b = to_x(v);
      cv::rectangle(image, cv::Rect(std::min(a, b), top, std::max(1, std::abs(b - a)), bar - 1), Bgr(rgb), cv::FILLED);
    }
  }
  cv::line(image, {to_x(options.origin), area.y}, {to_x(options.origin), area.y + area.height}, kInk, 1);
  cv::rectangle(image, area, kInk, 1);
  cv::putText(image, options.title, {8, 24}, kFont, 0.6, kInk, 1, cv::LINE_AA);
  cv::putText(image, options.x_label, {area.x + area.width / 2 - 60, height - 8}, kFont, 0.5, kInk, 1, cv::LINE_AA);
  return image;
}

void WritePng(const std::filesystem::path& path, const std::vector<cv::Mat>& panels) {
  cv::Mat stacked;
  cv::vconcat(panels, stacked);
  std::vector<uchar> png;
  if (!cv::imencode(".png", stacked, png)) ThrowInputError("{}: cannot encode PNG", path.string());
  WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace daylit::report
