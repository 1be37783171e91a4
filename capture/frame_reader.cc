#include "capture/frame_reader.h"

#include <opencv2/videoio.hpp>

#include "base/error.h"
#include "base/log.h"

namespace daylit::capture {

std::vector<cv::Mat> ReadVideoFrames(const std::filesystem::path& video, const std::vector<int>& indices) {
  cv::VideoCapture capture(video.string(), cv::CAP_FFMPEG);
  if (!capture.isOpened()) ThrowInputError("{}: cannot open as a video (FFmpeg)", video.string());
  std::vector<cv::Mat> frames(indices.size());
  int next = 0;  // index of the frame the decoder will return next
  for (size_t k = 0; k < indices.size(); ++k) {
    // Decoding forward is exact; seeking in H.264 lands on key frames, so skip by grabbing.
    while (next < indices[k] && capture.grab()) ++next;
    if (next == indices[k] && capture.read(frames[k])) {
      ++next;
    } else {
      frames[k].release();
      Log().warn("{}: frame {} cannot be decoded; skipped", video.string(), indices[k]);
    }
  }
  return frames;
}

}  // namespace daylit::capture
