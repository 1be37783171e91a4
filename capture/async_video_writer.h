// Writes linear frames into an H.264 video on a thread of its own: the camera's response, then
// the encoder, up to three frames behind the caller (daylit replay, live and relight).
#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "capture/response.h"
#include "capture/video_encoder.h"

namespace daylit::capture {

class AsyncVideoWriter {
 public:
  // Opens `path` (throws as VideoEncoder does).
  AsyncVideoWriter(const std::filesystem::path& path, int width, int height, double fps, const CameraResponse& response);
  // Without Finish (an error elsewhere) the queued frames are dropped; the caller removes the file.
  ~AsyncVideoWriter();
  AsyncVideoWriter(const AsyncVideoWriter&) = delete;
  AsyncVideoWriter& operator=(const AsyncVideoWriter&) = delete;

  // A buffer for the next frame: one the thread has encoded (no allocation), else an empty one.
  std::vector<float> TakeBuffer();
  // A linear frame in radiance units (width × height × 3) and its exposure; an empty one repeats
  // the last frame. Rethrows what went wrong on the thread.
  void Write(std::vector<float> linear, double exposure);
  // Encodes what is queued and finishes the file.
  void Finish();

 private:
  struct Item {
    std::vector<float> linear;
    float exposure = 1.0f;
    bool last = false;
  };
  void Push(Item item);
  void Run();

  VideoEncoder encoder_;
  const Encoder to_video_;
  const int width_, height_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> items_;
  std::vector<std::vector<float>> spare_;  // encoded frames' buffers, for reuse
  bool closing_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: starts once the rest is built
};

}  // namespace daylit::capture
