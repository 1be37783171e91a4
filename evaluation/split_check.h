// A check of the sun/sky split that needs no ground truth: the fit repeated with each stratum
// (a surface's sunlit or shadowed samples) left out in turn, a jackknife over the strata. Every
// stratum carries its own model error (its albedo, the light reflected onto it, the sky it sees),
// and the fit averages them; how far the estimate moves when one is left out measures how much
// one stratum's model error can move it. A burst whose E_sun or E_sky moves by more than the
// threshold (the jackknife's standard error, median over the burst's checked frames) has a split
// that rests on the model of a few strata: it is named with the stratum that moves it most.
//
// This catches what the residuals cannot: the fit absorbs a wrong transfer term into the sun/sky
// split, so the residuals of the stratum at fault stay small (courtyard-b's evening burst had
// E_sky 15% low in red with every stratum within 4% of its prediction), while leaving that
// stratum out moves the estimate by the error it caused.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "base/utc_time.h"
#include "bake/bake.h"
#include "estimation/sun_sky_fit.h"
#include "evaluation/run_report.h"
#include "pipeline/lighting_pipeline.h"
#include "scene/scene.h"

namespace daylit::evaluation {

struct SplitCheckOptions {
  double threshold = 0.05;  // jackknife standard error of E_sun or E_sky (relative, any channel)
                            // beyond which a burst's split is flagged
  int every = 5;            // frames checked: every this many fitted frames of a burst (the first
                            // included); a check costs one fit per stratum
  int min_stratum_samples = 30;  // strata with fewer samples in a frame are not left out alone
  estimation::SunSkyFitOptions fit;  // the estimator's fit options, so that the refits are its fits

  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// How much leaving one stratum out moves a burst's estimate, and how well the others' light
// predicts it: medians over the checked frames, per channel.
struct StratumInfluence {
  std::string surface;
  bool sunlit = false;
  int frames = 0;
  glm::dvec3 sun{0.0}, sky{0.0};  // relative change of E_sun, E_sky without it
  // Its observed over predicted radiance under the light fitted without it: how far its model
  // disagrees with the others' (a held-out residual, which the fit cannot absorb).
  glm::dvec3 held_out{1.0};
};

struct BurstSplit {
  int burst = 0;
  int first_frame = 0, last_frame = 0;
  int frames_checked = 0;
  // Median over the checked frames of the jackknife standard error relative to the estimate, per
  // channel. E_sun's over frames where the sun is present (it is nothing to move under overcast).
  glm::dvec3 sun_spread{0.0}, sky_spread{0.0};
  int sun_frames = 0;  // checked frames with the sun present
  // Frames in which E_sun rested on one sunlit stratum (leaving it out leaves no sunlit sample):
  // the sunlit surface's own model cannot be checked against another's.
  int single_sunlit = 0;
  std::vector<StratumInfluence> strata;  // every stratum left out in some checked frame
  bool flagged = false;
  // The stratum whose leaving out moves the estimate most, and the largest move (relative).
  std::string worst_stratum;
  double worst_move = 0.0;
  // The stratum the others' light predicts worst, and by how much (|held_out − 1|, largest channel).
  std::string odd_stratum;
  double odd_residual = 0.0;
};

class SplitCheck {
 public:
  SplitCheck(const scene::Scene& scene, const bake::SceneBake& bake, SplitCheckOptions options = {});

  // One frame: its samples and its own fit (frames whose fit is not usable are skipped).
  void Add(int frame, const UtcTime& utc, const std::vector<estimation::Sample>& samples,
           const estimation::SunSkyFitSummary& fit);

  // Per burst (frames less than 2 s apart), in order.
  std::vector<BurstSplit> Bursts() const;
  // split_check.csv and split_check.png into `dir`; a flagged burst as a warning on stderr and a
  // report line.
  void Finish(const std::filesystem::path& dir, RunReport* report) const;

 private:
  struct Checked {
    glm::dvec3 sun_spread{0.0}, sky_spread{0.0};
    bool sun_present = false;
    bool single_sunlit = false;
    std::vector<std::pair<uint32_t, glm::dvec3>> sun_moves, sky_moves;  // stratum key, relative change
    std::vector<std::pair<uint32_t, glm::dvec3>> held_out;             // stratum key, observed/predicted
  };
  struct Burst {
    int first_frame = 0, last_frame = 0;
    UtcTime last_utc;
    int fitted = 0;
    std::vector<Checked> checked;
  };
  Checked CheckFrame(const std::vector<estimation::Sample>& samples, const estimation::SunSkyFitSummary& fit) const;
  std::string StratumName(uint32_t key) const;

  const scene::Scene& scene_;
  const bake::SceneBake& bake_;
  SplitCheckOptions options_;
  std::vector<Burst> bursts_;
};

// The SplitCheck as a pipeline sink.
class SplitCheckSink final : public pipeline::FrameSink {
 public:
  explicit SplitCheckSink(SplitCheck* check) : check_(check) {}
  void Consume(const pipeline::PipelineFrame& frame) override;

 private:
  SplitCheck* check_;
};

// split_check.csv: burst,first_frame,last_frame,frames_checked,sun_frames,sun_spread_r,sun_spread_g,
// sun_spread_b,sky_spread_r,sky_spread_g,sky_spread_b,single_sunlit_frames,worst_stratum,worst_move,
// odd_stratum,odd_residual,flagged.
std::string SplitCheckCsv(const std::vector<BurstSplit>& bursts);

}  // namespace daylit::evaluation
