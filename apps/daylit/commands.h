// The subcommands of `daylit`. Each Add*Command registers itself on the app; its callback
// writes results to stdout or files and throws InputError for bad input (exit code 2).
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "scene/scene.h"

namespace daylit::app {

void AddSunposCommand(CLI::App& app);
void AddInfoCommand(CLI::App& app);
void AddBakeCommand(CLI::App& app);
void AddEstimateCommand(CLI::App& app);
void AddRelightEnvCommand(CLI::App& app);
void AddLightsCommand(CLI::App& app);
void AddCalibrateCommands(CLI::App& app);
void AddCalibrateSceneCommand(CLI::App& app);
void AddRecordCommand(CLI::App& app);
void AddRenderCommand(CLI::App& app);
void AddReplayCommand(CLI::App& app);
void AddRelightCommand(CLI::App& app);
void AddLiveCommand(CLI::App& app);
void AddResultsCommand(CLI::App& app);

// Throws InputError when two of a run's outputs (option or what it names, path) are one file,
// before any work: `estimate --out y.csv --plot y.csv` would write the plot over the table.
// Empty paths (an output not asked for) are skipped.
void RefuseSharedOutputs(const std::vector<std::pair<std::string, std::filesystem::path>>& outputs);

// Throws InputError when an output (option or what it names, path) is one of the files the run
// reads, `inputs` (the recording's: scene::InputsOf; or the command's own input files), or lies in
// one of the folders it reads, `input_folders`, compared through symlinks, before any work:
// `replay REC --out REC/video.mp4` would write the composite over the video it reads. Empty paths
// are skipped.
void RefuseInputsAsOutputs(const std::vector<std::filesystem::path>& inputs,
                           const std::vector<std::filesystem::path>& input_folders,
                           const std::vector<std::pair<std::string, std::filesystem::path>>& outputs);
// The same with a scene's inputs.
void RefuseInputsAsOutputs(const scene::Scene& scene,
                           const std::vector<std::pair<std::string, std::filesystem::path>>& outputs);

// Throws InputError naming `option` unless `path` can be written: its folder exists and may be
// written to, and it is not itself a folder. Called before any work, so that a bake or a run is
// not wasted on an output that cannot be written. Empty paths are skipped.
void RequireWritable(const std::string& option, const std::filesystem::path& path);

// An options struct's Check() before any work: its first problem, if any, as an input error
// "<what>: <problem>" (the problem names the field).
void RequireValid(const std::string& what, const std::string& problem);

// --lighting volume|lights:N, for the commands that render the objects (render::ParseLighting).
void AddLightingOption(CLI::App* cmd, std::string* lighting);

// --frames N of estimate, replay, live and record: a whole number from 1 up, said one way where it
// is not ("--frames: 0 is not a number of frames").
CLI::Validator FrameCount();

// While one lives, Ctrl-C or SIGTERM sets flag() instead of ending the process: a run checks it
// after each frame and ends with complete outputs. A second one ends the process. One at a time.
class StopOnInterrupt {
 public:
  StopOnInterrupt();
  ~StopOnInterrupt();
  StopOnInterrupt(const StopOnInterrupt&) = delete;
  StopOnInterrupt& operator=(const StopOnInterrupt&) = delete;
  const std::atomic<bool>* flag() const;
};

}  // namespace daylit::app
