// docs/results.md, the one page of measured figures, is generated: scripts/results.sh runs the
// benchmarks, the recording tests and daylit's own runs, and FillResultsPage fills a template
// (docs/results.md.in) with what they measured. A field is `{{key}}` or `{{key|unit}}`:
//   bench/<benchmark>/real_time, .../cpu_time   seconds   (Google Benchmark's JSON; with
//                                                          repetitions, their median)
//   bench/<benchmark>/<counter>                 as counted (items_per_second, ...)
//   test/<key>                                  what a recording test recorded with
//                                               RecordProperty (gtest's JSON output)
//   <run>/<key>                                 a figures.json of daylit replay or estimate
//                                               (evaluation::RunReport), <run> its name
// Units: s, ms, us (a time in seconds), /s (a time's inverse: per second), % (a fraction), k and
// M (thousands, millions); none
// writes the number as it is. Numbers get three significant digits.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

namespace daylit::evaluation {

struct MeasuredFigures {
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> texts;
};

// Google Benchmark's --benchmark_out JSON. Throws InputError naming `source` if it is not one.
void AddBenchmarkFigures(const nlohmann::json& json, const std::string& source, MeasuredFigures* figures);
// gtest's --gtest_output=json: the properties whose key has a '/', under test/<key>.
void AddTestFigures(const nlohmann::json& json, const std::string& source, MeasuredFigures* figures);
// A flat JSON object (figures.json), under <prefix>/<key>.
void AddRunFigures(const nlohmann::json& json, const std::string& prefix, const std::string& source,
                   MeasuredFigures* figures);

// Every *.json under `folder`, each by what it is: Google Benchmark's output, gtest's, or a
// figures object under the prefix of its path ("courtyard-a/replay/figures.json" and
// "courtyard-a/replay.json" both give courtyard-a/replay/<key>). Throws InputError naming a
// file that is not JSON.
MeasuredFigures LoadMeasuredFigures(const std::filesystem::path& folder);

// `value` in `unit` with three significant digits ("1.52", "33.6", "143", "25 100").
std::string FormatFigure(double value, const std::string& unit);

// The template with every field filled. Throws InputError naming the template's line and the
// key for a field nothing measured or a unit it does not know: the page is never half filled.
std::string FillResultsPage(const std::string& page_template, const std::string& template_name,
                            const MeasuredFigures& figures);

}  // namespace daylit::evaluation
