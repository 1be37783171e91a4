#include "estimation/recording_estimator.h"

#include <tbb/concurrent_queue.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <thread>
#include <cmath>
#include <map>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "base/csv.h"
#include "base/error.h"
#include "base/log.h"
#include "base/progress.h"
#include "base/statistics.h"
#include "capture/frame_source.h"
#include "report/plot.h"
#include "sunmodel/solar_position.h"

namespace daylit::estimation {
namespace {

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> v) { return MedianInPlace(v, static_cast<double>(NAN)); }

// What the source said for one frame (never kWaiting), and the frame.
struct DecodedFrame {
  capture::FrameStatus status = capture::FrameStatus::kEnd;
  capture::Frame frame;
  std::exception_ptr error;  // a failure that is not the frame's own: ends the run
};

// Reads the scene's frames (its FrameSource) in order on its own thread, a few ahead of the
// estimation, so that decoding and estimating overlap. One result per frame from `first_row` on
// (a frame, or one that could not be read), then one saying the end. While a live camera is gone
// nothing comes, and the estimate holds.
class FramePipeline {
 public:
  explicit FramePipeline(std::unique_ptr<capture::FrameSource> source) : source_(std::move(source)) {
    queue_.set_capacity(4);
    thread_ = std::thread([this] { Run(); });
  }
  ~FramePipeline() {
    // Wakes a reader blocked on a full queue (abort), and empties the queue so that one that was
    // still decoding pushes without waiting; either way it then sees stop_ and ends.
    stop_ = true;
    queue_.abort();
    DecodedFrame dropped;
    while (queue_.try_pop(dropped)) {}
    thread_.join();
  }
  DecodedFrame Next() {
    DecodedFrame frame;
    queue_.pop(frame);
    if (frame.error) std::rethrow_exception(frame.error);
    return frame;
  }

 private:
  void Run() {
    while (!stop_) {
      DecodedFrame frame;
      try {
        frame.status = source_->Next(&frame.frame);
        if (frame.status == capture::FrameStatus::kWaiting) continue;
      } catch (...) {
        frame.error = std::current_exception();
      }
      const bool last = static_cast<bool>(frame.error) || frame.status == capture::FrameStatus::kEnd;
      try {
        queue_.push(std::move(frame));  // waits while the estimation is 4 frames behind
      } catch (const tbb::user_abort&) {
        return;
      }
      if (last) return;
    }
  }

  std::unique_ptr<capture::FrameSource> source_;
  tbb::concurrent_bounded_queue<DecodedFrame> queue_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace

EstimateRun EstimateRecording(const scene::Scene& scene, const bake::SceneBake& bake, const EstimateOptions& options) {
  return EstimateRecording(scene, bake, options, scene::OpenFrameSource(scene));
}

EstimateRun EstimateRecording(const scene::Scene& scene, const bake::SceneBake& bake, const EstimateOptions& options,
                              std::unique_ptr<capture::FrameSource> source) {
  const scene::RayCaster caster(scene.model);
  const glm::vec3 capture = scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f);
  Sampler sampler(bake, capture, caster, options.sampler);
  TemporalFilter filter(options.filter);
  const capture::Linearizer linearizer(scene.response);
  const sunmodel::Atmosphere atmosphere = sunmodel::Atmosphere::Standard(scene.location.elevation_m);
  const sunmodel::SceneGeoFrame geo = scene.GeoFrame();
  EstimateRun run;
  // A recording's length is known; a live camera's is --frames, else until stopped.
  std::optional<size_t> total;
  if (scene.frame_times) total = scene.frame_times->frames.size();
  if (options.max_frames) total = std::min(total.value_or(SIZE_MAX), static_cast<size_t>(*options.max_frames));
  std::optional<Progress> progress;
  if (total) progress.emplace(options.progress_label, *total);
  const Clock::time_point start = Clock::now();
  std::vector<double> frame_ms;  // estimation after decoding, frames without a sun move
  FramePipeline frames(std::move(source));
  std::optional<UtcTime> first;
  double overcast_share = 0.0;  // the last usable fit's, held like the light
  for (size_t i = 0; !total || i < *total; ++i) {
    if (options.stop != nullptr && options.stop->load()) break;
    const DecodedFrame next = frames.Next();
    if (next.status == capture::FrameStatus::kEnd) break;
    const bool ok = next.status == capture::FrameStatus::kFrame;
    const capture::Frame& decoded = next.frame;
    FrameEstimate row;
    row.frame = decoded.index;
    row.time_utc = decoded.utc;
    const sunmodel::SunPosition sun = sunmodel::ComputeSunPosition(decoded.utc, scene.location, atmosphere, {});
    row.sun_elevation_deg = sun.ApparentElevationDeg();
    row.sun_azimuth_deg = sun.azimuth_deg;
    if (!first) first = decoded.utc;
    const double t_s = decoded.utc.SecondsSince(*first);
    if (!ok || decoded.rgb.cols != bake.camera.width || decoded.rgb.rows != bake.camera.height) {
      row.decoded = false;
      ++run.undecodable;
      if (ok) {
        Log().warn("{}: frame {} is {}x{}, not the camera's {}x{}; skipped", scene.file.string(), row.frame,
                   decoded.rgb.cols, decoded.rgb.rows, bake.camera.width, bake.camera.height);
      }
      const FilteredLight held = filter.Update(t_s, std::nullopt, 0.0);
      row.light = held.light, row.confidence = held.confidence;
      run.frames.push_back(row);
      if (options.on_frame) {
        const glm::vec3 sun_dir(geo.DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg));
        options.on_frame(row, capture::Frame{}, sun_dir, overcast_share);
      }
      if (progress) progress->Advance();
      continue;
    }
    const Clock::time_point began = Clock::now();
    const glm::vec3 sun_dir(geo.DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg));
    const bool moved = sampler.SetSun(sun_dir);
    const std::vector<Sample> samples = sampler.Draw(decoded.rgb, decoded.exposure, decoded.linear ? nullptr : &linearizer);
    const SunSkyFitSummary fit = FitSunSky(options.fit, samples);
    const FilteredLight filtered =
        filter.Update(t_s, fit.IsUsable() ? std::optional<SunSky>(fit.light) : std::nullopt, fit.confidence);
    const double ms = 1e3 * std::chrono::duration<double>(Clock::now() - began).count();
    if (moved) {
      run.sun_moves_ms.push_back(ms);
    } else {
      frame_ms.push_back(ms);
    }
    if (fit.IsUsable()) overcast_share = fit.overcast_share;
    row.light = filtered.light;
    row.confidence = filtered.confidence;
    row.samples = static_cast<int>(samples.size());
    run.frames.push_back(row);
    if (options.on_frame) options.on_frame(row, decoded, sun_dir, overcast_share);
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const double fps = static_cast<double>(i + 1) / std::max(elapsed, 1e-9);
    if (progress) {
      progress->Advance();
      progress->SetSuffix(fmt::format("{:.0f} fps", fps));
    } else if ((i + 1) % 100 == 0) {
      Log().info("{} frames, {:.0f} fps; E_sun ({:.3g}, {:.3g}, {:.3g}), E_sky ({:.3g}, {:.3g}, {:.3g})", i + 1, fps,
                 row.light.sun_rgb.x, row.light.sun_rgb.y, row.light.sun_rgb.z, row.light.sky_rgb.x,
                 row.light.sky_rgb.y, row.light.sky_rgb.z);
    }
  }
  run.median_frame_ms = Median(frame_ms);
  run.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return run;
}

