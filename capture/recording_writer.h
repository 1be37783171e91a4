// Writes the frames of a recording folder (docs/recording-format.md): an H.264 video
// (VideoEncoder) or lossless PNG images, and frames.csv with each frame's UTC time and exposure.
// Everything goes into `dir`; the caller writes scene.json and renames the folder into place.
#pragma once

#include <filesystem>
#include <memory>
#include <string>


#include "capture/frame_source.h"
#include "capture/response.h"
#include "capture/video_encoder.h"

namespace daylit::capture {

class RecordingWriter {
 public:
  // `fps` is the video's nominal rate (the times in frames.csv are the truth). Linear frames
  // (EXR sources) are encoded with `response` first.
  RecordingWriter(std::filesystem::path dir, bool images, double fps, CameraResponse response);

  // Appends a frame (renumbered from 0). Throws as VideoEncoder does when the video cannot be
  // written (InputError for the path, SystemError for a full disk or a missing encoder).
  void Write(const Frame& frame);
  // Closes the video and writes frames.csv. Returns the number of frames.
  int Finish();

  // The scene.json "frames" block for what was written.
  std::string FramesJson() const;

 private:
  std::filesystem::path dir_;
  bool images_;
  double fps_;
  CameraResponse response_;
  std::unique_ptr<VideoEncoder> video_;
  std::string csv_ = "frame,time_utc,exposure\n";
  int count_ = 0;
};

}  // namespace daylit::capture
