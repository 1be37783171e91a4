#include "calibrate/shadow_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "base/error.h"
#include "base/log.h"
#include "bake/surface_light.h"
#include "base/progress.h"
#include "capture/frame_source.h"
#include "capture/read_ahead.h"
#include "estimation/frame_estimator.h"
#include "scene/sun_tracker.h"
#include "sunmodel/geo_frame.h"
#include "sunmodel/solar_position.h"

namespace daylit::calibrate {
namespace {

constexpr float kNoSigma = std::numeric_limits<float>::quiet_NaN();
constexpr float kRayOffsetM = 2e-3f;  // shadow rays start this far off the surface (as the transfer's)
constexpr int kMinClearFrames = 3;     // a burst with fewer gives no σ
constexpr size_t kMinSunlitPixels = 200;  // nor one whose σ shows less sun than this

// How sunlit each diffuse pixel of `frame` (of the G-buffer's size) looks under the frame's light:
// the irradiance π·L/ρ less the sky's share E_sky·V, over the sun's E_sun·cos. Only the diffuse
// pixels are linearized (as LinearRadiance would).
void SunlitFraction(const bake::CameraGBuffer& g, const std::vector<uint32_t>& diffuse, const capture::Frame& frame,
                    const capture::Linearizer& linearizer, const estimation::SunSky& light, const glm::vec3& sun_dir,
                    std::vector<float>* sigma) {
  sigma->resize(diffuse.size());
  const glm::vec3 e_sun(light.sun_rgb), e_sky(light.sky_rgb);
  const float sun_sum = e_sun.x + e_sun.y + e_sun.z;
  const float saturated = static_cast<float>(0.98 / frame.exposure);
  const float scale = static_cast<float>(1.0 / frame.exposure);
  const uint32_t width = static_cast<uint32_t>(g.width);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, diffuse.size(), 4096), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const uint32_t p = diffuse[i];
      const float c = glm::dot(g.normal[p], sun_dir);
      const glm::vec3 rho = g.albedo[p];
      const float* in = frame.rgb.ptr<float>(static_cast<int>(p / width)) + 3 * (p % width);
      float linear[3] = {in[0], in[1], in[2]};
      if (!frame.linear) linearizer.Apply(in, linear, 3);
      const glm::vec3 l = glm::vec3(linear[0], linear[1], linear[2]) * scale;
      if (c < 0.05f || rho.x < 0.02f || rho.y < 0.02f || rho.z < 0.02f || l.x >= saturated || l.y >= saturated ||
          l.z >= saturated) {
        (*sigma)[i] = kNoSigma;
        continue;
      }
      const glm::vec3 beyond_sky = glm::pi<float>() * l / rho - e_sky * g.sky_visibility[p];
      (*sigma)[i] = (beyond_sky.x + beyond_sky.y + beyond_sky.z) / (sun_sum * c);
    }
  });
}

// The burst's σ: the median over its clear frames, per pixel, where at least half of them saw it.
BurstShadows MedianShadows(const bake::CameraGBuffer& g, const std::vector<uint32_t>& diffuse,
                           const std::vector<const std::vector<float>*>& frames, const UtcTime& time, const scene::Scene& scene,
                           double min_cos) {
  BurstShadows burst;
  burst.frames = static_cast<int>(frames.size());
  burst.time = time;
  const glm::vec3 sun = SunWith(scene, burst.time, 0.0, 0.0);
  std::vector<float> values;
  for (size_t i = 0; i < diffuse.size(); ++i) {
    if (glm::dot(g.normal[diffuse[i]], sun) < static_cast<float>(min_cos)) continue;
    values.clear();
    for (const std::vector<float>* f : frames) {
      if (!std::isnan((*f)[i])) values.push_back((*f)[i]);
    }
    if (2 * values.size() < frames.size() || values.empty()) continue;
    const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    burst.pixels.push_back(diffuse[i]);
    burst.sunlit.push_back(std::clamp(*mid, 0.0f, 1.0f));
  }
  return burst;
}

// A burst's pixels as the search sees them: the surface point each one shows and its normal
// (zero where it shows no model, under a rotated pose: never sunlit), and its ray in camera
// coordinates.
struct BurstRays {
  std::vector<glm::vec3> point, normal;
  std::vector<glm::dvec3> camera_dir;
};

// Σ |σ − V| over the listed pixels (`v` aligned with `which`).
double Mismatch(const std::vector<float>& sigma, const std::vector<uint32_t>& which, const std::vector<uint8_t>& v) {
  double s = 0.0;
  for (size_t i = 0; i < which.size(); ++i) s += std::abs(sigma[which[i]] - static_cast<float>(v[i]));
  return s;
}

