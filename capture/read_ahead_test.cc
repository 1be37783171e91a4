// capture::ReadAhead: the same frames as the source, in order, with its statuses; a source's
// error reaches the caller; a read-ahead cannot seek; leaving mid-stream ends the thread; a live
// camera is never kept waiting (the oldest waiting frame is given up, counted as skipped).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

#include "base/check.h"
#include "capture/read_ahead.h"

namespace daylit::capture {
namespace {

// Frames 0..count-1 of 2×1 pixels whose value is the frame number, kUndecodable for `bad`,
// kWaiting before every third frame, then the end or (with `fail`) an error.
class CountingSource final : public FrameSource {
 public:
  CountingSource(int count, int bad, bool fail, bool live = false) : count_(count), bad_(bad), fail_(fail), live_(live) {}
  FrameStatus Next(Frame* frame) override {
    ++calls;
    if (next_ % 3 == 0 && !waited_) {
      waited_ = true;
      return FrameStatus::kWaiting;
    }
    waited_ = false;
    if (next_ == count_) {
      if (fail_) throw std::runtime_error("the device went away");
      return FrameStatus::kEnd;
    }
    frame->index = next_;
    frame->rgb = next_ == bad_ ? cv::Mat() : cv::Mat(1, 2, CV_32FC3, cv::Scalar::all(next_));
    return next_++ == bad_ ? FrameStatus::kUndecodable : FrameStatus::kFrame;
  }
  void Seek(int) override {}
  std::string Describe() const override { return "counting"; }
  bool live() const override { return live_; }

  std::atomic<int> calls{0};  // Next() calls so far (read by the test's thread)

 private:
  int count_, bad_;
  bool fail_, live_;
  int next_ = 0;
  bool waited_ = false;
};

TEST(ReadAheadTest, GivesTheSourcesFramesInOrderWithoutWaiting) {
  std::unique_ptr<FrameSource> source = ReadAhead(std::make_unique<CountingSource>(50, 17, false), 3);
  Frame frame;
  for (int i = 0; i < 50; ++i) {
    const FrameStatus status = source->Next(&frame);
    ASSERT_EQ(status, i == 17 ? FrameStatus::kUndecodable : FrameStatus::kFrame) << i;
    EXPECT_EQ(frame.index, i);
    if (i != 17) {
      EXPECT_EQ(frame.rgb.at<cv::Vec3f>(0, 1)[2], static_cast<float>(i));
    }
  }
  EXPECT_EQ(source->Next(&frame), FrameStatus::kEnd);
  EXPECT_EQ(source->Next(&frame), FrameStatus::kEnd);  // and stays ended
  EXPECT_EQ(source->stats().delivered, 49);
  EXPECT_EQ(source->stats().undecodable, 1);
}

TEST(ReadAheadTest, TheSourcesErrorReachesTheCallerAfterItsFrames) {
  std::unique_ptr<FrameSource> source = ReadAhead(std::make_unique<CountingSource>(5, -1, true));
  Frame frame;
  for (int i = 0; i < 5; ++i) ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
  EXPECT_THROW(source->Next(&frame), std::runtime_error);
  EXPECT_EQ(source->Next(&frame), FrameStatus::kEnd);
}

TEST(ReadAheadTest, SeekIsABrokenInvariantAndLeavingEarlyEndsTheThread) {
  std::unique_ptr<FrameSource> source = ReadAhead(std::make_unique<CountingSource>(100000, -1, false), 2);
  Frame frame;
  ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
  EXPECT_THROW(source->Seek(3), InvariantError);
  source.reset();  // a reader blocked on the full queue must not hang the destructor
}

// A camera does not wait for its reader: with the reader away, the read-ahead goes on taking
// every frame (a driver would otherwise drop them for want of a queued buffer), keeps the newest
// `depth` and counts the others as skipped. A recording's read-ahead waits instead.
TEST(ReadAheadTest, ALiveSourceIsReadToTheEndWhileItsReaderIsAwayKeepingTheNewest) {
  constexpr int kFrames = 40, kDepth = 4;
  for (const bool live : {true, false}) {
    auto counting = std::make_unique<CountingSource>(kFrames, -1, false, live);
    const CountingSource* watched = counting.get();
    std::unique_ptr<FrameSource> source = ReadAhead(std::move(counting), kDepth);
    // Every Next() the source needs: the frames, the kWaiting before every third, the end.
    const int all_calls = kFrames + (kFrames + 2) / 3 + 1;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (watched->calls.load() < all_calls && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(live ? 5 : 200));
      if (!live) break;  // a recording's reader stops at a full queue: give it a moment, no more
    }
    Frame frame;
    if (live) {
      ASSERT_EQ(watched->calls.load(), all_calls) << "the live source was kept waiting";
      EXPECT_EQ(source->waiting(), kDepth);
      for (int i = kFrames - kDepth; i < kFrames; ++i) {
        ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
        EXPECT_EQ(frame.index, i) << "the newest frames, in order";
      }
      EXPECT_EQ(source->Next(&frame), FrameStatus::kEnd);
      EXPECT_EQ(source->stats().skipped, kFrames - kDepth);
    } else {
      EXPECT_LT(watched->calls.load(), all_calls);
      for (int i = 0; i < kFrames; ++i) {
        ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
        EXPECT_EQ(frame.index, i) << "every frame, in order";
      }
      EXPECT_EQ(source->Next(&frame), FrameStatus::kEnd);
      EXPECT_EQ(source->stats().skipped, 0);
    }
  }
}

}  // namespace
}  // namespace daylit::capture