FrameFit FitFrame(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster, size_t position,
                  const EstimateOptions& options) {
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no recorded frames", scene.file.string());
  const std::vector<capture::FrameTime>& times = scene.frame_times->frames;
  if (position >= times.size()) {
    ThrowInputError("{}: frame {} is past the recording's {} frames", scene.file.string(), position, times.size());
  }
  std::unique_ptr<capture::FrameSource> source = scene::OpenFrameSource(scene);
  source->Seek(times[position].index);
  capture::Frame frame;
  if (source->Next(&frame) != capture::FrameStatus::kFrame) {
    ThrowInputError("{}: frame {} cannot be decoded", scene.file.string(), times[position].index);
  }
  return FitDecodedFrame(scene, bake, caster, std::move(frame), options);
}

FrameFit FitDecodedFrame(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                         capture::Frame frame, const EstimateOptions& options) {
  FrameFit out;
  out.row.frame = frame.index;
  out.row.time_utc = frame.utc;
  if (frame.rgb.cols != bake.camera.width || frame.rgb.rows != bake.camera.height) {
    ThrowInputError("{}: frame {} is {}x{}, not the camera's {}x{}", scene.file.string(), frame.index, frame.rgb.cols,
                    frame.rgb.rows, bake.camera.width, bake.camera.height);
  }
  const sunmodel::SunPosition sun = sunmodel::ComputeSunPosition(
      frame.utc, scene.location, sunmodel::Atmosphere::Standard(scene.location.elevation_m), {});
  out.row.sun_elevation_deg = sun.ApparentElevationDeg();
  out.row.sun_azimuth_deg = sun.azimuth_deg;
  out.sun_dir = glm::vec3(scene.GeoFrame().DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg));
  const glm::vec3 capture = scene.envmap ? glm::vec3(scene.envmap->position) : glm::vec3(0.0f);
  Sampler sampler(bake, capture, caster, options.sampler);
  sampler.SetSun(out.sun_dir);
  const capture::Linearizer linearizer(scene.response);
  const std::vector<Sample> samples = sampler.Draw(frame.rgb, frame.exposure, frame.linear ? nullptr : &linearizer);
  out.fit = FitSunSky(options.fit, samples);
  out.row.light = out.fit.light;
  out.row.confidence = out.fit.confidence;
  out.row.samples = static_cast<int>(samples.size());
  out.frame = std::move(frame);
  return out;
}

