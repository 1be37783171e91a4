// The live camera path end to end: the real `daylit` binary against a userspace V4L2 device
// (tests/fakecam/fakecam.cc, preloaded) that serves courtyard-a's frames. What the device did
// (frames handed out, control writes) it logs to a CSV; the tests hold daylit's outputs to it.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/utc_time.h"
#include "tests/cli_run.h"

namespace daylit {
namespace {

namespace fs = std::filesystem;
using cli_testing::CliRun;
using cli_testing::Daylit;

const std::string kRecording = DAYLIT_SOURCE_DIR "/recordings/courtyard-a";
const std::string kDevice = "/dev/video-daylit-test";

// A test's own folder and the device's environment: the preload, the path it answers for, the
// video it serves, its log. ASan (the sanitizer pass) must come first among the preloads; the
// device library is not instrumented, so the order check is off.
struct FakeCamera {
  fs::path dir;
  std::string environment;
  explicit FakeCamera(const std::string& name, const std::string& extra = "") {
    dir = fs::temp_directory_path() / ("daylit_fakecam_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    environment = "LD_PRELOAD=" DAYLIT_FAKECAM_LIBRARY " DAYLIT_FAKECAM_DEVICE=" + kDevice +
                  " DAYLIT_FAKECAM_VIDEO=" + kRecording + "/video.mp4 DAYLIT_FAKECAM_LOG=" + (dir / "device.csv").string() +
                  " ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 " + extra + " ";
  }
  ~FakeCamera() { fs::remove_all(dir); }
  // The device's log rows of one kind ("frame" or "control"), fields after the kind.
  std::vector<std::vector<std::string>> Log(const std::string& kind) const {
    std::vector<std::vector<std::string>> rows;
    std::istringstream in(ReadTextFile(dir / "device.csv"));
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> fields;
      std::istringstream split(line);
      for (std::string f; std::getline(split, f, ',');) fields.push_back(f);
      if (!fields.empty() && fields[0] == kind) rows.emplace_back(fields.begin() + 1, fields.end());
    }
    return rows;
  }
};

double MeanAbsoluteDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d;
  cv::absdiff(a, b, d);
  const cv::Scalar m = cv::mean(d);
  return (m[0] + m[1] + m[2]) / 3.0;
}

// daylit record from the device: a recording folder whose frames are the ones the device handed
// out, in order, at the UTC times of their capture; daylit info reads it back as a recording.
TEST(LiveDeviceTest, RecordWritesTheServedFramesAtTheirCaptureTimes) {
  FakeCamera camera("record");
  const fs::path out = camera.dir / "rec";
  const CliRun run = Daylit("record --device " + kDevice + " --scene " + kRecording + " --out " + out.string() +
                                " --frames 12 --images --exposure-100us 300 --gain 40 --white-balance-k 5000",
                            camera.environment + "DAYLIT_FAKECAM_FRAMES=6 ");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("12 frames written"), std::string::npos) << run.out;
  const CsvTable frames = ReadCsvFile(out / "frames.csv");
  const auto served = camera.Log("frame");
  ASSERT_EQ(frames.rows.size(), 12u);
  ASSERT_GE(served.size(), 12u);
  // Frames the device lost while no buffer was queued (a busy machine) show as gaps in the
  // sequence numbers of those it handed out; record counts exactly those.
  int gaps = 0;
  for (size_t i = 1; i < 12; ++i) gaps += std::stoi(served[i][0]) - std::stoi(served[i - 1][0]) - 1;
  EXPECT_NE(run.out.find(fmt::format("0 could not be decoded, {} dropped by the driver", gaps)), std::string::npos) << run.out;
  const size_t c_time = static_cast<size_t>(frames.RequireColumn("time_utc"));
  // The device's first six frames of the video, as it decoded them.
  cv::VideoCapture video(kRecording + "/video.mp4");
  std::vector<cv::Mat> source(6);
  for (cv::Mat& m : source) ASSERT_TRUE(video.read(m));
  double worst_match = 0.0, nearest_other = 1e9;
  for (size_t i = 0; i < 12; ++i) {
    // Frame i is the i-th the device handed out: its capture instant in UTC within 1 ms.
    const double utc = UnixSeconds(ParseUtcTime(frames.rows[i][c_time], "frames.csv"));
    EXPECT_NEAR(utc, std::stod(served[i][3]), 1e-3) << "frame " << i;
    const cv::Mat image = cv::imread((out / "frames" / fmt::format("{:06d}.png", i)).string());
    ASSERT_FALSE(image.empty()) << i;
    const size_t from = std::stoul(served[i][1]);
    worst_match = std::max(worst_match, MeanAbsoluteDifference(image, source[from]));
    for (size_t k = 0; k < source.size(); ++k) {
      if (k != from) nearest_other = std::min(nearest_other, MeanAbsoluteDifference(image, source[k]));
    }
  }
  // YUYV (chroma shared by pixel pairs, studio range) costs about a code; a wrong frame, more.
  EXPECT_LT(worst_match, 2.5);
  EXPECT_GT(nearest_other, worst_match);
  const CliRun info = Daylit("info " + out.string());
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("12 frames"), std::string::npos) << info.out;
}

