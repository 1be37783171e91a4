#include "capture/frame_source.h"

#include <chrono>
#include <optional>
#include <thread>

#include <ImfArray.h>
#include <ImfRgbaFile.h>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "base/log.h"
#include "capture/video_decoder.h"

namespace daylit::capture {

void LinearRadiance(const Frame& frame, const Linearizer& linearizer, std::vector<float>* out) {
  const size_t n = static_cast<size_t>(frame.rgb.cols) * static_cast<size_t>(frame.rgb.rows) * 3;
  out->resize(n);
  const float scale = static_cast<float>(1.0 / frame.exposure);
  const float* in = frame.rgb.ptr<float>();
  float* linear = out->data();
  if (frame.linear) {
    for (size_t i = 0; i < n; ++i) linear[i] = in[i] * scale;
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n / 3, 16384), [&](const tbb::blocked_range<size_t>& pixels) {
    for (size_t i = 3 * pixels.begin(); i < 3 * pixels.end(); i += 3) {
      linear[i] = linearizer(in[i], 0) * scale;
      linear[i + 1] = linearizer(in[i + 1], 1) * scale;
      linear[i + 2] = linearizer(in[i + 2], 2) * scale;
    }
  });
}
namespace {

// A linear RGB EXR frame as floats (OpenEXR's RGBA interface: any channel layout it knows).
cv::Mat ReadExrFrame(const std::filesystem::path& path) {
  Imf::RgbaInputFile file(path.c_str());
  const Imath::Box2i window = file.dataWindow();
  const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
  Imf::Array2D<Imf::Rgba> pixels(height, width);
  file.setFrameBuffer(&pixels[0][0] - window.min.x - window.min.y * width, 1, width);
  file.readPixels(window.min.y, window.max.y);
  cv::Mat rgb(height, width, CV_32FC3);
  for (int y = 0; y < height; ++y) {
    auto* out = rgb.ptr<cv::Vec3f>(y);
    for (int x = 0; x < width; ++x) out[x] = {pixels[y][x].r, pixels[y][x].g, pixels[y][x].b};
  }
  return rgb;
}

// Rows of frames.csv in order, with the lookup of a frame number.
class Rows {
 public:
  Rows(FrameTimes times, double exposure) : times_(std::move(times)), exposure_(exposure) {}
  bool done() const { return next_ >= times_.frames.size(); }
  const FrameTime& current() const { return times_.frames[next_]; }
  // Fills the frame's number, time and exposure from the current row, and moves on.
  void Take(Frame* frame) {
    const FrameTime& row = times_.frames[next_];
    frame->index = row.index, frame->utc = row.utc, frame->exposure = times_.ExposureOf(next_, exposure_);
    ++next_;
  }
  void SeekTo(int index, const std::string& what) {
    for (size_t i = 0; i < times_.frames.size(); ++i) {
      if (times_.frames[i].index == index) {
        next_ = i;
        return;
      }
    }
    ThrowInputError("{}: frame {} is not in {}", what, index, times_.file.string());
  }

 private:
  FrameTimes times_;
  double exposure_;
  size_t next_ = 0;
};

class VideoSource final : public FrameSource {
 public:
  VideoSource(const std::filesystem::path& video, FrameTimes times, double exposure)
      : path_(video), decoder_(video), rows_(std::move(times), exposure) {}

