#include "evaluation/lighting_truth.h"

#include <array>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/statistics.h"
#include "report/plot.h"

namespace daylit::evaluation {
namespace {

double Median(std::vector<double> v) { return MedianInPlace(v, static_cast<double>(NAN)); }

}  // namespace

TruthComparison CompareWithTruth(const std::vector<estimation::FrameEstimate>& frames, const std::filesystem::path& groundtruth_csv) {
  const CsvTable table = ReadCsvFile(groundtruth_csv);
  const size_t c_frame = static_cast<size_t>(table.RequireColumn("frame"));
  std::array<size_t, 6> c{};
  const char* names[6] = {"sun_r", "sun_g", "sun_b", "sky_r", "sky_g", "sky_b"};
  for (size_t k = 0; k < 6; ++k) c[k] = static_cast<size_t>(table.RequireColumn(names[k]));
  std::map<int, estimation::SunSky> truth_by_frame;
  for (size_t r = 0; r < table.rows.size(); ++r) {
    estimation::SunSky t;
    for (int k = 0; k < 3; ++k) {
      t.sun_rgb[k] = ParseFiniteDouble(table.rows[r][c[static_cast<size_t>(k)]], table.Where(r));
      t.sky_rgb[k] = ParseFiniteDouble(table.rows[r][c[static_cast<size_t>(k) + 3]], table.Where(r));
    }
    truth_by_frame[static_cast<int>(ParseFiniteDouble(table.rows[r][c_frame], table.Where(r)))] = t;
  }
  TruthComparison cmp;
  std::array<std::vector<double>, 3> sun, sky, ratio;
  for (const estimation::FrameEstimate& f : frames) {
    const auto it = truth_by_frame.find(f.frame);
    cmp.truth.push_back(it == truth_by_frame.end() ? estimation::SunSky{glm::dvec3(NAN), glm::dvec3(NAN)} : it->second);
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

void PlotEstimates(const std::vector<estimation::FrameEstimate>& frames, const TruthComparison* truth, const std::string& title,
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

std::optional<TruthComparison> ReportLighting(const scene::Scene& scene, const std::vector<estimation::FrameEstimate>& frames,
                                              const std::filesystem::path& csv, const std::filesystem::path& png,
                                              RunReport* report) {
  WriteFileAtomically(csv, estimation::EstimatesCsv(frames));
  std::optional<TruthComparison> truth;
  if (scene.groundtruth.lighting) {
    truth = CompareWithTruth(frames, *scene.groundtruth.lighting);
    const auto line = [&](const char* what, const glm::dvec3& e) {
      report->Say(fmt::format("  {:<9}{:5.1f}% {:5.1f}% {:5.1f}%", what, 100 * e.x, 100 * e.y, 100 * e.z));
    };
    report->Say(fmt::format("lighting against groundtruth.csv, median relative error over {} frames (R, G, B):", truth->frames));
    line("E_sun", truth->sun_error);
    line("E_sky", truth->sky_error);
    line("sun/sky", truth->ratio_error);
    report->Figure("lighting/frames", truth->frames);
    for (int c = 0; c < 3; ++c) {
      const std::string channel(1, "rgb"[c]);
      report->Figure("lighting/sun_error/" + channel, truth->sun_error[c]);
      report->Figure("lighting/sky_error/" + channel, truth->sky_error[c]);
      report->Figure("lighting/ratio_error/" + channel, truth->ratio_error[c]);
    }
  }
  PlotEstimates(frames, truth ? &*truth : nullptr, scene.name, png);
  return truth;
}

}  // namespace daylit::evaluation
