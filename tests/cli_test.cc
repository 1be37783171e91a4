// The `daylit` binary as a user runs it: exit codes, one-line errors on stderr, results on stdout.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bake/synthetic_recording.h"
#include "tests/cli_run.h"
#include "capture/response.h"
#include "capture/video_decoder.h"
#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/utc_time.h"
#include "report/plot.h"
#include "sh/exact_irradiance.h"
#include "lightfit/lights.h"
#include "scene/hdr_image.h"
#include "scene/scene.h"
#include "scene/scene_test_util.h"

namespace daylit {
namespace {

namespace fs = std::filesystem;
using cli_testing::CliRun;
using cli_testing::Daylit;

const std::string kRecording = DAYLIT_SOURCE_DIR "/recordings/courtyard-a";
const std::string kProbe = DAYLIT_SOURCE_DIR "/probes/stpeters_latlong_1024x512.hdr";

// Where a plot drew one colour: the columns holding a pixel of exactly `rgb` inside `region`
// (anti-aliased lines keep their colour at their centre), and each column's highest such row;
// `skip` (the legend, top right) is left out. Plot facts are checked on these: a curve drawn
// where its data says, not only a PNG that exists.
struct Trace {
  std::map<int, int> top_row;  // column -> smallest row
  int Left() const { return top_row.empty() ? -1 : top_row.begin()->first; }
  int Right() const { return top_row.empty() ? -1 : top_row.rbegin()->first; }
  // The mean column of the curve's highest pixels.
  double PeakColumn() const {
    int best = 1 << 30;
    for (const auto& [column, row] : top_row) best = std::min(best, row);
    double sum = 0.0;
    int n = 0;
    for (const auto& [column, row] : top_row) {
      if (row == best) sum += column, ++n;
    }
    return n > 0 ? sum / n : -1.0;
  }
  // Runs of adjacent columns: one per vertical line drawn.
  std::vector<double> Runs() const {
    std::vector<double> centres;
    int start = -10, last = -10;
    for (const auto& [column, row] : top_row) {
      if (column > last + 1) {
        if (last >= 0) centres.push_back(0.5 * (start + last));
        start = column;
      }
      last = column;
    }
    if (last >= 0) centres.push_back(0.5 * (start + last));
    return centres;
  }
};

Trace TraceOf(const cv::Mat& image, const cv::Rect& region, std::array<int, 3> rgb, const cv::Rect& skip = {}) {
  Trace t;
  const cv::Vec3b bgr(static_cast<uchar>(rgb[2]), static_cast<uchar>(rgb[1]), static_cast<uchar>(rgb[0]));
  for (int y = region.y; y < region.y + region.height; ++y) {
    for (int x = region.x; x < region.x + region.width; ++x) {
      if (image.at<cv::Vec3b>(y, x) != bgr || skip.contains({x, y})) continue;
      const auto it = t.top_row.find(x);
      if (it == t.top_row.end() || y < it->second) t.top_row[x] = y;
    }
  }
  return t;
}

TEST(CliTest, HelpForEverySubcommand) {
  for (const char* sub : {"", "sunpos ", "info ", "lights ", "record ", "render ", "replay ", "live ", "calibrate-response ", "calibrate-camera "}) {
    const CliRun run = Daylit(std::string(sub) + "--help");
    EXPECT_EQ(run.exit_code, 0) << sub;
    EXPECT_NE(run.out.find("Usage"), std::string::npos) << sub << run.out;
  }
  const CliRun none = Daylit("");
  EXPECT_EQ(none.exit_code, 2);
}

TEST(CliTest, InfoSummarisesTheBundledRecording) {
  const CliRun run = Daylit("info " + kRecording);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("600 frames"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("6 bursts"), std::string::npos);
  EXPECT_NE(run.out.find("span 11 h 00 min 09.9 s"), std::string::npos);
  EXPECT_NE(run.out.find("OpenEXR 1024x512"), std::string::npos);
  EXPECT_NE(run.out.find("missing      nothing"), std::string::npos);
  EXPECT_EQ(run.err, "");  // nothing to warn about
}

TEST(CliTest, SunposSingleAndSceneVector) {
  const CliRun run = Daylit("sunpos --time 2003-10-17T12:30:30-07:00 --lat 39.742476 --lon -105.1786 "
                         "--elev 1830.14 --pressure 820 --temp 11 --delta-t 67");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("zenith_deg           50.1279"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("azimuth_deg          194.340"), std::string::npos) << run.out;
  const CliRun scene = Daylit("sunpos --time 2026-06-21T05:00:05Z --scene " + kRecording);
  ASSERT_EQ(scene.exit_code, 0) << scene.err;
  EXPECT_NE(scene.out.find("sun_in_scene         0.957"), std::string::npos) << scene.out;
}

TEST(CliTest, SunposFramesWritesOneRowPerFrame) {
  const fs::path out = fs::temp_directory_path() / ("daylit_cli_frames_" + std::to_string(::getpid()) + ".csv");
  const fs::path plot = fs::path(out).replace_extension(".png");
  const CliRun run = Daylit("sunpos --scene " + kRecording + " --frames --out " + out.string() + " --plot " + plot.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const CsvTable table = ReadCsvFile(out);
  fs::remove(out);
  EXPECT_EQ(table.rows.size(), 600u);
  EXPECT_EQ(table.header.back(), "sun_z");
  const cv::Mat image = cv::imread(plot.string());
  fs::remove(plot);
  ASSERT_EQ(image.size(), cv::Size(1200, 640));  // two 1200 x 320 panels
  // What the elevation panel shows: a dot per burst (frames 0.1 s apart overlap), the highest
  // one the burst the CSV gives the highest sun, each on the sun's path line.
  std::vector<double> burst_elevation;
  const size_t c_time = static_cast<size_t>(table.RequireColumn("time_utc"));
  const size_t c_elevation = static_cast<size_t>(table.RequireColumn("elevation_deg"));
  for (size_t r = 0; r < table.rows.size(); ++r) {
    const double elevation = ParseFiniteDouble(table.rows[r][c_elevation], "elevation");
    const bool starts = r == 0 || ParseUtcTime(table.rows[r][c_time], "t").SecondsSince(ParseUtcTime(table.rows[r - 1][c_time], "t")) > 2.0;
    if (starts) burst_elevation.push_back(elevation);
    burst_elevation.back() = std::max(burst_elevation.back(), elevation);
  }
  // Inside the top panel's plot area (report/plot.cc: 80 px left, 20 right, 50 top, 48 bottom),
  // off its frame, whose ink is the dots' colour.
  const cv::Rect top_panel(82, 52, 1096, 218), legend(1040, 40, 160, 60);
  const Trace dots = TraceOf(image, top_panel, {40, 40, 40}, legend);
  const Trace path = TraceOf(image, top_panel, report::SeriesColor(1), legend);
  const std::vector<double> clusters = dots.Runs();
  ASSERT_EQ(clusters.size(), burst_elevation.size());
  size_t highest = 0;
  int highest_row = 1 << 30;
  for (size_t b = 0; b < clusters.size(); ++b) {
    const int column = static_cast<int>(std::lround(clusters[b]));
    const int dot_centre = dots.top_row.at(column) + 3;  // radius 3
    if (dot_centre < highest_row) highest_row = dot_centre, highest = b;
    // The path's line just beside the dot (the dot covers it at its centre).
    const int beside = column + (b + 1 < clusters.size() ? 6 : -6);
    ASSERT_TRUE(path.top_row.count(beside)) << "no path line beside burst " << b;
    EXPECT_NEAR(path.top_row.at(beside) + 1, dot_centre, 6) << "burst " << b;
  }
  EXPECT_EQ(highest, static_cast<size_t>(std::max_element(burst_elevation.begin(), burst_elevation.end()) - burst_elevation.begin()));
}

TEST(CliTest, SunposCsvBatchMatchesThePublishedSpaExample) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_csv_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  WriteFileAtomically(dir / "in.csv",
                      "temp_c,utc,lat_deg,lon_deg,elev_m,pressure_hpa,delta_t_s,note\n"
                      "11,2003-10-17T19:30:30Z,39.742476,-105.1786,1830.14,820,67,\"SPA, A.5\"\n");
  const CliRun run = Daylit("sunpos --csv " + (dir / "in.csv").string() + " --out " + (dir / "out.csv").string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const CsvTable table = ReadCsvFile(dir / "out.csv");
  ASSERT_EQ(table.rows.size(), 1u);
  EXPECT_EQ(table.rows[0][static_cast<size_t>(table.RequireColumn("note"))], "SPA, A.5");
  const double apparent = ParseFiniteDouble(table.rows[0][static_cast<size_t>(table.RequireColumn("apparent_zenith_deg"))], "z");
  EXPECT_NEAR(apparent, 50.111622, 1e-3);
  // A bad row: exit 2, one line naming file, line and column, and no output file.
  WriteFileAtomically(dir / "bad.csv", "utc,lat_deg,lon_deg,elev_m\n2026-06-21T10:00:00Z,57,9,0\n2026-06-21T10:00:00Z,123,9,0\n");
  const CliRun bad = Daylit("sunpos --csv " + (dir / "bad.csv").string() + " --out " + (dir / "bad_out.csv").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("bad.csv:3: latitude_deg: 123 is outside [-90, 90]"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad_out.csv"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 3);  // no temporaries
  fs::remove_all(dir);
}

TEST(CliTest, BakePrintsAlbedoUsesItsCacheAndRebakesOnChange) {
  bake::testing::SyntheticRecording rec("cli_bake");
  const std::string scene = rec.Write().string();
  const std::string cache = (rec.dir / "cache").string();
  const CliRun first = Daylit("bake " + scene + " --cache " + cache + " --print-albedo");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const CsvTable table = ParseCsv(first.out, "stdout");
  EXPECT_EQ(table.header, (std::vector<std::string>{"surface", "r", "g", "b", "pixels"}));
  ASSERT_EQ(table.rows.size(), 1u);
  EXPECT_NEAR(ParseFiniteDouble(table.rows[0][1], "r"), 0.4, 0.004);
  EXPECT_NE(first.err.find("baked"), std::string::npos) << first.err;
  EXPECT_EQ(ReadTextFile(fs::path(cache) / "albedo.csv"), first.out);
  // Unchanged: loaded from the cache, and the cache folder is what it prints without flags.
  const CliRun second = Daylit("bake " + scene + " --cache " + cache);
  EXPECT_NE(second.err.find("loaded the cached bake"), std::string::npos) << second.err;
  EXPECT_EQ(second.out, cache + "\n");
  // A damaged cache file is baked again, with a warning, not an error.
  WriteFileAtomically(fs::path(cache) / "camera_gbuffer.exr", "not an EXR");
  const CliRun damaged = Daylit("bake " + scene + " --cache " + cache);
  EXPECT_EQ(damaged.exit_code, 0) << damaged.err;
  EXPECT_NE(damaged.err.find("cannot be read"), std::string::npos) << damaged.err;
  EXPECT_NE(damaged.err.find("baked"), std::string::npos) << damaged.err;
  // A changed env map is a new bake.
  rec.env = [](const glm::dvec3& d) { return d.z > 0.0 ? glm::vec3(2.0f) : glm::vec3(0.6f); };
  rec.Write();
  const CliRun third = Daylit("bake " + scene + " --cache " + cache + " --print-albedo");
  EXPECT_NE(third.err.find("baked"), std::string::npos) << third.err;
  EXPECT_EQ(third.err.find("loaded"), std::string::npos) << third.err;
  EXPECT_NEAR(ParseFiniteDouble(ParseCsv(third.out, "stdout").rows[0][1], "r"), 0.3, 0.003);  // 0.6 / 2
}

TEST(CliTest, EstimateWritesTheStableCsv) {
  // One flat grey frame (code 120) of open ground (albedo 0.4, V = 1) at night: sky only, and
  // the model gives E_sky = π·L/ρ with L the frame's linear value (exposure 1).
  bake::testing::SyntheticRecording rec("cli_estimate");
  const std::string scene = rec.Write().string();
  const fs::path out = rec.dir / "est.csv";
  const fs::path figures = rec.dir / "figures.json";
  const CliRun run = Daylit("estimate " + scene + " --cache " + (rec.dir / "cache").string() + " --out " + out.string() +
                            " --figures " + figures.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::ifstream figures_in(figures);
  const nlohmann::json figures_json = nlohmann::json::parse(figures_in);
  EXPECT_EQ(figures_json.at("frames").get<int>(), 1);
  EXPECT_EQ(figures_json.at("lighting/frames_sky_only").get<int>(), 1);
  EXPECT_EQ(figures_json.at("lighting/frames_held").get<int>(), 0);
  // One frame, which moved the sun: no per-frame timing, said in words, not "nan ms" (issue 43).
  EXPECT_EQ(run.err.find("nan"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("not timed"), std::string::npos) << run.err;
  // The sun is down: the report says which quantity is not observed, where and why.
  EXPECT_NE(run.out.find("burst 0: E_sun not observed in 1 of 1 frames: the sun below the horizon"), std::string::npos)
      << run.out;
  EXPECT_EQ(ReadCsvFile(rec.dir / "est_bursts.csv").rows.size(), 1u);  // the per-burst table, no truth
  // The report beside it: what was printed, after the version and how the run was started.
  const std::string report = ReadTextFile(rec.dir / "est_report.txt");
  EXPECT_NE(report.find("\nrun: " + figures_json.at("run/command").get<std::string>() + "\n"), std::string::npos) << report;
  EXPECT_NE(report.find("burst 0: E_sun not observed in 1 of 1 frames"), std::string::npos) << report;
  const CsvTable table = ReadCsvFile(out);
  EXPECT_EQ(table.header, (std::vector<std::string>{"frame", "time_utc", "sun_elevation_deg", "sun_azimuth_deg", "sun_r",
                                                     "sun_g", "sun_b", "sky_r", "sky_g", "sky_b", "confidence", "samples",
                                                     "sun_r_lo", "sun_r_hi", "sun_g_lo", "sun_g_hi", "sun_b_lo", "sun_b_hi",
                                                     "sky_r_lo", "sky_r_hi", "sky_g_lo", "sky_g_hi", "sky_b_lo", "sky_b_hi",
                                                     "status"}));
  ASSERT_EQ(table.rows.size(), 1u);
  // What became of the frame (issue 39): fitted, E_sky alone, and the report counts it.
  EXPECT_EQ(table.rows[0][static_cast<size_t>(table.RequireColumn("status"))], "sky_only");
  EXPECT_NE(run.out.find("frames by fit status (estimates.csv's status): 1 sky_only"), std::string::npos) << run.out;
  const double linear = capture::CameraResponse{}.ToLinear(120.0 / 255.0);
  const double sky = ParseFiniteDouble(table.rows[0][7], "sky_r");
  EXPECT_NEAR(sky, M_PI * linear / 0.4, 0.01 * M_PI * linear / 0.4);
  // The 90% interval: one surface, all of it sky-lit, agrees with itself, so E_sky's error is the
  // least model error, 2%: ±1.645 · 2%.
  EXPECT_NEAR(ParseFiniteDouble(table.rows[0][18], "sky_r_lo"), sky * (1.0 - 1.645 * 0.02), 1e-4 * sky);
  EXPECT_NEAR(ParseFiniteDouble(table.rows[0][19], "sky_r_hi"), sky * (1.0 + 1.645 * 0.02), 1e-4 * sky);
  EXPECT_EQ(ParseFiniteDouble(table.rows[0][4], "sun_r"), 0.0);
  EXPECT_LT(ParseFiniteDouble(table.rows[0][2], "elevation"), 0.0);  // midnight at (0°, 0°)
  EXPECT_TRUE(fs::is_regular_file(rec.dir / "est.png"));
}

// daylit results fills a template from a folder of figures, and writes nothing when a field
// names a figure nothing measured.
TEST(CliTest, ResultsFillsThePageOrNamesTheMissingFigure) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_results_" + std::to_string(::getpid()));
  fs::create_directories(dir / "measured" / "courtyard-a");
  WriteFileAtomically(dir / "measured" / "courtyard-a" / "estimate.json", R"({"fps": 176.38, "frames": 600})");
  WriteFileAtomically(dir / "page.md.in", "estimate: {{courtyard-a/estimate/fps}} fps over {{courtyard-a/estimate/frames}}\n");
  const std::string measured = (dir / "measured").string();
  const CliRun run = Daylit("results " + (dir / "page.md.in").string() + " " + measured + " --out " + (dir / "page.md").string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  std::ifstream page(dir / "page.md");
  std::string line;
  std::getline(page, line);
  EXPECT_EQ(line, "estimate: 176 fps over 600");
  WriteFileAtomically(dir / "gap.md.in", "{{courtyard-a/replay/fps}}\n");
  const CliRun gap = Daylit("results " + (dir / "gap.md.in").string() + " " + measured + " --out " + (dir / "gap.md").string());
  EXPECT_EQ(gap.exit_code, 2);
  EXPECT_NE(gap.err.find("gap.md.in:1: nothing measured \"courtyard-a/replay/fps\""), std::string::npos) << gap.err;
  EXPECT_FALSE(fs::exists(dir / "gap.md"));
  fs::remove_all(dir);
}

// lighting.png marks each burst's start (frames more than 2 s apart) with a grey line where its
// first frame is on the frame axis.
TEST(CliTest, EstimatePlotMarksWhereEachBurstStarts) {
  bake::testing::SyntheticRecording rec("cli_estimate_bursts");
  const std::string scene = rec.Write().string();
  for (const char* frame : {"000001.png", "000002.png", "000003.png", "000004.png"}) {
    fs::copy_file(rec.dir / "frames" / "000000.png", rec.dir / "frames" / frame);
  }
  // Bursts at frames 0-1 and 2-4: frame 2 is the middle of the axis (frames 0 to 4).
  WriteFileAtomically(rec.dir / "frames.csv",
                      "frame,time_utc\n0,2026-06-21T00:00:00Z\n1,2026-06-21T00:00:00.1Z\n2,2026-06-21T00:00:30Z\n"
                      "3,2026-06-21T00:00:30.1Z\n4,2026-06-21T00:00:30.2Z\n");
  const fs::path out = rec.dir / "est.csv";
  const CliRun run = Daylit("estimate " + scene + " --cache " + (rec.dir / "cache").string() + " --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(ReadCsvFile(rec.dir / "est_bursts.csv").rows.size(), 2u);
  const cv::Mat plot = cv::imread((rec.dir / "est.png").string());
  ASSERT_EQ(plot.size(), cv::Size(1400, 720));  // E_sun over E_sky, 1400 x 360 each
  // The E_sky panel's plot area (report/plot.cc's margins), its legend at the top right left out.
  const cv::Rect inside(82, 360 + 52, 1296, 258), legend(1150, 360 + 40, 250, 100);
  const Trace starts = TraceOf(plot, inside, {150, 150, 150}, legend);
  // The flat E_sky estimate over frames 0 to 4 (a grey sky: blue, drawn last, covers R and G).
  const Trace sky = TraceOf(plot, inside, {31, 119, 180}, legend);
  const std::vector<double> lines = starts.Runs();
  ASSERT_EQ(lines.size(), 1u) << "one line: the second burst's start";
  ASSERT_GT(sky.Right() - sky.Left(), 1000);
  EXPECT_NEAR(lines[0], 0.5 * (80 + 1380), 2.0) << "frame 2 of 0 to 4";
}

TEST(CliTest, EstimateSkipsAFrameThatCannotBeDecodedAndGoesOn) {
  bake::testing::SyntheticRecording rec("cli_estimate_corrupt");
  const std::string scene = rec.Write().string();
  // Three frames; the middle one's file is not an image.
  fs::copy_file(rec.dir / "frames" / "000000.png", rec.dir / "frames" / "000002.png");
  WriteFileAtomically(rec.dir / "frames" / "000001.png", "not a png");
  WriteFileAtomically(rec.dir / "frames.csv",
                      "frame,time_utc\n0,2026-06-21T00:00:00Z\n1,2026-06-21T00:00:00.1Z\n2,2026-06-21T00:00:00.2Z\n");
  const fs::path out = rec.dir / "est.csv";
  const CliRun run = Daylit("estimate " + scene + " --cache " + (rec.dir / "cache").string() + " --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("frame 1 cannot be decoded; skipped"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("1 frames could not be decoded"), std::string::npos) << run.err;
  const CsvTable table = ReadCsvFile(out);
  ASSERT_EQ(table.rows.size(), 3u);
  // The skipped frame holds the estimate of the one before, and says why.
  EXPECT_EQ(table.rows[1][7], table.rows[0][7]);
  EXPECT_EQ(table.rows[2][7], table.rows[0][7]);
  const size_t status = static_cast<size_t>(table.RequireColumn("status"));
  EXPECT_EQ(table.rows[0][status], "sky_only");
  EXPECT_EQ(table.rows[1][status], "unreadable");
  EXPECT_NE(run.out.find("2 sky_only, 1 unreadable; 1 not fitted, each holding the estimate before it"), std::string::npos)
      << run.out;
}

TEST(CliTest, RelightEnvWritesTheRelitMapAndItsPreview) {
  // Night, one grey frame (code 120) of open ground of albedo 0.4: the fit gives E_sky = π·L/0.4
  // (see EstimateWritesTheStableCsv), so the relit sky has radiance E_sky/π = L/0.4 everywhere
  // (a uniform sky with the sun down) and the ground 0.4/π · E_sky · V = L.
  bake::testing::SyntheticRecording rec("cli_relight_env");
  const std::string scene = rec.Write().string();
  const fs::path out = rec.dir / "env.exr";
  const CliRun run = Daylit("relight-env " + scene + " --frame 0 --cache " + (rec.dir / "cache").string() +
                            " --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(fs::is_regular_file(rec.dir / "env.png"));
  const HdrImage env = scene::ReadHdrImage(out);
  const float linear = static_cast<float>(capture::CameraResponse{}.ToLinear(120.0 / 255.0));
  EXPECT_NEAR(env.Pixel(0, 0)[1], linear / 0.4f, 0.01f * linear / 0.4f);                   // zenith
  EXPECT_NEAR(env.Pixel(10, env.height - 1)[1], linear, 0.02f * linear);                     // ground below
}

TEST(CliTest, AVolumeOutsideTheModelIsAWarning) {
  scene::testing::SceneSandbox sandbox("cli_volume");
  sandbox.json()["volume"] = {{"min", {5000, 5000, 0}}, {"max", {5001, 5001, 1}}, {"resolution", {2, 2, 2}}};
  const CliRun run = Daylit("info " + sandbox.Write().string());
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("volume: the box (5000, 5000, 0)-(5001, 5001, 1) lies outside the model's bounds"), std::string::npos)
      << run.err << run.out;
}

struct BadCall {
  std::string args;
  std::string error;  // expected on stderr
};

// Each call is refused as bad input: exit 2 and one line on stderr that holds its error.
template <size_t N>
void ExpectEachRefused(const BadCall (&calls)[N]) {
  for (const BadCall& call : calls) {
    const CliRun run = Daylit(call.args);  // NOLINT
    EXPECT_EQ(run.exit_code, 2) << call.args << "\n" << run.err;
    EXPECT_NE(run.err.find(call.error), std::string::npos) << call.args << "\n" << run.err.substr(0, 2000);
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << call.args << "\n" << run.err.substr(0, 2000);
  }
}

TEST(CliTest, LightsWritesTheLightsTheirErrorsAndTheAutomaticN) {
  const fs::path out = fs::temp_directory_path() / ("daylit_cli_lights_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const CliRun run = Daylit("lights " + kProbe + " --n 1,2,4,8 --threshold 0.05 --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("SH9 relative to the maximum irradiance"), std::string::npos) << run.out;
  const CsvTable errors = ReadCsvFile(out / "errors.csv");
  ASSERT_EQ(errors.header, (std::vector<std::string>{"method", "n", "mean_error", "max_error"}));
  // The file's lights, evaluated as its format says (E(n) = ambient + Σ irradiance·max(0, n·d)),
  // give the error the CSV reports against the exact irradiance.
  const HdrImage map = scene::ReadHdrImage(kProbe);
  const std::vector<glm::vec3> normals = sh::IcosahedronNormals(5);
  const std::vector<glm::dvec3> truth = sh::ExactIrradiance(map, normals);
  std::map<std::string, double> mean_of;
  for (const auto& row : errors.rows) mean_of[row[0] + "_" + row[1]] = std::stod(row[2]);
  for (const char* name : {"mediancut_1", "mediancut_8", "io_1", "io_4"}) {
    ASSERT_TRUE(mean_of.count(name)) << name;
    const nlohmann::json json = nlohmann::json::parse(ReadTextFile(out / (std::string("lights_") + name + ".json")));
    lightfit::LightSet set;
    set.ambient = glm::vec3(json["ambient"][0], json["ambient"][1], json["ambient"][2]);
    for (const auto& l : json["lights"]) {
      set.lights.push_back({glm::vec3(l["direction"][0], l["direction"][1], l["direction"][2]),
                            glm::vec3(l["irradiance"][0], l["irradiance"][1], l["irradiance"][2])});
    }
    EXPECT_NEAR(lightfit::RelativeError(truth, set.Irradiance(normals)).mean, mean_of[name], 1e-5) << name;
  }
  EXPECT_TRUE(mean_of.count("sh_9"));
  EXPECT_LT(mean_of["io_4"], 0.05);
  EXPECT_GT(mean_of["mediancut_8"], 0.05);
  // The automatic N: the smallest with a mean error below 5%; median cut's search adds its rows.
  const nlohmann::json automatic = nlohmann::json::parse(ReadTextFile(out / "automatic.json"));
  const int io_n = automatic["io"]["n"], mc_n = automatic["mediancut"]["n"];
  EXPECT_LT(mean_of["io_" + std::to_string(io_n)], 0.05);
  EXPECT_GE(mean_of["io_" + std::to_string(io_n - 1)], 0.05);
  EXPECT_LT(mean_of["mediancut_" + std::to_string(mc_n)], 0.05);
  EXPECT_GE(mean_of["mediancut_" + std::to_string(mc_n - 1)], 0.05);
  EXPECT_TRUE(fs::is_regular_file(out / "sh9.json"));
  // The mean-error panel (1000 x 380, log-log) draws irradiance optimization below median cut
  // wherever both are drawn, as the CSV has it at every shared N.
  for (const int n : {1, 2, 4, 8}) {
    EXPECT_LT(mean_of["io_" + std::to_string(n)], mean_of["mediancut_" + std::to_string(n)]) << n;
  }
  const cv::Mat plot = cv::imread((out / "errors.png").string());
  ASSERT_EQ(plot.size(), cv::Size(1000, 760));
  const cv::Rect inside(82, 52, 896, 278), legend(760, 40, 240, 80);
  const Trace mc = TraceOf(plot, inside, report::SeriesColor(0), legend), io = TraceOf(plot, inside, report::SeriesColor(1), legend);
  size_t shared = 0, below = 0;
  for (const auto& [column, row] : io.top_row) {
    if (!mc.top_row.count(column)) continue;
    ++shared;
    below += row > mc.top_row.at(column) ? 1 : 0;
  }
  EXPECT_GT(shared, 400u) << "both curves across most of the panel";
  EXPECT_EQ(below, shared);
  fs::remove_all(out);
}

TEST(CliTest, CalibrateResponseWritesATableTheSceneCanName) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_response_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // A gamma-2.2 camera photographing a ramp over three decades at four exposures.
  std::string images;
  for (int k = 0; k < 4; ++k) {
    cv::Mat bgr(64, 300, CV_8UC3);
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x < bgr.cols; ++x) {
        const double linear = std::pow(10.0, 3.0 * x / (bgr.cols - 1.0) - 2.5 + 0.6 * k) * (0.8 + 0.2 * std::sin(0.5 * y));
        const auto code = static_cast<uint8_t>(std::lround(255.0 * std::pow(std::min(linear, 1.0), 1.0 / 2.2)));
        bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(code, code, code);
      }
    }
    const fs::path file = dir / ("bracket" + std::to_string(k) + ".png");
    ASSERT_TRUE(cv::imwrite(file.string(), bgr));
    images.append(" ").append(file.string());
  }
  const fs::path out = dir / "response.csv";
  std::string args = "calibrate-response";
  args.append(images).append(" --times 1,3.981,15.85,63.1 --out ").append(out.string());
  const CliRun run = Daylit(args);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto table = capture::ReadResponseTable(out);
  // Gamma 2.2: code 128 is 0.22 of code 255.
  EXPECT_NEAR(table->linear[1][128], std::pow(128.0 / 255.0, 2.2), 0.03);
  EXPECT_TRUE(fs::is_regular_file(dir / "response.png"));
  // One image twice, at two times: the curve is undetermined; refused, nothing written.
  const fs::path same = dir / "bracket0.png";
  const CliRun twice = Daylit("calibrate-response " + same.string() + " " + same.string() + " --times 1,2 --out " +
                              (dir / "same.csv").string());
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("every image of the bracket is the same"), std::string::npos) << twice.err;
  EXPECT_FALSE(fs::exists(dir / "same.csv"));
  fs::remove_all(dir);
}

TEST(CliTest, RecordWritesARecordingThatReplaysItsFrames) {
  const scene::Scene original = scene::LoadScene(kRecording);
  for (const bool images : {false, true}) {
    const fs::path out = fs::temp_directory_path() / ("daylit_cli_record_" + std::to_string(::getpid()) + (images ? "_png" : "_h264"));
    fs::remove_all(out);
    const CliRun run = Daylit("record --from " + kRecording + " --frames 12 --out " + out.string() + (images ? " --images" : ""));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.out.find("12 frames written"), std::string::npos) << run.out;
    const scene::Scene copy = scene::LoadScene(out);
    ASSERT_TRUE(copy.frame_times.has_value());
    ASSERT_EQ(copy.frame_times->frames.size(), 12u);
    EXPECT_FALSE(copy.groundtruth.lighting.has_value());
    auto a = scene::OpenFrameSource(original), b = scene::OpenFrameSource(copy);
    double worst_mean = 0.0, worst_max = 0.0, worst_bias = 0.0;
    for (int i = 0; i < 12; ++i) {
      capture::Frame fa, fb;
      ASSERT_EQ(a->Next(&fa), capture::FrameStatus::kFrame);
      ASSERT_EQ(b->Next(&fb), capture::FrameStatus::kFrame);
      EXPECT_EQ(fb.index, i);
      EXPECT_EQ(fb.utc.SecondsSince(fa.utc), 0.0);
      EXPECT_DOUBLE_EQ(fb.exposure, fa.exposure);
      cv::Mat diff;
      cv::absdiff(fa.rgb, fb.rgb, diff);
      worst_mean = std::max(worst_mean, cv::mean(diff.reshape(1))[0]);
      const cv::Mat signed_diff = fb.rgb - fa.rgb;
      worst_bias = std::max(worst_bias, std::abs(cv::mean(signed_diff.reshape(1))[0]));
      double lo = 0, hi = 0;
      cv::minMaxLoc(diff.reshape(1), &lo, &hi);
      worst_max = std::max(worst_max, hi);
    }
    std::printf("record %s: frames differ by %.2f codes on average (bias %.3f), %.1f at most\n", images ? "PNG" : "H.264",
                255 * worst_mean, 255 * worst_bias, 255 * worst_max);
    if (images) {
      EXPECT_LE(worst_max, 0.5 / 255 + 1e-6);  // 8-bit rounding only
    } else {
      // H.264 (crf 10) of a path-traced, noisy source: the noise costs about a code value, but
      // a frame's mean moves by at most 0.25 code (0.3% of linear light at mid-grey; measured
      // 0.18). OpenCV's writer lost 2.7 codes on average, its conversion truncating.
      EXPECT_LT(worst_mean, 1.5 / 255);
      EXPECT_LT(worst_bias, 0.25 / 255);
    }
    fs::remove_all(out);
  }
}

// Mesa's llvmpipe leaks ~240 bytes that LeakSanitizer sees only after the driver is unloaded
// (render/CMakeLists.txt): commands that open GL run without leak detection under ASan.
const std::string kGlEnvironment = "ASAN_OPTIONS=detect_leaks=0 ";

TEST(CliTest, RenderWritesTheCompositeAndComparesItWithTheTruth) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_render_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string cache = std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const CliRun exr =
      Daylit("render " + kRecording + " --frame 300 --cache " + cache + " --out " + (dir / "f.exr").string(), kGlEnvironment);
  ASSERT_EQ(exr.exit_code, 0) << exr.err;
  EXPECT_NE(exr.out.find("objects "), std::string::npos) << exr.out;
  EXPECT_TRUE(fs::is_regular_file(dir / "f_vs_truth.png"));
  // The EXR is the linear composite in radiance units: where no object or shadow reaches, the
  // frame linearised with its exposure divided out, so within the video's noise of the truth.
  const HdrImage image = scene::ReadHdrImage(dir / "f.exr");
  const HdrImage truth = scene::ReadHdrImage(kRecording + "/groundtruth/without_objects/000300.exr");
  ASSERT_EQ(image.width, truth.width);
  double ratio = 0.0;
  int n = 0;
  for (int y = 20; y < 120; ++y) {  // the far wall, above the objects
    for (int x = 100; x < 860; x += 4) {
      const size_t p = (static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)) * 3 + 1;
      ratio += image.rgb[p] / truth.rgb[p], ++n;
    }
  }
  EXPECT_NEAR(ratio / n, 1.0, 0.03);
  // The PNG, with the objects lit by the sun and 8 lights fitted to the relit map instead of the
  // volume: as close to the truth on the objects.
  const CliRun png = Daylit("render " + kRecording + " --frame 300 --lighting lights:8 --cache " + cache + " --out " +
                                (dir / "f.png").string(), kGlEnvironment);
  ASSERT_EQ(png.exit_code, 0) << png.err;
  EXPECT_NE(png.err.find("the objects lit by the sun and 8 lights fitted to the relit env map"), std::string::npos) << png.err;
  const size_t at = png.out.find(": objects ");
  ASSERT_NE(at, std::string::npos) << png.out;
  EXPECT_LT(std::stod(png.out.substr(at + 10)), 6.0) << png.out;
  const cv::Mat encoded = cv::imread((dir / "f.png").string());
  EXPECT_EQ(encoded.cols, image.width);
  fs::remove_all(dir);
}

// The main job on the first 60 frames (two of them with the path tracer's truth): the video has
// every frame, the objects are in it where the truth's mask says and nowhere else changes more
// than the H.264 round trip does; the CSV, plots and report are beside it, nothing half-written.
TEST(CliTest, ReplayWritesTheAugmentedVideoAndItsReport) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_replay_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string cache = std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const CliRun run = Daylit("replay " + kRecording + " --frames 60 --cache " + cache + " --out " + (dir / "r.mp4").string(),
                            kGlEnvironment);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("60 frames in"), std::string::npos) << run.out;
  EXPECT_NE(run.err.find("replay 100%"), std::string::npos) << "progress";
  for (const char* name : {"r.mp4", "estimates.csv", "bursts.csv", "lighting.png", "report.txt", "figures.json",
                           "fidelity.csv", "fidelity.png", "worst_vs_truth.png"}) {
    EXPECT_TRUE(fs::is_regular_file(dir / name)) << name;
  }
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 9u) << "a temporary file was left behind";
  // The first 60 frames are one burst (frames 0.1 s apart), with its errors against the truth.
  const CsvTable bursts = ReadCsvFile(dir / "bursts.csv");
  ASSERT_EQ(bursts.rows.size(), 1u);
  EXPECT_EQ(bursts.rows[0][static_cast<size_t>(bursts.RequireColumn("frames"))], "60");
  EXPECT_LT(std::stod(bursts.rows[0][static_cast<size_t>(bursts.RequireColumn("sky_error_g"))]), 0.10);
  // Its 90% interval, made from the frames alone, holds the errors (estimation/light_interval.h).
  EXPECT_EQ(bursts.rows[0][static_cast<size_t>(bursts.RequireColumn("interval_covers"))], "1");
  EXPECT_LT(std::stod(bursts.rows[0][static_cast<size_t>(bursts.RequireColumn("sky_g_lo"))]),
            std::stod(bursts.rows[0][static_cast<size_t>(bursts.RequireColumn("sky_g"))]));
  EXPECT_NE(run.out.find("per burst"), std::string::npos) << run.out;
  // The report's figures for scripts (docs/results.md): the run and the composite's truth frames.
  std::ifstream figures_in(dir / "figures.json");
  const nlohmann::json figures = nlohmann::json::parse(figures_in);
  EXPECT_EQ(figures.at("frames").get<int>(), 60);
  EXPECT_EQ(figures.at("composite/frames").get<int>(), 2);
  EXPECT_GT(figures.at("fps").get<double>(), 0.0);
  EXPECT_LT(figures.at("composite/objects/worst").get<double>(), 0.10);
  EXPECT_NE(figures.at("gl_renderer").get<std::string>(), "");
  // How the run was started, saved beside its results (issue 39): the command line as typed, the
  // folder it ran in, the version.
  const std::string command = figures.at("run/command").get<std::string>();
  EXPECT_NE(command.find(" replay " + kRecording + " --frames 60 --cache "), std::string::npos) << command;
  EXPECT_EQ(figures.at("run/argv").size(), 9u);
  EXPECT_EQ(figures.at("run/cwd").get<std::string>(), fs::current_path().string());
  EXPECT_NE(figures.at("run/daylit").get<std::string>(), "");
  const std::string report = ReadTextFile(dir / "report.txt");
  EXPECT_NE(report.find("\nrun: " + command + "\nin: " + fs::current_path().string() + "\nstarted: "), std::string::npos)
      << report;
  EXPECT_EQ(ReadCsvFile(dir / "estimates.csv").rows.size(), 60u);
  // Frames 40 and 50 against the truth: the issue's bar is 10% on the objects and their shadows.
  const CsvTable fidelity = ReadCsvFile(dir / "fidelity.csv");
  ASSERT_EQ(fidelity.rows.size(), 2u);
  for (const auto& row : fidelity.rows) {
    EXPECT_LT(std::stod(row[static_cast<size_t>(fidelity.RequireColumn("object_error"))]), 0.10) << row[0];
    EXPECT_LT(std::stod(row[static_cast<size_t>(fidelity.RequireColumn("shadow_error"))]), 0.10) << row[0];
  }
  // The video against the recording, frame 40: the objects' pixels changed, the far wall not.
  capture::VideoDecoder replay(dir / "r.mp4"), original(kRecording + "/video.mp4");
  cv::Mat a, b;
  int frames = 0;
  double object_change = 0.0, wall_change = 0.0;
  while (replay.Next(&a)) {
    ASSERT_TRUE(original.Next(&b));
    if (frames++ != 40) continue;
    const cv::Mat mask = cv::imread(kRecording + "/groundtruth/objects_mask/000040.png", cv::IMREAD_GRAYSCALE);
    cv::Mat difference;
    cv::absdiff(a, b, difference);
    cv::cvtColor(difference, difference, cv::COLOR_RGB2GRAY);
    object_change = 255.0 * cv::mean(difference, mask >= 128)[0];
    wall_change = 255.0 * cv::mean(difference(cv::Rect(100, 20, 760, 100)))[0];
  }
  EXPECT_EQ(frames, 60);
  EXPECT_EQ(replay.width(), 960);
  EXPECT_GT(object_change, 10.0) << "the objects are not in the video";
  EXPECT_LT(wall_change, 1.5) << "codes; pixels no object reaches changed";
  fs::remove_all(dir);
}

