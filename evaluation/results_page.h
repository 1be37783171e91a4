// docs/results.md, the one page of measured figures, is generated: scripts/results.sh runs the
// benchmarks, the recording tests and daylit's own runs, and FillResultsPage fills a template
// (docs/results.md.in) with what they measured. A field is `{{key}}` or `{{key|unit}}`:
//   bench/<benchmark>/real_time, .../cpu_time   seconds   (Google Benchmark's JSON; with
//                                                          repetitions, their median)
//   bench/<benchmark>/<counter>                 as counted (items_per_second, ...)
//   test/<key>                                  what a recording test recorded with
//                                               RecordProperty (gtest's JSON output)
//   <run>/<key>                                 a figures.json of daylit replay or estimate
//                                               (evaluation::RunReport), <run> its name;
//                                               nested objects as <run>/<key>/<key>
// and a table is `{{csv:<path>}}` or `{{csv:<path>|column:unit:title,...}}`: a CSV file under
// the measured folder as a Markdown table, all its columns or the ones named, each numeric cell
// in the column's unit (as above) and under its title (default: the column's name).
// Units: s, ms, us (a time in seconds), /s (a time's inverse: per second), % (a fraction), k and
// M (thousands, millions); none writes the number as it is. Numbers get three significant
// digits, except whole numbers without a unit (counts: frames, lights), written exactly.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "base/csv.h"

namespace daylit::evaluation {

struct MeasuredFigures {
  std::map<std::string, double> numbers;
  std::map<std::string, std::string> texts;
  std::map<std::string, CsvTable> tables;  // by path under the measured folder
};

// Google Benchmark's --benchmark_out JSON. Throws InputError naming `source` if it is not one.
void AddBenchmarkFigures(const nlohmann::json& json, const std::string& source, MeasuredFigures* figures);
// gtest's --gtest_output=json: the properties whose key has a '/', under test/<key>.
void AddTestFigures(const nlohmann::json& json, const std::string& source, MeasuredFigures* figures);
// A JSON object (figures.json), under <prefix>/<key>; nested objects under <prefix>/<key>/<key>,
// null as the text "none"; arrays (a fit's lights, coefficients) are not figures and are left out.
void AddRunFigures(const nlohmann::json& json, const std::string& prefix, const std::string& source,
                   MeasuredFigures* figures);

// The JSON `text` of a measured file (`source` names it in errors; a file that is not JSON is an
// InputError). Google Benchmark writes NaN and inf, which JSON has not, for a counter's coefficient
// of variation when the counter is always 0 (serve_bench's `dropped`): those read as null, and a
// null counter is no figure.
nlohmann::json ParseMeasuredJson(const std::string& text, const std::string& source);

// Every *.json under `folder`, each by what it is: Google Benchmark's output, gtest's, or a
// figures object under the prefix of its path ("courtyard-a/replay/figures.json" and
// "courtyard-a/replay.json" both give courtyard-a/replay/<key>); and every *.csv as a table.
// Throws InputError naming a file that is not JSON or CSV.
MeasuredFigures LoadMeasuredFigures(const std::filesystem::path& folder);

// `value` in `unit` with three significant digits ("1.52", "33.6", "143", "25100"); a whole
// number without a unit exactly ("600").
std::string FormatFigure(double value, const std::string& unit);

// The template with every field filled. Throws InputError naming the template's line and the
// key for a field nothing measured or a unit it does not know: the page is never half filled.
std::string FillResultsPage(const std::string& page_template, const std::string& template_name,
                            const MeasuredFigures& figures);

}  // namespace daylit::evaluation
