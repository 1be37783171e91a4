// The V4L2 source's decisions, which need no kernel, and its behaviour without a camera (there is
// none on the test machines; docs/capture.md says what was verified how).
#include "capture/v4l2_source.h"

#include <gtest/gtest.h>
#include <linux/videodev2.h>
#include <sys/time.h>

#include <ctime>

#include "base/error.h"

namespace daylit::capture {
namespace {

const std::vector<V4l2Format> kWebcam = {
    {V4L2_PIX_FMT_YUYV, 640, 480, 30},   {V4L2_PIX_FMT_YUYV, 1280, 720, 10},  {V4L2_PIX_FMT_MJPEG, 640, 480, 30},
    {V4L2_PIX_FMT_MJPEG, 1280, 720, 30}, {V4L2_PIX_FMT_MJPEG, 1280, 720, 60}, {V4L2_PIX_FMT_MJPEG, 1920, 1080, 30},
    {V4L2_PIX_FMT_H264, 1280, 720, 30}};

V4l2Format Choose(int w, int h, double fps) { return ChooseFormat(kWebcam, w, h, fps).value(); }

TEST(V4l2SourceTest, FormatChoiceWantsTheSizeTheRateAndThenUncompressedPixels) {
  // YUYV at 640×480 reaches 30 fps: uncompressed wins.
  EXPECT_EQ(Choose(640, 480, 30).fourcc, static_cast<uint32_t>(V4L2_PIX_FMT_YUYV));
  // At 1280×720 YUYV only does 10 fps: MJPEG, at the slowest rate that reaches 30.
  const V4l2Format hd = Choose(1280, 720, 30);
  EXPECT_EQ(hd.fourcc, static_cast<uint32_t>(V4L2_PIX_FMT_MJPEG));
  EXPECT_EQ(hd.fps, 30.0);
  // 10 fps asked: YUYV does it.
  EXPECT_EQ(Choose(1280, 720, 10).fourcc, static_cast<uint32_t>(V4L2_PIX_FMT_YUYV));
  // A size not offered: the smallest that covers it; one larger than all: the largest.
  EXPECT_EQ(Choose(1000, 600, 30).width, 1280);
  EXPECT_EQ(Choose(4000, 3000, 30).width, 1920);
  // A rate no format reaches: the fastest at that size.
  EXPECT_EQ(Choose(1280, 720, 120).fps, 60.0);
  // Only formats daylit cannot decode: nothing.
  EXPECT_FALSE(ChooseFormat({{V4L2_PIX_FMT_H264, 1280, 720, 30}}, 1280, 720, 30).has_value());
  EXPECT_EQ(FourccName(V4L2_PIX_FMT_MJPEG), "MJPG");
}

std::map<uint32_t, ControlInfo> UvcControls() {
  return {{V4L2_CID_EXPOSURE_AUTO, {0, 3, 1, 3, 3}},
          {V4L2_CID_EXPOSURE_ABSOLUTE, {3, 2047, 1, 250, 312}},  // auto had converged to 312
          {V4L2_CID_AUTOGAIN, {0, 1, 1, 1, 1}},
          {V4L2_CID_GAIN, {0, 255, 1, 0, 64}},
          {V4L2_CID_AUTO_WHITE_BALANCE, {0, 1, 1, 1, 1}},
          {V4L2_CID_WHITE_BALANCE_TEMPERATURE, {2000, 6500, 10, 4000, 5230}}};
}

TEST(V4l2SourceTest, ControlPlanLocksExposureGainAndWhiteBalanceAtWhatAutoReached) {
  std::vector<std::string> notes;
  const std::vector<ControlWrite> plan = PlanControls(UvcControls(), {}, &notes);
  ASSERT_EQ(plan.size(), 6u);
  // Each automatic switch goes off before its value is written.
  EXPECT_EQ(plan[0].id, static_cast<uint32_t>(V4L2_CID_EXPOSURE_AUTO));
  EXPECT_EQ(plan[0].value, V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(plan[1].id, static_cast<uint32_t>(V4L2_CID_EXPOSURE_ABSOLUTE));
  EXPECT_EQ(plan[1].value, 312);
  EXPECT_NE(plan[1].what.find("held from auto"), std::string::npos);
  EXPECT_EQ(plan[2].value, 0);
  EXPECT_EQ(plan[3].value, 64);
  EXPECT_EQ(plan[4].value, 0);
  EXPECT_EQ(plan[5].value, 5230);
  EXPECT_TRUE(notes.empty());
}

TEST(V4l2SourceTest, ControlPlanClampsAskedValuesAndWarnsWhenExposureCannotBeLocked) {
  std::vector<std::string> notes;
  CameraSettings asked;
  asked.exposure_100us = 5000;  // beyond 2047
  asked.white_balance_k = 5555;  // snapped to the 10 K step
  std::vector<ControlWrite> plan = PlanControls(UvcControls(), asked, &notes);
  EXPECT_EQ(plan[1].value, 2047);
  EXPECT_EQ(plan[5].value, 5550);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("exposure 5000 is outside [3, 2047] step 1; using 2047"), std::string::npos) << notes[0];

  std::map<uint32_t, ControlInfo> bare = UvcControls();
  bare.erase(V4L2_CID_EXPOSURE_AUTO);
  bare.erase(V4L2_CID_GAIN);
  notes.clear();
  plan = PlanControls(bare, {}, &notes);
  EXPECT_EQ(plan.size(), 4u);  // exposure value, auto gain off, white balance off and value
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0].rfind("warning: the camera has no auto exposure control", 0), 0u) << notes[0];
  EXPECT_NE(notes[1].find("no gain control"), std::string::npos);
}

TEST(V4l2SourceTest, KernelTimestampsBecomeUtc) {
  // A buffer stamped 0.75 s before the moment both clocks were read.
  timeval stamp{};
  stamp.tv_sec = 1000, stamp.tv_usec = 250000;
  timespec monotonic{};
  monotonic.tv_sec = 1001, monotonic.tv_nsec = 0;
  const UtcTime now = ParseUtcTime("2026-06-21T05:00:00Z", "test");
  EXPECT_EQ(FormatUtcTime(KernelTimestampToUtc(stamp, monotonic, now), 6), "2026-06-21T04:59:59.250000Z");
}

TEST(V4l2SourceTest, WithoutACameraTheErrorSaysSo) {
  try {
    OpenV4l2Source("/dev/video-daylit-absent", {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/video-daylit-absent: cannot open (No such file or directory); is the camera plugged in?"),
              std::string::npos)
        << e.what();
  }
  try {
    OpenV4l2Source("/dev/null", {});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/null: not a V4L2 device"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace daylit::capture
