#include "capture/recording_writer.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/atomic_file.h"
#include "base/error.h"

namespace daylit::capture {

namespace {

// The frame's 8-bit BGR: encoded values as they are, linear ones (EXR sources) through `response`.
cv::Mat EncodeFrame8(const Frame& frame, const CameraResponse& response) {
  const cv::Mat rgb = frame.rgb.isContinuous() ? frame.rgb : frame.rgb.clone();
  return EncodeToBgr8(rgb.ptr<float>(), rgb.cols, rgb.rows, 1.0, frame.linear ? &response : nullptr);
}

}  // namespace

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