  FrameStatus Next(Frame* frame) override {
    if (rows_.done()) return FrameStatus::kEnd;
    const int wanted = rows_.current().index;
    // The decoded frame waiting for its row (after a gap), else the next one from the stream.
    while (!pending_ || pending_index_ < wanted) {
      if (ended_ || !decoder_.Next(&pending_rgb_)) {
        if (!ended_) Log().warn("{}: the video ends before frame {} of its frames.csv", path_.string(), wanted);
        ended_ = true;
        pending_ = false;
        break;
      }
      pending_ = true;
      pending_index_ = decoder_.last_index();
    }
    if (!pending_ || pending_index_ > wanted) {
      // The stream skipped this frame (a packet that does not decode) or ended.
      if (!ended_) Log().warn("{}: frame {} cannot be decoded; skipped", path_.string(), wanted);
      rows_.Take(frame);
      frame->rgb.release();
      ++stats_.undecodable;
      return FrameStatus::kUndecodable;
    }
    rows_.Take(frame);
    frame->rgb = pending_rgb_;
    pending_rgb_ = cv::Mat();  // the next decode gets its own buffer
    frame->linear = false;
    pending_ = false;
    ++stats_.delivered;
    return FrameStatus::kFrame;
  }

  void Seek(int index) override {
    rows_.SeekTo(index, path_.string());
    decoder_.Seek(index);
    pending_ = false, ended_ = false;
  }

  std::string Describe() const override {
    return fmt::format("{} ({}x{}, {})", path_.string(), decoder_.width(), decoder_.height(), decoder_.matrix());
  }

 private:
  std::filesystem::path path_;
  VideoDecoder decoder_;
  Rows rows_;
  cv::Mat pending_rgb_;
  bool pending_ = false;
  int pending_index_ = -1;
  bool ended_ = false;
};

class ImageSequence final : public FrameSource {
 public:
  ImageSequence(std::string pattern, FrameTimes times, double exposure)
      : pattern_(std::move(pattern)), rows_(std::move(times), exposure) {}

  FrameStatus Next(Frame* frame) override {
    if (rows_.done()) return FrameStatus::kEnd;
    const std::filesystem::path path = FramePath(pattern_, rows_.current().index);
    rows_.Take(frame);
    if (Read(path, frame)) {
      ++stats_.delivered;
      return FrameStatus::kFrame;
    }
    frame->rgb.release();
    ++stats_.undecodable;
    return FrameStatus::kUndecodable;
  }

  void Seek(int index) override { rows_.SeekTo(index, pattern_); }
  std::string Describe() const override { return pattern_; }

 private:
  static bool Read(const std::filesystem::path& path, Frame* frame) {
    if (!std::filesystem::is_regular_file(path)) {
      Log().warn("{}: missing; frame {} skipped", path.string(), frame->index);
      return false;
    }
    if (path.extension() == ".exr") {
      try {
        frame->rgb = ReadExrFrame(path);  // linear already
      } catch (const std::exception& e) {
        Log().warn("{}: cannot be read as OpenEXR ({}); frame {} skipped", path.string(), e.what(), frame->index);
        return false;
      }
      frame->linear = true;
      return true;
    }
    const cv::Mat bgr = cv::imread(path.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) {
      Log().warn("{}: frame {} cannot be decoded; skipped", path.string(), frame->index);
      return false;
    }
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    rgb.convertTo(frame->rgb, CV_32FC3, 1.0 / 255.0);
    frame->linear = false;
    return true;
  }

  std::string pattern_;
  Rows rows_;
};

class PacedSource final : public FrameSource {
 public:
  PacedSource(std::unique_ptr<FrameSource> source, double speed) : source_(std::move(source)), speed_(speed) {
    if (!(speed_ > 0.0)) ThrowInputError("pacing speed {} must be > 0", speed_);
  }