// --window under Xvfb (installed by scripts/setup.sh): the window shows the composite, encoded
// like the video, with the overlay; read back from its framebuffer at the end.
TEST(CliTest, ReplayInAWindowShowsTheComposite) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_window_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string cache = std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const CliRun run = Daylit("replay " + kRecording + " --window --frames 41 --cache " + cache + " --out " +
                                (dir / "w.mp4").string() + " --screenshot " + (dir / "shot.png").string(),
                            kGlEnvironment + "xvfb-run -a -s '-screen 0 1280x1024x24' ");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const cv::Mat shot = cv::imread((dir / "shot.png").string());
  ASSERT_EQ(shot.cols, 960);
  ASSERT_EQ(shot.rows, 540);
  // The last frame shown is frame 40: the objects where the truth's mask has them, the far wall
  // as the video's frame 40 (away from the overlay), the overlay's white text top left.
  capture::VideoDecoder original(kRecording + "/video.mp4");
  cv::Mat frame;
  for (int i = 0; i <= 40; ++i) ASSERT_TRUE(original.Next(&frame));
  cv::Mat expected;
  frame.convertTo(expected, CV_8UC3, 255.0);
  cv::cvtColor(expected, expected, cv::COLOR_RGB2BGR);
  cv::Mat difference;
  cv::absdiff(shot, expected, difference);
  cv::cvtColor(difference, difference, cv::COLOR_BGR2GRAY);
  const cv::Mat mask = cv::imread(kRecording + "/groundtruth/objects_mask/000040.png", cv::IMREAD_GRAYSCALE);
  EXPECT_GT(cv::mean(difference, mask >= 128)[0], 10.0) << "the objects are not in the window";
  EXPECT_LT(cv::mean(difference(cv::Rect(300, 100, 560, 90)))[0], 1.0) << "codes off on the far wall";
  cv::Mat overlay;
  cv::inRange(shot(cv::Rect(0, 0, 400, 80)), cv::Scalar(250, 250, 250), cv::Scalar(255, 255, 255), overlay);
  EXPECT_GT(cv::countNonZero(overlay), 200) << "no overlay text";
  // With --out as well, the video is written too.
  EXPECT_TRUE(fs::is_regular_file(dir / "w.mp4"));
  fs::remove_all(dir);
}

