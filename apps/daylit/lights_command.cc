// daylit lights: a light probe approximated by N directional lights (median cut, irradiance
// optimization) and by SH9, with seed 002's error measure, the automatic N and the error plot
// (docs/relight.md).
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "apps/daylit/commands.h"
#include "base/atomic_file.h"
#include "base/error.h"
#include "base/log.h"
#include "base/progress.h"
#include "relight/exact_irradiance.h"
#include "relight/light_fit.h"
#include "relight/lights.h"
#include "relight/probe.h"
#include "relight/sh9.h"
#include "report/plot.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

// The most lights each method takes: irradiance optimization's dense normal equations grow as
// (5N)², median cut's regions are cheap.
constexpr int kMaxIoLights = 128;
constexpr int kMaxMedianCutLights = 1024;

struct LightsOptions {
  std::string probe;
  std::string n = "1,2,4,8,16,32,64,128";
  std::string methods = "mediancut,io,sh";
  std::optional<double> threshold;
  std::string out = "lights";
  bool no_ambient = false;
};

struct Row {
  std::string method;
  int n = 0;
  relight::ApproximationError error;
};

std::vector<std::string> SplitList(const std::string& list) {
  std::vector<std::string> items;
  size_t begin = 0;
  while (begin <= list.size()) {
    const size_t end = std::min(list.find(',', begin), list.size());
    if (end > begin) items.push_back(list.substr(begin, end - begin));
    begin = end + 1;
  }
  return items;
}

int ParseCount(const std::string& text) {
  size_t used = 0;
  int n = 0;
  try {
    n = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || text.empty()) ThrowInputError("--n: '{}' is not a number of lights", text);
  return n;
}

// "1,2,4,8" or ranges "1-8"; each in [1, max].
std::vector<int> ParseCounts(const std::string& list, int max) {
  std::vector<int> counts;
  for (const std::string& item : SplitList(list)) {
    const size_t dash = item.find('-', 1);
    const int lo = ParseCount(item.substr(0, dash)), hi = dash == std::string::npos ? lo : ParseCount(item.substr(dash + 1));
    for (const int n : {lo, hi}) {
      if (n < 1 || n > max) ThrowInputError("--n: {} lights; the number of lights must be in [1, {}]", n, max);
    }
    if (hi < lo) ThrowInputError("--n: the range '{}' runs backwards", item);
    for (int n = lo; n <= hi; ++n) counts.push_back(n);
  }
  if (counts.empty()) ThrowInputError("--n: no number of lights given");
  std::sort(counts.begin(), counts.end());
  counts.erase(std::unique(counts.begin(), counts.end()), counts.end());
  return counts;
}


class Approximator {
 public:
  Approximator(const scene::HdrImage& map, fs::path out, relight::LightFitOptions fit)
      : map_(map), out_(std::move(out)), fit_(fit) {
    normals_ = relight::IcosahedronNormals(5);
    truth_ = relight::ExactIrradiance(map_, normals_);
  }

