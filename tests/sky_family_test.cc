// The re-aimed sky (sky/sky_distribution.h) held to clear skies it was not made from: Blender 3.4's
// Nishita, Hosek-Wilkie and Preetham skies (scenes/skies/, made by scenes/skies.py), each at two
// hazes and five sun elevations. Each sky is captured under one sun (its upper hemisphere, a few
// of its low directions hidden, as buildings hide them from a capture point) and re-aimed at each
// other sun of the same sky, then compared with that sky as rendered.
//
// What a surface takes from the sky relative to the DHI is what the fit's clear-sky transfer term
// carries (estimation/transfer.h normalises the sky to a unit DHI), so that is what is compared:
// the irradiance of a vertical wall facing toward the sun, away from it and across, and of the
// floor of a courtyard that sees only the sky above 30°, each over the DHI.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <nlohmann/json.hpp>

#include "base/latlong.h"
#include "scene/hdr_image.h"
#include "sky/sky_distribution.h"

namespace daylit {
namespace {

const std::filesystem::path kSkies = std::filesystem::path(DAYLIT_SOURCE_DIR) / "scenes" / "skies";

struct Sky {
  std::string family, haze;
  double elevation_deg = 0.0;
  glm::vec3 sun{0.0f};
  HdrImage map;
};

std::vector<Sky> ReadSkies() {
  std::ifstream in(kSkies / "skies.json");
  const nlohmann::json index = nlohmann::json::parse(in);
  std::vector<Sky> out;
  for (const nlohmann::json& s : index.at("skies")) {
    Sky sky;
    sky.family = s.at("family");
    sky.haze = s.at("haze");
    sky.elevation_deg = s.at("sun_elevation_deg");
    const std::vector<double> d = s.at("sun_dir");
    sky.sun = glm::normalize(glm::vec3(d[0], d[1], d[2]));
    sky.map = scene::ReadHdrImage(kSkies / s.at("file").get<std::string>());
    out.push_back(std::move(sky));
  }
  return out;
}

// What surfaces see of a sky, each over its DHI: walls facing toward the sun's azimuth, across it
// and away from it, and a courtyard floor that sees the sky above 30°.
constexpr int kViews = 4;
const char* const kViewNames[kViews] = {"wall toward the sun", "wall across", "wall away", "courtyard floor"};

template <typename Radiance>
std::array<glm::dvec3, kViews> ViewsOf(const Radiance& radiance, const glm::vec3& sun, int w, int h) {
  const glm::dvec3 toward = glm::normalize(glm::dvec3(sun.x, sun.y, 0.0));
  const glm::dvec3 across(-toward.y, toward.x, 0.0);
  std::array<glm::dvec3, kViews> sum{};
  glm::dvec3 dhi(0.0);
  for (int v = 0; v < h / 2; ++v) {
    const double omega = LatLongTexelSolidAngle(v, w, h);
    for (int u = 0; u < w; ++u) {
      const glm::dvec3 d = LatLongDirection(u, v, w, h);
      const glm::dvec3 l = radiance(u, v, glm::vec3(d)) * omega;
      dhi += l * d.z;
      sum[0] += l * std::max(0.0, glm::dot(d, toward));
      sum[1] += l * std::max(0.0, glm::dot(d, across));
      sum[2] += l * std::max(0.0, -glm::dot(d, toward));
      if (d.z > std::sin(glm::radians(30.0))) sum[3] += l * d.z;
    }
  }
  for (glm::dvec3& s : sum) s /= dhi;
  return sum;
}

struct Errors {
  std::vector<double> reaimed, as_captured;  // |relative error| of every view, channel and pair
};

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1))];
}

