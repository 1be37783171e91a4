// What a video file holds, read through OpenCV's FFmpeg backend without decoding it all.
#pragma once

#include <filesystem>
#include <string>

namespace daylit::capture {

struct VideoInfo {
  int width = 0;
  int height = 0;
  int frame_count = 0;  // as the container states it
  double fps = 0.0;
  std::string codec;    // FourCC, e.g. "avc1"
};

// Opens `path` with the FFmpeg backend and reads its header and first frame. Throws InputError
// naming the file when it cannot be opened or its first frame cannot be decoded.
VideoInfo ProbeVideo(const std::filesystem::path& path);

}  // namespace daylit::capture