  // Fits (or looks up) `method` with n lights, writes lights_<method>_<n>.json, returns the row.
  const Row& Lights(const std::string& method, int n) {
    const auto key = std::make_pair(method, n);
    if (const auto found = rows_.find(key); found != rows_.end()) return found->second;
    const auto start = std::chrono::steady_clock::now();
    relight::LightSet set;
    std::string detail;
    if (method == "io") {
      const relight::LightFitResult fit = relight::IrradianceOptimization(map_, n, fit_);
      set = fit.lights;
      if (!fit.converged) Log().warn("io, {} lights: not converged: {}", n, fit.termination);
      detail = fmt::format(", {} iterations", fit.iterations);
    } else {
      set = relight::MedianCutLights(map_, n);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WriteFileAtomically(out_ / fmt::format("lights_{}_{}.json", method, n), relight::LightSetJson(set));
    Row row{method, n, relight::RelativeError(truth_, set.Irradiance(normals_))};
    Log().debug("{}, {} lights: mean {:.2f}%, max {:.2f}% ({:.3f} s{})", method, n, 100 * row.error.mean,
                100 * row.error.max, seconds, detail);
    return rows_.emplace(key, row).first->second;
  }

  // SH9 in both measures; writes sh9.json.
  Row Sh9() {
    const relight::ShRgb9 sh = relight::ProjectLatLong(map_.rgb.data(), map_.width, map_.height);
    std::vector<glm::dvec3> e(normals_.size());
    for (size_t i = 0; i < normals_.size(); ++i) e[i] = sh.Irradiance(glm::dvec3(normals_[i]));
    const relight::ApproximationError per_normal = relight::RelativeError(truth_, e);
    sh9_to_max_ = relight::RelativeToMaxError(truth_, e);
    nlohmann::json coefficients = nlohmann::json::array();
    for (const glm::dvec3& c : sh.coefficients) coefficients.push_back({c.x, c.y, c.z});
    const nlohmann::json json = {
        {"radiance_coefficients", coefficients},
        {"basis", "real SH, l <= 2, order 00 1-1 10 11 2-2 2-1 20 21 22 (relight/sh9.h); E(n) = sum A_l L_lm Y_lm(n)"},
        {"error_per_normal", {{"mean", per_normal.mean}, {"max", per_normal.max}}},
        {"error_relative_to_max", {{"mean", sh9_to_max_.mean}, {"max", sh9_to_max_.max}}}};
    WriteFileAtomically(out_ / "sh9.json", json.dump(2) + "\n");
    return {"sh", 9, per_normal};
  }

  // The smallest n ≤ max whose mean error is below `threshold`: doubling, then bisection (the
  // error falls with n, nearly monotonically). Empty when even `max` lights do not reach it.
  std::optional<int> Automatic(const std::string& method, double threshold, int max) {
    int below = 1;
    while (Lights(method, below).error.mean >= threshold) {
      if (below == max) return std::nullopt;
      below = std::min(2 * below, max);
    }
    int above = below / 2;  // its error is ≥ threshold (or it is 0)
    while (below - above > 1) {
      const int middle = (above + below) / 2;
      (Lights(method, middle).error.mean < threshold ? below : above) = middle;
    }
    return below;
  }

  const std::map<std::pair<std::string, int>, Row>& rows() const { return rows_; }
  const relight::ApproximationError& sh9_to_max() const { return sh9_to_max_; }

 private:
  const scene::HdrImage& map_;
  fs::path out_;
  relight::LightFitOptions fit_;
  std::vector<glm::vec3> normals_;
  std::vector<glm::dvec3> truth_;
  std::map<std::pair<std::string, int>, Row> rows_;
  relight::ApproximationError sh9_to_max_;
};

const char* MethodName(const std::string& method) {
  return method == "io" ? "irradiance optimization" : method == "mediancut" ? "median cut" : "SH9";
}

// Seed 002's Fig. 4: mean and max error against the number of lights, log-log.
void WritePlot(const fs::path& path, const std::string& probe, const std::vector<Row>& rows, std::optional<double> threshold) {
  std::vector<cv::Mat> panels;
  for (const bool max : {false, true}) {
    report::PlotOptions options{fmt::format("{}: {} irradiance error vs number of lights (seed 002, Fig. 4)", probe,
                                            max ? "max" : "mean"),
                                "lights", "error %", 1000, 380};
    options.x_log = options.y_log = true;
    report::LinePlot plot(options);
    int color = 0;
    double x_lo = 1e9, x_hi = 0.0;
    for (const std::string method : {"mediancut", "io", "sh"}) {
      report::Series series{MethodName(method), {}, {}, report::SeriesColor(color++)};
      series.markers_only = method == "sh";
      if (method == "sh") series.name = "SH9 (9 coefficients)";
      for (const Row& r : rows) {
        if (r.method != method) continue;
        series.x.push_back(r.n), series.y.push_back(100 * (max ? r.error.max : r.error.mean));
        x_lo = std::min(x_lo, static_cast<double>(r.n)), x_hi = std::max(x_hi, static_cast<double>(r.n));
      }
      if (!series.x.empty()) plot.Add(series);
    }
    if (threshold && !max && x_hi > 0.0) {
      report::Series line{fmt::format("threshold {:g}%", 100 * *threshold), {x_lo, x_hi}, {100 * *threshold, 100 * *threshold},
                          {127, 127, 127}};
      line.dashed = true;
      plot.Add(line);
    }
    panels.push_back(plot.Render());
  }
  report::WritePng(path, panels);
}

void RunLights(const LightsOptions& o) {
  const std::vector<std::string> methods = SplitList(o.methods);
  if (methods.empty()) ThrowInputError("--method: no method given (mediancut, io, sh)");
  for (const std::string& m : methods) {
    if (m != "mediancut" && m != "io" && m != "sh") ThrowInputError("--method: '{}' is not one of mediancut, io, sh", m);
  }
  const bool io = std::find(methods.begin(), methods.end(), "io") != methods.end();
  const std::vector<int> counts = ParseCounts(o.n, io ? kMaxIoLights : kMaxMedianCutLights);
  if (o.threshold && !(*o.threshold > 0.0 && *o.threshold < 1.0)) {
    ThrowInputError("--threshold: {} is not a mean relative error in (0, 1)", *o.threshold);
  }
  relight::Probe probe = relight::LoadProbe(o.probe);
  for (const std::string& w : probe.warnings) Log().warn("{}", w);
  Log().info("{}: {}x{} lat-long{}", o.probe, probe.map.width, probe.map.height,
             probe.converted_from_angular ? " (converted from an angular map)" : "");
  fs::create_directories(o.out);
  relight::LightFitOptions fit;
  fit.ambient = !o.no_ambient;
  Approximator approximator(probe.map, o.out, fit);

  std::vector<Row> rows;
  size_t jobs = 0;
  for (const std::string& m : methods) jobs += m == "sh" ? 1 : counts.size();
  {
    Progress progress("lights", jobs);
    for (const std::string& m : methods) {
      if (m == "sh") {
        rows.push_back(approximator.Sh9());
        progress.Advance();
        continue;
      }
      // Small n first: the cheap fits show progress early; io's 64 and 128 take tens of seconds.
      for (const int n : counts) {
        progress.SetSuffix(fmt::format("{} {}", m, n));
        approximator.Lights(m, n);
        progress.Advance();
      }
    }
  }
  nlohmann::json automatic = nlohmann::json::object();
  if (o.threshold) {
    automatic["threshold"] = *o.threshold;
    for (const std::string& m : methods) {
      if (m == "sh") continue;
      const int max = m == "io" ? kMaxIoLights : kMaxMedianCutLights;
      const std::optional<int> n = approximator.Automatic(m, *o.threshold, max);
      if (!n) {
        Log().warn("{}: no number of lights up to {} reaches a mean error below {:g}%", MethodName(m), max, 100 * *o.threshold);
        automatic[m] = nullptr;
        continue;
      }
      const Row& row = approximator.Lights(m, *n);
      automatic[m] = {{"n", *n}, {"mean_error", row.error.mean}, {"max_error", row.error.max},
                      {"lights", fmt::format("lights_{}_{}.json", m, *n)}};
      fmt::print("{}: {} lights reach a mean error of {:.2f}% (below {:g}%)\n", MethodName(m), *n, 100 * row.error.mean,
                 100 * *o.threshold);
    }
    WriteFileAtomically(fs::path(o.out) / "automatic.json", automatic.dump(2) + "\n");
  }
  // Every (method, n) computed, the automatic search's included, in method then n order.
  std::vector<Row> all;
  for (const std::string& m : methods) {
    if (m == "sh") {
      for (const Row& r : rows) {
        if (r.method == "sh") all.push_back(r);
      }
      continue;
    }
    for (const auto& [key, row] : approximator.rows()) {
      if (key.first == m) all.push_back(row);
    }
  }
  std::string csv = "method,n,mean_error,max_error\n";
  for (const Row& r : all) csv += fmt::format("{},{},{:.6g},{:.6g}\n", r.method, r.n, r.error.mean, r.error.max);
  WriteFileAtomically(fs::path(o.out) / "errors.csv", csv);
  WritePlot(fs::path(o.out) / "errors.png", fs::path(o.probe).filename().string(), all, o.threshold);

  fmt::print("{:<24} {:>6} {:>10} {:>10}   (per-normal relative irradiance error over {} normals)\n", "method", "n",
             "mean", "max", all.empty() ? 0 : all.front().error.normals);
  for (const Row& r : all) {
    fmt::print("{:<24} {:>6} {:>9.2f}% {:>9.2f}%\n", MethodName(r.method), r.n, 100 * r.error.mean, 100 * r.error.max);
  }
  if (std::find(methods.begin(), methods.end(), "sh") != methods.end()) {
    fmt::print("SH9 relative to the maximum irradiance (Ramamoorthi & Hanrahan's measure): mean {:.2f}%, max {:.2f}%\n",
               100 * approximator.sh9_to_max().mean, 100 * approximator.sh9_to_max().max);
  }
  Log().info("wrote {}/errors.csv, errors.png and the lights", o.out);
}

}  // namespace

void AddLightsCommand(CLI::App& app) {
  auto options = std::make_shared<LightsOptions>();
  CLI::App* cmd = app.add_subcommand(
      "lights", "Approximate a light probe by N directional lights (median cut, irradiance optimization) and SH9");
  cmd->add_option("probe", options->probe, "Probe: .exr or .hdr, 2:1 lat-long or square angular map")->required();
  cmd->add_option("--n", options->n, "Numbers of lights: a list, ranges allowed (default 1,2,4,8,16,32,64,128)");
  cmd->add_option("--method", options->methods, "Methods: mediancut,io,sh (default all)");
  cmd->add_option("--threshold", options->threshold,
                  "Also find the smallest N whose mean error is below this (e.g. 0.05)");
  cmd->add_option("--out", options->out, "Output folder (default lights)");
  cmd->add_flag("--no-ambient", options->no_ambient, "Irradiance optimization without the ambient term (seed 002's form)");
  cmd->callback([options] { RunLights(*options); });
}

}  // namespace daylit::app