std::string EstimatesCsv(const std::vector<FrameEstimate>& frames) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "frame,time_utc,sun_elevation_deg,sun_azimuth_deg,sun_r,sun_g,sun_b,sky_r,"
                                          "sky_g,sky_b,confidence,samples\n");
  for (const FrameEstimate& f : frames) {
    fmt::format_to(std::back_inserter(out), "{},{},{:.4f},{:.4f},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{}\n",
                   f.frame, FormatUtcTime(f.time_utc), f.sun_elevation_deg, f.sun_azimuth_deg, f.light.sun_rgb.x,
                   f.light.sun_rgb.y, f.light.sun_rgb.z, f.light.sky_rgb.x, f.light.sky_rgb.y, f.light.sky_rgb.z,
                   f.confidence, f.samples);
  }
  return fmt::to_string(out);
}

TruthComparison CompareWithTruth(const std::vector<FrameEstimate>& frames, const std::filesystem::path& groundtruth_csv) {
  const CsvTable table = ReadCsvFile(groundtruth_csv);
  const size_t c_frame = static_cast<size_t>(table.RequireColumn("frame"));
  std::array<size_t, 6> c{};
  const char* names[6] = {"sun_r", "sun_g", "sun_b", "sky_r", "sky_g", "sky_b"};
  for (size_t k = 0; k < 6; ++k) c[k] = static_cast<size_t>(table.RequireColumn(names[k]));
  std::map<int, SunSky> truth_by_frame;
  for (size_t r = 0; r < table.rows.size(); ++r) {
    SunSky t;
    for (int k = 0; k < 3; ++k) {
      t.sun_rgb[k] = ParseFiniteDouble(table.rows[r][c[static_cast<size_t>(k)]], table.Where(r));
      t.sky_rgb[k] = ParseFiniteDouble(table.rows[r][c[static_cast<size_t>(k) + 3]], table.Where(r));
    }
    truth_by_frame[static_cast<int>(ParseFiniteDouble(table.rows[r][c_frame], table.Where(r)))] = t;
  }
  TruthComparison cmp;
  std::array<std::vector<double>, 3> sun, sky, ratio;
  for (const FrameEstimate& f : frames) {
    const auto it = truth_by_frame.find(f.frame);
    cmp.truth.push_back(it == truth_by_frame.end() ? SunSky{glm::dvec3(NAN), glm::dvec3(NAN)} : it->second);
    if (it == truth_by_frame.end() || !f.decoded) continue;
    ++cmp.frames;
    for (int k = 0; k < 3; ++k) {
      const double ts = it->second.sun_rgb[k], tk = it->second.sky_rgb[k];
      if (tk > 0) sky[static_cast<size_t>(k)].push_back(std::abs(f.light.sky_rgb[k] / tk - 1.0));
      if (ts > 0) sun[static_cast<size_t>(k)].push_back(std::abs(f.light.sun_rgb[k] / ts - 1.0));
      if (ts > 0 && tk > 0 && f.light.sky_rgb[k] > 0) {
        ratio[static_cast<size_t>(k)].push_back(std::abs((f.light.sun_rgb[k] / f.light.sky_rgb[k]) / (ts / tk) - 1.0));
      }
    }
  }
  for (int k = 0; k < 3; ++k) {
    cmp.sun_error[k] = Median(sun[static_cast<size_t>(k)]);
    cmp.sky_error[k] = Median(sky[static_cast<size_t>(k)]);
    cmp.ratio_error[k] = Median(ratio[static_cast<size_t>(k)]);
  }
  return cmp;
}

void PlotEstimates(const std::vector<FrameEstimate>& frames, const TruthComparison* truth, const std::string& title,
                   const std::filesystem::path& png) {
  std::vector<cv::Mat> panels;
  for (const bool sun : {true, false}) {
    report::LinePlot plot({sun ? title + ": E_sun (DNI), estimate solid, truth dashed" : "E_sky (DHI)",
                           sun ? "" : "frame", "radiance units", 1400, 360, true});
    for (int k = 0; k < 3; ++k) {
      const std::array<int, 3> color = k == 0 ? std::array<int, 3>{214, 39, 40} : k == 1 ? std::array<int, 3>{44, 160, 44}
                                                                                          : std::array<int, 3>{31, 119, 180};
      report::Series est{std::string(1, "RGB"[k]), {}, {}, color, false, false};
      report::Series tru{std::string(1, "RGB"[k]) + " truth", {}, {}, color, true, false};
      for (size_t i = 0; i < frames.size(); ++i) {
        est.x.push_back(frames[i].frame);
        est.y.push_back(sun ? frames[i].light.sun_rgb[k] : frames[i].light.sky_rgb[k]);
        if (truth != nullptr) {
          tru.x.push_back(frames[i].frame);
          tru.y.push_back(sun ? truth->truth[i].sun_rgb[k] : truth->truth[i].sky_rgb[k]);
        }
      }
      plot.Add(std::move(est));
      if (truth != nullptr) plot.Add(std::move(tru));
    }
    panels.push_back(plot.Render());
  }
  report::WritePng(png, panels);
}

}  // namespace daylit::estimation