// The search's state: every burst's rays and σ, and the sun of each burst for given offsets.
class ShadowScore {
 public:
  ShadowScore(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
              const ShadowObservations& observed)
      : scene_(scene), caster_(caster), observed_(observed) {
    const glm::dmat3& cam_from_world = scene.cam_from_world.rotation;
    const scene::CameraModel camera = scene.Camera();
    for (const BurstShadows& b : observed.bursts) {
      BurstRays r;
      std::vector<glm::dvec2> pixels;
      for (uint32_t p : b.pixels) {
        r.point.push_back(bake.camera.point[p]);
        r.normal.push_back(bake.camera.normal[p]);
        pixels.push_back({static_cast<double>(p % static_cast<uint32_t>(bake.camera.width)),
                          static_cast<double>(p / static_cast<uint32_t>(bake.camera.width))});
      }
      for (const glm::dvec3& d : camera.UnprojectToWorldRays(pixels)) r.camera_dir.push_back(cam_from_world * d);
      rays_.push_back(std::move(r));
    }
  }

  // The rays of a camera rotated by `rotation_deg` (RotatedPose): each pixel's point is where its
  // ray from the camera's centre now meets the model.
  void UsePose(const glm::dvec3& rotation_deg) {
    for (size_t b = 0; b < rays_.size(); ++b) {
      std::vector<uint32_t> every(rays_[b].camera_dir.size());
      std::iota(every.begin(), every.end(), 0u);
      SeenByRotatedCamera(b, every, rotation_deg, &rays_[b].point, &rays_[b].normal);
    }
  }

  size_t bursts() const { return rays_.size(); }
  size_t pixels(size_t b) const { return rays_[b].point.size(); }

  // V (1: the sun reaches it) of the listed pixels of burst `b` for the offsets.
  void Visibility(size_t b, const std::vector<uint32_t>& which, double north, double clock, std::vector<uint8_t>* v) const {
    std::vector<glm::vec3> points, normals;
    points.clear(), normals.clear();
    for (uint32_t i : which) points.push_back(rays_[b].point[i]), normals.push_back(rays_[b].normal[i]);
    SunVisibility(b, points, normals, north, clock, v);
  }

  // V of the listed pixels of burst `b` seen by the camera rotated by `rotation_deg` (their rays
  // meet the model anew), for the offsets.
  void PoseVisibility(size_t b, const std::vector<uint32_t>& which, const glm::dvec3& rotation_deg, double north,
                      double clock, std::vector<uint8_t>* v) const {
    std::vector<glm::vec3> points, normals;
    SeenByRotatedCamera(b, which, rotation_deg, &points, &normals);
    SunVisibility(b, points, normals, north, clock, v);
  }

  // Σ |σ − V| over the listed pixels of each burst, per burst, for the rotated camera.
  std::vector<double> PerBurstPose(const std::vector<std::vector<uint32_t>>& which, const glm::dvec3& rotation_deg,
                                   double north, double clock) const {
    std::vector<double> score(bursts(), 0.0);
    std::vector<uint8_t> v;
    for (size_t b = 0; b < bursts(); ++b) {
      PoseVisibility(b, which[b], rotation_deg, north, clock, &v);
      score[b] = Mismatch(observed_.bursts[b].sunlit, which[b], v);
    }
    return score;
  }

  // Σ |σ − V| over the listed pixels of each burst (`which[b]`), per burst.
  std::vector<double> PerBurst(const std::vector<std::vector<uint32_t>>& which, double north, double clock) const {
    std::vector<double> score(bursts(), 0.0);
    std::vector<uint8_t> v;
    for (size_t b = 0; b < bursts(); ++b) {
      Visibility(b, which[b], north, clock, &v);
      score[b] = Mismatch(observed_.bursts[b].sunlit, which[b], v);
    }
    return score;
  }

  // The listed pixels' sides, summed over the bursts: how many, how many on the wrong side
  // (|σ − V| > 0.5), and how many sides drawn independently with each burst's own shares would
  // put there, Σ_b n_b·(p_b(1 − q_b) + (1 − p_b)q_b) (p the model's sunlit share, q the frames',
  // σ > 0.5). Chance is counted per burst, so a burst that is all sunlit in both adds nothing to
  // the agreement.
  struct Sides {
    double pixels = 0.0, wrong = 0.0, chance = 0.0;
  };
  Sides CountSides(const std::vector<std::vector<uint32_t>>& which, double north, double clock) const {
    Sides sides;
    std::vector<uint8_t> v;
    for (size_t b = 0; b < bursts(); ++b) {
      if (which[b].empty()) continue;
      Visibility(b, which[b], north, clock, &v);
      const std::vector<float>& sigma = observed_.bursts[b].sunlit;
      double model_lit = 0.0, frame_lit = 0.0;
      for (size_t i = 0; i < which[b].size(); ++i) {
        const float s = sigma[which[b][i]];
        sides.wrong += std::abs(s - static_cast<float>(v[i])) > 0.5f, model_lit += v[i] != 0, frame_lit += s > 0.5f;
      }
      const double n = static_cast<double>(which[b].size()), p = model_lit / n, q = frame_lit / n;
      sides.pixels += n, sides.chance += n * (p * (1.0 - q) + (1.0 - p) * q);
    }
    return sides;
  }

  // The share of the listed pixels on the wrong side.
  double Disagree(const std::vector<std::vector<uint32_t>>& which, double north, double clock) const {
    const Sides sides = CountSides(which, north, clock);
    return sides.pixels == 0.0 ? 0.0 : sides.wrong / sides.pixels;
  }