// The window's time slider, started at 16:30 UTC (--relight-at; the arrows and the bar move it):
// frame 0 (07:00 local) is shown as daylit relight makes it for that time, objects included,
// with the slider's knob on the bar.
TEST(CliTest, TheWindowsTimeSliderRelightsTheFrames) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_slider_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string cache = " --cache " + std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const CliRun shown = Daylit("replay " + kRecording + " --window --frames 1 --relight-at 16:30 --screenshot " +
                                  (dir / "shot.png").string() + " --out " + (dir / "w.mp4").string() + cache,
                              kGlEnvironment + "xvfb-run -a -s '-screen 0 1280x1024x24' ");
  ASSERT_EQ(shown.exit_code, 0) << shown.err;
  const CliRun relit = Daylit("relight " + kRecording + " --frame 0 --at 2026-06-21T16:30:00Z --objects --out " +
                                  (dir / "relit.png").string() + cache,
                              kGlEnvironment);
  ASSERT_EQ(relit.exit_code, 0) << relit.err;
  const cv::Mat shot = cv::imread((dir / "shot.png").string());
  const cv::Mat expected = cv::imread((dir / "relit.png").string());
  ASSERT_EQ(shot.size(), expected.size());
  // Between the overlay's text and the slider.
  const cv::Rect middle(0, 90, shot.cols, 380);
  cv::Mat difference;
  cv::absdiff(shot(middle), expected(middle), difference);
  EXPECT_LT(cv::mean(difference)[0], 1.5) << "the window's relit frame is not daylit relight's";
  // And it is not the frame as recorded: the morning's shadows and light are gone.
  capture::VideoDecoder original(kRecording + "/video.mp4");
  cv::Mat frame, recorded;
  ASSERT_TRUE(original.Next(&frame));
  frame.convertTo(recorded, CV_8UC3, 255.0);
  cv::cvtColor(recorded, recorded, cv::COLOR_RGB2BGR);
  cv::absdiff(shot(middle), recorded(middle), difference);
  EXPECT_GT(cv::mean(difference)[0], 8.0) << "the window shows the frame unrelit";
  // The knob (orange) on the bar along the bottom.
  cv::Mat knob;
  cv::inRange(shot(cv::Rect(0, shot.rows - 40, shot.cols, 40)), cv::Scalar(0, 190, 245), cv::Scalar(10, 210, 255), knob);
  EXPECT_GT(cv::countNonZero(knob), 40) << "no slider knob";
  fs::remove_all(dir);
}