// Exposure, gain and white balance: the automatics off before each manual value (uvcvideo refuses
// a manual value while its automatic is on), values clamped and snapped to the control's range
// and step before they are written, each read back; a control that keeps its old value is a
// warning.
TEST(LiveDeviceTest, ControlsAreLockedClampedAndReadBack) {
  FakeCamera camera("controls", "DAYLIT_FAKECAM_STUCK=gain");
  const CliRun run = Daylit("record --device " + kDevice + " --scene " + kRecording + " --out " + (camera.dir / "rec").string() +
                                " --frames 2 --exposure-100us 5000 --gain 40 --white-balance-k 5003",
                            camera.environment + "DAYLIT_FAKECAM_FRAMES=2 ");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("exposure 5000 is outside [3, 2047] step 1; using 2047"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("white balance 5003 is outside [2800, 6500] step 10; using 5000"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("exposure 2047 ×100 µs (as asked); reads back 2047"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("gain 40 (as asked) did not take: the camera reports 64"), std::string::npos) << run.err;
  std::vector<std::string> order;
  for (const auto& row : camera.Log("control")) order.push_back(row[0] + "=" + row[2]);
  EXPECT_EQ(order, (std::vector<std::string>{"exposure_auto=1", "exposure=2047", "gain_auto=0", "gain=64",
                                             "white_balance_auto=0", "white_balance=5000"}));
}

// A live run: a frame in seven lost by the driver (gaps in the sequence numbers, counted), the
// camera unplugged for 1.5 s mid-stream (one warning, retries, streaming again with its controls
// reapplied, the estimate held meanwhile), and `live --frames N` ending cleanly.
TEST(LiveDeviceTest, LiveCountsDroppedFramesAndSurvivesAnUnplug) {
  FakeCamera camera("live", "DAYLIT_FAKECAM_DROP=7 DAYLIT_FAKECAM_UNPLUG=20,1.5");
  nlohmann::json scene = nlohmann::json::parse(ReadTextFile(kRecording + "/scene.json"));
  scene["frames"] = {{"device", kDevice}, {"fps", 30}};
  scene.erase("groundtruth");
  for (const char* file : {"model.obj", "envmap.exr"}) fs::copy_file(fs::path(kRecording) / file, camera.dir / file);
  WriteFileAtomically(camera.dir / "scene.json", scene.dump(1));
  const fs::path out = camera.dir / "live";
  fs::create_directories(out);
  const CliRun run = Daylit("live --scene " + (camera.dir / "scene.json").string() + " --cache " + (camera.dir / "cache").string() +
                                " --frames 40 --out " + (out / "live.mp4").string(),
                            camera.environment + "DAYLIT_FAKECAM_FRAMES=10 ");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto count = [&](const std::string& text) {
    size_t n = 0;
    for (size_t at = run.err.find(text); at != std::string::npos; at = run.err.find(text, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("the camera stopped"), 1u) << run.err;
  EXPECT_EQ(count("back; streaming again"), 1u) << run.err;
  EXPECT_EQ(count("auto exposure off (manual); reads back 1"), 2u) << "controls set at the start and again after the unplug\n" << run.err;
  const nlohmann::json figures = nlohmann::json::parse(ReadTextFile(out / "figures.json"));
  EXPECT_EQ(figures.at("frames").get<int>(), 40);
  // Every frame estimated; each composited, or (a newer frame waiting) estimated only.
  EXPECT_EQ(figures.at("composited").get<int>() + figures.at("composites_skipped").get<int>(), 40);
  EXPECT_GE(figures.at("composited").get<int>(), 1);
  // daylit's count is the gaps in the sequence numbers of the frames it took, in the order the
  // device handed them out (a new stream after the unplug starts again at 0). They include
  // every 7th sensor frame (lost on purpose) and any the device lost for want of a queued buffer
  // (a client slower than 30 fps).
  // daylit also took from the driver, and gave back unread, the frames that were waiting while
  // a newer one was there (figures' skipped): the device handed out 40 + skipped frames.
  const auto served = camera.Log("frame");
  const size_t taken = 40 + static_cast<size_t>(figures.at("skipped").get<int>());
  ASSERT_GE(served.size(), taken);
  int gaps = 0, injected = 0;
  for (size_t i = 1; i < taken; ++i) {
    const long previous = std::stol(served[i - 1][0]), sequence = std::stol(served[i][0]);
    if (sequence > previous) gaps += static_cast<int>(sequence - previous - 1);
  }
  for (const auto& lost : camera.Log("lost")) injected += lost[1] == "injected" ? 1 : 0;
  EXPECT_EQ(figures.at("dropped").get<int>(), gaps);
  EXPECT_GE(gaps, 5) << "at least the injected losses among 40 frames";
  EXPECT_GT(injected, 0);
  RecordProperty("fps_end_to_end", std::to_string(figures.at("fps").get<double>()));
  RecordProperty("latency_median_ms", std::to_string(figures.at("latency_median_ms").get<double>()));
  const CsvTable estimates = ReadCsvFile(out / "estimates.csv");
  ASSERT_EQ(estimates.rows.size(), 40u);
  const size_t c_sky = static_cast<size_t>(estimates.RequireColumn("sky_g"));
  for (const auto& row : estimates.rows) EXPECT_GT(ParseFiniteDouble(row[c_sky], "sky_g"), 0.0);
  // The frames' UTC times show the gap the unplug left (1.5 s plus the retry's wait).
  const size_t c_time = static_cast<size_t>(estimates.RequireColumn("time_utc"));
  double largest_gap = 0.0;
  for (size_t i = 1; i < estimates.rows.size(); ++i) {
    largest_gap = std::max(largest_gap, ParseUtcTime(estimates.rows[i][c_time], "t").SecondsSince(ParseUtcTime(estimates.rows[i - 1][c_time], "t")));
  }
  EXPECT_GT(largest_gap, 1.4);
  EXPECT_TRUE(fs::is_regular_file(out / "live.mp4"));
}

}  // namespace
}  // namespace daylit
