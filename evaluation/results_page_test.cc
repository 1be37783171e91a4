#include "evaluation/results_page.h"

#include <gtest/gtest.h>

#include "base/error.h"

namespace daylit::evaluation {
namespace {

// As Google Benchmark 1.7 writes it with --benchmark_repetitions=3 --benchmark_report_aggregates_only.
const char* kBenchmarkJson = R"({
  "context": {"num_cpus": 2},
  "benchmarks": [
    {"name": "BM_EstimateFrame_mean", "run_name": "BM_EstimateFrame", "run_type": "aggregate",
     "aggregate_name": "mean", "iterations": 3, "real_time": 1700.0, "cpu_time": 1690.0, "time_unit": "us"},
    {"name": "BM_EstimateFrame_median", "run_name": "BM_EstimateFrame", "run_type": "aggregate",
     "aggregate_name": "median", "iterations": 3, "real_time": 1523.4, "cpu_time": 1500.0, "time_unit": "us",
     "items_per_second": 656.4},
    {"name": "BM_FirstSun/iterations:3/real_time", "run_name": "BM_FirstSun/iterations:3/real_time",
     "run_type": "iteration", "iterations": 3, "real_time": 0.43, "cpu_time": 0.8, "time_unit": "s"},
    {"name": "BM_RenderFrame/8/real_time", "run_name": "BM_RenderFrame/8/real_time",
     "run_type": "iteration", "iterations": 40, "real_time": 17.0, "cpu_time": 17.0, "time_unit": "ms"},
    {"name": "BM_Draw", "run_name": "BM_Draw", "run_type": "iteration", "repetitions": 1,
     "iterations": 3800, "real_time": 0.18, "cpu_time": 0.18, "time_unit": "ms"}
  ]})";

const char* kGtestJson = R"({
  "testsuites": [{"name": "EstimateRecording", "testsuite": [
    {"name": "EveryBurst", "status": "RUN", "time": "12s",
     "courtyard-a/burst0/sky_error/r": "0.0213", "courtyard-a/worst_surface": "pillar_2"}]}]})";

MeasuredFigures Figures() {
  MeasuredFigures figures;
  AddBenchmarkFigures(nlohmann::json::parse(kBenchmarkJson), "estimate_bench.json", &figures);
  AddTestFigures(nlohmann::json::parse(kGtestJson), "estimate_recording_test.json", &figures);
  AddRunFigures(nlohmann::json::parse(R"json({"fps": 41.23, "gl_renderer": "llvmpipe (LLVM 15.0.6, 256 bits)"})json"),
                "courtyard-a/replay", "figures.json", &figures);
  AddRunFigures(nlohmann::json::parse(R"json({"seconds": 10.9, "at_range_edge": false, "pose_fitted": true})json"),
                "courtyard-a/calibrate", "calibrate.json", &figures);
  return figures;
}

// calibrate-scene's figures carry flags: 1 and 0.
TEST(ResultsPage, FlagsAreOneAndZero) {
  const MeasuredFigures figures = Figures();
  EXPECT_EQ(figures.numbers.at("courtyard-a/calibrate/at_range_edge"), 0.0);
  EXPECT_EQ(figures.numbers.at("courtyard-a/calibrate/pose_fitted"), 1.0);
  EXPECT_DOUBLE_EQ(figures.numbers.at("courtyard-a/calibrate/seconds"), 10.9);
}

TEST(ResultsPage, MediansOfRepetitionsInSeconds) {
  const MeasuredFigures figures = Figures();
  EXPECT_DOUBLE_EQ(figures.numbers.at("bench/BM_EstimateFrame/real_time"), 1523.4e-6);  // the median, not the mean
  EXPECT_DOUBLE_EQ(figures.numbers.at("bench/BM_EstimateFrame/items_per_second"), 656.4);
  EXPECT_DOUBLE_EQ(figures.numbers.at("bench/BM_Draw/cpu_time"), 0.18e-3);
  EXPECT_EQ(figures.numbers.count("bench/BM_Draw/iterations"), 0u);
  // How a run ran is not part of its key; its arguments are.
  EXPECT_DOUBLE_EQ(figures.numbers.at("bench/BM_FirstSun/real_time"), 0.43);
  EXPECT_DOUBLE_EQ(figures.numbers.at("bench/BM_RenderFrame/8/real_time"), 17.0e-3);
}

