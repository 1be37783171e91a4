#include "capture/frame_source.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"
#include "capture/video_decoder.h"

namespace daylit::capture {
namespace {

namespace fs = std::filesystem;

const fs::path kRecording = DAYLIT_SOURCE_DIR "/recordings/courtyard-a";

fs::path TempDir(const std::string& name) {
  const fs::path dir = fs::path(DAYLIT_BINARY_DIR) / "frame_source_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

FrameTimes Times() { return LoadFrameTimes(kRecording / "frames.csv"); }

double MaxDifference(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return 1e9;
  return cv::norm(a, b, cv::NORM_INF);
}

// `count` frames of the courtyard video decoded in order.
std::vector<cv::Mat> Sequential(int count) {
  VideoDecoder decoder(kRecording / "video.mp4");
  std::vector<cv::Mat> frames(static_cast<size_t>(count));
  for (cv::Mat& f : frames) EXPECT_TRUE(decoder.Next(&f));
  return frames;
}

TEST(FrameSourceTest, VideoFramesCarryTheirRowsTimesAndExposures) {
  const FrameTimes times = Times();
  auto source = OpenVideoSource(kRecording / "video.mp4", times, 1.0);
  Frame frame;
  size_t n = 0;
  FrameStatus status;
  while ((status = source->Next(&frame)) == FrameStatus::kFrame) {
    ASSERT_LT(n, times.frames.size());
    EXPECT_EQ(frame.index, times.frames[n].index);
    EXPECT_EQ(frame.utc.SecondsSince(times.frames[n].utc), 0.0);
    EXPECT_DOUBLE_EQ(frame.exposure, *times.frames[n].exposure);
    EXPECT_EQ(frame.rgb.type(), CV_32FC3);
    EXPECT_EQ(frame.rgb.cols, 960);
    EXPECT_FALSE(frame.linear);
    ++n;
  }
  EXPECT_EQ(status, FrameStatus::kEnd);
  EXPECT_EQ(n, times.frames.size());
  EXPECT_EQ(source->stats().delivered, static_cast<int>(n));
  EXPECT_EQ(source->stats().undecodable, 0);
}

TEST(FrameSourceTest, SeekingGivesExactlyTheFrameReadInOrder) {
  const std::vector<cv::Mat> in_order = Sequential(60);
  auto source = OpenVideoSource(kRecording / "video.mp4", Times(), 1.0);
  Frame frame;
  for (const int index : {47, 3, 59, 0, 31}) {  // forwards and backwards, across key frames
    source->Seek(index);
    ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
    EXPECT_EQ(frame.index, index);
    EXPECT_EQ(MaxDifference(frame.rgb, in_order[static_cast<size_t>(index)]), 0.0) << "frame " << index;
    ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
    EXPECT_EQ(frame.index, index + 1);
  }
  EXPECT_THROW(source->Seek(100000), InputError);
}

TEST(FrameSourceTest, AFrameMissingFromTheStreamIsNamedAndTheRestStayInPlace) {
  // The first 20 frames with frame 5 left out, timestamps kept (ffmpeg, installed by setup.sh).
  const fs::path dir = TempDir("gap");
  const fs::path gap = dir / "gap.mp4";
  const std::string command = "ffmpeg -v error -y -i " + (kRecording / "video.mp4").string() +
                              " -frames:v 20 -vf \"select='not(eq(n\\,5))'\" -fps_mode passthrough -c:v libx264 "
                              "-pix_fmt yuv420p -crf 0 " + gap.string();
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  FrameTimes times = Times();
  times.frames.resize(20);
  auto source = OpenVideoSource(gap, times, 1.0);
  Frame frame;
  std::vector<int> got, undecodable;
  for (FrameStatus s; (s = source->Next(&frame)) != FrameStatus::kEnd;) {
    (s == FrameStatus::kFrame ? got : undecodable).push_back(frame.index);
    if (s == FrameStatus::kFrame) {
      EXPECT_EQ(frame.utc.SecondsSince(times.frames[static_cast<size_t>(frame.index)].utc), 0.0);
    }
  }
  EXPECT_EQ(undecodable, std::vector<int>{5});
  EXPECT_EQ(got.size(), 19u);
  EXPECT_EQ(source->stats().undecodable, 1);
}

TEST(FrameSourceTest, ATruncatedVideoEndsWithItsMissingFramesCounted) {
  const fs::path dir = TempDir("truncated");
  const fs::path cut = dir / "cut.mp4";
  // The first third of the file's bytes: mp4's index is at the front (faststart) or the back;
  // either way the stream ends early or cannot be opened, and neither may crash.
  const std::string bytes = ReadTextFile(kRecording / "video.mp4");
  WriteFileAtomically(cut, std::string_view(bytes).substr(0, bytes.size() / 3));
  std::unique_ptr<FrameSource> source;
  try {
    source = OpenVideoSource(cut, Times(), 1.0);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.mp4"), std::string::npos) << e.what();
    return;
  }
  Frame frame;
  int frames = 0, undecodable = 0;
  for (FrameStatus s; (s = source->Next(&frame)) != FrameStatus::kEnd;) (s == FrameStatus::kFrame ? frames : undecodable)++;
  EXPECT_EQ(frames + undecodable, static_cast<int>(Times().frames.size()));
  EXPECT_GT(undecodable, 0);
  EXPECT_EQ(source->stats().undecodable, undecodable);
}

TEST(FrameSourceTest, ImageSequenceReadsPngAndExrAndSkipsBrokenFiles) {
  const fs::path dir = TempDir("images");
  const std::vector<cv::Mat> video = Sequential(3);
  // Frame 0 as an 8-bit PNG, frame 1 not an image, frame 2 as a linear EXR, frame 3 missing.
  cv::Mat bgr8;
  cv::cvtColor(video[0], bgr8, cv::COLOR_RGB2BGR);
  bgr8.convertTo(bgr8, CV_8UC3, 255.0);
  ASSERT_TRUE(cv::imwrite((dir / "000000.png").string(), bgr8));
  WriteFileAtomically(dir / "000001.png", "not a png");
  FrameTimes times = Times();
  times.frames.resize(4);
  cv::Mat linear = video[2].clone();
  linear.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) { p *= 0.5f; });
  {
    // Written through OpenCV: its EXR writer is half-float RGB.
    ::setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 1);
    cv::Mat bgr;
    cv::cvtColor(linear, bgr, cv::COLOR_RGB2BGR);
    ASSERT_TRUE(cv::imwrite((dir / "000002.exr").string(), bgr));
  }
  auto source = OpenImageSequence((dir / "%06d.png").string(), times, 2.0);
  Frame frame;
  ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
  EXPECT_EQ(frame.index, 0);
  EXPECT_FALSE(frame.linear);
  EXPECT_LE(MaxDifference(frame.rgb, video[0]), 0.5 / 255.0 + 1e-6);
  ASSERT_EQ(source->Next(&frame), FrameStatus::kUndecodable);
  EXPECT_EQ(frame.index, 1);
  EXPECT_TRUE(frame.rgb.empty());
  auto exr = OpenImageSequence((dir / "%06d.exr").string(), times, 2.0);
  exr->Seek(2);
  ASSERT_EQ(exr->Next(&frame), FrameStatus::kFrame);
  EXPECT_EQ(frame.index, 2);
  EXPECT_TRUE(frame.linear);
  EXPECT_LE(MaxDifference(frame.rgb, linear), 1e-3);  // half floats
  ASSERT_EQ(exr->Next(&frame), FrameStatus::kUndecodable);  // 000003.exr does not exist
  EXPECT_EQ(frame.index, 3);
  EXPECT_EQ(exr->Next(&frame), FrameStatus::kEnd);
}

