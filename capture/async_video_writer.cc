#include "capture/async_video_writer.h"

#include <utility>

#include <opencv2/core.hpp>

namespace daylit::capture {

AsyncVideoWriter::AsyncVideoWriter(const std::filesystem::path& path, int width, int height, double fps,
                                   const CameraResponse& response)
    : encoder_(path, width, height, VideoEncoderOptions{fps}), to_video_(response), width_(width), height_(height),
      thread_([this] { Run(); }) {}

AsyncVideoWriter::~AsyncVideoWriter() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
    items_.clear();
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

std::vector<float> AsyncVideoWriter::TakeBuffer() {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (spare_.empty()) return {};
  std::vector<float> buffer = std::move(spare_.back());
  spare_.pop_back();
  return buffer;
}

void AsyncVideoWriter::Write(std::vector<float> linear, double exposure) {
  Push(Item{std::move(linear), static_cast<float>(exposure), false});
}

void AsyncVideoWriter::Finish() {
  Push(Item{{}, 0.0f, true});
  thread_.join();
  if (error_) std::rethrow_exception(error_);
  encoder_.Finish();
}

void AsyncVideoWriter::Push(Item item) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return items_.size() < 3 || error_ != nullptr; });
  if (error_) std::rethrow_exception(error_);
  items_.push_back(std::move(item));
  changed_.notify_all();
}

void AsyncVideoWriter::Run() {
  cv::Mat encoded = cv::Mat::zeros(height_, width_, CV_32FC3);
  for (;;) {
    Item item;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !items_.empty() || closing_; });
      if (items_.empty()) return;
      item = std::move(items_.front());
      items_.pop_front();
    }
    changed_.notify_all();
    if (item.last) return;
    try {
      if (!item.linear.empty()) to_video_.Apply(item.linear.data(), item.exposure, encoded.ptr<float>(), item.linear.size());
      encoder_.Write(encoded);
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!item.linear.empty()) spare_.push_back(std::move(item.linear));
    } catch (...) {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
      }
      changed_.notify_all();
      return;
    }
  }
}

}  // namespace daylit::capture
