#include "capture/video_probe.h"

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "base/error.h"
#include "base/files.h"

namespace daylit::capture {

VideoInfo ProbeVideo(const std::filesystem::path& path) {
  RequireRegularFile(path);
  cv::VideoCapture video(path.string(), cv::CAP_FFMPEG);
  if (!video.isOpened()) ThrowInputError("{}: cannot open as a video (FFmpeg)", path.string());
  VideoInfo info;
  info.width = static_cast<int>(video.get(cv::CAP_PROP_FRAME_WIDTH));
  info.height = static_cast<int>(video.get(cv::CAP_PROP_FRAME_HEIGHT));
  info.frame_count = static_cast<int>(std::lround(video.get(cv::CAP_PROP_FRAME_COUNT)));
  info.fps = video.get(cv::CAP_PROP_FPS);
  const int fourcc = static_cast<int>(video.get(cv::CAP_PROP_FOURCC));
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xFF);
    if (c > ' ' && c < 127) info.codec.push_back(c);
  }
  cv::Mat first;
  if (!video.read(first) || first.empty()) {
    ThrowInputError("{}: frame 0 cannot be decoded", path.string());
  }
  return info;
}

}  // namespace daylit::capture
