// daylit: consistent lighting for outdoor augmented reality. See README.md.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <new>
#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/core/utils/logger.hpp>

#include "apps/daylit/commands.h"
#include "capture/video_decoder.h"
#include "base/check.h"
#include "base/error.h"
#include "base/invocation.h"
#include "base/log.h"
#include "base/version.h"
#include "scene/scene.h"

namespace {

// Every number an option takes as FLOAT must be finite and within float's range (the maps and the
// GL are float): CLI11 reads "nan", "inf" and 1e39 as doubles, and its Range lets NaN through.
void RefuseNonFiniteNumbers(CLI::App* app) {
  const CLI::Validator finite(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str()) return {};  // not a number: CLI11's own conversion says so
        if (!std::isfinite(value) || std::fabs(value) > 1e30) return "'" + text + "' is not a finite number within ±1e30";
        return {};
      },
      "");
  for (CLI::Option* option : app->get_options()) {
    if (option->get_type_name().rfind("FLOAT", 0) == 0) option->check(finite);
  }
  for (CLI::App* sub : app->get_subcommands({})) RefuseNonFiniteNumbers(sub);
}

}  // namespace

int main(int argc, char** argv) {
  // libav's and OpenCV's own lines would come before daylit's one-line messages: libav's go to
  // daylit's logger (debug), OpenCV's are silenced (daylit says what failed itself).
  daylit::RecordInvocation(argc, argv);  // saved beside a run's results (report.txt, figures.json)
  daylit::capture::RouteLibavLogging();
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  CLI::App app{"daylit: estimate sun and sky light from a camera and light virtual objects with it"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("daylit ") + daylit::kVersion);
  // -q, -v and --allow-outside-paths work after the subcommand too.
  app.fallthrough();
  int verbosity = 1;
  app.add_flag_callback("-q,--quiet", [&] { verbosity = 0; }, "Only warnings and errors on stderr");
  app.add_flag_callback("-v,--verbose", [&] { verbosity = 2; }, "Debug output on stderr");
  app.add_flag_callback("--allow-outside-paths", [] { daylit::scene::AllowPathsOutsideRecording(true); },
                        "Follow paths in scene.json that leave the recording's folder (refused by default)");
  app.parse_complete_callback([&] { daylit::SetLogVerbosity(verbosity); });
  daylit::app::AddSunposCommand(app);
  daylit::app::AddInfoCommand(app);
  daylit::app::AddBakeCommand(app);
  daylit::app::AddEstimateCommand(app);
  daylit::app::AddRelightEnvCommand(app);
  daylit::app::AddLightsCommand(app);
  daylit::app::AddCalibrateCommands(app);
  daylit::app::AddCalibrateSceneCommand(app);
  daylit::app::AddRecordCommand(app);
  daylit::app::AddRenderCommand(app);
  daylit::app::AddReplayCommand(app);
  daylit::app::AddRelightCommand(app);
  daylit::app::AddLiveCommand(app);
  daylit::app::AddResultsCommand(app);
  RefuseNonFiniteNumbers(&app);
  // The first word that is not an option must be a command: say so when it is not, rather than
  // that one is required.
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-') continue;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) known = known || sub->check_name(word);
    if (!known) {
      daylit::Log().error("'{}' is not a daylit command (see daylit --help)", word.substr(0, 80));
      return daylit::kInputErrorExitCode;
    }
    break;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    daylit::Log().error("{} (see daylit --help)", e.what());
    return daylit::kInputErrorExitCode;
  } catch (const daylit::InputError& e) {
    daylit::Log().error("{}", e.what());
    return daylit::kInputErrorExitCode;
  } catch (const daylit::SystemError& e) {
    daylit::Log().error("{}", e.what());
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path the user gave that the system will not take (a symlink loop, a file where a folder
    // must be, a read-only folder): bad input, with the path.
    daylit::Log().error("{}: {}", e.path1().empty() ? std::string("a path") : e.path1().string(), e.code().message());
    return daylit::kInputErrorExitCode;
  } catch (const daylit::InvariantError& e) {
    daylit::Log().critical("internal error (a bug in daylit, not your input): {}", e.what());
    return daylit::kInternalErrorExitCode;
  } catch (const std::bad_alloc&) {
    // What the machine lacks, not the input and not daylit.
    daylit::Log().error("out of memory: this machine has too little for this run");
    return 1;
  } catch (const std::exception& e) {
    // Anything else no part of daylit said is the input's or the machine's: a bug.
    daylit::Log().critical("internal error (a bug in daylit, not your input): {}", e.what());
    return daylit::kInternalErrorExitCode;
  }
  return 0;
}