  // Cohen's kappa of the model's sides against the frames': 1 − wrong / chance. 0: the model's
  // shadows tell no more about the frames' than a coin of the right bias would; 1: they agree
  // everywhere.
  double Kappa(const std::vector<std::vector<uint32_t>>& which, double north, double clock) const {
    const Sides sides = CountSides(which, north, clock);
    return sides.chance <= 0.0 ? 0.0 : 1.0 - sides.wrong / sides.chance;
  }

 private:
  // bake::SunVisibility of the points toward burst `b`'s sun for the offsets; none at night.
  void SunVisibility(size_t b, const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& normals, double north,
                     double clock, std::vector<uint8_t>* v) const {
    const glm::vec3 sun = SunWith(scene_, observed_.bursts[b].time, north, clock);
    v->assign(points.size(), 0);
    if (sun.z <= 0.0f) return;
    bake::SunVisibility(caster_, points.data(), normals.data(), points.size(), sun, kRayOffsetM, v->data());
  }

  // Where the listed pixels of burst `b` meet the model when the camera is rotated by
  // `rotation_deg` about its centre: points and normals (zero where they see no model).
  void SeenByRotatedCamera(size_t b, const std::vector<uint32_t>& which, const glm::dvec3& rotation_deg,
                           std::vector<glm::vec3>* points, std::vector<glm::vec3>* normals) const {
    const scene::RigidPose pose = RotatedPose(scene_.cam_from_world, rotation_deg);
    const glm::dmat3 world_from_cam = glm::transpose(pose.rotation);
    const glm::vec3 centre(pose.CenterInWorld());
    const size_t n = which.size();
    std::vector<glm::vec3> origins(n, centre), dirs(n);
    for (size_t i = 0; i < n; ++i) dirs[i] = glm::vec3(glm::normalize(world_from_cam * rays_[b].camera_dir[which[i]]));
    std::vector<scene::RayHit> hits(n);
    caster_.IntersectMany(origins.data(), dirs.data(), n, 0.0f, hits.data());
    points->resize(n), normals->resize(n);
    for (size_t i = 0; i < n; ++i) {
      (*points)[i] = hits[i].IsHit() ? centre + hits[i].t * dirs[i] : centre;
      (*normals)[i] = hits[i].IsHit() ? hits[i].normal : glm::vec3(0.0f);
    }
  }

  const scene::Scene& scene_;
  const scene::RayCaster& caster_;
  const ShadowObservations& observed_;
  std::vector<BurstRays> rays_;
};

struct Offsets {
  double north = 0.0, clock = 0.0;
};

double Sum(const std::vector<double>& v, int leave_out = -1) {
  double s = 0.0;
  for (size_t i = 0; i < v.size(); ++i) s += static_cast<int>(i) == leave_out ? 0.0 : v[i];
  return s;
}

// Halving pattern search from `start`: at each step the best of the 3×3 neighbourhood (only the
// fitted axes) until the centre is best, then half the step, until below the tolerances.
Offsets PatternSearch(const ShadowScore& score, const std::vector<std::vector<uint32_t>>& which, Offsets start,
                      double north_step, double clock_step, const FitOptions& options, int leave_out,
                      const Offsets& low, const Offsets& high) {
  const auto total = [&](const Offsets& o) { return Sum(score.PerBurst(which, o.north, o.clock), leave_out); };
  Offsets best = start;
  double best_score = total(best);
  while ((options.north && north_step >= options.north_tolerance_deg) || (options.clock && clock_step >= options.clock_tolerance_s)) {
    for (int move = 0; move < 6; ++move) {
      Offsets centre = best;
      for (int i = options.north ? -1 : 0; i <= (options.north ? 1 : 0); ++i) {
        for (int j = options.clock ? -1 : 0; j <= (options.clock ? 1 : 0); ++j) {
          if (i == 0 && j == 0) continue;
          const Offsets o{std::clamp(centre.north + i * north_step, low.north, high.north),
                          std::clamp(centre.clock + j * clock_step, low.clock, high.clock)};
          const double s = total(o);
          if (s < best_score) best_score = s, best = o;
        }
      }
      if (best.north == centre.north && best.clock == centre.clock) break;
    }
    north_step *= 0.5, clock_step *= 0.5;
  }
  return best;
}

}  // namespace

glm::vec3 SunWith(const scene::Scene& scene, const UtcTime& utc, double north_offset_deg, double clock_offset_s) {
  const sunmodel::SunPosition sun = sunmodel::ComputeSunPosition(
      ShiftedUtc(utc, clock_offset_s), scene.location, sunmodel::Atmosphere::Standard(scene.location.elevation_m), {});
  const sunmodel::SceneGeoFrame geo(scene.location, scene.north_azimuth_deg + north_offset_deg);
  return glm::vec3(geo.DirectionInScene(sun.azimuth_deg, sun.apparent_zenith_deg));
}

