// daylit: consistent lighting for outdoor augmented reality. See README.md.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "apps/daylit/commands.h"
#include "base/check.h"
#include "base/error.h"
#include "base/log.h"
#include "scene/scene.h"

int main(int argc, char** argv) {
  CLI::App app{"daylit: estimate sun and sky light from a camera and light virtual objects with it"};
  app.require_subcommand(1);
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
  daylit::app::AddRecordCommand(app);
  daylit::app::AddRenderCommand(app);
  daylit::app::AddReplayCommand(app);
  daylit::app::AddRelightCommand(app);
  daylit::app::AddLiveCommand(app);
  daylit::app::AddResultsCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
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
  } catch (const daylit::InvariantError& e) {
    daylit::Log().critical("internal error (a bug in daylit, not your input): {}", e.what());
    return daylit::kInternalErrorExitCode;
  } catch (const std::exception& e) {
    daylit::Log().critical("internal error: {}", e.what());
    return 1;
  }
  return 0;
}
