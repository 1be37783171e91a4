#include "evaluation/fidelity_sink.h"

#include <algorithm>

#include <fmt/format.h>

#include "base/atomic_file.h"
#include "report/plot.h"

namespace daylit::evaluation {

FidelitySink::FidelitySink(const scene::Scene& scene) : scene_(scene), linearizer_(scene.response) {}

void FidelitySink::Consume(const pipeline::PipelineFrame& frame) {
  if (frame.image == nullptr || frame.image_light != pipeline::ImageLight::kFrameLight) return;
  const std::optional<TruthFrame> truth = ReadTruthFrame(scene_, frame.frame.index);
  if (!truth) return;
  capture::LinearRadiance(frame.frame, linearizer_, &linear_);
  const CompositeFidelity f = CompareComposite(*frame.image, linear_, truth->with, truth->without, truth->mask);
  frames_.push_back({frame.frame.index, f});
  const double score = std::max(f.object_error, f.shadow_error);
  if (score > worst_) {  // its strip is written once, after the last frame
    worst_ = score;
    worst_truth_ = truth->with, worst_composite_ = *frame.image, worst_exposure_ = frame.frame.exposure;
  }
}

void FidelitySink::Finish(const std::filesystem::path& dir, RunReport* report) const {
  if (frames_.empty()) return;
  double objects = 0.0, shadows = 0.0;
  const FrameFidelity* worst_objects = &frames_[0];
  const FrameFidelity* worst_shadows = &frames_[0];
  for (const FrameFidelity& r : frames_) {
    objects += r.fidelity.object_error / static_cast<double>(frames_.size());
    shadows += r.fidelity.shadow_error / static_cast<double>(frames_.size());
    if (r.fidelity.object_error > worst_objects->fidelity.object_error) worst_objects = &r;
    if (r.fidelity.shadow_error > worst_shadows->fidelity.shadow_error) worst_shadows = &r;
  }
  report->Say(fmt::format("composite against the path-traced truth over {} frames (mean relative error of linear radiance):",
                          frames_.size()));
  report->Say(fmt::format("  objects        {:5.1f}% (worst {:.1f}% at frame {})", 100 * objects,
                          100 * worst_objects->fidelity.object_error, worst_objects->frame));
  report->Say(fmt::format("  their shadows  {:5.1f}% (worst {:.1f}% at frame {})", 100 * shadows,
                          100 * worst_shadows->fidelity.shadow_error, worst_shadows->frame));
  report->Figure("composite/frames", static_cast<double>(frames_.size()));
  report->Figure("composite/objects/mean", objects);
  report->Figure("composite/objects/worst", worst_objects->fidelity.object_error);
  report->Figure("composite/objects/worst_frame", worst_objects->frame);
  report->Figure("composite/shadows/mean", shadows);
  report->Figure("composite/shadows/worst", worst_shadows->fidelity.shadow_error);
  report->Figure("composite/shadows/worst_frame", worst_shadows->frame);
  WriteCompositeStrip(dir / "worst_vs_truth.png", scene_.intrinsics.width, scene_.intrinsics.height, worst_truth_,
                      worst_composite_, worst_exposure_, scene_.response);
  WriteFileAtomically(dir / "fidelity.csv", FidelityCsv(frames_));
  PlotFidelity(frames_, scene_.name, dir / "fidelity.png");
}

std::string FidelityCsv(const std::vector<FrameFidelity>& rows) {
  std::string csv = "frame,object_error,object_pixels,shadow_error,shadow_pixels,frame_shadow_error,false_shadow_pixels\n";
  for (const FrameFidelity& r : rows) {
    const CompositeFidelity& f = r.fidelity;
    csv += fmt::format("{},{:.5f},{},{:.5f},{},{:.5f},{}\n", r.frame, f.object_error, f.object_pixels, f.shadow_error,
                       f.shadow_pixels, f.frame_shadow_error, f.false_shadow_pixels);
  }
  return csv;
}

void PlotFidelity(const std::vector<FrameFidelity>& rows, const std::string& title, const std::filesystem::path& png) {
  report::LinePlot plot({title + ": composite against the path-traced truth", "frame", "mean relative error (%)", 1400,
                         420, true});
  report::Series objects{"objects", {}, {}, report::SeriesColor(0), false, false};
  report::Series shadows{"their shadows", {}, {}, report::SeriesColor(1), false, false};
  report::Series camera{"the frame itself on the shadow pixels", {}, {}, report::SeriesColor(7), true, false};
  for (const FrameFidelity& r : rows) {
    objects.x.push_back(r.frame), objects.y.push_back(100 * r.fidelity.object_error);
    shadows.x.push_back(r.frame), shadows.y.push_back(100 * r.fidelity.shadow_error);
    camera.x.push_back(r.frame), camera.y.push_back(100 * r.fidelity.frame_shadow_error);
  }
  plot.Add(std::move(objects));
  plot.Add(std::move(shadows));
  plot.Add(std::move(camera));
  report::WritePng(png, {plot.Render()});
}

}  // namespace daylit::evaluation
