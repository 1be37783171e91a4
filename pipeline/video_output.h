// The video a command writes (daylit replay, live, relight): --out checked (.mp4 or .mkv, its
// folder there), written under a temporary name beside it on its own thread, renamed when
// complete; removed if the command ends any other way.
#pragma once

#include <filesystem>
#include <optional>

#include "capture/async_video_writer.h"
#include "scene/scene.h"

namespace daylit::pipeline {

// Throws InputError unless `out` ends in .mp4 or .mkv.
void CheckVideoName(const std::filesystem::path& out);

class VideoOutput {
 public:
  // Throws InputError "--out: …" if the folder is missing or the file cannot be written.
  VideoOutput(const std::filesystem::path& out, const scene::Scene& scene);
  ~VideoOutput();
  VideoOutput(const VideoOutput&) = delete;
  VideoOutput& operator=(const VideoOutput&) = delete;

  capture::AsyncVideoWriter& writer() { return *writer_; }
  // Finishes the video and gives it its name.
  void Commit();

 private:
  std::filesystem::path out_, partial_;
  std::optional<capture::AsyncVideoWriter> writer_;
  bool committed_ = false;
};

}  // namespace daylit::pipeline
