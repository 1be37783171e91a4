#include "capture/read_ahead.h"

#include <tbb/concurrent_queue.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>

#include <fmt/format.h>

#include "base/check.h"

namespace daylit::capture {
namespace {

struct DecodedFrame {
  FrameStatus status = FrameStatus::kEnd;
  Frame frame;
  std::exception_ptr error;  // a failure that is not the frame's own: ends the stream
  int dropped = 0;           // the source's counts of frames its driver dropped and it skipped,
  int skipped = 0;           // up to this one
};

class ReadAheadSource final : public FrameSource {
 public:
  ReadAheadSource(std::unique_ptr<FrameSource> source, int depth) : source_(std::move(source)) {
    DAYLIT_CHECK(source_ != nullptr);
    DAYLIT_CHECK(depth >= 1 && depth <= 64, "depth {}", depth);
    live_ = source_->live();
    queue_.set_capacity(depth);
    thread_ = std::thread([this] { Run(); });
  }
  ~ReadAheadSource() override {
    // Wakes a reader blocked on a full queue (abort) and empties the queue so that one still
    // decoding pushes without waiting; either way it then sees stop_ and ends.
    stop_ = true;
    queue_.abort();
    DecodedFrame dropped;
    while (queue_.try_pop(dropped)) {}
    thread_.join();
  }

  FrameStatus Next(Frame* frame) override {
    if (ended_) return FrameStatus::kEnd;
    DecodedFrame next;
    queue_.pop(next);
    if (next.error) {
      ended_ = true;
      std::rethrow_exception(next.error);
    }
    if (next.status == FrameStatus::kEnd) ended_ = true;
    if (next.status == FrameStatus::kFrame) ++stats_.delivered;
    if (next.status == FrameStatus::kUndecodable) ++stats_.undecodable;
    stats_.dropped = next.dropped, stats_.skipped = next.skipped + given_up_.load();
    *frame = std::move(next.frame);
    return next.status;
  }
  void Seek(int index) override { DAYLIT_CHECK(false, "Seek({}) on a read-ahead source", index); }
  std::string Describe() const override { return fmt::format("{}, read ahead", source_->Describe()); }
  bool live() const override { return live_; }
  // tbb's size() counts pops waiting (negative) and a push waiting on the full queue (one over).
  int waiting() const override {
    return static_cast<int>(std::clamp<std::ptrdiff_t>(queue_.size(), 0, queue_.capacity()));
  }

 private:
  void Run() {
    while (!stop_) {
      DecodedFrame frame;
      try {
        frame.status = source_->Next(&frame.frame);
        if (frame.status == FrameStatus::kWaiting) continue;
        frame.dropped = source_->stats().dropped;  // read on the source's own thread
        frame.skipped = source_->stats().skipped;
      } catch (...) {
        frame.error = std::current_exception();
      }
      const bool last = static_cast<bool>(frame.error) || frame.status == FrameStatus::kEnd;
      try {
        if (!live_ || last) {
          queue_.push(std::move(frame));  // waits while the caller is `depth` frames behind
        } else {
          // The camera does not wait: the oldest frame waiting makes room for this one.
          while (!stop_ && !queue_.try_push(std::move(frame))) {
            DecodedFrame oldest;
            if (queue_.try_pop(oldest)) ++given_up_;
          }
        }
      } catch (const tbb::user_abort&) {
        return;
      }
      if (last) return;
    }
  }

  std::unique_ptr<FrameSource> source_;
  bool live_ = false;  // set before the thread starts
  tbb::concurrent_bounded_queue<DecodedFrame> queue_;
  std::atomic<int> given_up_{0};  // live: waiting frames given up for newer ones
  std::atomic<bool> stop_{false};
  bool ended_ = false;
  std::thread thread_;  // last: starts once the rest is built
};

}  // namespace

std::unique_ptr<FrameSource> ReadAhead(std::unique_ptr<FrameSource> source, int depth) {
  return std::make_unique<ReadAheadSource>(std::move(source), depth);
}

}  // namespace daylit::capture
