// Writing H.264 video exactly enough for radiometry: the RGB → YUV conversion is VideoDecoder's
// in reverse (float, limited-range BT.601, chroma sited as the decoder expects), and libx264
// encodes at a constant quality high enough that a frame reads back within about half a code
// value on average (OpenCV's writer, fixed at its default quality, loses 2.7).
#pragma once

#include <string>

#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

namespace daylit::capture {

struct VideoEncoderOptions {
  double fps = 30.0;
  int crf = 10;                    // libx264 constant rate factor: 0 lossless, 23 its default
  const char* preset = "veryfast";  // libx264 speed/size trade-off
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

class VideoEncoder {
 public:
  // Opens `path` (.mp4 or .mkv) for width × height frames (even sizes). Throws InputError naming
  // the file when the path or sizes are wrong, SystemError when the machine lacks or fails at it
  // (no libx264, no memory; a write that fails, as on a full disk, here or in Write and Finish).
  VideoEncoder(const std::filesystem::path& path, int width, int height, const VideoEncoderOptions& options = {});
  ~VideoEncoder();  // finishes the file if Finish() was not called
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  // Appends an encoded (non-linear) RGB float frame, CV_32FC3 in [0, 1], or 8-bit BGR CV_8UC3.
  void Write(const cv::Mat& frame);
  // Flushes the encoder and writes the file's index.
  void Finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Encoded RGB floats (CV_32FC3) to planar limited-range BT.601 YUV 4:2:0: the inverse of
// Yuv420ToRgb, rounded to 8 bits. Exposed for tests.
void RgbToYuv420(const cv::Mat& rgb, uint8_t* y, int y_stride, uint8_t* u, int u_stride, uint8_t* v, int v_stride);

}  // namespace daylit::capture
