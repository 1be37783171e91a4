#include "estimation/sampler.h"

#include "base/check.h"

#include "base/options_check.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>

#include <opencv2/imgproc.hpp>

#include "bake/surface_light.h"

namespace daylit::estimation {

std::vector<size_t> FairShares(const std::vector<size_t>& sizes, size_t total) {
  std::vector<size_t> order(sizes.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return sizes[a] < sizes[b]; });
  std::vector<size_t> shares(sizes.size(), 0);
  size_t left = total;
  for (size_t j = 0; j < order.size(); ++j) {
    const size_t fair = (left + (order.size() - j) - 1) / (order.size() - j);  // rounded up
    shares[order[j]] = std::min(fair, sizes[order[j]]);
    left -= std::min(left, shares[order[j]]);
  }
  return shares;
}

Sampler::Sampler(const bake::SceneBake& bake, const glm::vec3& capture_position, const scene::RayCaster& caster,
                 SamplerOptions options)
    : gbuffer_(bake.camera), caster_(caster), options_(options),
      transfer_(bake, TransferPoints::Camera(bake.camera), capture_position, caster, options.transfer) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  const bake::CameraGBuffer& gbuffer = bake.camera;
  for (size_t i = 0; i < gbuffer.diffuse.size(); ++i) {
    if (gbuffer.diffuse[i]) diffuse_pixels_.push_back(static_cast<uint32_t>(i));
    if (gbuffer.surface[i] != bake::kNoSurface) model_pixels_.push_back(static_cast<uint32_t>(i));
  }
  // A fixed order: the same pixels are read frame after frame, so sampling adds no flicker.
  std::mt19937 rng(20060101u);
  std::shuffle(diffuse_pixels_.begin(), diffuse_pixels_.end(), rng);
  sunlit_.assign(gbuffer.diffuse.size(), 0);
  near_boundary_.assign(gbuffer.diffuse.size(), 0);
  sun_term_.assign(gbuffer.diffuse.size(), 0.0f);
}

bool Sampler::SetSun(const glm::vec3& sun_dir) {
  // The caller decides when the sun has moved (scene::SunTracker): any other sun is re-cast.
  if (sun_ && *sun_ == sun_dir) return false;
  sun_ = sun_dir;
  const int w = gbuffer_.width, h = gbuffer_.height;
  // Sun visibility of every model pixel (not only diffuse ones), so that the shadow map in the
  // image is the model's own.
  bake::DirectSun(caster_, gbuffer_.point.data(), gbuffer_.normal.data(), model_pixels_, sun_dir, 2e-3f,
                  sun_term_.data(), sunlit_.data());
  cv::Mat lit(h, w, CV_8UC1, cv::Scalar(0));
  cv::Mat surface(h, w, CV_32SC1, cv::Scalar(-1));
  for (const uint32_t i : model_pixels_) {
    lit.at<uint8_t>(static_cast<int>(i) / w, static_cast<int>(i) % w) = sunlit_[i] ? 255 : 0;
    surface.at<int32_t>(static_cast<int>(i) / w, static_cast<int>(i) % w) = static_cast<int32_t>(gbuffer_.surface[i]);
  }
  // Left out: pixels within the margin of a shadow edge (lit next to unlit) or of a silhouette
  // (one surface next to another, or the sky): where the model and the image are misregistered
  // by a pixel or two, these read the other side's light.
  const int r = options_.boundary_margin_px;
  cv::Mat near(h, w, CV_8UC1, cv::Scalar(0));
  if (r > 0) {
    cv::Mat edges(h, w, CV_8UC1, cv::Scalar(0));
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int32_t s0 = surface.at<int32_t>(y, x);
        const uint8_t l0 = lit.at<uint8_t>(y, x);
        const bool right = x + 1 < w && (surface.at<int32_t>(y, x + 1) != s0 || lit.at<uint8_t>(y, x + 1) != l0);
        const bool down = y + 1 < h && (surface.at<int32_t>(y + 1, x) != s0 || lit.at<uint8_t>(y + 1, x) != l0);
        if (right || down) edges.at<uint8_t>(y, x) = 255;
      }
    }
    cv::dilate(edges, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
  }
  // Strata: (surface, sunlit?) in the shuffled order.
  std::map<std::pair<uint32_t, int>, size_t> index;
  std::vector<std::vector<uint32_t>> strata;
  for (const uint32_t i : diffuse_pixels_) {
    const bool boundary = near.at<uint8_t>(static_cast<int>(i) / w, static_cast<int>(i) % w) != 0;
    near_boundary_[i] = boundary ? 1 : 0;
    if (boundary) continue;
    const auto key = std::make_pair(gbuffer_.surface[i], static_cast<int>(sunlit_[i]));
    auto [it, inserted] = index.emplace(key, strata.size());
    if (inserted) strata.emplace_back();
    strata[it->second].push_back(i);
  }
  // Each stratum's pool: the first pixels of its list, its fair share of `pool` × the samples,
  // with their transfer under this sun.
  std::vector<size_t> sizes(strata.size());
  for (size_t s = 0; s < strata.size(); ++s) sizes[s] = strata[s].size();
  const std::vector<size_t> pools = FairShares(sizes, static_cast<size_t>(std::ceil(options_.pool * options_.samples)));
  std::vector<uint32_t> pooled;
  for (size_t s = 0; s < strata.size(); ++s) {
    strata[s].resize(pools[s]);
    pooled.insert(pooled.end(), strata[s].begin(), strata[s].end());
  }
  std::vector<Transfer> transfer(pooled.size());
  transfer_.Compute(pooled, sun_dir, sun_term_.data(), transfer.data());
  strata_.assign(strata.size(), {});
  size_t k = 0;
  for (size_t s = 0; s < strata.size(); ++s) {
    for (const uint32_t i : strata[s]) strata_[s].push_back({i, transfer[k++]});
  }
  // Each stratum's quota per frame: its fair share of the samples over the pools. A pool holds
  // `pool` × its quota, room for the pixels a frame skips as clipped or black.
  quotas_ = FairShares(pools, static_cast<size_t>(options_.samples));
  return true;
}

