// Which camera pixels the per-frame fit reads. Stratified across surfaces and across sunlit and
// shadowed areas (the two strata are what separates E_sun from E_sky), skipping pixels near a
// shadow edge or a silhouette of the model (misregistration there is the main error source) and,
// per frame, saturated and near-black pixels. The sun visibility behind the strata is re-cast only for another
// sun (the pipeline's scene::SunTracker hands the same direction until the sun has moved); so are
// the transfer terms (estimation/transfer.h) of the pixels each stratum may use.
#pragma once

#include <string>

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include "bake/bake.h"
#include "capture/response.h"
#include "estimation/sun_sky_fit.h"
#include "estimation/transfer.h"
#include "scene/raycaster.h"

namespace daylit::estimation {

struct SamplerOptions {
  int samples = 8000;                // per frame, shared fairly over the strata that exist: each its
                                     // pixels up to an equal share of what smaller strata leave
  int boundary_margin_px = 3;        // pixels this close to a shadow edge or silhouette are left out
  double saturated = 0.98;           // linear pixel value (before exposure) treated as clipped
  double near_black = 0.002;         // linear pixel value below which noise dominates
  double pool = 1.5;                 // pixels per stratum given transfer terms, in units of its quota
                                     // (room for pixels a frame skips as clipped or black)
  TransferOptions transfer;
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// `total` shared over groups of the given sizes (the strata's pools, or their quotas): each group
// all of its members up to an equal share of what the smaller groups leave (water-filling). A
// group of a few members takes only those, so one that appears or goes as the sun moves changes
// the others' shares by little; an equal split, total / groups, would change every one of them.
std::vector<size_t> FairShares(const std::vector<size_t>& sizes, size_t total);

class Sampler {
 public:
  // `capture_position`: scene.envmap.position. `bake` and `caster` must outlive the sampler.
  Sampler(const bake::SceneBake& bake, const glm::vec3& capture_position, const scene::RayCaster& caster,
          SamplerOptions options = {});

  // Updates the strata for the sun direction `sun_dir` (unit, scene coordinates; z ≤ 0: night,
  // everything is shadowed). Cheap when the sun has not moved enough. Returns true if it re-cast.
  bool SetSun(const glm::vec3& sun_dir);

  // Samples of one frame: `frame` as RGB floats (CV_32FC3, R G B order), linear (before dividing
  // out the exposure) or, with `linearizer`, encoded and linearised here, only where read.
  // `exposure` is the k of "linear pixel = k · radiance".
  std::vector<Sample> Draw(const cv::Mat& frame, double exposure, const capture::Linearizer* linearizer = nullptr) const;

  size_t StratumCount() const { return strata_.size(); }
  const LightTransfer& transfer() const { return transfer_; }
  // The current sun visibility of each pixel (1: sunlit), and its boundary exclusion mask.
  const std::vector<uint8_t>& sunlit() const { return sunlit_; }
  const std::vector<uint8_t>& near_boundary() const { return near_boundary_; }

 private:
  const bake::CameraGBuffer& gbuffer_;
  const scene::RayCaster& caster_;
  SamplerOptions options_;
  std::vector<uint32_t> diffuse_pixels_;  // in a fixed shuffled order
  std::vector<uint32_t> model_pixels_;    // every pixel that sees the model
  std::optional<glm::vec3> sun_;
  std::vector<uint8_t> sunlit_, near_boundary_;
  std::vector<float> sun_term_;  // s·max(0, n·l) per pixel
  LightTransfer transfer_;
  struct Candidate {
    uint32_t pixel;
    Transfer transfer;
  };
  std::vector<std::vector<Candidate>> strata_;  // the pool of each stratum, in the shuffled order
  std::vector<size_t> quotas_;                  // samples each stratum gives a frame (FairShares)
};

}  // namespace daylit::estimation
