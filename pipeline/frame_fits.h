// Chosen frames of a recording fitted as daylit estimate fits them, for the commands that show one
// frame (render, relight --frame and --like-frame, relight-env) and the tests that compare one
// frame with its truth. The pipeline (lighting_pipeline.h) runs from the recording's first frame to
// the last one asked for, so each frame's fit carries what the frames before it measured, as it
// does in estimate, replay and live: the sun's colour where its own sun is weak
// (estimation/sun_colour.h), the sky shape's spread in its interval. A frame fitted alone would
// have the capture's colour only: an overcast frame's E_sun and its interval would differ from
// the estimates.csv row of the same frame.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "capture/frame_source.h"
#include "estimation/frame_estimator.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::pipeline {

struct FrameFit {
  estimation::FrameEstimate row;  // estimates.csv's row, with light and confidence the fit's own (not the filter's)
  estimation::SunSkyFitSummary fit;
  glm::vec3 sun_dir{0.0f};        // unit, scene coordinates
  capture::Frame frame;           // the frame it was fitted to
};

// The fits of the frames at `positions` (indexes into frames.csv, any order, repeats allowed), in
// the order asked; the recording is read once, up to the furthest. Throws InputError for a live
// device, a position past the recording, or a frame asked for that cannot be decoded.
std::vector<FrameFit> FitRecordingFrames(const scene::Scene& scene, const bake::SceneBake& bake,
                                         const scene::RayCaster& caster, const std::vector<size_t>& positions,
                                         const estimation::FrameEstimatorOptions& options = {});
FrameFit FitRecordingFrame(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& caster,
                           size_t position, const estimation::FrameEstimatorOptions& options = {});

}  // namespace daylit::pipeline
