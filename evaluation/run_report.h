// The report of a run: its text (report.txt beside daylit replay's video), each line printed on
// stdout as it is said, and its figures (figures.json) under stable keys for scripts, such as
// scripts/results.sh, which fills docs/results.md from them. Both are written atomically.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <variant>

#include "pipeline/lighting_pipeline.h"

namespace daylit::evaluation {

class RunReport {
 public:
  void Say(const std::string& line);
  // A figure under `key` ("fps", "objects/worst"): a number in the unit its key names
  // (fractions for errors, ms, fps), or a text such as the GL renderer's name.
  void Figure(const std::string& key, double value) { figures_[key] = value; }
  void Figure(const std::string& key, const std::string& value) { figures_[key] = value; }

  const std::string& text() const { return text_; }
  // The figures as one JSON object, keys sorted, with how the run was started: run/daylit (the
  // version), and where main() recorded it (base/invocation.h) run/command (one line a shell
  // reads back), run/argv, run/cwd, run/started_utc.
  std::string FiguresJson() const;
  // The text with the build's version (base/version.h) on its first line, then the command line,
  // the folder it ran in and when it started (`run:`, `in:`, `started:`), where main() recorded them:
  // enough to repeat the run from its output folder.
  void Write(const std::filesystem::path& file) const;
  void WriteFigures(const std::filesystem::path& file) const;

 private:
  std::string text_;
  std::map<std::string, std::variant<double, std::string>> figures_;
};

// A run's speed as figures: frames, seconds, fps (end to end), estimate_ms (median after
// decoding, frames without a sun move), sun_moves and sun_moves_ms (their total), stage_ms.
void RunFigures(const pipeline::PipelineRun& run, RunReport* report);

}  // namespace daylit::evaluation