// Google Benchmark's coefficient of variation of a counter that is always 0 is NaN, which JSON
// has not (serve_bench's `dropped`): read as null, no figure; the run's other figures stay.
TEST(ResultsPage, NotANumberFromGoogleBenchmarkIsNoFigure) {
  const nlohmann::json json = ParseMeasuredJson(R"({"benchmarks": [
    {"name": "BM_ServeFrame/0/real_time_median", "run_name": "BM_ServeFrame/0/real_time", "run_type": "aggregate",
     "aggregate_name": "median", "real_time": 9.0, "time_unit": "us", "dropped": NaN, "worst": -inf,
     "note": "ratio: NaN, kept"}]})", "serve_bench.json");
  MeasuredFigures figures;
  AddBenchmarkFigures(json, "serve_bench.json", &figures);
  EXPECT_DOUBLE_EQ(figures.numbers.at("bench/BM_ServeFrame/0/real_time"), 9.0e-6);
  EXPECT_EQ(figures.numbers.count("bench/BM_ServeFrame/0/dropped"), 0u);
  EXPECT_EQ(figures.numbers.count("bench/BM_ServeFrame/0/worst"), 0u);
  EXPECT_EQ(json["benchmarks"][0]["note"], "ratio: NaN, kept");  // a text is left as it is
  EXPECT_THROW(ParseMeasuredJson("{\"a\": }", "broken.json"), InputError);
}

TEST(ResultsPage, FillsFieldsInTheirUnits) {
  const std::string page = FillResultsPage(
      "| frame | {{bench/BM_EstimateFrame/real_time|ms}} ms |\n"
      "sky {{test/courtyard-a/burst0/sky_error/r|%}}%, worst {{test/courtyard-a/worst_surface}}, "
      "{{courtyard-a/replay/fps}} fps on {{courtyard-a/replay/gl_renderer}}; draw {{bench/BM_Draw/real_time|us}} us\n",
      "results.md.in", Figures());
  EXPECT_EQ(page,
            "| frame | 1.52 ms |\n"
            "sky 2.13%, worst pillar_2, 41.2 fps on llvmpipe (LLVM 15.0.6, 256 bits); draw 180 us\n");
}

TEST(ResultsPage, NestedFiguresAndCsvTables) {
  MeasuredFigures figures;
  AddRunFigures(nlohmann::json::parse(R"({"threshold": 0.05, "io": {"n": 3, "mean_error": 0.0368}, "mediancut": null,
                                          "lights": [1, 2]})"),
                "lights/galileo/automatic", "automatic.json", &figures);
  figures.tables["bursts.csv"] = ParseCsv("burst,first_frame,sky_error_r\n0,0,0.0213\n1,100,0.118\n", "bursts.csv");
  EXPECT_EQ(FillResultsPage("{{lights/galileo/automatic/io/n}} lights ({{lights/galileo/automatic/io/mean_error|%}}%), "
                            "median cut: {{lights/galileo/automatic/mediancut}}\n"
                            "{{csv:bursts.csv|burst,sky_error_r:%:E_sky red (%)}}\n",
                            "t", figures),
            "3 lights (3.68%), median cut: none\n"
            "| burst | E_sky red (%) |\n| --- | --- |\n| 0 | 2.13 |\n| 1 | 11.8 |\n");
  EXPECT_EQ(FillResultsPage("{{csv:bursts.csv}}", "t", figures),
            "| burst | first_frame | sky_error_r |\n| --- | --- | --- |\n| 0 | 0 | 0.0213 |\n| 1 | 100 | 0.118 |");
  EXPECT_THROW(FillResultsPage("{{csv:bursts.csv|sun_error_r:%}}", "t", figures), InputError);  // no such column
  EXPECT_THROW(FillResultsPage("{{csv:other.csv}}", "t", figures), InputError);
}

TEST(ResultsPage, ThreeSignificantDigits) {
  EXPECT_EQ(FormatFigure(25123.0, "k"), "25.1");
  EXPECT_EQ(FormatFigure(25123.4, ""), "25100");
  EXPECT_EQ(FormatFigure(25123.0, ""), "25123");  // a count, exactly
  EXPECT_EQ(FormatFigure(0.0123456, ""), "0.0123");
  EXPECT_EQ(FormatFigure(0.1, "%"), "10.0");
  EXPECT_EQ(FormatFigure(0.0, "ms"), "0");
  EXPECT_EQ(FormatFigure(3.8e-3, "/s"), "263");  // a frame's decoding time as frames per second
  EXPECT_THROW(FormatFigure(1.0, "hours"), InputError);
}

TEST(ResultsPage, NamesTheFieldNothingMeasured) {
  try {
    FillResultsPage("line one\n{{bench/BM_Gone/real_time|ms}}\n", "results.md.in", Figures());
    FAIL() << "filled a field nothing measured";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "results.md.in:2: nothing measured \"bench/BM_Gone/real_time\"");
  }
  // A text where a number belongs, an unclosed field, a unit nobody knows.
  EXPECT_THROW(FillResultsPage("{{test/courtyard-a/worst_surface|%}}", "t", Figures()), InputError);
  EXPECT_THROW(FillResultsPage("{{courtyard-a/replay/fps|ms", "t", Figures()), InputError);
  EXPECT_THROW(FillResultsPage("{{courtyard-a/replay/fps|days}}", "t", Figures()), InputError);
  EXPECT_THROW(AddBenchmarkFigures(nlohmann::json::parse(kGtestJson), "x.json", nullptr), InputError);
}

}  // namespace
}  // namespace daylit::evaluation