TEST(CliTest, ReplayAndRenderWithoutOpenGlSayWhy) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_nogl_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // libglvnd finds no EGL vendor: as on a machine without libegl-mesa0 or a GPU driver.
  const std::string no_egl = kGlEnvironment + "__EGL_VENDOR_LIBRARY_DIRS=/nonexistent ";
  for (const std::string& args : {"replay " + kRecording + " --frames 5 --out " + (dir / "r.mp4").string(),
                                  "render " + kRecording + " --frame 5 --out " + (dir / "f.png").string()}) {
    const CliRun run = Daylit(args, no_egl);
    EXPECT_EQ(run.exit_code, 1) << args;  // the machine's, not bad input (2) nor a bug (3)
    EXPECT_NE(run.err.find("OpenGL: no EGL display"), std::string::npos) << run.err;
  }
  // No display for --window: said so.
  const CliRun headless = Daylit("replay " + kRecording + " --window --frames 5", kGlEnvironment + "env -u DISPLAY -u WAYLAND_DISPLAY ");
  EXPECT_EQ(headless.exit_code, 2);
  EXPECT_NE(headless.err.find("--window: no display for a window"), std::string::npos) << headless.err;
  EXPECT_TRUE(fs::is_empty(dir)) << "an output was left behind";
  fs::remove_all(dir);
}

