#include "evaluation/results_page.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string_view>
#include <set>
#include <vector>

#include <fmt/format.h>

#include "base/csv.h"
#include "base/error.h"

namespace daylit::evaluation {
namespace {

// Seconds per the time unit Google Benchmark writes.
double SecondsPer(const std::string& time_unit, const std::string& source) {
  if (time_unit == "ns") return 1e-9;
  if (time_unit == "us") return 1e-6;
  if (time_unit == "ms") return 1e-3;
  if (time_unit == "s") return 1.0;
  ThrowInputError("{}: time_unit \"{}\" is not ns, us, ms or s", source, time_unit);
}

// A run's name without what Google Benchmark appends for how it ran ("/iterations:3",
// "/real_time", "/repeats:3", ...): BM_FirstSun/iterations:3/real_time is BM_FirstSun.
std::string FamilyAndArguments(const std::string& run_name) {
  static const char* kHowItRan[] = {"iterations:", "repeats:", "threads:", "min_time:", "min_warmup_time:",
                                    "real_time", "process_time", "manual_time"};
  std::string name;
  size_t at = 0;
  while (at <= run_name.size()) {
    const size_t slash = std::min(run_name.find('/', at), run_name.size());
    const std::string part = run_name.substr(at, slash - at);
    const bool how = std::any_of(std::begin(kHowItRan), std::end(kHowItRan),
                                 [&](const char* prefix) { return part.rfind(prefix, 0) == 0; });
    if (!how) name += (name.empty() ? "" : "/") + part;
    at = slash + 1;
  }
  return name;
}

}  // namespace

void AddBenchmarkFigures(const nlohmann::json& json, const std::string& source, MeasuredFigures* figures) {
  if (!json.is_object() || !json.contains("benchmarks") || !json["benchmarks"].is_array()) {
    ThrowInputError("{}: not Google Benchmark's JSON output (no \"benchmarks\" array)", source);
  }
  static const std::set<std::string> kNotCounters = {"family_index", "per_family_instance_index", "repetitions",
                                                     "repetition_index", "threads", "iterations"};
  // Runs first, then the medians of repeated runs over them.
  for (const bool medians : {false, true}) {
    for (const nlohmann::json& run : json["benchmarks"]) {
      const bool aggregate = run.value("run_type", "iteration") == "aggregate";
      if (aggregate != medians || (aggregate && run.value("aggregate_name", "") != "median")) continue;
      if (!run.contains("name") || !run.contains("time_unit")) ThrowInputError("{}: a benchmark without name or time_unit", source);
      const std::string name = FamilyAndArguments(run.value("run_name", run["name"].get<std::string>()));
      const double unit = SecondsPer(run["time_unit"].get<std::string>(), source);
      for (const auto& [field, value] : run.items()) {
        if (!value.is_number() || kNotCounters.count(field) > 0) continue;
        const bool time = field == "real_time" || field == "cpu_time";
        figures->numbers["bench/" + name + "/" + field] = value.get<double>() * (time ? unit : 1.0);
      }
    }
  }
}

void AddTestFigures(const nlohmann::json& json, const std::string& source, MeasuredFigures* figures) {
  if (!json.is_object() || !json.contains("testsuites") || !json["testsuites"].is_array()) {
    ThrowInputError("{}: not gtest's JSON output (no \"testsuites\" array)", source);
  }
  for (const nlohmann::json& suite : json["testsuites"]) {
    for (const nlohmann::json& test : suite.value("testsuite", nlohmann::json::array())) {
      for (const auto& [key, value] : test.items()) {
        if (key.find('/') == std::string::npos || !value.is_string()) continue;
        double number = 0.0;
        if (TryParseFiniteDouble(value.get<std::string>(), &number)) {
          figures->numbers["test/" + key] = number;
        } else {
          figures->texts["test/" + key] = value.get<std::string>();
        }
      }
    }
  }
}

void AddRunFigures(const nlohmann::json& json, const std::string& prefix, const std::string& source,
                   MeasuredFigures* figures) {
  if (!json.is_object()) ThrowInputError("{}: figures are a JSON object of numbers and texts", source);
  for (const auto& [key, value] : json.items()) {
    const std::string name = prefix + "/" + key;
    if (value.is_boolean()) {
      figures->numbers[name] = value.get<bool>() ? 1.0 : 0.0;
    } else if (value.is_number()) {
      figures->numbers[name] = value.get<double>();
    } else if (value.is_string()) {
      figures->texts[name] = value.get<std::string>();
    } else if (value.is_null()) {
      figures->texts[name] = "none";
    } else if (value.is_object()) {
      AddRunFigures(value, name, source, figures);
    } else if (!value.is_array()) {
      ThrowInputError("{}: \"{}\" is neither a number, a boolean, a text, an object nor an array", source, name);
    }
  }
}

nlohmann::json ParseMeasuredJson(const std::string& text, const std::string& source) {
  // Outside strings (a scan that follows quotes and their escapes), the words NaN, nan, inf and
  // Infinity, with or without a minus, become null.
  std::string cleaned;
  cleaned.reserve(text.size());
  bool in_string = false;
  for (size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (in_string) {
      cleaned += c;
      if (c == '\\' && i + 1 < text.size()) {
        cleaned += text[i + 1];
        i += 2;
        continue;
      }
      in_string = c != '"';
      ++i;
      continue;
    }
    if (c == '"') {
      in_string = true;
      cleaned += c;
      ++i;
      continue;
    }
    const size_t start = i + (c == '-' ? 1 : 0);
    bool replaced = false;
    for (const std::string_view word : {"Infinity", "NaN", "nan", "inf"}) {
      if (text.compare(start, word.size(), word) == 0) {
        cleaned += "null";
        i = start + word.size();
        replaced = true;
        break;
      }
    }
    if (!replaced) cleaned += c, ++i;
  }
  nlohmann::json json = nlohmann::json::parse(cleaned, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded()) ThrowInputError("{}: not JSON", source);
  return json;
}

MeasuredFigures LoadMeasuredFigures(const std::filesystem::path& folder) {
  if (!std::filesystem::is_directory(folder)) ThrowInputError("{}: not a folder of measured figures", folder.string());
  std::vector<std::filesystem::path> files;
  MeasuredFigures figures;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder)) {
    if (!entry.is_regular_file()) continue;
    if (entry.path().extension() == ".json") files.push_back(entry.path());
    if (entry.path().extension() == ".csv") {
      figures.tables[entry.path().lexically_relative(folder).generic_string()] = ReadCsvFile(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  for (const std::filesystem::path& file : files) {
    std::ifstream in(file);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const nlohmann::json json = ParseMeasuredJson(text, file.string());
    if (json.contains("benchmarks")) {
      AddBenchmarkFigures(json, file.string(), &figures);
    } else if (json.contains("testsuites")) {
      AddTestFigures(json, file.string(), &figures);
    } else {
      std::filesystem::path prefix = file.lexically_relative(folder).replace_extension();
      if (prefix.filename() == "figures") prefix = prefix.parent_path();
      AddRunFigures(json, prefix.generic_string(), file.string(), &figures);
    }
  }
  return figures;
}

std::string FormatFigure(double value, const std::string& unit) {
  static const std::map<std::string, double> kScale = {{"", 1.0}, {"s", 1.0},  {"ms", 1e3}, {"us", 1e6},
                                                        {"%", 1e2}, {"k", 1e-3}, {"M", 1e-6}};
  const auto scale = kScale.find(unit);
  if (scale == kScale.end() && unit != "/s") ThrowInputError("unit \"{}\" is not one of s, ms, us, /s, %, k, M", unit);
  const double v = unit == "/s" ? 1.0 / value : value * scale->second;
  if (v == 0.0 || !std::isfinite(v)) return fmt::format("{}", v);
  if (unit.empty() && std::floor(v) == v && std::abs(v) < 1e15) return fmt::format("{:.0f}", v);  // a count
  const int magnitude = static_cast<int>(std::floor(std::log10(std::abs(v))));
  if (magnitude >= 2) {
    const double step = std::pow(10.0, magnitude - 2);
    return fmt::format("{:.0f}", std::round(v / step) * step);
  }
  return fmt::format("{:.{}f}", v, 2 - magnitude);
}

namespace {

// `{{csv:path|column:unit:title,...}}`'s table, as Markdown.
std::string MarkdownTable(const CsvTable& table, const std::string& spec) {
  struct Column {
    int index = 0;
    std::string unit, title;
  };
  std::vector<Column> columns;
  if (spec.empty()) {
    for (size_t i = 0; i < table.header.size(); ++i) columns.push_back({static_cast<int>(i), "", table.header[i]});
  }
  size_t at = 0;
  while (!spec.empty() && at <= spec.size()) {
    const size_t comma = std::min(spec.find(',', at), spec.size());
    const std::string part = spec.substr(at, comma - at);
    const size_t colon = part.find(':');
    const size_t second = colon == std::string::npos ? std::string::npos : part.find(':', colon + 1);
    const std::string name = part.substr(0, colon);
    Column column{table.RequireColumn(name), "", name};
    if (colon != std::string::npos) column.unit = part.substr(colon + 1, second == std::string::npos ? second : second - colon - 1);
    if (second != std::string::npos) column.title = part.substr(second + 1);
    columns.push_back(column);
    at = comma + 1;
  }
  std::string markdown = "|", rule = "|";
  for (const Column& c : columns) markdown += " " + c.title + " |", rule += " --- |";
  markdown += "\n" + rule + "\n";
  for (const std::vector<std::string>& row : table.rows) {
    markdown += "|";
    for (const Column& c : columns) {
      const std::string& cell = row[static_cast<size_t>(c.index)];
      double number = 0.0;
      markdown += " " + (TryParseFiniteDouble(cell, &number) ? FormatFigure(number, c.unit) : cell) + " |";
    }
    markdown += "\n";
  }
  markdown.pop_back();  // the field's own line ends it
  return markdown;
}

// One field's text; throws InputError naming the key.
std::string FieldText(const std::string& key, const std::string& unit, const MeasuredFigures& figures) {
  if (key.rfind("csv:", 0) == 0) {
    const auto table = figures.tables.find(key.substr(4));
    if (table == figures.tables.end()) ThrowInputError("no table {} was measured", key.substr(4));
    try {
      return MarkdownTable(table->second, unit);
    } catch (const InputError& e) {
      ThrowInputError("{}: {}", key, e.what());
    }
  }
  if (const auto number = figures.numbers.find(key); number != figures.numbers.end()) {
    try {
      return FormatFigure(number->second, unit);
    } catch (const InputError& e) {
      ThrowInputError("{}: {}", key, e.what());
    }
  }
  const auto text = figures.texts.find(key);
  if (text != figures.texts.end() && unit.empty()) return text->second;
  ThrowInputError("nothing measured \"{}\"{}", key, text != figures.texts.end() ? " as a number" : "");
}

}  // namespace

std::string FillResultsPage(const std::string& page_template, const std::string& template_name,
                            const MeasuredFigures& figures) {
  std::string page;
  size_t at = 0;
  while (true) {
    const size_t open = page_template.find("{{", at);
    if (open == std::string::npos) break;
    const size_t close = page_template.find("}}", open);
    const int line = 1 + static_cast<int>(std::count(page_template.begin(), page_template.begin() + open, '\n'));
    if (close == std::string::npos) ThrowInputError("{}:{}: a field opened with {{{{ is not closed", template_name, line);
    page.append(page_template, at, open - at);
    const std::string field = page_template.substr(open + 2, close - open - 2);
    const size_t bar = field.find('|');
    const std::string key = field.substr(0, bar);
    const std::string unit = bar == std::string::npos ? "" : field.substr(bar + 1);
    try {
      page += FieldText(key, unit, figures);
    } catch (const InputError& e) {
      ThrowInputError("{}:{}: {}", template_name, line, e.what());
    }
    at = close + 2;
  }
  page.append(page_template, at, std::string::npos);
  return page;
}

}  // namespace daylit::evaluation