// A live camera's clock offset (scene.json's frames.clock_offset_s) is added to each frame's time,
// decoded or not; pixels, indices and counts pass through.
TEST(FrameSourceTest, AClockShiftedSourceMovesEveryFramesTime) {
  FrameTimes times = Times();
  times.frames.resize(3);
  auto source = ClockShifted(OpenVideoSource(kRecording / "video.mp4", times, 1.0), -600.5);
  Frame frame;
  for (size_t i = 0; i < 3; ++i) {
    ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
    EXPECT_EQ(frame.index, static_cast<int>(i));
    EXPECT_NEAR(frame.utc.SecondsSince(times.frames[i].utc), -600.5, 1e-6);
    EXPECT_FALSE(frame.rgb.empty());
  }
  EXPECT_EQ(source->Next(&frame), FrameStatus::kEnd);
  EXPECT_EQ(source->stats().delivered, 3);
  source->Seek(1);
  ASSERT_EQ(source->Next(&frame), FrameStatus::kFrame);
  EXPECT_EQ(frame.index, 1);
}

TEST(FrameSourceTest, PacedReplayKeepsToTheTimestamps) {
  // Frames 0.1 s apart, replayed at 4× speed: 5 frames take at least 0.1 s.
  FrameTimes times = Times();
  times.frames.resize(5);
  auto source = Paced(OpenVideoSource(kRecording / "video.mp4", times, 1.0), 4.0);
  Frame frame;
  const auto start = std::chrono::steady_clock::now();
  int n = 0;
  while (source->Next(&frame) == FrameStatus::kFrame) ++n;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(n, 5);
  EXPECT_GE(seconds, 0.4 / 4.0);
  EXPECT_NEAR(source->stats().scheduled_s, times.frames[4].utc.SecondsSince(times.frames[0].utc) / 4.0, 1e-6);
  EXPECT_EQ(source->stats().delivered, 5);
}

TEST(FrameSourceTest, PacedReplaySkipsTheGapsOfATimeLapse) {
  // Frames 98, 99 (the end of the first burst) and 100, 101 (the next, 2 h 12 min later): paced
  // at 1×, two frame intervals, not hours.
  FrameTimes times = Times();
  times.frames.resize(102);
  ASSERT_GT(times.frames[100].utc.SecondsSince(times.frames[99].utc), 3600.0);
  auto source = Paced(OpenVideoSource(kRecording / "video.mp4", times, 1.0), 1.0);
  source->Seek(98);
  Frame frame;
  const auto start = std::chrono::steady_clock::now();
  int n = 0;
  while (source->Next(&frame) == FrameStatus::kFrame) ++n;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(n, 4);
  // The schedule: 98 → 99 and 100 → 101, one frame interval each; the hours between them are
  // not waited for. Within each burst still paced: the time spent is at least the schedule.
  const double interval = times.frames[99].utc.SecondsSince(times.frames[98].utc) +
                          times.frames[101].utc.SecondsSince(times.frames[100].utc);
  EXPECT_NEAR(source->stats().scheduled_s, interval, 1e-6);
  EXPECT_GE(seconds, interval);
}

TEST(FrameSourceTest, FramePathFormatsThePattern) {
  EXPECT_EQ(FramePath("/a/%06d.png", 42), fs::path("/a/000042.png"));
  EXPECT_EQ(FramePath("/a/f%d.exr", 7), fs::path("/a/f7.exr"));
}

}  // namespace
}  // namespace daylit::capture
