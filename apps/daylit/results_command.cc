// daylit results: docs/results.md from its template and the figures scripts/results.sh measured.
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "apps/daylit/commands.h"
#include "base/atomic_file.h"
#include "base/error.h"
#include "base/log.h"
#include "evaluation/results_page.h"

namespace daylit::app {
namespace {

struct ResultsOptions {
  std::string page_template;
  std::string measured;
  std::string out;
};

void RunResults(const ResultsOptions& o) {
  RefuseInputsAsOutputs({o.page_template}, {o.measured}, {{"--out", o.out}});
  std::ifstream in(o.page_template, std::ios::binary);
  if (!in) ThrowInputError("{}: cannot read the template", o.page_template);
  std::ostringstream text;
  text << in.rdbuf();
  const evaluation::MeasuredFigures figures = evaluation::LoadMeasuredFigures(o.measured);
  const std::string page = evaluation::FillResultsPage(text.str(), o.page_template, figures);
  WriteFileAtomically(o.out, page);
  Log().info("wrote {} from {} measured figures", o.out, figures.numbers.size() + figures.texts.size());
}

}  // namespace

void AddResultsCommand(CLI::App& app) {
  auto options = std::make_shared<ResultsOptions>();
  CLI::App* cmd = app.add_subcommand("results", "Fill a results page's template with measured figures (scripts/results.sh)");
  cmd->add_option("template", options->page_template, "The template, e.g. docs/results.md.in")->required();
  cmd->add_option("measured", options->measured,
                  "Folder of JSON: Google Benchmark's and gtest's outputs, daylit's figures.json files")
      ->required();
  cmd->add_option("--out", options->out, "The page (written only when every field is filled)")->required();
  cmd->footer("A field is {{key}} or {{key|unit}}: bench/<benchmark>/real_time (seconds; with repetitions their\n"
              "median), bench/<benchmark>/<counter>, test/<key> (a recording test's RecordProperty), <run>/<key>\n"
              "(a figures.json under the folder, <run> its path). Units: s, ms, us, /s, %, k, M.");
  cmd->callback([options] { RunResults(*options); });
}

}  // namespace daylit::app
