// Decoding a recording's video exactly. OpenCV's and ffmpeg's default YUV→RGB conversion
// (libswscale without accurate rounding) truncates, reading textured areas 1–1.4 code values low:
// −2% in linear light in mid-tones, −5% in dark shadow, half the estimation's error budget
// (recordings/courtyard-a/README.md). Here libavcodec decodes the stream and the conversion is
// done in floating point: limited-range BT.601 (or BT.709 when the stream says so), chroma
// upsampled bilinearly with MPEG-2/H.264 siting, no quantisation of the result.
#pragma once

#include <filesystem>
#include <memory>

#include <opencv2/core.hpp>

namespace daylit::capture {

class VideoDecoder {
 public:
  // Opens the first video stream of `path`. Throws InputError naming the file if it cannot.
  explicit VideoDecoder(const std::filesystem::path& path);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;

  int width() const;
  int height() const;
  const char* matrix() const;  // "BT.601" or "BT.709"

  // The next frame as encoded (non-linear) RGB floats in [0, 1], CV_32FC3 in R, G, B order.
  // Returns false at the end of the stream. A packet that cannot be decoded is skipped (counted
  // in `errors()`); decoding goes on.
  bool Next(cv::Mat* rgb);
  int frames_read() const;
  int errors() const;

  // The frame number of the frame Next() returned last, from its presentation time and the
  // stream's frame rate (0 for the first frame); a gap means frames that could not be decoded.
  int last_index() const;
  // Makes the next Next() return frame `index` (or the first after it that decodes): seeks to the
  // key frame before it and decodes forward from there, so the frame is exactly as when read in
  // order.
  void Seek(int index);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Sends libav's own messages to daylit's logger (debug level) instead of stderr; idempotent.
void RouteLibavLogging();

// Planar 8-bit YUV 4:2:0 (limited range) to encoded RGB floats; `bt709` selects the matrix.
// Exposed for tests. Chroma sample (i, j) sits at luma (2i, 2j + 0.5).
void Yuv420ToRgb(const uint8_t* y, int y_stride, const uint8_t* u, int u_stride, const uint8_t* v, int v_stride,
                 int width, int height, bool bt709, cv::Mat* rgb);

}  // namespace daylit::capture