  FrameStatus Next(Frame* frame) override {
    const FrameStatus status = source_->Next(frame);
    stats_ = source_->stats();
    stats_.scheduled_s = scheduled_s_;
    if (status != FrameStatus::kFrame && status != FrameStatus::kUndecodable) return status;
    const auto now = std::chrono::steady_clock::now();
    // A gap of more than kMaxGap between two frames (a time-lapse's bursts hours apart) is not
    // waited for: pacing starts again from the frame after it.
    const bool gap = previous_ && frame->utc.SecondsSince(*previous_) / speed_ > kMaxGapSeconds;
    previous_ = frame->utc;
    if (!first_ || gap) {
      first_ = frame->utc, start_ = now;
      done_s_ = scheduled_s_;
      return status;
    }
    const double seconds = frame->utc.SecondsSince(*first_) / speed_;
    scheduled_s_ = done_s_ + seconds;
    stats_.scheduled_s = scheduled_s_;
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(seconds)));
    return status;
  }
  void Seek(int index) override {
    source_->Seek(index);
    first_.reset(), previous_.reset();  // pacing restarts at the new position
  }
  std::string Describe() const override { return fmt::format("{}, paced ×{:g}", source_->Describe(), speed_); }
  bool live() const override { return source_->live(); }
  int waiting() const override { return source_->waiting(); }

 private:
  static constexpr double kMaxGapSeconds = 2.0;
  std::unique_ptr<FrameSource> source_;
  double speed_;
  std::optional<UtcTime> first_, previous_;
  std::chrono::steady_clock::time_point start_;
  double scheduled_s_ = 0.0;  // the schedule so far
  double done_s_ = 0.0;       // of which the stretches before the current one
};

class BorrowedSource final : public FrameSource {
 public:
  explicit BorrowedSource(FrameSource* source) : source_(source) {}
  FrameStatus Next(Frame* frame) override {
    const FrameStatus status = source_->Next(frame);
    stats_ = source_->stats();
    return status;
  }
  void Seek(int index) override { source_->Seek(index); }
  std::string Describe() const override { return source_->Describe(); }
  bool live() const override { return source_->live(); }
  int waiting() const override { return source_->waiting(); }

 private:
  FrameSource* source_;
};

class ClockShiftedSource final : public FrameSource {
 public:
  ClockShiftedSource(std::unique_ptr<FrameSource> source, double seconds) : source_(std::move(source)), seconds_(seconds) {}

  FrameStatus Next(Frame* frame) override {
    const FrameStatus status = source_->Next(frame);
    stats_ = source_->stats();
    if (status == FrameStatus::kFrame || status == FrameStatus::kUndecodable) frame->utc = ShiftedUtc(frame->utc, seconds_);
    return status;
  }
  void Seek(int index) override { source_->Seek(index); }
  std::string Describe() const override { return fmt::format("{}, clock {:+.3f} s", source_->Describe(), seconds_); }
  bool live() const override { return source_->live(); }
  int waiting() const override { return source_->waiting(); }

 private:
  std::unique_ptr<FrameSource> source_;
  double seconds_;
};

}  // namespace

std::filesystem::path FramePath(const std::string& pattern, int index) {
  const size_t percent = pattern.find('%');
  const size_t d = pattern.find('d', percent);
  const std::string spec = pattern.substr(percent + 1, d - percent - 1);  // "", "06", "6"
  const int width = spec.empty() ? 0 : std::stoi(spec);
  return pattern.substr(0, percent) + fmt::format("{:0{}d}", index, width) + pattern.substr(d + 1);
}

std::unique_ptr<FrameSource> OpenVideoSource(const std::filesystem::path& video, FrameTimes times, double exposure) {
  return std::make_unique<VideoSource>(video, std::move(times), exposure);
}

std::unique_ptr<FrameSource> OpenImageSequence(std::string pattern, FrameTimes times, double exposure) {
  return std::make_unique<ImageSequence>(std::move(pattern), std::move(times), exposure);
}

std::unique_ptr<FrameSource> Borrowed(FrameSource* source) { return std::make_unique<BorrowedSource>(source); }

std::unique_ptr<FrameSource> ClockShifted(std::unique_ptr<FrameSource> source, double seconds) {
  return std::make_unique<ClockShiftedSource>(std::move(source), seconds);
}

std::unique_ptr<FrameSource> Paced(std::unique_ptr<FrameSource> source, double speed) {
  return std::make_unique<PacedSource>(std::move(source), speed);
}

}  // namespace daylit::capture