// daylit relight: one frame relit to the sun and light of a frame six and a half hours later,
// compared with it (the issue's bars, also in relight_image_recording_test) with its strip; a
// range of frames into a video; a sun below the horizon relights with the sky alone.
TEST(CliTest, RelightWritesTheRelitFrameItsStripAndAVideo) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_relight_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string cache = " --cache " + std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const CliRun like = Daylit("relight " + kRecording + " --frame 152 --like-frame 452 --out " + (dir / "r.png").string() + cache);
  ASSERT_EQ(like.exit_code, 0) << like.err;
  double error = 0.0, iou = 0.0;
  ASSERT_EQ(std::sscanf(like.out.c_str(), "relit frame 152 against frame 452: diffuse pixels %lf%% mean relative error; "
                                          "shadow layout IoU %lf", &error, &iou), 2) << like.out;
  EXPECT_LE(error, 10.0);
  EXPECT_GE(iou, 0.9);
  const cv::Mat strip = cv::imread((dir / "r_strip.png").string());
  EXPECT_EQ(strip.cols, 960);
  EXPECT_EQ(strip.rows, 3 * 540);
  EXPECT_EQ(cv::imread((dir / "r.png").string()).cols, 960);
  // The sun 5° below the horizon: sky only, said so; the sunlit frame gets darker everywhere.
  const CliRun night = Daylit("relight " + kRecording + " --frame 152 --sun-azimuth 300 --sun-elevation -5 --out " +
                              (dir / "n.exr").string() + cache);
  ASSERT_EQ(night.exit_code, 0) << night.err;
  EXPECT_NE(night.err.find("below the horizon; a sky-only relight (E_sun = 0)"), std::string::npos) << night.err;
  const HdrImage dark = scene::ReadHdrImage(dir / "n.exr");
  const HdrImage truth = scene::ReadHdrImage(kRecording + "/groundtruth/without_objects/000152.exr");
  double dark_sum = 0.0, day_sum = 0.0;
  for (size_t i = 0; i < dark.rgb.size(); ++i) dark_sum += dark.rgb[i], day_sum += truth.rgb[i];
  EXPECT_LT(dark_sum, 0.5 * day_sum);
  // Frames 0 to 9 at 18:30 local time, into a video of ten frames; nothing else left behind.
  const CliRun video = Daylit("relight " + kRecording + " --at 2026-06-21T16:30:00Z --frames 0:9 --sky follow --out " +
                              (dir / "v.mp4").string() + cache);
  ASSERT_EQ(video.exit_code, 0) << video.err;
  EXPECT_NE(video.out.find("10 frames relit to the sun at 2026-06-21T16:30:00Z"), std::string::npos) << video.out;
  capture::VideoDecoder decoder(dir / "v.mp4");
  cv::Mat frame;
  int frames = 0;
  while (decoder.Next(&frame)) ++frames;
  EXPECT_EQ(frames, 10);
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 4u) << "a temporary file was left behind";
  fs::remove_all(dir);
}

// A frame without an estimate (black: no usable pixel) is not relit: the single frame is an
// error naming it; in a video it is written as it is, and said so.
TEST(CliTest, RelightOfAFrameWithoutAnEstimate) {
  bake::testing::SyntheticRecording rec("cli_relight_black");
  const std::string scene = rec.Write().string();
  cv::imwrite((rec.dir / "frames" / "000000.png").string(), cv::Mat(48, 64, CV_8UC3, cv::Scalar(0, 0, 0)));
  const std::string args = "relight " + scene + " --sun-azimuth 180 --sun-elevation 40 --cache " + (rec.dir / "cache").string();
  const CliRun one = Daylit(args + " --frame 0 --out " + (rec.dir / "r.png").string());
  EXPECT_EQ(one.exit_code, 2);
  EXPECT_NE(one.err.find("frame 0: no estimate ("), std::string::npos) << one.err;
  EXPECT_FALSE(fs::exists(rec.dir / "r.png"));
  const CliRun video = Daylit(args + " --out " + (rec.dir / "r.mp4").string());
  ASSERT_EQ(video.exit_code, 0) << video.err;
  EXPECT_NE(video.err.find("1 frames had no estimate yet (no usable fit) and are written as they are"), std::string::npos)
      << video.err;
  EXPECT_TRUE(fs::is_regular_file(rec.dir / "r.mp4"));
}

// A process id that no process has now (a child that has ended and been reaped).
pid_t DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

// SIGTERM (as a service manager or `timeout` sends it) ends a replay as Ctrl-C does: after the
// frame at hand, with a complete video and its report, exit 0. A temporary that a killed run
// left beside the output is removed by the next run, and none is left by this one.
TEST(CliTest, SigtermEndsAReplayWithCompleteOutputsAndNoTemporaries) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_term_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path stale = dir / ("r.mp4.tmp-" + std::to_string(DeadPid()) + "-0.mp4");
  WriteFileAtomically(stale, "half a video");
  const fs::path err = dir / "stderr.txt";
  // Its environment: this one, with kGlEnvironment's ASAN_OPTIONS (it opens GL).
  std::vector<std::string> env_text = {kGlEnvironment.substr(0, kGlEnvironment.size() - 1)};
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string(*e).rfind("ASAN_OPTIONS=", 0) != 0) env_text.emplace_back(*e);
  }
  std::vector<char*> env;
  for (std::string& e : env_text) env.push_back(e.data());
  env.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    const std::string cache = DAYLIT_BINARY_DIR "/test-cache/courtyard-a", out = (dir / "r.mp4").string();
    ::execle(DAYLIT_BINARY_DIR "/bin/daylit", "daylit", "replay", kRecording.c_str(), "--cache", cache.c_str(), "--out",
             out.c_str(), static_cast<char*>(nullptr), env.data());
    ::_exit(127);
  }
  // Once frames are going out (the progress line says fps), stop it.
  const auto progress = [&] { return fs::exists(err) ? ReadTextFile(err) : std::string(); };
  for (int i = 0; i < 600 && progress().find(" fps") == std::string::npos; ++i) ::usleep(100000);
  ASSERT_NE(progress().find(" fps"), std::string::npos) << progress();
  ::kill(child, SIGTERM);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "ended by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << ReadTextFile(err);
  capture::VideoDecoder video(dir / "r.mp4");
  cv::Mat frame;
  int frames = 0;
  while (video.Next(&frame)) ++frames;
  EXPECT_GT(frames, 0);
  EXPECT_LT(frames, 600);  // stopped early
  EXPECT_EQ(ReadCsvFile(dir / "estimates.csv").rows.size(), static_cast<size_t>(frames));
  EXPECT_TRUE(fs::is_regular_file(dir / "report.txt"));
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
  }
  fs::remove_all(dir);
}

