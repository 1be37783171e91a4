// daylit lights: a light probe approximated by N directional lights (median cut, irradiance
// optimization) and by SH9, with seed 002's error measure, the automatic N and the error plot
// (docs/lightfit.md).
#include <algorithm>
#include <filesystem>
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
#include "lightfit/light_fit.h"
#include "lightfit/lights.h"
#include "lightfit/probe.h"
#include "lightfit/probe_approximations.h"
#include "report/plot.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

struct LightsOptions {
  std::string probe;
  std::string n = "1,2,4,8,16,32,64,128";
  std::string methods = "mediancut,io,sh";
  std::optional<double> threshold;
  std::string out = "lights";
  bool no_ambient = false;
};

// One line of errors.csv and of the plot.
struct Row {
  lightfit::Method method;
  int n = 0;
  lightfit::ApproximationError error;
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
    for (const lightfit::Method method :
         {lightfit::Method::kMedianCut, lightfit::Method::kIrradianceOptimization, lightfit::Method::kSh9}) {
      report::Series series{lightfit::MethodName(method), {}, {}, report::SeriesColor(color++)};
      series.markers_only = method == lightfit::Method::kSh9;
      if (method == lightfit::Method::kSh9) series.name = "SH9 (9 coefficients)";
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

std::vector<lightfit::Method> ParseMethods(const std::string& list) {
  std::vector<lightfit::Method> methods;
  for (const std::string& key : SplitList(list)) {
    const std::optional<lightfit::Method> m = lightfit::ParseMethod(key);
    if (!m) ThrowInputError("--method: '{}' is not one of mediancut, io, sh", key);
    methods.push_back(*m);
  }
  if (methods.empty()) ThrowInputError("--method: no method given (mediancut, io, sh)");
  return methods;
}

// The table's fits (small n first: the cheap ones show progress early; io's 64 and 128 take tens
// of seconds), then the automatic N of each method under the threshold (automatic.json).
void Approximate(const LightsOptions& o, const std::vector<lightfit::Method>& methods, const std::vector<int>& counts,
                 lightfit::ProbeApproximations* table) {
  size_t jobs = 0;
  for (const lightfit::Method m : methods) jobs += m == lightfit::Method::kSh9 ? 1 : counts.size();
  {
    Progress progress("lights", jobs);
    for (const lightfit::Method m : methods) {
      for (const int n : m == lightfit::Method::kSh9 ? std::vector<int>{9} : counts) {
        progress.SetSuffix(fmt::format("{} {}", lightfit::MethodKey(m), n));
        if (m == lightfit::Method::kSh9) {
          table->Sh9();
        } else {
          table->Lights(m, n);
        }
        progress.Advance();
      }
    }
  }
  if (!o.threshold) return;
  nlohmann::json automatic = {{"threshold", *o.threshold}};
  for (const lightfit::Method m : methods) {
    if (m == lightfit::Method::kSh9) continue;
    const char* name = lightfit::MethodName(m);
    const std::optional<int> n = table->AutomaticN(m, *o.threshold);
    if (!n) {
      Log().warn("{}: no number of lights up to {} reaches a mean error below {:g}%", name, lightfit::MaxLights(m),
                 100 * *o.threshold);
      automatic[lightfit::MethodKey(m)] = nullptr;
      continue;
    }
    const lightfit::LightsApproximation& row = table->Lights(m, *n);
    automatic[lightfit::MethodKey(m)] = {{"n", *n}, {"mean_error", row.error.mean}, {"max_error", row.error.max},
                                         {"lights", fmt::format("lights_{}_{}.json", lightfit::MethodKey(m), *n)}};
    fmt::print("{}: {} lights reach a mean error of {:.2f}% (below {:g}%)\n", name, *n, 100 * row.error.mean,
               100 * *o.threshold);
  }
  WriteFileAtomically(fs::path(o.out) / "automatic.json", automatic.dump(2) + "\n");
}

// lights_<method>_<n>.json for every fit and sh9.json; the rows of errors.csv in method then n order.
std::vector<Row> WriteFits(const fs::path& out, const std::vector<lightfit::Method>& methods,
                           lightfit::ProbeApproximations* table) {
  std::vector<Row> rows;
  for (const lightfit::Method m : methods) {
    if (m == lightfit::Method::kSh9) {
      const lightfit::Sh9Approximation& sh9 = table->Sh9();
      nlohmann::json coefficients = nlohmann::json::array();
      for (const glm::dvec3& c : sh9.radiance.coefficients) coefficients.push_back({c.x, c.y, c.z});
      const nlohmann::json json = {
          {"radiance_coefficients", coefficients},
          {"basis", "real SH, l <= 2, order 00 1-1 10 11 2-2 2-1 20 21 22 (sh/sh9.h); E(n) = sum A_l L_lm Y_lm(n)"},
          {"error_per_normal", {{"mean", sh9.error.mean}, {"max", sh9.error.max}}},
          {"error_relative_to_max", {{"mean", sh9.error_to_max.mean}, {"max", sh9.error_to_max.max}}}};
      WriteFileAtomically(out / "sh9.json", json.dump(2) + "\n");
      rows.push_back({m, 9, sh9.error});
      continue;
    }
    for (const lightfit::LightsApproximation* fit : table->Fitted(m)) {
      WriteFileAtomically(out / fmt::format("lights_{}_{}.json", lightfit::MethodKey(m), fit->n),
                          lightfit::LightSetJson(fit->lights));
      if (!fit->converged) Log().warn("io, {} lights: not converged: {}", fit->n, fit->termination);
      Log().debug("{}, {} lights: mean {:.2f}%, max {:.2f}% ({:.3f} s)", lightfit::MethodKey(m), fit->n,
                  100 * fit->error.mean, 100 * fit->error.max, fit->seconds);
      rows.push_back({m, fit->n, fit->error});
    }
  }
  return rows;
}

void RunLights(const LightsOptions& o) {
  const std::vector<lightfit::Method> methods = ParseMethods(o.methods);
  const bool io = std::find(methods.begin(), methods.end(), lightfit::Method::kIrradianceOptimization) != methods.end();
  const std::vector<int> counts =
      ParseCounts(o.n, lightfit::MaxLights(io ? lightfit::Method::kIrradianceOptimization : lightfit::Method::kMedianCut));
  if (o.threshold && !(*o.threshold > 0.0 && *o.threshold < 1.0)) {
    ThrowInputError("--threshold: {} is not a mean relative error in (0, 1)", *o.threshold);
  }
  // Nothing it writes may be the probe, through a link or by another name.
  std::vector<std::pair<std::string, fs::path>> outputs;
  for (const char* name : {"errors.csv", "errors.png", "automatic.json", "sh9.json"}) {
    outputs.emplace_back(fmt::format("--out's {}", name), fs::path(o.out) / name);
  }
  for (const lightfit::Method m : methods) {
    for (const int n : counts) {
      const std::string name = fmt::format("lights_{}_{}.json", lightfit::MethodKey(m), n);
      outputs.emplace_back("--out's " + name, fs::path(o.out) / name);
    }
  }
  RefuseInputsAsOutputs({fs::path(o.probe)}, {}, outputs);
  // The output folder first: a file in its place, or a folder that cannot be made or written, is
  // said before the probe is read.
  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec || !fs::is_directory(o.out)) {
    ThrowInputError("--out: {}: cannot make the folder ({})", o.out, ec ? ec.message() : "a file is in the way");
  }
  RequireWritable("--out", fs::path(o.out) / "errors.csv");
  lightfit::Probe probe = lightfit::LoadProbe(o.probe);
  for (const std::string& w : probe.warnings) Log().warn("{}", w);
  Log().info("{}: {}x{} lat-long{}", o.probe, probe.map.width, probe.map.height,
             probe.converted_from_angular ? " (converted from an angular map)" : "");
  lightfit::LightFitOptions fit;
  fit.ambient = !o.no_ambient;
  lightfit::ProbeApproximations table(probe.map, fit);
  Approximate(o, methods, counts, &table);
  const std::vector<Row> rows = WriteFits(o.out, methods, &table);
  std::string csv = "method,n,mean_error,max_error\n";
  for (const Row& r : rows) {
    csv += fmt::format("{},{},{:.6g},{:.6g}\n", lightfit::MethodKey(r.method), r.n, r.error.mean, r.error.max);
  }
  WriteFileAtomically(fs::path(o.out) / "errors.csv", csv);
  WritePlot(fs::path(o.out) / "errors.png", fs::path(o.probe).filename().string(), rows, o.threshold);
  fmt::print("{:<24} {:>6} {:>10} {:>10}   (per-normal relative irradiance error over {} normals)\n", "method", "n",
             "mean", "max", rows.empty() ? 0 : rows.front().error.normals);
  for (const Row& r : rows) {
    fmt::print("{:<24} {:>6} {:>9.2f}% {:>9.2f}%\n", lightfit::MethodName(r.method), r.n, 100 * r.error.mean,
               100 * r.error.max);
  }
  if (std::find(methods.begin(), methods.end(), lightfit::Method::kSh9) != methods.end()) {
    fmt::print("SH9 relative to the maximum irradiance (Ramamoorthi & Hanrahan's measure): mean {:.2f}%, max {:.2f}%\n",
               100 * table.Sh9().error_to_max.mean, 100 * table.Sh9().error_to_max.max);
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
