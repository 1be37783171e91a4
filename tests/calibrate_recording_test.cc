// Issue 19 on the bundled recordings: a scene whose north or clock is off is put right by its own
// footage. In memory (the recording's bake, the scene's sun moved) for the whole set of
// perturbations, and end to end through `daylit calibrate-scene` and `daylit estimate` (a
// perturbed scene.json, its own bake) for the worst one.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/csv.h"
#include "calibrate/shadow_calibration.h"
#include "capture/frame_source.h"
#include "estimation/frame_estimator.h"
#include "scene/raycaster.h"
#include "scene/sun_tracker.h"
#include "tests/cli_run.h"
#include "tests/courtyard_fixture.h"

namespace daylit {
namespace {

namespace fs = std::filesystem;
using cli_testing::Daylit;

struct Perturbation {
  const char* recording;
  double north_deg;
  double clock_s;
};

void PrintTo(const Perturbation& p, std::ostream* os) {
  *os << fmt::format("{} north {:+g} deg clock {:+g} s", p.recording, p.north_deg, p.clock_s);
}

// A recording's name as a test name allows it: "courtyard-a" -> "courtyarda".
std::string TestNameOf(std::string recording) {
  recording.erase(std::remove(recording.begin(), recording.end(), '-'), recording.end());
  return recording;
}

std::string Name(const ::testing::TestParamInfo<Perturbation>& info) {
  const auto signed_name = [](double v, const char* unit) {
    return fmt::format("{}{}{}", v < 0.0 ? "minus" : "plus", static_cast<int>(std::abs(v)), unit);
  };
  return fmt::format("{}_north_{}_clock_{}", TestNameOf(info.param.recording), signed_name(info.param.north_deg, "deg"),
                     signed_name(info.param.clock_s, "s"));
}

const testing::BundledCourtyard& Bundled(const std::string& name) {
  return name == "courtyard-a" ? testing::Courtyard() : testing::CourtyardC();
}

// The scene as a user with a wrong north and a clock `clock_s` off would have written it.
scene::Scene Perturbed(const scene::Scene& truth, double north_deg, double clock_s) {
  scene::Scene wrong = truth;
  wrong.north_azimuth_deg += north_deg;
  wrong.frames.clock_offset_s = clock_s;
  for (capture::FrameTime& f : wrong.frame_times->frames) f.utc = ShiftedUtc(f.utc, clock_s);
  return wrong;
}

class CalibrateRecordingTest : public ::testing::TestWithParam<Perturbation> {};

// Issue 19's bars: north within 0.3°, the clock within 60 s, every perturbation of ±1°, ±3°, ±2 min
// and ±10 min and both together; the unperturbed scenes stay where they are within those bounds.
TEST_P(CalibrateRecordingTest, NorthWithinAThirdOfADegreeAndTheClockWithinAMinute) {
  const Perturbation& p = GetParam();
  const testing::BundledCourtyard& c = Bundled(p.recording);
  const scene::Scene wrong = Perturbed(c.scene, p.north_deg, p.clock_s);
  const scene::RayCaster caster(c.scene.model);
  const calibrate::ShadowObservations observed = calibrate::ObserveShadows(wrong, c.bake, caster);
  const calibrate::FitResult fit = calibrate::Calibrate(wrong, c.bake, caster, observed);
  ASSERT_TRUE(fit.north_fitted && fit.clock_fitted) << fit.note;  // both recordings span hours
  EXPECT_FALSE(fit.at_range_edge);
  EXPECT_NEAR(fit.north_offset_deg, -p.north_deg, 0.3);
  EXPECT_NEAR(fit.clock_offset_s, -p.clock_s, 60.0);
  // What the fit claims is honest: within 3σ (σ no smaller than the search's last step).
  EXPECT_LE(std::abs(fit.north_offset_deg + p.north_deg), 3.0 * std::max(fit.north_sigma_deg, 0.05));
  EXPECT_LE(std::abs(fit.clock_offset_s + p.clock_s), 3.0 * std::max(fit.clock_sigma_s, 10.0));
  EXPECT_LE(fit.disagree_after, 0.02);  // of the shadow-edge pixels, on the wrong side after the fit
  const std::string key = fmt::format("{}/calibrate/{}", p.recording, Name({p, 0}));
  testing::RecordFigure(key + "/north_error_deg", fit.north_offset_deg + p.north_deg);
  testing::RecordFigure(key + "/clock_error_s", fit.clock_offset_s + p.clock_s);
}

INSTANTIATE_TEST_SUITE_P(
    Perturbations, CalibrateRecordingTest,
    // Each kind once: unperturbed, north alone, clock alone, both (all twenty combinations passed
    // when measured, docs/calibrate.md); four here for CI's time, and the end-to-end run below
    // has both on courtyard-c.
    ::testing::Values(Perturbation{"courtyard-a", 0.0, 0.0}, Perturbation{"courtyard-a", -1.0, -120.0},
                      Perturbation{"courtyard-c", 3.0, 0.0}, Perturbation{"courtyard-c", 0.0, -600.0}),
    Name);

// A folder whose scene.json is the recording's with north and clock moved, its other files linked.
fs::path PerturbedFolder(const std::string& recording, double north_deg, double clock_s) {
  const fs::path source = fs::path(DAYLIT_SOURCE_DIR) / "recordings" / recording;
  const fs::path dir = fs::temp_directory_path() / fmt::format("daylit_calibrate_{}_{}", recording, ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const fs::directory_entry& e : fs::directory_iterator(source)) {
    if (e.path().filename() != "scene.json") fs::create_symlink(e.path(), dir / e.path().filename());
  }
  nlohmann::json scene = nlohmann::json::parse(ReadTextFile(source / "scene.json"));
  scene["north_azimuth_deg"] = scene.value("north_azimuth_deg", 0.0) + north_deg;
  scene["frames"]["clock_offset_s"] = clock_s;
  WriteFileAtomically(dir / "scene.json", scene.dump(2));
  return dir;
}

nlohmann::json Figures(const fs::path& file) { return nlohmann::json::parse(ReadTextFile(file)); }

// End to end, as a user: a scene.json 3° and 10 minutes off (its bake made with that north), put
// right in place by calibrate-scene (the old one kept as .bak); then the estimates on the corrected
// scene, per burst, against those on the true scene: within issue 19's 1 point. (Held to 2 until
// the estimate stopped jumping under a sun moved by the few hundredths of a degree the shadows
// leave of the clock: docs/estimation.md, items 5 and 6.)
void EndToEnd(const std::string& recording, double north_deg, double clock_s) {
  const fs::path dir = PerturbedFolder(recording, north_deg, clock_s);
  const std::string original = ReadTextFile(dir / "scene.json");
  const fs::path cache = dir.string() + "-cache";
  const auto run = Daylit(fmt::format("calibrate-scene {} --cache {} --out {} --figures {}", dir.string(), cache.string(),
                                      (dir / "scene.json").string(), (dir / "fit.json").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(ReadTextFile(dir / "scene.json.bak"), original);
  const nlohmann::json fit = Figures(dir / "fit.json");
  EXPECT_NEAR(fit["north_offset_deg"].get<double>(), -north_deg, 0.3) << run.out;
  EXPECT_NEAR(fit["clock_offset_s"].get<double>(), -clock_s, 60.0) << run.out;
  const nlohmann::json corrected = nlohmann::json::parse(ReadTextFile(dir / "scene.json"));
  EXPECT_EQ(corrected["model"], nlohmann::json::parse(original)["model"]);  // paths still resolve there

  const auto fixed = Daylit(fmt::format("estimate {} --cache {} --out {} --figures {}", dir.string(), cache.string(),
                                        (dir / "fixed.csv").string(), (dir / "fixed.json").string()));
  ASSERT_EQ(fixed.exit_code, 0) << fixed.err;
  EXPECT_EQ(fixed.err.find("run daylit calibrate-scene"), std::string::npos) << fixed.err;
  const auto truth = Daylit(fmt::format("estimate {} --cache {} --out {} --figures {}",
                                        (fs::path(DAYLIT_SOURCE_DIR) / "recordings" / recording).string(),
                                        (fs::path(DAYLIT_BINARY_DIR) / "test-cache" / recording).string(),
                                        (dir / "truth.csv").string(), (dir / "truth.json").string()));
  ASSERT_EQ(truth.exit_code, 0) << truth.err;
  const nlohmann::json a = Figures(dir / "fixed.json"), b = Figures(dir / "truth.json");
  const int bursts = static_cast<int>(b["lighting/bursts"].get<double>());
  for (int burst = 0; burst < bursts; ++burst) {
    for (const char* part : {"sun_error", "sky_error"}) {
      for (const char* channel : {"r", "g", "b"}) {
        const std::string key = fmt::format("lighting/burst/{}/{}/{}", burst, part, channel);
        EXPECT_NEAR(a[key].get<double>(), b[key].get<double>(), 0.01) << recording << " " << key;
        testing::RecordFigure(fmt::format("{}/calibrate/end_to_end/{}", recording, key), a[key].get<double>() - b[key].get<double>());
      }
    }
  }
  fs::remove_all(dir), fs::remove_all(cache);
}

// courtyard-a's run (3°, −10 min) passed too when measured (docs/calibrate.md); one recording
// here for CI's time.
TEST(CalibrateEndToEndTest, CourtyardCThreeDegreesAndTenMinutesOffIsPutRight) { EndToEnd("courtyard-c", -3.0, 600.0); }

// The camera turned by 0.5° (about an oblique axis; its bake made at that pose): with pose
// refinement, the corrected world_to_camera within 0.1° of the true one, north and clock still
// within their bars.
void PoseEndToEnd(const std::string& recording, const glm::dvec3& axis) {
  const fs::path dir = PerturbedFolder(recording, 0.0, 0.0);
  nlohmann::json scene = nlohmann::json::parse(ReadTextFile(dir / "scene.json"));
  const scene::Scene& truth = Bundled(recording).scene;
  const scene::RigidPose turned = calibrate::RotatedPose(truth.cam_from_world, 0.5 * glm::normalize(axis));
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) scene["camera"]["world_to_camera"]["rotation"][r][c] = turned.rotation[c][r];
  }
  scene["camera"]["world_to_camera"]["translation"] = {turned.translation.x, turned.translation.y, turned.translation.z};
  WriteFileAtomically(dir / "scene.json", scene.dump(2));
  const fs::path cache = dir.string() + "-cache";
  const auto run = Daylit(fmt::format("calibrate-scene {} --cache {} --out {} --what north,clock,pose --figures {}", dir.string(),
                                      cache.string(), (dir / "scene.json").string(), (dir / "fit.json").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const scene::Scene fixed = scene::LoadScene(dir / "scene.json");
  const glm::dmat3 residual = fixed.cam_from_world.rotation * glm::transpose(truth.cam_from_world.rotation);
  const double angle_deg =
      glm::degrees(std::acos(std::clamp((residual[0][0] + residual[1][1] + residual[2][2] - 1.0) / 2.0, -1.0, 1.0)));
  EXPECT_LE(angle_deg, 0.1) << run.out;
  EXPECT_NEAR(fixed.north_azimuth_deg, truth.north_azimuth_deg, 0.3) << run.out;
  EXPECT_NEAR(fixed.frames.clock_offset_s, 0.0, 60.0) << run.out;
  EXPECT_LE(glm::distance(fixed.Camera().CenterInWorld(), truth.Camera().CenterInWorld()), 1e-6);  // turned about its centre
  const nlohmann::json fit = Figures(dir / "fit.json");
  testing::RecordFigure(fmt::format("{}/calibrate/pose_error_deg", recording), angle_deg);
  fs::remove_all(dir), fs::remove_all(cache);
}

// courtyard-a's (0.5° about (1, 2, 2)) came back within 0.035° when measured; one recording here.
TEST(CalibrateEndToEndTest, CourtyardCCameraTurnedHalfADegreeIsTurnedBack) { PoseEndToEnd("courtyard-c", {-2.0, 1.0, -1.0}); }

// North 30° off lies beyond the default ±10° search: said, exit 2, the scene untouched.
TEST(CalibrateEndToEndTest, ANorthBeyondTheSearchRangeIsSaidAndTheSceneLeftAlone) {
  const fs::path dir = PerturbedFolder("courtyard-a", 30.0, 0.0);
  const std::string original = ReadTextFile(dir / "scene.json");
  const fs::path cache = dir.string() + "-cache";
  const auto run = Daylit(fmt::format("calibrate-scene {} --cache {} --out {}", dir.string(), cache.string(),
                                      (dir / "scene.json").string()));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("the scene is left as it was"), std::string::npos) << run.err;
  EXPECT_EQ(ReadTextFile(dir / "scene.json"), original);
  EXPECT_FALSE(fs::exists(dir / "scene.json.bak"));
  fs::remove_all(dir), fs::remove_all(cache);
}

// Issue 38's bad input: a model that does not match the footage. Each bundled recording's own
// model, pose and north explain its shadows far better than a sun turned 20-40° away would
// (measured 0.55 on courtyard-e, whose sketch lacks the tree, bench and cornices, 0.96-0.98 on the
// others), so the quick check passes them.
TEST(ShadowCheckTest, EachBundledModelMatchesItsFootage) {
  for (const testing::BundledCourtyard* c :
       {&testing::Courtyard(), &testing::CourtyardB(), &testing::CourtyardC(), &testing::CourtyardE()}) {
    const scene::RayCaster caster(c->scene.model);
    const std::optional<calibrate::ShadowCheck> check =
        calibrate::CheckShadows(c->scene, c->bake, caster, calibrate::ObserveShadows(c->scene, c->bake, caster));
    ASSERT_TRUE(check.has_value()) << c->scene.name;
    EXPECT_TRUE(check->ModelMatchesFootage()) << c->scene.name << ": sun skill " << check->SunSkill();
    EXPECT_GE(check->SunSkill(), 0.5) << c->scene.name;
    testing::RecordFigure(fmt::format("{}/shadow_check/sun_skill", c->scene.name), check->SunSkill());
  }
}

// The same footage with the camera's pose another camera's (turned 10° about the vertical through
// its centre, baked at that pose as a user's wrong scene.json would be): `daylit info` and `daylit
// estimate` say the model does not match, exit 0, and the estimate's confidence is what it is worth.
TEST(ShadowCheckTest, AnotherCamerasPoseIsSaidByInfoAndEstimate) {
  const fs::path dir = PerturbedFolder("courtyard-c", 0.0, 0.0);
  nlohmann::json scene = nlohmann::json::parse(ReadTextFile(dir / "scene.json"));
  const scene::Scene& truth = testing::CourtyardC().scene;
  // World-to-camera R·Rz(10°): the camera turned about the world's vertical through its centre.
  const glm::dmat3 turn = glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(10.0), glm::dvec3(0.0, 0.0, 1.0)));
  const glm::dmat3 rotation = truth.cam_from_world.rotation * turn;
  const glm::dvec3 translation = -(rotation * truth.Camera().CenterInWorld());
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) scene["camera"]["world_to_camera"]["rotation"][r][c] = rotation[c][r];
  }
  scene["camera"]["world_to_camera"]["translation"] = {translation.x, translation.y, translation.z};
  WriteFileAtomically(dir / "scene.json", scene.dump(2));
  const fs::path cache = dir.string() + "-cache";
  ASSERT_EQ(Daylit(fmt::format("bake {} --cache {}", dir.string(), cache.string())).exit_code, 0);
  const auto info = Daylit(fmt::format("info {} --cache {}", dir.string(), cache.string()));
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("do not match the model's"), std::string::npos) << info.out;
  const auto run = Daylit(fmt::format("estimate {} --cache {} --out {} --figures {}", dir.string(), cache.string(),
                                      (dir / "e.csv").string(), (dir / "e.json").string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("may not be this footage's"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("run daylit calibrate-scene"), std::string::npos) << run.err;  // not a north to correct
  const nlohmann::json figures = Figures(dir / "e.json");
  EXPECT_EQ(figures["shadow_check/model_matches_footage"].get<double>(), 0.0);
  EXPECT_LE(figures["shadow_check/sun_skill"].get<double>(), calibrate::kShadowCheckMinSunSkill);
  testing::RecordFigure("courtyard-c/shadow_check/turned_10_deg/sun_skill", figures["shadow_check/sun_skill"].get<double>());
  // No confident estimate from it: the median confidence a fifth or less of what the true pose's
  // frames get (their bursts' medians 0.52-0.81, docs/results.md).
  const CsvTable rows = ReadCsvFile(dir / "e.csv");
  const size_t confidence = static_cast<size_t>(rows.RequireColumn("confidence"));
  std::vector<double> values;
  for (const auto& row : rows.rows) values.push_back(std::stod(row[confidence]));
  ASSERT_FALSE(values.empty());
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  EXPECT_LE(values[values.size() / 2], 0.1);
  testing::RecordFigure("courtyard-c/shadow_check/turned_10_deg/median_confidence", values[values.size() / 2]);
  fs::remove_all(dir), fs::remove_all(cache);
}

// A live camera's stream is one burst however long it runs; ObserveOptions::max_burst_s cuts it
// into stretches, each with its own sun, and a stretch that shows the sun is counted as soon as the
// next one starts (live --calibrate stops there). courtyard-a's first burst (10 s at 10 fps) cut
// every 3 s: four stretches, frames 0-29, 30-59, 60-89 and 90-99, the first counted at frame 30.
TEST(ShadowObserverTest, ALongBurstIsCutIntoStretchesEachWithItsOwnSun) {
  const testing::BundledCourtyard& c = testing::Courtyard();
  const scene::RayCaster caster(c.scene.model);
  calibrate::ObserveOptions options;
  options.max_burst_s = 3.0;
  calibrate::ShadowObserver observer(c.scene, c.bake, options);
  std::unique_ptr<capture::FrameSource> source = scene::OpenFrameSource(c.scene);
  scene::SunTracker tracker(c.scene);
  estimation::FrameEstimator estimator(c.scene, c.bake, caster, {});
  int first_counted = -1;
  for (int i = 0; i < 100; ++i) {
    capture::Frame frame;
    ASSERT_EQ(source->Next(&frame), capture::FrameStatus::kFrame) << i;
    observer.Add(frame, estimator.Estimate(frame, tracker.Update(frame.utc)).row);
    if (first_counted < 0 && observer.sunlit_bursts() > 0) first_counted = frame.index;
  }
  EXPECT_EQ(first_counted, 30);
  const calibrate::ShadowObservations observed = observer.Finish();
  EXPECT_EQ(observed.bursts_seen, 4);
  ASSERT_EQ(observed.bursts.size(), 4u);
  const int firsts[] = {0, 30, 60, 90}, lasts[] = {29, 59, 89, 99};
  for (size_t k = 0; k < observed.bursts.size(); ++k) {
    const calibrate::BurstShadows& b = observed.bursts[k];
    EXPECT_EQ(b.first_frame, firsts[k]) << k;
    EXPECT_EQ(b.last_frame, lasts[k]) << k;
    // Its time is its own frames' (a clear frame's within it), not the burst's.
    const double t = b.time.SecondsSince(c.scene.frame_times->frames[0].utc);
    EXPECT_GE(t, 0.1 * firsts[k] - 1e-6) << k;
    EXPECT_LE(t, 0.1 * lasts[k] + 1e-6) << k;
  }
}

// daylit live --calibrate against a camera: the userspace V4L2 test device (tests/fakecam) serves a
// recording's first burst, and libfaketime (Debian's faketime) sets the process's UTC clock to that
// burst's time, the monotonic clock left alone, so the device's kernel timestamps become the
// recording's times as a webcam's would. North is 1° off. What live applies is within issue 19's
// 0.3° of the truth, or north is left as it was and the log says how little the camera's stretch
// constrains it. One burst constrains north as far as its shadow edges do (docs/calibrate.md):
// courtyard-c's first (sun 15° up, 25 000 edge pixels) to ±0.12°, so there live must correct it;
// courtyard-a's first (sun 17° up, 1 400 edge pixels) only to ±0.34°, so there it may keep it.
struct LiveCase {
  const char* recording;
  const char* fake_time;  // the burst's UTC, a few seconds in
  bool must_apply;
};

void PrintTo(const LiveCase& c, std::ostream* os) { *os << fmt::format("{} at {}", c.recording, c.fake_time); }

class CalibrateLiveTest : public ::testing::TestWithParam<LiveCase> {};

TEST_P(CalibrateLiveTest, WhatLiveAppliesIsWithinTheBarOrNorthIsKeptAndSaid) {
  const LiveCase& c = GetParam();
  const fs::path recording = fs::path(DAYLIT_SOURCE_DIR) / "recordings" / c.recording;
  const fs::path dir = fs::temp_directory_path() / fmt::format("daylit_live_calibrate_{}_{}", c.recording, ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir / "out");
  nlohmann::json scene = nlohmann::json::parse(ReadTextFile(recording / "scene.json"));
  const double truth = scene["north_azimuth_deg"].get<double>();
  scene["north_azimuth_deg"] = truth + 1.0;
  scene["frames"] = {{"device", "/dev/video-daylit-test"}, {"fps", 30}};
  scene.erase("groundtruth");
  for (const char* file : {"model.obj", "envmap.exr"}) fs::copy_file(recording / file, dir / file);
  WriteFileAtomically(dir / "scene.json", scene.dump(1));
  const std::string environment = fmt::format(
      "LD_PRELOAD=" DAYLIT_FAKECAM_LIBRARY ":" DAYLIT_FAKETIME_LIBRARY " FAKETIME='@{}' "
      "FAKETIME_DONT_FAKE_MONOTONIC=1 DAYLIT_FAKECAM_DEVICE=/dev/video-daylit-test DAYLIT_FAKECAM_VIDEO={} "
      "DAYLIT_FAKECAM_FRAMES=90 ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 ",
      c.fake_time, (recording / "video.mp4").string());
  const auto run = Daylit(fmt::format("live --scene {} --cache {} --calibrate 10 --frames 3 --out {}", (dir / "scene.json").string(),
                                      (dir / "cache").string(), (dir / "out" / "live.mp4").string()),
                          environment);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The frames' times are the burst's (the sun of the recording, not of the wall clock).
  const CsvTable estimates = ReadCsvFile(dir / "out" / "estimates.csv");
  ASSERT_FALSE(estimates.rows.empty());
  const std::string first_time = estimates.rows[0][static_cast<size_t>(estimates.RequireColumn("time_utc"))];
  const std::string fake_time = c.fake_time;  // "YYYY-MM-DD hh:mm:ss": the frames' times start "YYYY-MM-DDThh:m"
  const std::string burst_start = fake_time.substr(0, 10) + "T" + fake_time.substr(11, 4);
  EXPECT_EQ(first_time.rfind(burst_start, 0), 0u) << first_time;
  const size_t applied = run.err.find("--calibrate: north ");
  const size_t kept = run.err.find("constrain north only to ±");
  ASSERT_TRUE((applied == std::string::npos) != (kept == std::string::npos)) << run.err;
  const std::string figure = fmt::format("{}/calibrate/live/north_error_deg", c.recording);
  if (applied != std::string::npos) {
    double before = 0.0, after = 0.0;
    ASSERT_EQ(std::sscanf(run.err.c_str() + applied, "--calibrate: north %lf -> %lf", &before, &after), 2) << run.err;
    EXPECT_NEAR(after, truth, 0.3) << run.err;
    testing::RecordFigure(figure, after - truth);
  } else {
    EXPECT_FALSE(c.must_apply) << run.err;
    EXPECT_NE(run.err.find(fmt::format("north left at {:.3f} deg", truth + 1.0)), std::string::npos) << run.err;
    testing::RecordFigure(figure, 1.0);
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(FirstBurst, CalibrateLiveTest,
                         ::testing::Values(LiveCase{"courtyard-c", "2026-06-21 13:20:03", true},
                                           LiveCase{"courtyard-a", "2026-06-21 05:00:03", false}),
                         [](const ::testing::TestParamInfo<LiveCase>& param) { return TestNameOf(param.param.recording); });

}  // namespace
}  // namespace daylit