ShadowObserver::ShadowObserver(const scene::Scene& scene, const bake::SceneBake& bake, const ObserveOptions& options)
    : scene_(scene), bake_(bake), options_(options), linearizer_(scene.response) {
  const bake::CameraGBuffer& g = bake.camera;
  std::vector<uint8_t> near(g.surface.size(), 0);
  const int r = options.silhouette_margin_px;
  if (r > 0) {
    const int w = g.width, h = g.height;
    cv::Mat edges(h, w, CV_8UC1, cv::Scalar(0));
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const uint32_t s = g.surface[static_cast<size_t>(y) * w + x];
        if ((x + 1 < w && g.surface[static_cast<size_t>(y) * w + x + 1] != s) ||
            (y + 1 < h && g.surface[static_cast<size_t>(y + 1) * w + x] != s)) {
          edges.at<uint8_t>(y, x) = 255;
        }
      }
    }
    cv::Mat grown;
    cv::dilate(edges, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    for (size_t p = 0; p < near.size(); ++p) near[p] = grown.data[p] != 0;
  }
  for (uint32_t p = 0; p < g.surface.size(); ++p) {
    if (g.diffuse[p] && g.surface[p] != bake::kNoSurface && !near[p]) diffuse_.push_back(p);
  }
}

void ShadowObserver::Step(const capture::Frame& frame) {
  const bool gap = previous_ && capture::StartsBurst(*previous_, frame.utc);
  const bool cut = previous_ && !gap && options_.max_burst_s > 0.0 && frame.utc.SecondsSince(start_) >= options_.max_burst_s;
  if (gap || cut) CloseBurst();
  if (!previous_ || gap || cut) first_ = frame.index, start_ = frame.utc;
  previous_ = frame.utc, last_ = frame.index;
}

void ShadowObserver::AddUnreadable(const capture::Frame& frame) { Step(frame); }

void ShadowObserver::Add(const capture::Frame& frame, const estimation::FrameEstimate& row) {
  Step(frame);
  ++out_.frames_read;
  if (!row.sun_up || !row.HasEstimate() || row.sunlit_samples < 30) return;
  const glm::dvec3& e_sun = row.light.sun_rgb;
  const glm::dvec3& e_sky = row.light.sky_rgb;
  const double ratio = (e_sun.x + e_sun.y + e_sun.z) / (e_sky.x + e_sky.y + e_sky.z);
  if (!(ratio >= options_.min_sun_to_sky)) return;
  auto weakest = std::min_element(kept_.begin(), kept_.end(),
                                  [](const ClearFrame& a, const ClearFrame& b) { return a.sun_to_sky < b.sun_to_sky; });
  const bool full = static_cast<int>(kept_.size()) >= options_.frames_per_burst;
  if (full && weakest->sun_to_sky >= ratio) return;
  ClearFrame f{ratio, frame.utc, frame.index, {}};
  SunlitFraction(bake_.camera, diffuse_, frame, linearizer_, row.light, SunWith(scene_, frame.utc, 0.0, 0.0), &f.sigma);
  if (full) {
    *weakest = std::move(f);
  } else {
    kept_.push_back(std::move(f));
  }
}

void ShadowObserver::CloseBurst() {
  if (static_cast<int>(kept_.size()) >= kMinClearFrames) {
    std::sort(kept_.begin(), kept_.end(), [](const ClearFrame& a, const ClearFrame& b) { return a.index < b.index; });
    std::vector<const std::vector<float>*> sigma;
    for (const ClearFrame& f : kept_) sigma.push_back(&f.sigma);
    BurstShadows b = MedianShadows(bake_.camera, diffuse_, sigma, kept_[kept_.size() / 2].utc, scene_, options_.min_cos);
    b.burst = out_.bursts_seen, b.first_frame = first_, b.last_frame = last_;
    const size_t sunlit = static_cast<size_t>(std::count_if(b.sunlit.begin(), b.sunlit.end(), [](float s) { return s > 0.5f; }));
    if (sunlit >= kMinSunlitPixels) {
      out_.bursts.push_back(std::move(b));
    } else {
      Log().info("burst {} (frames {}-{}): {} pixels of the model look sunlit; left out", out_.bursts_seen, first_, last_, sunlit);
    }
  }
  kept_.clear();
  ++out_.bursts_seen;
}

ShadowObservations ShadowObserver::Finish() {
  if (previous_) CloseBurst();
  previous_.reset();
  return std::move(out_);
}

ShadowObservations ObserveShadows(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                                  const ObserveOptions& options) {
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no recorded frames", scene.file.string());
  std::unique_ptr<capture::FrameSource> frames = capture::ReadAhead(scene::OpenFrameSource(scene), 4);
  scene::SunTracker tracker(scene);
  estimation::FrameEstimator estimator(scene, bake, caster, {});
  ShadowObserver observer(scene, bake, options);
  size_t total = scene.frame_times->frames.size();
  if (options.max_frames > 0) total = std::min(total, static_cast<size_t>(options.max_frames));
  Progress progress("shadows", total);
  for (size_t i = 0; i < total; ++i) {
    capture::Frame frame;
    const capture::FrameStatus status = frames->Next(&frame);
    if (status == capture::FrameStatus::kEnd) break;
    progress.Advance();
    const scene::TrackedSun& sun = tracker.Update(frame.utc);
    if (status != capture::FrameStatus::kFrame || frame.rgb.cols != bake.camera.width || frame.rgb.rows != bake.camera.height) {
      observer.AddUnreadable(frame);
      continue;
    }
    observer.Add(frame, estimator.Estimate(frame, sun).row);
  }
  ShadowObservations out = observer.Finish();
  if (out.frames_read == 0) ThrowInputError("{}: no frame of the recording could be read", scene.file.string());
  return out;
}

