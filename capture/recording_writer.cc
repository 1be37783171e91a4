#include "capture/recording_writer.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/atomic_file.h"
#include "base/error.h"

namespace daylit::capture {

cv::Mat EncodeFrame8(const Frame& frame, const CameraResponse& response) {
  cv::Mat rgb8(frame.rgb.size(), CV_8UC3);
  for (int y = 0; y < frame.rgb.rows; ++y) {
    const auto* in = frame.rgb.ptr<cv::Vec3f>(y);
    auto* out = rgb8.ptr<cv::Vec3b>(y);
    for (int x = 0; x < frame.rgb.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const double encoded = frame.linear ? response.ToEncoded(in[x][c], c) : std::clamp(static_cast<double>(in[x][c]), 0.0, 1.0);
        out[x][c] = static_cast<uint8_t>(std::lround(255.0 * encoded));
      }
    }
  }
  cv::Mat bgr;
  cv::cvtColor(rgb8, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

RecordingWriter::RecordingWriter(std::filesystem::path dir, bool images, double fps, CameraResponse response)
    : dir_(std::move(dir)), images_(images), fps_(fps), response_(std::move(response)) {
  std::filesystem::create_directories(images_ ? dir_ / "frames" : dir_);
}

void RecordingWriter::Write(const Frame& frame) {
  if (images_) {
    const std::filesystem::path file = dir_ / "frames" / fmt::format("{:06d}.png", count_);
    if (!cv::imwrite(file.string(), EncodeFrame8(frame, response_))) ThrowInputError("{}: cannot write", file.string());
  } else {
    if (!video_) video_ = std::make_unique<VideoEncoder>(dir_ / "video.mp4", frame.rgb.cols, frame.rgb.rows, VideoEncoderOptions{fps_});
    if (frame.linear) {
      video_->Write(EncodeFrame8(frame, response_));
    } else {
      video_->Write(frame.rgb);
    }
  }
  csv_ += fmt::format("{},{},{:.9g}\n", count_, FormatUtcTime(frame.utc, 6), frame.exposure);
  ++count_;
}

int RecordingWriter::Finish() {
  if (video_) video_->Finish();
  WriteFileAtomically(dir_ / "frames.csv", csv_);
  return count_;
}

std::string RecordingWriter::FramesJson() const {
  const nlohmann::json frames = images_ ? nlohmann::json{{"images", "frames/%06d.png"}, {"timestamps", "frames.csv"}}
                                        : nlohmann::json{{"video", "video.mp4"}, {"timestamps", "frames.csv"}};
  return frames.dump();
}

}  // namespace daylit::capture
