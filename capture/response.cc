#include "capture/response.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <opencv2/photo.hpp>

#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"

namespace daylit::capture {

namespace {

// Linear interpolation in a 256-entry table at encoded value v in [0, 1].
double TableLookup(const std::vector<double>& table, double v) {
  const double x = v * 255.0;
  const int i = std::min(static_cast<int>(x), 254);
  const double f = x - i;
  return table[static_cast<size_t>(i)] + f * (table[static_cast<size_t>(i) + 1] - table[static_cast<size_t>(i)]);
}

}  // namespace

double CameraResponse::ToLinear(double encoded, int channel) const {
  const double v = std::clamp(encoded, 0.0, 1.0);
  switch (curve) {
    case ResponseCurve::kTable: return TableLookup(table->linear[static_cast<size_t>(channel)], v);
    case ResponseCurve::kLinear: return v;
    case ResponseCurve::kGamma: return std::pow(v, gamma);
    case ResponseCurve::kSrgb:
      return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
  }
  return v;
}

double CameraResponse::ToEncoded(double linear, int channel) const {
  const double v = std::clamp(linear, 0.0, 1.0);
  switch (curve) {
    case ResponseCurve::kTable: {
      // The inverse of the non-decreasing table: the first code whose value reaches v, refined
      // linearly within its step.
      const std::vector<double>& t = table->linear[static_cast<size_t>(channel)];
      const auto it = std::lower_bound(t.begin(), t.end(), v);
      if (it == t.begin()) return 0.0;
      if (it == t.end()) return 1.0;
      const size_t i = static_cast<size_t>(it - t.begin());
      const double step = t[i] - t[i - 1];
      return (static_cast<double>(i - 1) + (step > 0.0 ? (v - t[i - 1]) / step : 1.0)) / 255.0;
    }
    case ResponseCurve::kLinear: return v;
    case ResponseCurve::kGamma: return std::pow(v, 1.0 / gamma);
    case ResponseCurve::kSrgb:
      return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  }
  return v;
}

std::array<float, 256> CameraResponse::LinearLut8(int channel) const {
  std::array<float, 256> lut{};
  for (int i = 0; i < 256; ++i) lut[static_cast<size_t>(i)] = static_cast<float>(ToLinear(i / 255.0, channel));
  return lut;
}

void CameraResponse::Linearize(const float* encoded, float* linear, size_t count) const {
  Linearizer(*this).Apply(encoded, linear, count);
}

Linearizer::Linearizer(const CameraResponse& response) {
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i <= kSteps; ++i) {
      tables_[static_cast<size_t>(c)][static_cast<size_t>(i)] =
          static_cast<float>(response.ToLinear(static_cast<double>(i) / kSteps, c));
    }
  }
}

void Linearizer::Apply(const float* encoded, float* linear, size_t count) const {
  for (size_t k = 0; k < count; ++k) linear[k] = (*this)(encoded[k], static_cast<int>(k % 3));
}

Encoder::Encoder(const CameraResponse& response) {
  for (int c = 0; c < 3; ++c) {
    for (int i = 0; i <= kSteps; ++i) {
      const double s = static_cast<double>(i) / kSteps;
      tables_[static_cast<size_t>(c)][static_cast<size_t>(i)] = static_cast<float>(response.ToEncoded(s * s, c));
    }
  }
}

void Encoder::Apply(const float* linear, float scale, float* encoded, size_t count) const {
  for (size_t k = 0; k < count; k += 3) {
    for (int c = 0; c < 3; ++c) encoded[k + static_cast<size_t>(c)] = (*this)(linear[k + static_cast<size_t>(c)] * scale, c);
  }
}

std::string CameraResponse::Describe() const {
  switch (curve) {
    case ResponseCurve::kLinear: return "linear";
    case ResponseCurve::kSrgb: return "srgb";
    case ResponseCurve::kGamma: return fmt::format("gamma {}", gamma);
    case ResponseCurve::kTable: return fmt::format("table {}", table->file.filename().string());
  }
  return "?";
}

cv::Mat EncodeToBgr8(const float* rgb, int width, int height, double scale, const CameraResponse* response) {
  cv::Mat bgr(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    auto* row = bgr.ptr<cv::Vec3b>(y);
    const float* in = rgb + static_cast<size_t>(y) * static_cast<size_t>(width) * 3;
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double v = in[3 * x + c] * scale;
        const double encoded = response != nullptr ? response->ToEncoded(v, c) : std::clamp(v, 0.0, 1.0);
        row[x][2 - c] = static_cast<uint8_t>(std::lround(255.0 * encoded));
      }
    }
  }
  return bgr;
}