constexpr size_t kPrefetchAhead = 16;

std::vector<Sample> Sampler::Draw(const cv::Mat& frame, double exposure, const capture::Linearizer* linearizer) const {
  std::vector<Sample> samples;
  if (strata_.empty() || frame.empty()) return samples;
  samples.reserve(static_cast<size_t>(options_.samples));
  const float inv_exposure = static_cast<float>(1.0 / exposure);
  for (size_t t = 0; t < strata_.size(); ++t) {
    const std::vector<Candidate>& stratum = strata_[t];
    const size_t quota = quotas_[t];
    size_t taken = 0;
    for (size_t k = 0; k < stratum.size() && taken < quota; ++k) {
      // The pixels are scattered over a frame another core decoded: asked for ahead, their cache
      // misses overlap (Draw took 0.8 ms a frame in `daylit estimate` on courtyard-c, 0.4 ms so).
      if (k + kPrefetchAhead < stratum.size()) {
        const uint32_t j = stratum[k + kPrefetchAhead].pixel;
        __builtin_prefetch(&frame.at<cv::Vec3f>(static_cast<int>(j / gbuffer_.width), static_cast<int>(j % gbuffer_.width)));
        __builtin_prefetch(&gbuffer_.albedo[j]);
      }
      const uint32_t i = stratum[k].pixel;
      cv::Vec3f p = frame.at<cv::Vec3f>(static_cast<int>(i / gbuffer_.width), static_cast<int>(i % gbuffer_.width));
      if (linearizer != nullptr) p = cv::Vec3f((*linearizer)(p[0], 0), (*linearizer)(p[1], 1), (*linearizer)(p[2], 2));
      bool usable = true;
      for (int c = 0; c < 3; ++c) usable = usable && p[c] < options_.saturated && p[c] > options_.near_black;
      if (!usable) continue;
      Sample s;
      s.radiance = glm::vec3(p[0], p[1], p[2]) * inv_exposure;
      s.albedo = gbuffer_.albedo[i];
      s.sun = stratum[k].transfer.sun;
      s.sky = stratum[k].transfer.clear;
      s.overcast = stratum[k].transfer.overcast;
      s.sunlit = sunlit_[i] != 0;
      s.pixel = i;
      s.surface = gbuffer_.surface[i];
      samples.push_back(s);
      ++taken;
    }
  }
  return samples;
}

std::string SamplerOptions::Check() const {
  return FirstProblem({InClosed("samples", samples, 100, 1000000), InClosed("boundary_margin_px", boundary_margin_px, 0, 50),
                       InOpenClosed("saturated", saturated, 0.0, 1.0), InClosed("near_black", near_black, 0.0, saturated),
                       InClosed("pool", pool, 1.0, 100.0), Nested("transfer", transfer.Check())});
}

}  // namespace daylit::estimation