TEST(SkyFamilyTest, TheReaimedSkyAgainstNishitaHosekWilkieAndPreetham) {
  const std::vector<Sky> skies = ReadSkies();
  ASSERT_EQ(skies.size(), 30u);
  std::map<std::string, Errors> by_family;
  std::map<std::string, std::array<double, kViews>> worst_view;
  for (const Sky& capture : skies) {
    const int w = capture.map.width, h = capture.map.height;
    // The capture point's sky: its upper hemisphere, the sky below 15° hidden over a quarter of
    // the horizon (a building beside it).
    std::vector<uint8_t> is_sky(static_cast<size_t>(w) * h, 0);
    for (int v = 0; v < h / 2; ++v) {
      for (int u = 0; u < w; ++u) {
        const glm::dvec3 d = LatLongDirection(u, v, w, h);
        is_sky[static_cast<size_t>(v) * w + u] = !(d.x > 0.0 && d.y > 0.0 && d.z < std::sin(glm::radians(15.0)));
      }
    }
    const sky::SkyDistribution captured(capture.map, is_sky, capture.sun);
    for (const Sky& target : skies) {
      if (target.family != capture.family || target.haze != capture.haze || &target == &capture) continue;
      const auto truth = ViewsOf([&](int u, int v, const glm::vec3&) { return glm::dvec3(glm::make_vec3(target.map.Pixel(u, v))); },
                                 target.sun, w, h);
      Errors& e = by_family[capture.family];
      for (const bool reaim : {true, false}) {
        const sky::SkyDistribution under = captured.Under(target.sun, reaim);
        const auto got = ViewsOf([&](int, int, const glm::vec3& d) { return glm::dvec3(under.Radiance(d)); }, target.sun, w, h);
        for (int k = 0; k < kViews; ++k) {
          for (int c = 0; c < 3; ++c) {
            const double err = std::abs(got[k][c] / truth[k][c] - 1.0);
            (reaim ? e.reaimed : e.as_captured).push_back(err);
            if (reaim) worst_view[capture.family][k] = std::max(worst_view[capture.family][k], err);
          }
        }
      }
    }
  }
  std::printf("what surfaces take from the sky over its DHI, re-aimed from another sun of the same sky: |relative error| over "
              "20 pairs x 2 hazes x 4 views x 3 channels\n");
  std::printf("%-10s %28s %28s\n", "family", "re-aimed median / p90 / max", "as captured median / p90 / max");
  for (const auto& [family, e] : by_family) {
    std::printf("%-10s %8.3f %8.3f %8.3f   %8.3f %8.3f %8.3f   worst by view:", family.c_str(), Quantile(e.reaimed, 0.5),
                Quantile(e.reaimed, 0.9), Quantile(e.reaimed, 1.0), Quantile(e.as_captured, 0.5),
                Quantile(e.as_captured, 0.9), Quantile(e.as_captured, 1.0));
    for (int k = 0; k < kViews; ++k) std::printf(" %s %.3f;", kViewNames[k], worst_view[family][k]);
    std::printf("\n");
  }
  // Measured (docs/sky.md): Nishita 0.5% / 1.7% / 6.6% re-aimed against 1.3% / 9.7% / 32% as
  // captured; Hosek-Wilkie 1.1% / 4.3% / 16.7% against 1.5% / 5.6% / 18.3%; Preetham 1.4% / 9.3% /
  // 33% against 0.4% / 4.1% / 17%.
  // The family the atmosphere is of: re-aiming is what makes another sun's sky right.
  EXPECT_LT(Quantile(by_family["nishita"].reaimed, 0.9), 0.025);
  EXPECT_LT(Quantile(by_family["nishita"].reaimed, 0.9), 0.5 * Quantile(by_family["nishita"].as_captured, 0.9));
  // A sky fitted to multiple-scattering simulations: re-aiming helps, less; a typical surface within 2%.
  EXPECT_LT(Quantile(by_family["hosek"].reaimed, 0.5), 0.02);
  EXPECT_LT(Quantile(by_family["hosek"].reaimed, 0.9), Quantile(by_family["hosek"].as_captured, 0.9));
  // Preetham's sky changes with the sun otherwise than a physical atmosphere: re-aimed at a sun
  // 10-20° up, the wall toward it gets 15-29% more than Preetham gives it, and the table as
  // captured is closer. Held where it stands, so that a change that makes it worse is seen.
  EXPECT_LT(Quantile(by_family["preetham"].reaimed, 0.9), 0.11);
}

}  // namespace
}  // namespace daylit
