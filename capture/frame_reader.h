// Decoding a few chosen frames of a recording (video through OpenCV's FFmpeg backend, or image
// files), as 8-bit BGR or linear float images. Issue 7 grows this into the streaming FrameSource.
#pragma once

#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

namespace daylit::capture {

// Frames `indices` (ascending) of a video, as decoded BGR 8-bit images; a frame that cannot be
// decoded is left empty and logged with its index. Throws InputError if the file cannot be opened.
std::vector<cv::Mat> ReadVideoFrames(const std::filesystem::path& video, const std::vector<int>& indices);

}  // namespace daylit::capture