// --version; -q and -v after the command as before it.
TEST(CliTest, VersionAndVerbosityAnywhere) {
  const CliRun version = Daylit("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_EQ(version.out.rfind("daylit 0.", 0), 0u) << version.out;
  const CliRun quiet_after = Daylit("sunpos --time 2026-06-21T10:00:00Z --lat 57 --lon 9 -v");
  EXPECT_EQ(quiet_after.exit_code, 0) << quiet_after.err;
  const CliRun quiet = Daylit("info " + kRecording + " -q");
  EXPECT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
}

TEST(CliTest, BadInputExitsWithCode2AndOneLine) {
  scene::testing::SceneSandbox sandbox("cli");
  sandbox.WriteText("broken.json", "{\"format\": \"daylit-recording/1\",");
  sandbox.WriteText("nan.obj", "o ground\nv 0 0 0\nv 1 nan 0\nv 1 1 0\nf 1 2 3\n");
  sandbox.json()["model"]["file"] = "nan.obj";
  const fs::path nan_scene = sandbox.Write();
  const std::string dir = sandbox.dir().string();
  // An env map whose header claims far more than its file holds (a real 64×32 OpenEXR with its
  // data window rewritten): refused before anything is allocated.
  const auto claiming = [&](const std::string& name, int width, int height) {
    const fs::path path = sandbox.dir() / name;
    const std::vector<float> rgb(64 * 32 * 3, 1.0f);
    scene::WriteRgbExr(path, 64, 32, rgb.data());
    std::string bytes = ReadTextFile(path);
    const size_t at = bytes.find(std::string("dataWindow\0box2i\0", 17));
    EXPECT_NE(at, std::string::npos);
    const int32_t box[4] = {0, 0, width - 1, height - 1};
    bytes.replace(at + 17 + 4, 16, reinterpret_cast<const char*>(box), 16);  // after the attribute's size
    WriteFileAtomically(path, bytes);
    return path;
  };
  claiming("huge.exr", 65536, 32768);
  claiming("thin.exr", 8192, 4096);
  scene::testing::SceneSandbox hostile("cli_huge");
  hostile.json()["envmap"]["file"] = "huge.exr";
  fs::copy_file(sandbox.dir() / "huge.exr", hostile.dir() / "huge.exr", fs::copy_options::overwrite_existing);
  const fs::path huge = hostile.Write();
  fs::create_symlink(sandbox.dir() / "loop", sandbox.dir() / "loop");
  ::mkfifo((sandbox.dir() / "fifo").c_str(), 0644);
  // An OBJ whose coordinate is a 5 MB token: the error quotes 60 characters of it.
  scene::testing::SceneSandbox long_obj("cli_long_token");
  long_obj.WriteText("long.obj", "o ground\nv " + std::string(5 << 20, '7') + "x 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  long_obj.json()["model"]["file"] = "long.obj";
  const fs::path long_token = long_obj.Write();
  scene::testing::SceneSandbox empty("cli_no_surfaces");
  empty.json()["diffuse_surfaces"] = nlohmann::json::array();
  const fs::path no_surfaces = empty.Write();
  // A garbage .glb object: said before any bake (render baked 15 s before it read the object).
  scene::testing::SceneSandbox glb("cli_garbage_glb");
  glb.WriteText("statue.glb", "glTF but not a binary glTF");
  glb.json()["objects"] = {{{"mesh", "statue.glb"}, {"position", {0, 0, 0.5}}}};
  const fs::path garbage_glb = glb.Write();
  // Objects the ray tracer cannot hold (issue 43: Embree aborted on a 1e30 m sphere).
  scene::testing::SceneSandbox planet("cli_planet");
  planet.json()["objects"] = {{{"mesh", "builtin:sphere"}, {"radius", 1e30}, {"position", {0, 0, 1}}}};
  const fs::path planet_scene = planet.Write();
  scene::testing::SceneSandbox far("cli_far");
  far.json()["objects"] = {{{"mesh", "builtin:box"}, {"size", {1, 1, 1}}, {"position", {1e30, 0, 0}}}};
  const fs::path far_scene = far.Write();
  // A glTF whose buffer climbs out of the recording, percent-encoded.
  scene::testing::SceneSandbox escape("cli_gltf_escape");
  escape.WriteText("statue.gltf", R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "buffers": [{"uri": "%2e%2e/%2e%2e/%2e%2e/%2e%2e/%2e%2e/%2e%2e/etc/passwd", "byteLength": 36}],
      "bufferViews": [{"buffer": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})");
  escape.json()["objects"] = {{{"mesh", "statue.gltf"}, {"position", {0, 0, 0.5}}}};
  const fs::path escape_scene = escape.Write();
  scene::testing::SceneSandbox live("cli_live");
  live.json()["frames"] = {{"device", "/dev/video-daylit-absent"}, {"fps", 30}};
  const fs::path live_scene = live.Write();
  const BadCall calls[] = {
      {"estimate " + live_scene.string(), "/dev/video-daylit-absent: cannot open (No such file or directory); is the camera plugged in?"},
      {"live --scene " + live_scene.string() + " --out " + dir + "/live.mp4",
       "/dev/video-daylit-absent: cannot open (No such file or directory); is the camera plugged in?"},
      {"live --scene " + kRecording, "frames name recorded frames, not a camera; replay them with daylit replay"},
      {"info /no/such/recording", "/no/such/recording: no such file or folder"},
      {"info " + dir + "/broken.json", "broken.json: invalid JSON"},
      {"info " + nan_scene.string(), "nan.obj:3: vertex coordinate y is not a finite number ('nan')"},
      {"sunpos --time 2026-06-21T10:00:00 --lat 57 --lon 9", "--time: time has no zone"},
      {"sunpos --time 2026-06-21T10:00:00Z --lat 123 --lon 9", "--latitude_deg: 123 is outside [-90, 90]"},
      {"sunpos --time 2026-06-21T10:00:00Z --lat 57", "--lat and --lon are required"},
      {"sunpos --csv /no/such.csv", "/no/such.csv: cannot open"},
      {"sunpos --frobnicate", "frobnicate"},
      {"relight-env " + std::string(DAYLIT_SOURCE_DIR) + "/recordings/courtyard-a --frame 99999",
       "--frame: 99999 is not in"},
      {"estimate " + std::string(DAYLIT_SOURCE_DIR) + "/recordings/courtyard-a --samples -5",
       "--samples: Value -5 not in range 100 to 1000000"},
      {"lights " + kProbe + " --n 0 --out " + dir + "/l", "--n: 0 lights; the number of lights must be in [1, 128]"},
      {"lights " + kProbe + " --n 1,500 --out " + dir + "/l", "--n: 500 lights; the number of lights must be in [1, 128]"},
      {"lights " + kProbe + " --n 2000 --method mediancut --out " + dir + "/l",
       "--n: 2000 lights; the number of lights must be in [1, 1024]"},
      {"lights " + kProbe + " --n four --out " + dir + "/l", "--n: 'four' is not a number of lights"},
      {"lights " + kProbe + " --method kmeans --out " + dir + "/l", "--method: 'kmeans' is not one of mediancut, io, sh"},
      {"lights " + kProbe + " --threshold 5 --out " + dir + "/l", "--threshold: 5 is not a mean relative error in (0, 1)"},
      {"lights " + dir + "/broken.json --out " + dir + "/l", "broken.json"},
      {"calibrate-response " + kProbe + " " + kProbe + " --times 1", "--times: 1 exposure times for 2 images"},
      {"calibrate-response " + kProbe + " " + kProbe + " --times 1,1", "have the same exposure time 1 s"},
      {"calibrate-response " + dir + "/none.png " + dir + "/none.png --times 1,2", "none.png: no such file"},
      {"calibrate-camera " + dir + "/broken.json --board 9by6", "--board: '9by6' is not COLSxROWS"},
      {"calibrate-camera " + dir + "/broken.json --board 99999x99999", "--board: 99999x99999 inner corners; at most 100 a side"},
      {"calibrate-camera " + dir + "/broken.json", "broken.json: cannot be decoded as an image"},
      {"record --device /dev/video-daylit-absent --scene " + kRecording + " --out " + dir + "/rec",
       "/dev/video-daylit-absent: cannot open (No such file or directory); is the camera plugged in?"},
      {"record --from " + kRecording + " --out " + dir, "exists; record into a new folder"},
      {"record --device /dev/video-daylit-absent --scene " + kRecording + " --out " + dir + "/rec --exposure-100us -5",
       "--exposure-100us: Value -5 not in range 1 to 1000000"},
      {"render " + kRecording + " --frame 300 --out " + dir + "/frame.jpg", "--out: " + dir + "/frame.jpg must end in .png or .exr"},
      {"render " + kRecording + " --frame 99999 --out " + dir + "/frame.png", "--frame: 99999 is not in"},
      {"replay " + kRecording + " --out " + dir + "/r.avi", "--out: " + dir + "/r.avi must end in .mp4 or .mkv"},
      {"replay " + kRecording + " --out " + dir + "/no/such/r.mp4", "--out: " + dir + "/no/such: no such folder"},
      {"replay " + kRecording + " --out /proc/r.mp4", "--out: cannot write /proc/r.mp4"},
      {"replay " + kRecording + " --frames 0", "--frames: 0 is not a number of frames"},
      {"replay " + kRecording + " --screenshot " + dir + "/s.png", "--screenshot: needs --window"},
      {"replay " + kRecording + " --relight-at 18:30", "--relight-at: needs --window"},
      {"replay " + kRecording + " --lighting lights:0", "--lighting: 0 lights; give 1 to 16"},
      {"render " + kRecording + " --frame 300 --lighting lights:99 --out " + dir + "/f.png", "--lighting: 99 lights; give 1 to 16"},
      {"render " + kRecording + " --frame 300 --lighting sun --out " + dir + "/f.png", "--lighting: 'sun' is not volume or lights:N"},
      {"replay " + kRecording + " --window --relight-at 25:00", "--relight-at: '25:00' is not a UTC time of day HH:MM"},
      {"relight " + kRecording + " --out " + dir + "/r.mp4",
       "give the new sun one way: --at, --sun-azimuth with --sun-elevation, or --like-frame"},
      {"relight " + kRecording + " --at 2026-06-21T10:00:00 --out " + dir + "/r.mp4", "--at: time has no zone"},
      {"relight " + kRecording + " --sun-azimuth 10 --out " + dir + "/r.mp4", "--sun-azimuth and --sun-elevation go together"},
      {"relight " + kRecording + " --sun-azimuth 10 --sun-elevation 95 --out " + dir + "/r.mp4", "--sun-elevation: 95 is outside [-90, 90]"},
      {"relight " + kRecording + " --like-frame 99999 --out " + dir + "/r.mp4", "--like-frame: 99999 is not in"},
      {"relight " + kRecording + " --like-frame 5 --frame 3 --out " + dir + "/r.mp4", "--out: " + dir + "/r.mp4 must end in .png or .exr"},
      {"relight " + kRecording + " --like-frame 5 --frames 5 --out " + dir + "/r.mp4", "--frames: '5' is not a:b (frame numbers)"},
      {"relight " + kRecording + " --like-frame 5 --frames 9:3 --out " + dir + "/r.mp4", "--frames: 9:3 ends before it starts"},
      {"relight " + kRecording + " --like-frame 5 --sky up --out " + dir + "/r.mp4", "--sky: 'up' is not keep or follow"},
      {"relight " + kRecording + " --like-frame 5 --e-sun 1,2 --out " + dir + "/r.mp4", "--e-sun: give R,G,B (2 values given)"},
      {"relight " + kRecording + " --like-frame 5 --out " + dir + "/r.avi", "--out: " + dir + "/r.avi must end in .mp4 or .mkv"},
      // Two outputs of one run with one name, refused before any work (issue 21).
      {"estimate " + kRecording + " --out " + dir + "/y.csv --plot " + dir + "/y.csv",
       "--out and --plot (or the --out's .png) both name " + dir + "/y.csv"},
      {"estimate " + kRecording + " --out " + dir + "/x.png", "--out and --plot (or the --out's .png) both name " + dir + "/x.png"},
      {"sunpos --scene " + kRecording + " --frames --out " + dir + "/s.png --plot " + dir + "/s.png",
       "--out and --plot both name " + dir + "/s.png"},
      {"relight-env " + kRecording + " --frame 0 --out " + dir + "/e.png", "--out: " + dir + "/e.png must end in .exr"},
      {"sunpos --time 2026-06-21T10:00:00Z --lat 50 --lon 10 --dut1 5", "--dut1: 5 s is not UT1 − UTC"},
      {"sunpos --time 2026-06-21T10:00:00Z --lat 50 --lon 10 --delta-t 1e300", "--delta-t: '1e300' is not a finite number within ±1e30"},
      {"sunpos --time 2026-06-21T10:00:00Z --lat 50 --lon 10 --delta-t 30000", "--delta-t: 30000 s is outside [-1000, 20000]"},
      // NaN and inf on the command line (issue 43): CLI11's Range let NaN through, and a double
      // beyond float's range overflowed the relit map to inf.
      {"calibrate-scene " + kRecording + " --out " + dir + "/c.json --north-range nan", "--north-range: 'nan' is not a finite number"},
      {"calibrate-scene " + kRecording + " --out " + dir + "/c.json --clock-range nan", "--clock-range: 'nan' is not a finite number"},
      {"relight " + kRecording + " --like-frame 5 --e-sun 1e39,1e39,1e39 --out " + dir + "/r.mp4", "--e-sun: '1e39' is not a finite number"},
      {"relight " + kRecording + " --like-frame 5 --e-sun 1e20,1,1 --out " + dir + "/r.mp4", "--e-sun: 1e+20 is not an irradiance (finite, in [0, 1e9])"},
      {"sunpos --time 2026-06-21T10:00:00Z --lat nan --lon 10", "--lat: 'nan' is not a finite number"},
      {"sunpos --time 2023-03-01T23:59:60Z --lat 50 --lon 10", "no leap second ends that UTC day"},
      // Paths that are not what they must be (issue 21): bad input, exit 2, with the path.
      {"info " + (sandbox.dir() / "loop").string(), "loop: Too many levels of symbolic links"},
      {"info /dev/zero", "/dev/zero: is not a regular file"},
      {"info " + (sandbox.dir() / "fifo").string(), "fifo: is not a regular file"},
      {"lights " + kProbe + " --out " + dir + "/broken.json", "broken.json"},
      {"estimate " + kRecording + " --out " + dir, "--out: " + dir + " is a folder, not a file to write"},
      {"estimate " + kRecording + " --out /proc/y.csv", "--out: /proc: may not be written to"},
      {"estimate " + kRecording + " --cache /proc/daylit-cache", "/proc/daylit-cache: cannot create the cache folder"},
      {"render " + kRecording + " --frame 300 --out /proc/f.png", "--out: /proc: may not be written to"},
      {"estimate " + kRecording + " --frames 0", "--frames: 0 is not a number of frames"},
      {"info " + long_token.string(), "vertex coordinate x is not a finite number"},
      {"info " + no_surfaces.string(), "diffuse_surfaces: empty"},
      {"render " + garbage_glb.string() + " --frame 0 --out " + dir + "/f.png", "statue.glb: not a glTF 2.0 file"},
      {"estimate " + garbage_glb.string(), "statue.glb: not a glTF 2.0 file"},
      {"render " + planet_scene.string() + " --frame 0 --out " + dir + "/f.png",
       "objects[0]: reaches 1e+30 m from the scene's origin; a virtual object must lie within 10000 m"},
      {"replay " + far_scene.string() + " --out " + dir + "/r.mp4",
       "objects[0]: reaches 1e+30 m from the scene's origin; a virtual object must lie within 10000 m"},
      {"info " + escape_scene.string(), "outside the recording folder"},
      // The command line itself.
      {"frobnicate", "'frobnicate' is not a daylit command"},
      {"lights " + (sandbox.dir() / "huge.exr").string() + " --out " + dir + "/l",
       "huge.exr: its header claims 65536x32768 pixels, over daylit's limit of 16384x8192"},
      {"lights " + (sandbox.dir() / "thin.exr").string() + " --out " + dir + "/l",
       "thin.exr: its header claims 8192x4096 pixels, which no compression fits in its"},
  };
  // info prints as it goes: the recording's lines, then the env map's error.
  const CliRun info = Daylit("info " + huge.string());
  EXPECT_EQ(info.exit_code, 2);
  EXPECT_NE(info.err.find("huge.exr: its header claims 65536x32768 pixels, over daylit's limit of 16384x8192"), std::string::npos)
      << info.err;
  for (const BadCall& call : calls) {
    const CliRun run = Daylit(call.args);  // NOLINT
    EXPECT_EQ(run.exit_code, 2) << call.args;
    EXPECT_NE(run.err.find(call.error), std::string::npos) << call.args << "\n" << run.err.substr(0, 2000);
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << call.args << "\n" << run.err.substr(0, 2000);
    EXPECT_LT(run.err.size(), 400u) << call.args;  // one line, quoting at most an excerpt
    EXPECT_EQ(run.out, "") << call.args;
  }
}

// An output never lands on what the run reads (issue 43): `--out` naming the recording's video,
// env map, model, frames.csv, ground truth or scene files, one of a command's input images, or a
// symlink to any of them, is refused with exit 2 before any work, and every input keeps its bytes.
// Paths as a user types them, relative to the folder they are in: a scene named by its bare file
// name from its own folder (its folder the working one: it was "a path: Invalid argument", exit
// 2), an --out without a folder; the refusal to replace a recording's file holds there too.
TEST(CliTest, PathsRelativeToTheWorkingFolderWork) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_relative_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path rec = dir / "rec";
  fs::create_directories(rec);
  for (const char* f : {"scene.json", "model.obj", "frames.csv", "video.mp4", "envmap.exr", "groundtruth.csv"}) {
    fs::copy_file(fs::path(kRecording) / f, rec / f);
  }
  fs::create_symlink(fs::path(kRecording) / "groundtruth", rec / "groundtruth");
  const std::string cache = std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const std::string in_recording = "cd " + rec.string() + " && ", in_dir = "cd " + dir.string() + " && ";
  const auto from_its_folder = Daylit("estimate scene.json --cache " + cache + " --frames 3 --out " + (dir / "a.csv").string(),
                                      in_recording);
  EXPECT_EQ(from_its_folder.exit_code, 0) << from_its_folder.err;
  EXPECT_EQ(ReadCsvFile(dir / "a.csv").rows.size(), 3u);
  const auto bare_out = Daylit("estimate rec --cache " + cache + " --frames 3 --out b.csv", in_dir);
  EXPECT_EQ(bare_out.exit_code, 0) << bare_out.err;
  EXPECT_EQ(ReadCsvFile(dir / "b.csv").rows.size(), 3u);
  const std::string frames = ReadTextFile(rec / "frames.csv");
  const auto replacing = Daylit("estimate scene.json --cache " + cache + " --frames 3 --out frames.csv", in_recording);
  EXPECT_EQ(replacing.exit_code, 2) << replacing.err;
  EXPECT_NE(replacing.err.find("frames.csv"), std::string::npos) << replacing.err;
  EXPECT_EQ(ReadTextFile(rec / "frames.csv"), frames);
  fs::remove_all(dir);
}

TEST(CliTest, AnOutputThatNamesAnInputIsRefusedAndTheInputIsUntouched) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_inputs_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path rec = dir / "rec", linked = dir / "linked";
  fs::create_directories(rec);
  fs::create_directories(linked);
  for (const char* f : {"scene.json", "model.obj", "frames.csv", "video.mp4", "envmap.exr", "groundtruth.csv"}) {
    fs::copy_file(fs::path(kRecording) / f, rec / f);
  }
  fs::create_symlink(fs::path(kRecording) / "groundtruth", rec / "groundtruth");
  // A recording whose video is a symlink into the first one: --out through the link is the video.
  for (const char* f : {"scene.json", "model.obj", "frames.csv", "envmap.exr", "groundtruth.csv"}) {
    fs::copy_file(rec / f, linked / f);
  }
  fs::create_symlink(fs::path(kRecording) / "groundtruth", linked / "groundtruth");
  fs::create_symlink(rec / "video.mp4", linked / "video.mp4");
  fs::create_directories(dir / "images");
  const fs::path b0 = dir / "images" / "b0.png";
  cv::imwrite(b0.string(), cv::Mat(16, 16, CV_8UC3, cv::Scalar(40, 80, 120)));
  cv::imwrite((dir / "images" / "b1.png").string(), cv::Mat(16, 16, CV_8UC3, cv::Scalar(80, 160, 240)));
  const fs::path page = dir / "page.md.in";
  WriteFileAtomically(page, "figure {{a}}\n");
  const auto bytes = [](const fs::path& p) { return ReadTextFile(p); };
  std::map<fs::path, std::string> before;
  for (const fs::path& p : {rec / "scene.json", rec / "model.obj", rec / "frames.csv", rec / "video.mp4", rec / "envmap.exr",
                            rec / "groundtruth.csv", b0, page}) {
    before[p] = bytes(p);
  }
  const std::string cache = " --cache " + std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const std::string r = rec.string();
  const BadCall calls[] = {
      {"replay " + r + cache + " --frames 5 --out " + r + "/video.mp4", "names a file this run reads"},
      {"replay " + linked.string() + cache + " --frames 5 --out " + linked.string() + "/video.mp4", "names a file this run reads"},
      {"replay " + linked.string() + cache + " --frames 5 --out " + r + "/video.mp4", "names a file this run reads"},
      {"relight-env " + r + cache + " --frame 0 --out " + r + "/envmap.exr", "names a file this run reads"},
      {"calibrate-scene " + r + cache + " --out " + r + "/model.obj", "names a file this run reads"},
      {"calibrate-scene " + r + cache + " --out " + r + "/frames.csv", "names a file this run reads"},
      {"calibrate-scene " + r + cache + " --out " + dir.string() + "/s.json --figures " + r + "/scene.json",
       "names a file this run reads"},
      {"estimate " + r + cache + " --out " + r + "/groundtruth.csv", "names a file this run reads"},
      {"estimate " + r + cache + " --residuals " + r + "/groundtruth", "which this run reads"},
      {"render " + r + cache + " --frame 0 --out " + r + "/envmap.exr", "names a file this run reads"},
      {"sunpos --scene " + r + " --frames --out " + r + "/frames.csv", "names a file this run reads"},
      {"calibrate-response " + b0.string() + " " + (dir / "images" / "b1.png").string() + " --times 1,2 --out " + b0.string(),
       "names a file this run reads"},
      {"calibrate-response " + b0.string() + " " + (dir / "images" / "b1.png").string() + " --times 1,2 --out " +
           (dir / "images" / "b0.csv").string(),
       "names a file this run reads"},  // its plot, b0.png
      {"results " + page.string() + " " + dir.string() + " --out " + page.string(), "names a file this run reads"},
  };
  ExpectEachRefused(calls);
  for (const auto& [path, content] : before) EXPECT_TRUE(bytes(path) == content) << path << " changed";
  EXPECT_TRUE(fs::is_symlink(linked / "video.mp4"));
  for (const fs::path& folder : {rec, linked, dir / "images"}) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
    }
  }
  fs::remove_all(dir);
}