namespace {

// FitNorthAndClock on the rays of `score` (the bake's camera, or a rotated one).
FitResult FitWithScore(const scene::Scene& scene, const ShadowObservations& observed, const ShadowScore& score,
                       const FitOptions& requested) {
  if (observed.bursts.empty()) {
    ThrowInputError("{}: no burst of the {} shows the sun on the model's diffuse surfaces (overcast, or the sun on none "
                    "of them): the footage cannot constrain north or the clock",
                    scene.file.string(), observed.bursts_seen == 1 ? "one burst" : fmt::format("{} bursts", observed.bursts_seen));
  }
  FitOptions options = requested;
  FitResult result;
  double earliest = 0.0, latest = 0.0;
  for (const BurstShadows& b : observed.bursts) {
    const double t = b.time.SecondsSince(observed.bursts.front().time);
    earliest = std::min(earliest, t), latest = std::max(latest, t);
    result.frames += b.frames;
    result.pixels += b.pixels.size();
  }
  result.bursts = static_cast<int>(observed.bursts.size());
  if (options.north && options.clock && latest - earliest < options.min_span_for_both_s) {
    options.clock = false;
    result.note = fmt::format(
        "the bursts with sun span {:.0f} min, one time of day: a north offset and a clock offset move the sun alike "
        "(along its path), so only north was fitted and the clock held; bursts {:.0f} min or more apart give both",
        (latest - earliest) / 60.0, options.min_span_for_both_s / 60.0);
  }
  if (!options.north && !options.clock) ThrowInputError("calibrate: nothing to fit (give north or clock)");
  result.north_fitted = options.north, result.clock_fitted = options.clock;
  const size_t bursts = score.bursts();

  // The coarse grid over every n-th pixel.
  std::vector<std::vector<uint32_t>> coarse(bursts), all(bursts);
  for (size_t b = 0; b < bursts; ++b) {
    for (uint32_t i = 0; i < score.pixels(b); ++i) {
      all[b].push_back(i);
      if (i % static_cast<uint32_t>(std::max(1, options.coarse_stride)) == 0) coarse[b].push_back(i);
    }
  }
  const int north_steps = options.north ? static_cast<int>(std::round(options.north_range_deg / options.north_step_deg)) : 0;
  const int clock_steps = options.clock ? static_cast<int>(std::round(options.clock_range_s / options.clock_step_s)) : 0;
  const Offsets low{-north_steps * options.north_step_deg, -clock_steps * options.clock_step_s};
  const Offsets high{north_steps * options.north_step_deg, clock_steps * options.clock_step_s};
  // Which coarse pixels change sides anywhere on the grid: the edges (the rest add the same to
  // every candidate).
  std::vector<std::vector<uint8_t>> seen(bursts);
  std::vector<std::vector<uint8_t>> first_v(bursts);
  Offsets best;
  double best_score = std::numeric_limits<double>::infinity();
  std::vector<uint8_t> v;
  Progress progress("search", static_cast<size_t>((2 * north_steps + 1) * (2 * clock_steps + 1)));
  for (int i = -north_steps; i <= north_steps; ++i) {
    for (int j = -clock_steps; j <= clock_steps; ++j) {
      const Offsets o{i * options.north_step_deg, j * options.clock_step_s};
      double s = 0.0;
      for (size_t b = 0; b < bursts; ++b) {
        score.Visibility(b, coarse[b], o.north, o.clock, &v);
        if (first_v[b].empty()) first_v[b] = v, seen[b].assign(v.size(), 0);
        s += Mismatch(observed.bursts[b].sunlit, coarse[b], v);
        for (size_t k = 0; k < v.size(); ++k) seen[b][k] |= v[k] != first_v[b][k];
      }
      if (s < best_score) best_score = s, best = o;
      progress.Advance();
    }
  }
  std::vector<std::vector<uint32_t>> edges(bursts);
  for (size_t b = 0; b < bursts; ++b) {
    for (size_t k = 0; k < coarse[b].size(); ++k) {
      if (seen[b][k]) edges[b].push_back(coarse[b][k]);
    }
    result.edge_pixels += edges[b].size();
  }
  result.at_range_edge = (options.north && std::abs(best.north) >= high.north - 1e-9) ||
                         (options.clock && std::abs(best.clock) >= high.clock - 1e-9);

  // The fine search over every pixel near the coarse best's edges: those whose side changes
  // within two coarse steps of it.
  std::vector<std::vector<uint32_t>> band(bursts);
  for (size_t b = 0; b < bursts; ++b) {
    std::vector<uint8_t> changes(all[b].size(), 0), base;
    score.Visibility(b, all[b], best.north, best.clock, &base);
    for (int i = options.north ? -2 : 0; i <= (options.north ? 2 : 0); ++i) {
      for (int j = options.clock ? -2 : 0; j <= (options.clock ? 2 : 0); ++j) {
        if (i == 0 && j == 0) continue;
        score.Visibility(b, all[b], best.north + i * options.north_step_deg, best.clock + j * options.clock_step_s, &v);
        for (size_t k = 0; k < v.size(); ++k) changes[k] |= v[k] != base[k];
      }
    }
    for (size_t k = 0; k < all[b].size(); ++k) {
      if (changes[k]) band[b].push_back(all[b][k]);
    }
  }
  const Offsets fine = PatternSearch(score, band, best, 0.5 * options.north_step_deg, 0.5 * options.clock_step_s, options, -1,
                                     low, high);
  result.north_offset_deg = fine.north, result.clock_offset_s = fine.clock;
  result.disagree_before = score.Disagree(edges, 0.0, 0.0);
  result.disagree_after = score.Disagree(edges, fine.north, fine.clock);
  result.kappa_after = score.Kappa(coarse, fine.north, fine.clock);
  for (const double away : {-40.0, -20.0, 20.0, 40.0}) {
    result.kappa_away = std::max(result.kappa_away, score.Kappa(coarse, fine.north + away, fine.clock));
  }

  // The uncertainty: the jackknife over bursts (each left out in turn, searched again from the
  // fit), or with fewer than three, where the score rises by its own noise (√ of the edge count).
  if (bursts >= 3) {
    std::vector<Offsets> leave(bursts);
    for (size_t b = 0; b < bursts; ++b) {
      leave[b] = PatternSearch(score, band, fine, 0.25 * options.north_step_deg, 0.25 * options.clock_step_s, options,
                               static_cast<int>(b), low, high);
    }
    const double n = static_cast<double>(bursts);
    Offsets mean;
    for (const Offsets& o : leave) mean.north += o.north / n, mean.clock += o.clock / n;
    double vn = 0.0, vc = 0.0;
    for (const Offsets& o : leave) vn += (o.north - mean.north) * (o.north - mean.north), vc += (o.clock - mean.clock) * (o.clock - mean.clock);
    result.north_sigma_deg = std::sqrt((n - 1.0) / n * vn), result.clock_sigma_s = std::sqrt((n - 1.0) / n * vc);
  } else {
    const double at_best = Sum(score.PerBurst(band, fine.north, fine.clock));
    size_t band_pixels = 0;
    for (const auto& b : band) band_pixels += b.size();
    const double rise = std::max(1.0, std::sqrt(static_cast<double>(band_pixels)));
    const auto width = [&](bool north_axis, double step, double limit) {
      double w = 0.0;
      for (int side : {-1, 1}) {
        double d = step;
        while (d < limit) {
          const Offsets o{fine.north + (north_axis ? side * d : 0.0), fine.clock + (north_axis ? 0.0 : side * d)};
          if (Sum(score.PerBurst(band, o.north, o.clock)) > at_best + rise) break;
          d += step;
        }
        w += 0.5 * d;
      }
      return w;
    };
    if (options.north) result.north_sigma_deg = width(true, options.north_tolerance_deg * 2.0, 2.0 * options.north_step_deg);
    if (options.clock) result.clock_sigma_s = width(false, options.clock_tolerance_s * 2.0, 2.0 * options.clock_step_s);
  }
  return result;
}


// The camera rotation (degrees, axis-angle in camera coordinates) whose view puts the model's
// shadows on σ, and with `north` the north offset with it (a turn of the camera about the vertical
// and a turn of the sun about it trade against each other, so they are searched together): a
// pattern search from `start`, moving each coordinate and each pair with north by ±step until the
// centre is best, then half the step, from `first_step_deg` to under 0.01°; rotations within
// ±range. `leave_out`: a burst left out of the score (the jackknife), or −1.
struct PoseAndNorth {
  glm::dvec3 rotation{0.0};
  double north = 0.0;
};
PoseAndNorth FitRotation(const ShadowScore& score, const std::vector<std::vector<uint32_t>>& which, PoseAndNorth start,
                         double clock, bool north, double range_deg, double first_step_deg, int leave_out) {
  const auto total = [&](const PoseAndNorth& p) { return Sum(score.PerBurstPose(which, p.rotation, p.north, clock), leave_out); };
  // Moves: ±1 on one coordinate (3 rotations, north), and with north, ±1 on a rotation and ±1 on north.
  std::vector<glm::dvec4> moves;
  for (int axis = 0; axis < (north ? 4 : 3); ++axis) {
    for (int side : {-1, 1}) {
      glm::dvec4 m(0.0);
      m[axis] = side;
      moves.push_back(m);
    }
  }
  for (int axis = 0; north && axis < 3; ++axis) {
    for (int a : {-1, 1}) {
      for (int b : {-1, 1}) {
        glm::dvec4 m(0.0);
        m[axis] = a, m[3] = b;
        moves.push_back(m);
      }
    }
  }
  PoseAndNorth best = start;
  double best_score = total(best);
  for (double step = first_step_deg; step >= 0.01; step *= 0.5) {
    for (int move = 0; move < 8; ++move) {
      const PoseAndNorth centre = best;
      for (const glm::dvec4& m : moves) {
        PoseAndNorth p = centre;
        for (int axis = 0; axis < 3; ++axis) p.rotation[axis] = std::clamp(p.rotation[axis] + m[axis] * step, -range_deg, range_deg);
        p.north += m[3] * step;
        const double s = total(p);
        if (s < best_score) best_score = s, best = p;
      }
      if (best.rotation == centre.rotation && best.north == centre.north) break;
    }
  }
  return best;
}

// The pixels (every second one) whose side changes when the camera turns by 1° either way about
// any axis from `rotation_deg`: where a rotation shows in the score.
std::vector<std::vector<uint32_t>> PoseBand(const ShadowScore& score, const glm::dvec3& rotation_deg, const Offsets& offsets) {
  std::vector<std::vector<uint32_t>> band(score.bursts());
  std::vector<uint8_t> base, v;
  for (size_t b = 0; b < score.bursts(); ++b) {
    std::vector<uint32_t> every;
    for (uint32_t i = 0; i < score.pixels(b); i += 2) every.push_back(i);
    score.PoseVisibility(b, every, rotation_deg, offsets.north, offsets.clock, &base);
    std::vector<uint8_t> changes(every.size(), 0);
    for (int axis = 0; axis < 3; ++axis) {
      for (int side : {-1, 1}) {
        glm::dvec3 r = rotation_deg;
        r[axis] += side * 1.0;
        score.PoseVisibility(b, every, r, offsets.north, offsets.clock, &v);
        for (size_t k = 0; k < v.size(); ++k) changes[k] |= v[k] != base[k];
      }
    }
    for (size_t k = 0; k < every.size(); ++k) {
      if (changes[k]) band[b].push_back(every[k]);
    }
  }
  return band;
}

}  // namespace

