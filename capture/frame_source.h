// One interface for every source of frames: recorded videos, image sequences and live V4L2
// cameras. The pipeline reads frames through it and cannot tell them apart.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "base/utc_time.h"
#include "capture/frame_times.h"
#include "capture/response.h"

namespace daylit::capture {

struct Frame {
  int index = 0;         // frames.csv's frame number; a live source counts from 0
  UtcTime utc;           // when the frame was exposed
  double exposure = 1.0;  // k: linear pixel = k · radiance
  cv::Mat rgb;           // CV_32FC3, R, G, B; each frame gets its own buffer, never written again
                         // once handed out, so a reader may keep it (daylit's lighting server)
  bool linear = false;   // true: linear light (EXR); false: encoded by the camera response
};

// A frame in radiance units, interleaved RGB (width × height × 3): the response's inverse (unless
// the frame is linear already), then the exposure divided out. On all cores.
void LinearRadiance(const Frame& frame, const Linearizer& linearizer, std::vector<float>* out);

enum class FrameStatus {
  kFrame,        // `frame` holds the next frame
  kUndecodable,  // the next frame could not be read: `frame` names it (index, time), no pixels
  kWaiting,      // a live source has no frame now (device gone, retrying); call again
  kEnd,          // no more frames
};

struct SourceStats {
  int delivered = 0;    // frames returned
  int undecodable = 0;  // frames that could not be decoded or read
  int dropped = 0;      // live: frames the driver's sequence numbers show were never delivered
  int skipped = 0;      // live: frames delivered while a newer one was waiting, given back unread
  // Paced replay: the time its schedule gave the frames so far, seconds (the recording's time
  // over the speed, gaps between bursts left out). Time spent is at least this.
  double scheduled_s = 0.0;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual FrameStatus Next(Frame* frame) = 0;
  // Recorded sources: the next Next() returns frame `index` (frames.csv's numbering). Throws
  // InputError for an index not in the recording, or for a live source.
  virtual void Seek(int index) = 0;
  virtual std::string Describe() const = 0;
  virtual bool live() const { return false; }
  // Frames already read and waiting for Next() (a read-ahead's queue): a caller that finds one
  // is behind its source. 0 for a source that reads on demand.
  virtual int waiting() const { return 0; }
  const SourceStats& stats() const { return stats_; }

 protected:
  SourceStats stats_;
};

// A video file (decoded exactly by VideoDecoder) with its frames.csv; `exposure` where a row
// has none. Frames the decoder cannot produce are kUndecodable, named by their row.
std::unique_ptr<FrameSource> OpenVideoSource(const std::filesystem::path& video, FrameTimes times, double exposure);

// Images named by `pattern` (one %d or %0Nd for the frame number; PNG/JPEG encoded, EXR
// linear) with their frames.csv. A missing or unreadable image is kUndecodable, with a warning
// naming the file.
std::unique_ptr<FrameSource> OpenImageSequence(std::string pattern, FrameTimes times, double exposure);

// The file of frame `index` for an image pattern.
std::filesystem::path FramePath(const std::string& pattern, int index);

// `source`, not owned: for a loop that reads the first frames of a source and hands the rest to
// another (daylit live --calibrate). `source` must outlive it.
std::unique_ptr<FrameSource> Borrowed(FrameSource* source);

// `source` with `seconds` added to every frame's time: a camera clock that is known to be off
// (scene.json's frames.clock_offset_s: UTC = the clock's time + offset).
std::unique_ptr<FrameSource> ClockShifted(std::unique_ptr<FrameSource> source, double seconds);

// `source` paced to its timestamps: each frame is returned no earlier than its time after the
// first frame's, divided by `speed`, on the steady clock (for replay in a window). A gap of more
// than 2 s (after dividing by `speed`) between two frames, such as a time-lapse's bursts hours
// apart, is skipped: pacing starts again from the frame after it.
std::unique_ptr<FrameSource> Paced(std::unique_ptr<FrameSource> source, double speed);

}  // namespace daylit::capture