// Issue 52: any file already in the recording's folder is the user's, whether this run reads it
// or not (a glTF's buffer and textures, an OBJ's .mtl), and so are the files written beside --out
// (render's and relight's strips, replay's lighting.png, --residuals' files); a bake cache in the
// recording is a folder of its own (new, empty or a bake); lights never writes over its probe. Each was replaced with exit 0.
TEST(CliTest, AFileOfTheRecordingOrTheProbeIsNeverReplaced) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_keep_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path rec = dir / "rec", objects = rec / "objects";
  fs::create_directories(objects);
  for (const char* f : {"scene.json", "model.obj", "frames.csv", "video.mp4", "envmap.exr", "groundtruth.csv"}) {
    fs::copy_file(fs::path(kRecording) / f, rec / f);
  }
  fs::create_symlink(fs::path(kRecording) / "groundtruth", rec / "groundtruth");
  std::map<fs::path, std::string> before;
  for (const char* f : {"x.bin", "tex.png", "a_vs_truth.png", "b_strip.png", "lighting.png", "residuals.png"}) {
    WriteFileAtomically(objects / f, std::string("the user's ") + f);
  }
  WriteFileAtomically(rec / "model.mtl", "newmtl stone\n");
  // A probe saved as errors.png, and an --out folder whose errors.csv links to another probe.
  const fs::path probe = dir / "probe" / "errors.png", other = dir / "other.exr", out = dir / "lights";
  fs::create_directories(probe.parent_path());
  fs::create_directories(out);
  fs::copy_file(fs::path(kRecording) / "envmap.exr", other);
  WriteFileAtomically(probe, "not really a png");
  fs::create_symlink(other, out / "errors.csv");
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) before[entry.path()] = ReadTextFile(entry.path());
  }
  const std::string cache = " --cache " + std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const std::string r = rec.string(), o = objects.string();
  const BadCall calls[] = {
      {"estimate " + r + cache + " --out " + o + "/x.bin", "is a file of the recording"},
      {"estimate " + r + cache + " --out " + o + "/tex.csv", "is a file of the recording"},  // its plot, tex.png
      {"estimate " + r + cache + " --out " + r + "/model.mtl", "is a file of the recording"},
      {"estimate " + r + cache + " --out " + dir.string() + "/e.csv --residuals " + o, "is a file of the recording"},
      {"render " + r + cache + " --frame 40 --out " + o + "/tex.png", "is a file of the recording"},
      {"render " + r + cache + " --frame 40 --out " + o + "/a.png", "is a file of the recording"},  // a_vs_truth.png
      {"relight " + r + cache + " --frame 40 --like-frame 450 --out " + o + "/b.png", "is a file of the recording"},
      {"replay " + r + cache + " --frames 5 --out " + o + "/r.mp4", "is a file of the recording"},  // lighting.png
      {"bake " + r + " --cache " + o, "lies in the recording and holds files that are not a bake's"},
      {"bake " + r + " --cache " + r, "is the recording's folder"},
      {"lights " + probe.string() + " --n 1 --method mediancut --out " + probe.parent_path().string(),
       "names a file this run reads"},
      {"lights " + other.string() + " --n 1 --method mediancut --out " + out.string(), "names a file this run reads"},
  };
  ExpectEachRefused(calls);
  for (const auto& [path, content] : before) EXPECT_TRUE(ReadTextFile(path) == content) << path << " changed";
  EXPECT_TRUE(fs::is_symlink(out / "errors.csv"));
  // A new name in the recording is still written (the rule protects files, not the folder).
  const CliRun fresh = Daylit("estimate " + r + cache + " --frames 3 --out " + r + "/fresh.csv");
  EXPECT_EQ(fresh.exit_code, 0) << fresh.err;
  EXPECT_TRUE(fs::is_regular_file(rec / "fresh.csv"));
  fs::remove_all(dir);
}