scene::RigidPose RotatedPose(const scene::RigidPose& cam_from_world, const glm::dvec3& rotation_deg) {
  const glm::dvec3 w = glm::radians(rotation_deg);
  const double angle = glm::length(w);
  glm::dmat3 delta(1.0);
  if (angle > 0.0) {
    const cv::Mat rodrigues = (cv::Mat_<double>(3, 1) << w.x, w.y, w.z);
    cv::Mat m;
    cv::Rodrigues(rodrigues, m);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) delta[c][r] = m.at<double>(r, c);  // glm is column-major
    }
  }
  return {delta * cam_from_world.rotation, delta * cam_from_world.translation};
}

std::string EnvMapSunBeyondRange(const scene::Scene& scene, const bake::SceneBake& bake, double north_range_deg) {
  if (!scene.envmap || !bake.capture_sun.above_horizon) return {};
  const glm::vec3 at = SunWith(scene, scene.envmap->time_utc, 0.0, 0.0);
  double reach = 0.0;  // how far a north within the range moves the capture's sun
  for (double north : {-north_range_deg, north_range_deg}) {
    const glm::vec3 moved = SunWith(scene, scene.envmap->time_utc, north, 0.0);
    reach = std::max(reach, glm::degrees(std::acos(std::clamp(static_cast<double>(glm::dot(at, moved)), -1.0, 1.0))));
  }
  const double offset = bake.capture_sun.brightest_offset_deg;
  if (offset <= reach + 1.0) return {};
  return fmt::format("the env map's sun lies {:.1f} deg from where the scene puts it at envmap.time_utc, beyond the {:.1f} deg "
                     "a north within ±{:g} deg could explain: north_azimuth_deg (or envmap.time_utc) is off by more than the "
                     "search covers",
                     offset, reach, north_range_deg);
}

