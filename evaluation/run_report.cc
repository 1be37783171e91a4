#include "evaluation/run_report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/invocation.h"
#include "base/version.h"

namespace daylit::evaluation {

void RunReport::Say(const std::string& line) {
  fmt::print("{}\n", line);
  text_ += line;
  text_ += '\n';
}

namespace {

// How the run was started (base/invocation.h), for report.txt's head and figures.json's run/ keys.
std::string RunHead() {
  const Invocation& run = CurrentInvocation();
  if (run.argv.empty()) return "";
  return fmt::format("run: {}\nin: {}\nstarted: {}\n", run.CommandLine(), run.cwd, run.started_utc);
}

}  // namespace

std::string RunReport::FiguresJson() const {
  nlohmann::json json = nlohmann::json::object();
  json["run/daylit"] = kVersion;
  if (const Invocation& run = CurrentInvocation(); !run.argv.empty()) {
    json["run/command"] = run.CommandLine();
    json["run/argv"] = run.argv;
    json["run/cwd"] = run.cwd;
    json["run/started_utc"] = run.started_utc;
  }
  for (const auto& [key, value] : figures_) {
    if (const double* number = std::get_if<double>(&value); number != nullptr && std::floor(*number) == *number &&
                                                             std::abs(*number) < 1e15) {
      json[key] = static_cast<int64_t>(*number);  // counts as counts: 600, not 600.0
    } else {
      std::visit([&, &key = key](const auto& v) { json[key] = v; }, value);
    }
  }
  return json.dump(2) + "\n";
}

void RunReport::Write(const std::filesystem::path& file) const {
  WriteFileAtomically(file, fmt::format("daylit {}\n{}{}", kVersion, RunHead(), text_));
}

void RunReport::WriteFigures(const std::filesystem::path& file) const { WriteFileAtomically(file, FiguresJson()); }

void RunFigures(const pipeline::PipelineRun& run, RunReport* report) {
  const double frames = static_cast<double>(run.frames.size());
  double moves_ms = 0.0;
  for (const double ms : run.sun_moves_ms) moves_ms += ms;
  report->Figure("frames", frames);
  report->Figure("seconds", run.seconds);
  report->Figure("fps", frames / std::max(run.seconds, 1e-9));
  report->Figure("estimate_ms", run.median_estimate_ms);
  report->Figure("sun_moves", static_cast<double>(run.sun_moves_ms.size()));
  report->Figure("sun_moves_ms", moves_ms);
  report->Figure("stage_ms", run.median_stage_ms);
}

}  // namespace daylit::evaluation