// calibrate-scene on one burst (--frames 100): one time of day, so north alone is fitted and the
// output says why; written outside the recording, its paths lead back to the recording's files;
// what it cannot fit is refused by name.
TEST(CliTest, CalibrateSceneFitsNorthOnOneBurstAndWritesAResolvableScene) {
  const fs::path dir = fs::temp_directory_path() / ("daylit_cli_calibrate_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string cache = " --cache " + std::string(DAYLIT_BINARY_DIR) + "/test-cache/courtyard-a";
  const CliRun run = Daylit("calibrate-scene " + kRecording + cache + " --frames 100 --out " + (dir / "scene.json").string() +
                            " --figures " + (dir / "fit.json").string());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("only north was fitted"), std::string::npos) << run.out;
  const nlohmann::json fit = nlohmann::json::parse(ReadTextFile(dir / "fit.json"));
  EXPECT_TRUE(fit["north_fitted"].get<bool>());
  EXPECT_FALSE(fit["clock_fitted"].get<bool>());
  EXPECT_EQ(fit["bursts"].get<int>(), 1);
  // The bundled scene's north is right; one early burst (sun 17° up, 1 400 edge pixels on the
  // coarse grid) pins it only to ±0.34° (measured: +0.375°), and the fit says so.
  const double sigma = fit["north_sigma_deg"].get<double>();
  EXPECT_GT(sigma, 0.05);
  EXPECT_LE(std::abs(fit["north_offset_deg"].get<double>()), 2.0 * sigma);
  const nlohmann::json written = nlohmann::json::parse(ReadTextFile(dir / "scene.json"));
  EXPECT_EQ(fs::weakly_canonical(dir / written["model"]["file"].get<std::string>()),
            fs::weakly_canonical(fs::path(kRecording) / "model.obj"));
  EXPECT_FALSE(written["frames"].contains("clock_offset_s"));  // not fitted, not written
  const CliRun info = Daylit("--allow-outside-paths info " + (dir / "scene.json").string() + " --no-shadow-check");
  EXPECT_EQ(info.exit_code, 0) << info.err;
  EXPECT_FALSE(fs::exists(fs::path(kRecording) / "scene.json.bak"));
  // Written in place twice: each run keeps the scene it replaced (.bak, then .bak.1), so the
  // user's first scene is never lost.
  const std::string first = ReadTextFile(dir / "scene.json");
  for (int i = 0; i < 2; ++i) {
    const CliRun again = Daylit("--allow-outside-paths calibrate-scene " + (dir / "scene.json").string() + cache +
                                " --frames 10 --out " + (dir / "scene.json").string());
    ASSERT_EQ(again.exit_code, 0) << again.err;
  }
  EXPECT_EQ(ReadTextFile(dir / "scene.json.bak"), first);
  EXPECT_TRUE(fs::is_regular_file(dir / "scene.json.bak.1"));
  EXPECT_FALSE(fs::exists(dir / "scene.json.bak.2"));

  const CliRun bad = Daylit("calibrate-scene " + kRecording + cache + " --what sky --out " + (dir / "x.json").string());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--what"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "x.json"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace daylit

namespace daylit {
namespace {

// --serve takes its port before any work: a port in use, or text that is not [HOST:]PORT, exits 2
// with one line naming it, and nothing is written (no bake, no video).
TEST(CliTest, ServeOnAPortInUseOrNotAPortExitsWithCode2BeforeAnyWork) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
  ASSERT_EQ(listen(fd, 1), 0);
  socklen_t length = sizeof(addr);
  ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length), 0);
  const int port = ntohs(addr.sin_port);
  const fs::path dir = fs::temp_directory_path() / fmt::format("daylit_serve_{}", ::getpid());
  fs::create_directories(dir);
  const std::string common = " --cache " + (dir / "cache").string() + " --out " + (dir / "r.mp4").string();
  const CliRun taken = Daylit(fmt::format("replay {} --serve {}{}", kRecording, port, common));
  EXPECT_EQ(taken.exit_code, 2) << taken.err;
  EXPECT_NE(taken.err.find(fmt::format("--serve: cannot listen on 127.0.0.1:{}: Address already in use", port)),
            std::string::npos)
      << taken.err;
  const CliRun bad = Daylit("replay " + kRecording + " --serve localhost:http" + common);
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--serve: 'localhost:http' is not [HOST:]PORT"), std::string::npos) << bad.err;
  const CliRun hold = Daylit("replay " + kRecording + " --hold" + common);  // nothing to hold without a server
  EXPECT_EQ(hold.exit_code, 2) << hold.err;
  EXPECT_NE(hold.err.find("--hold: needs --serve"), std::string::npos) << hold.err;
  EXPECT_FALSE(fs::exists(dir / "cache"));
  EXPECT_FALSE(fs::exists(dir / "r.mp4"));
  close(fd);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace daylit