FitResult FitNorthAndClock(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                           const ShadowObservations& observed, const FitOptions& options) {
  return FitWithScore(scene, observed, ShadowScore(scene, bake, caster, observed), options);
}

std::vector<uint8_t> CaptureEdgeMask(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                                     double north_offset_deg) {
  const bake::CameraGBuffer& g = bake.camera;
  if (!scene.envmap) return std::vector<uint8_t>(g.surface.size(), 0);
  std::vector<uint32_t> seen;  // pixels whose albedo is the env map's own texel's
  std::vector<glm::vec3> points, normals;
  for (uint32_t p = 0; p < g.surface.size(); ++p) {
    if (g.surface[p] != bake::kNoSurface && g.env_texel[p] != bake::kNoSurface) {
      seen.push_back(p);
      points.push_back(g.point[p]), normals.push_back(g.normal[p]);
    }
  }
  const int steps = std::max(2, static_cast<int>(std::ceil(std::abs(north_offset_deg) / 0.1)));
  std::vector<uint8_t> first(seen.size()), now(seen.size()), differs(seen.size(), 0);
  for (int k = 0; k <= steps; ++k) {
    const glm::vec3 sun = SunWith(scene, scene.envmap->time_utc, north_offset_deg * k / steps, 0.0);
    bake::SunVisibility(caster, points.data(), normals.data(), seen.size(), sun, kRayOffsetM, (k == 0 ? first : now).data());
    for (size_t i = 0; k > 0 && i < seen.size(); ++i) differs[i] |= now[i] != first[i];
  }
  cv::Mat mask(g.height, g.width, CV_8UC1, cv::Scalar(0));
  for (size_t i = 0; i < seen.size(); ++i) mask.data[seen[i]] = differs[i];
  // The env map's texels are coarser than the camera's pixels: its albedo errs a little beyond.
  cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  return std::vector<uint8_t>(mask.data, mask.data + mask.total());
}

