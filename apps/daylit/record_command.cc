// daylit record: a live camera (or another recording's frames) written as a recording folder
// that daylit replays later (docs/capture.md, docs/recording-format.md).
#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <memory>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "apps/daylit/commands.h"
#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"
#include "base/log.h"
#include "base/progress.h"
#include "capture/recording_writer.h"
#include "capture/v4l2_source.h"
#include "scene/scene.h"

namespace daylit::app {
namespace {

namespace fs = std::filesystem;

std::atomic<bool> g_stop{false};
extern "C" void StopRecording(int) { g_stop = true; }

struct RecordOptions {
  std::string device;
  std::string from;
  std::string scene;
  std::string out;
  std::optional<int> frames;
  std::optional<double> seconds;
  bool images = false;
  std::optional<int64_t> exposure_100us, gain, white_balance_k;  // override scene.json's frames.controls
};

// Copies a file scene.json names into the new folder (keeping its name) and returns the new
// relative path.
std::string CopyInto(const fs::path& source_dir, const std::string& relative, const fs::path& out) {
  const fs::path from = source_dir / relative;
  fs::path to = fs::path(relative).lexically_normal();
  if (to.is_absolute() || to.string().rfind("..", 0) == 0) to = to.filename();
  fs::create_directories((out / to).parent_path());
  fs::copy_file(from, out / to, fs::copy_options::overwrite_existing);
  return to.generic_string();
}

// scene.json for the new folder: the source's, with its files copied along, the frames replaced
// and the ground truth (which describes other frames) left out.
nlohmann::json NewSceneJson(const scene::Scene& scene, const capture::RecordingWriter& writer, const fs::path& out) {
  nlohmann::json json = nlohmann::json::parse(ReadTextFile(scene.file));
  const fs::path dir = scene.file.parent_path();
  const auto copy = [&](nlohmann::json& field) {
    if (field.is_string()) field = CopyInto(dir, field.get<std::string>(), out);
  };
  if (json.contains("model")) copy(json["model"]["file"]);
  if (json.contains("envmap")) copy(json["envmap"]["file"]);
  if (json.contains("diffuse_mask")) copy(json["diffuse_mask"]);
  if (json.contains("camera") && json["camera"].contains("response") && json["camera"]["response"].is_object() &&
      json["camera"]["response"].contains("curve")) {
    copy(json["camera"]["response"]["curve"]);
  }
  if (json.contains("objects")) {
    for (nlohmann::json& o : json["objects"]) {
      if (o.contains("mesh") && o["mesh"].is_string() && o["mesh"].get<std::string>().rfind("builtin:", 0) != 0) copy(o["mesh"]);
    }
  }
  json.erase("groundtruth");
  json["frames"] = nlohmann::json::parse(writer.FramesJson());
  return json;
}

// The frames to record: the V4L2 camera (the scene's controls, overridden by the options) or
// the recording `--from`; its frame rate, and how many frames it has if it ends.
struct RecordSource {
  std::unique_ptr<capture::FrameSource> source;
  double fps = 30.0;
  std::optional<size_t> total;
};

RecordSource OpenRecordSource(const RecordOptions& o, const scene::Scene& scene) {
  RecordSource r;
  if (!o.device.empty()) {
    capture::V4l2Options v4l2;
    v4l2.width = scene.intrinsics.width, v4l2.height = scene.intrinsics.height;
    v4l2.fps = scene.frames.kind == scene::FrameSourceKind::kDevice ? scene.frames.fps : 30.0;
    if (scene.frames.kind == scene::FrameSourceKind::kDevice) v4l2.settings = scene.frames.controls;
    if (o.exposure_100us) v4l2.settings.exposure_100us = o.exposure_100us;
    if (o.gain) v4l2.settings.gain = o.gain;
    if (o.white_balance_k) v4l2.settings.white_balance_k = o.white_balance_k;
    v4l2.exposure = scene.exposure;
    r.source = capture::OpenV4l2Source(o.device, v4l2);
    r.fps = v4l2.fps;
  } else {
    if (!scene.frame_times) ThrowInputError("--from: {} has no recorded frames", o.from);
    r.source = scene::OpenFrameSource(scene);
    r.fps = scene::NominalFps(scene);
    r.total = scene.frame_times->frames.size();
  }
  if (o.frames) r.total = r.total ? std::min(*r.total, static_cast<size_t>(*o.frames)) : static_cast<size_t>(*o.frames);
  return r;
}

// Frames from `r` into `writer` until the source ends, --frames or --seconds, or Ctrl-C;
// returns how many were written.
int CopyFrames(const RecordOptions& o, RecordSource* r, capture::RecordingWriter* writer) {
  g_stop = false;
  std::signal(SIGINT, StopRecording);
  std::signal(SIGTERM, StopRecording);
  std::optional<Progress> progress;
  if (r->total) progress.emplace("record", *r->total);
  std::optional<UtcTime> first;
  const auto start = std::chrono::steady_clock::now();
  int written = 0;
  while (!g_stop && (!o.frames || written < *o.frames)) {
    capture::Frame frame;
    const capture::FrameStatus status = r->source->Next(&frame);
    if (status == capture::FrameStatus::kEnd) break;
    if (status == capture::FrameStatus::kWaiting) continue;
    if (status == capture::FrameStatus::kUndecodable) {
      if (progress) progress->Advance();
      continue;
    }
    if (!first) first = frame.utc;
    if (o.seconds && frame.utc.SecondsSince(*first) > *o.seconds) break;
    writer->Write(frame);
    ++written;
    if (progress) {
      progress->Advance();
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      progress->SetSuffix(fmt::format("{:.0f} fps", written / std::max(elapsed, 1e-9)));
    }
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  return written;
}

void RunRecord(const RecordOptions& o) {
  if (o.device.empty() == o.from.empty()) ThrowInputError("record: give exactly one of --device and --from");
  if (o.device.empty() ? false : o.scene.empty()) ThrowInputError("--scene: needed with --device (the model, camera and location)");
  if (o.frames && *o.frames < 1) ThrowInputError("--frames: {} is not a number of frames", *o.frames);
  if (o.seconds && !(*o.seconds > 0.0)) ThrowInputError("--seconds: {} is not a duration", *o.seconds);
  const fs::path out(o.out);
  if (fs::exists(out) && !(fs::is_directory(out) && fs::is_empty(out))) {
    ThrowInputError("--out: {} exists; record into a new folder", out.string());
  }
  const scene::Scene scene = scene::LoadScene(o.scene.empty() ? o.from : o.scene);
  RecordSource source = OpenRecordSource(o, scene);
  Log().info("recording {} into {}", source.source->Describe(), out.string());
  // Into out.partial, renamed to `out` once complete with its scene.json.
  const fs::path partial = fs::path(out.string() + ".partial");
  fs::remove_all(partial);
  capture::RecordingWriter writer(partial, o.images, source.fps, scene.response);
  const int written = CopyFrames(o, &source, &writer);
  if (written == 0) {
    fs::remove_all(partial);
    ThrowInputError("record: no frame could be read from {}", source.source->Describe());
  }
  writer.Finish();
  WriteFileAtomically(partial / "scene.json", NewSceneJson(scene, writer, partial).dump(2) + "\n");
  fs::remove(out);  // an empty folder, if any
  fs::rename(partial, out);
  const capture::SourceStats& stats = source.source->stats();
  fmt::print("{} frames written to {}; {} could not be decoded, {} dropped by the driver\n", written, out.string(),
             stats.undecodable, stats.dropped);
  if (stats.undecodable + stats.dropped > 0) {
    Log().warn("{} frames could not be decoded and {} were dropped", stats.undecodable, stats.dropped);
  }
}

}  // namespace

void AddRecordCommand(CLI::App& app) {
  auto options = std::make_shared<RecordOptions>();
  CLI::App* cmd = app.add_subcommand("record", "Write a live camera (or a recording's frames) as a recording folder");
  cmd->add_option("--device", options->device, "V4L2 camera, e.g. /dev/video0");
  cmd->add_option("--from", options->from, "A recording whose frames to write instead (to cut or convert it)");
  cmd->add_option("--scene", options->scene, "scene.json with the model, camera and location (default: --from's)");
  cmd->add_option("--out", options->out, "New recording folder")->required();
  cmd->add_option("--frames", options->frames, "Stop after this many frames")->check(FrameCount());
  cmd->add_option("--seconds", options->seconds, "Stop after this many seconds of frames");
  cmd->add_flag("--images", options->images, "Lossless PNG frames instead of an H.264 video");
  cmd->add_option("--exposure-100us", options->exposure_100us,
                  "Exposure in 100 µs units (default: scene.json's frames.controls, else held at what auto reached)")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--gain", options->gain, "Gain, device units (default as for --exposure-100us)")->check(CLI::Range(0, 1000000));
  cmd->add_option("--white-balance-k", options->white_balance_k, "White balance in kelvin (default as for --exposure-100us)")
      ->check(CLI::Range(1000, 20000));
  cmd->callback([options] { RunRecord(*options); });
}

}  // namespace daylit::app
