// capture::ReadAhead: the same frames as the source, in order, with its statuses; a source's
// error reaches the caller; a read-ahead cannot seek; leaving mid-stream ends the thread.
#include <gtest/gtest.h>

#include <stdexcept>

#include "base/check.h"
#include "capture/read_ahead.h"

namespace daylit::capture {
namespace {

// Frames 0..count-1 of 2×1 pixels whose value is the frame number, kUndecodable for `bad`,
// kWaiting before every third frame, then the end or (with `fail`) an error.
class CountingSource final : public FrameSource {
 public:
  CountingSource(int count, int bad, bool fail) : count_(count), bad_(bad), fail_(fail) {}
  FrameStatus Next(Frame* frame) override {
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

 private:
  int count_, bad_;
  bool fail_;
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

}  // namespace
}  // namespace daylit::capture