namespace {

// The north/clock fit, then the camera's rotation with them held, north and clock again from the
// rotated camera, and the rotation once more; the rotation's σ by the jackknife over bursts.
FitResult WithPose(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                   const ShadowObservations& observed, const FitOptions& options, const FitResult& fit) {
  ShadowScore score(scene, bake, caster, observed);
  const bool north = fit.north_fitted;
  PoseAndNorth pose{glm::dvec3(0.0), fit.north_offset_deg};
  pose = FitRotation(score, PoseBand(score, pose.rotation, {pose.north, fit.clock_offset_s}), pose, fit.clock_offset_s, north,
                     options.pose_range_deg, 0.25, -1);
  // North and the clock again from the rotated camera, then the rotation (and north) once more.
  score.UsePose(pose.rotation);
  FitResult refit = FitWithScore(scene, observed, score, options);
  const Offsets offsets{refit.north_offset_deg, refit.clock_offset_s};
  const std::vector<std::vector<uint32_t>> band = PoseBand(score, pose.rotation, offsets);
  pose = FitRotation(score, band, {pose.rotation, refit.north_offset_deg}, refit.clock_offset_s, north, options.pose_range_deg,
                     0.1, -1);
  refit.north_offset_deg = pose.north;
  refit.pose_fitted = true;
  refit.rotation_deg = pose.rotation;
  refit.disagree_before = fit.disagree_before;
  const size_t bursts = score.bursts();
  if (bursts >= 3) {
    std::vector<PoseAndNorth> leave(bursts);
    glm::dvec3 mean(0.0);
    for (size_t b = 0; b < bursts; ++b) {
      leave[b] = FitRotation(score, band, pose, refit.clock_offset_s, north, options.pose_range_deg, 0.05, static_cast<int>(b));
      mean += leave[b].rotation / static_cast<double>(bursts);
    }
    glm::dvec3 var(0.0);
    for (const PoseAndNorth& r : leave) var += (r.rotation - mean) * (r.rotation - mean);
    refit.rotation_sigma_deg = glm::sqrt(var * ((static_cast<double>(bursts) - 1.0) / static_cast<double>(bursts)));
  }
  return refit;
}

}  // namespace

FitResult Calibrate(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                    const ShadowObservations& observed, const FitOptions& options) {
  const FitResult first = FitNorthAndClock(scene, bake, caster, observed, options);
  if (!first.north_fitted || first.at_range_edge || std::abs(first.north_offset_deg) < 0.1) {
    return options.pose && !first.at_range_edge ? WithPose(scene, bake, caster, observed, options, first) : first;
  }
  const std::vector<uint8_t> mask = CaptureEdgeMask(scene, bake, caster, first.north_offset_deg);
  ShadowObservations kept = observed;
  size_t left_out = 0;
  for (BurstShadows& b : kept.bursts) {
    size_t n = 0;
    for (size_t i = 0; i < b.pixels.size(); ++i) {
      if (mask[b.pixels[i]]) continue;
      b.pixels[n] = b.pixels[i], b.sunlit[n] = b.sunlit[i], ++n;
    }
    left_out += b.pixels.size() - n;
    b.pixels.resize(n), b.sunlit.resize(n);
  }
  Log().info("calibrate: north {:+.3f} deg at first; again without the {} pixels whose albedo it put on the wrong side of "
             "the capture's shadow edges",
             first.north_offset_deg, left_out);
  FitResult second = FitNorthAndClock(scene, bake, caster, kept, options);
  second.disagree_before = first.disagree_before;
  return options.pose && !second.at_range_edge ? WithPose(scene, bake, caster, kept, options, second) : second;
}

std::optional<ShadowCheck> CheckShadows(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                                        const ShadowObservations& observed) {
  if (observed.bursts.empty()) return std::nullopt;
  FitOptions options;
  options.clock = false;
  options.north_range_deg = kShadowCheckNorthRangeDeg, options.north_step_deg = 0.5, options.north_tolerance_deg = 0.05;
  options.coarse_stride = 4;
  const FitResult fit = FitNorthAndClock(scene, bake, caster, observed, options);
  return ShadowCheck{fit.disagree_before, fit.north_offset_deg, fit.edge_pixels, fit.disagree_after, fit.kappa_after,
                     fit.kappa_away};
}

}  // namespace daylit::calibrate