std::shared_ptr<const ResponseTable> ReadResponseTable(const std::filesystem::path& csv) {
  const CsvTable t = ReadCsvFile(csv);
  const int code = t.RequireColumn("code");
  const std::array<int, 3> columns = {t.RequireColumn("r"), t.RequireColumn("g"), t.RequireColumn("b")};
  if (t.rows.size() != 256) ThrowInputError("{}: {} rows; a response table has one per code, 0-255", csv.string(), t.rows.size());
  auto table = std::make_shared<ResponseTable>();
  table->file = csv;
  for (auto& channel : table->linear) channel.assign(256, 0.0);
  for (size_t row = 0; row < 256; ++row) {
    if (ParseFiniteDouble(t.rows[row][static_cast<size_t>(code)], t.Where(row) + ": code") != static_cast<double>(row)) {
      ThrowInputError("{}: code: expected {} (codes 0-255 in order)", t.Where(row), row);
    }
    for (size_t c = 0; c < 3; ++c) {
      const std::string& name = t.header[static_cast<size_t>(columns[c])];
      const double v = ParseFiniteDouble(t.rows[row][static_cast<size_t>(columns[c])], t.Where(row) + ": " + name);
      if (!std::isfinite(v) || v < 0.0) ThrowInputError("{}: {}: {} is not a linear value ≥ 0", t.Where(row), name, v);
      if (row > 0 && v < table->linear[c][row - 1]) {
        ThrowInputError("{}: {}: {} is below the previous code's {}; a response never falls", t.Where(row), name, v,
                        table->linear[c][row - 1]);
      }
      table->linear[c][row] = v;
    }
  }
  for (size_t c = 0; c < 3; ++c) {
    const double top = table->linear[c][255];
    if (!(top > 0.0)) ThrowInputError("{}: {}: code 255 is 0; the curve carries no light", csv.string(), "rgb"[c]);
    for (double& v : table->linear[c]) v /= top;
  }
  return table;
}

void WriteResponseTable(const std::filesystem::path& csv, const ResponseTable& table) {
  std::string text = "code,r,g,b\n";
  for (size_t i = 0; i < 256; ++i) {
    text += fmt::format("{},{:.8g},{:.8g},{:.8g}\n", i, table.linear[0][i], table.linear[1][i], table.linear[2][i]);
  }
  WriteFileAtomically(csv, text);
}

ResponseTable CalibrateResponse(const std::vector<cv::Mat>& images, const std::vector<float>& seconds) {
  cv::Mat response;  // 256×1 CV_32FC3, BGR, linear up to a scale per channel
  cv::createCalibrateDebevec()->process(images, response, seconds);
  // Debevec's weights fall to 0 at the ends of the code range, so the curve's top is barely
  // constrained: on a clean sRGB bracket it sags 5-10% from code 220 and then bends up sevenfold
  // by 255. Above code 210 it is replaced by the power law (ln g = a + γ ln code) fitted over
  // codes 128-210, where it is well determined, then scaled to 1 at 255.
  constexpr int kFitFrom = 128, kFitTo = 210;
  ResponseTable table;
  for (size_t c = 0; c < 3; ++c) {
    std::vector<double>& channel = table.linear[c];
    channel.resize(256);
    double running = 0.0;
    for (int i = 0; i < 256; ++i) {
      running = std::max(running, static_cast<double>(response.at<cv::Vec3f>(i)[2 - static_cast<int>(c)]));
      channel[static_cast<size_t>(i)] = running;
    }
    double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
    for (int i = kFitFrom; i <= kFitTo; ++i) {
      const double x = std::log(i / 255.0), y = std::log(std::max(channel[static_cast<size_t>(i)], 1e-30));
      sx += x, sy += y, sxx += x * x, sxy += x * y, n += 1;
    }
    const double power = std::max(0.0, (n * sxy - sx * sy) / (n * sxx - sx * sx)), intercept = (sy - power * sx) / n;
    for (int i = kFitTo + 1; i < 256; ++i) {
      const double continued = std::exp(intercept + power * std::log(i / 255.0));
      channel[static_cast<size_t>(i)] = std::max(channel[static_cast<size_t>(i) - 1], continued);
    }
    for (double& v : channel) v /= channel.back();
  }
  return table;
}

}  // namespace daylit::capture
