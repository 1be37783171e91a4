// SH9 irradiance against exact integration on real light probes (probes/, from shared/probes; see
// probes/SOURCES.md), in Ramamoorthi & Hanrahan's measure: the error relative to the maximum
// irradiance over all normals. They report about 1% on average for their probes; the issue asks
// for about 1-2.5% mean and 5-8% max.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "bake/sampling.h"
#include "sh/exact_irradiance.h"
#include "scene/hdr_image.h"
#include "sh/sh9.h"

namespace daylit::sh {
namespace {

struct ProbeError {
  double mean = 0.0, max = 0.0;  // of |E_sh − E| / max E, averaged over RGB
  double mean_relative = 0.0;    // of |E_sh − E| / E (normals with E ≥ 1e-3 of the maximum)
};

ProbeError Sh9Error(const std::string& file) {
  const HdrImage full = scene::ReadHdrImage(std::string(DAYLIT_SOURCE_DIR "/probes/") + file);
  const HdrImage map = DownsampleLatLong(full, 4);  // 256×128: the irradiance changes < 0.1%
  const std::vector<glm::vec3> normals = bake::SphericalFibonacci(2000);
  const std::vector<glm::dvec3> exact = ExactIrradiance(map, normals);
  const ShRgb9 sh = ProjectLatLong(map.rgb.data(), map.width, map.height);
  glm::dvec3 peak(0.0);
  for (const glm::dvec3& e : exact) peak = glm::max(peak, e);
  ProbeError error;
  int counted = 0;
  for (size_t i = 0; i < normals.size(); ++i) {
    const glm::dvec3 diff = glm::abs(sh.Irradiance(glm::dvec3(normals[i])) - exact[i]);
    const glm::dvec3 d = diff / peak;
    const double e = (d.x + d.y + d.z) / 3.0;
    error.mean += e / static_cast<double>(normals.size());
    error.max = std::max(error.max, e);
    if (glm::all(glm::greaterThanEqual(exact[i], 1e-3 * peak))) {
      const glm::dvec3 r = diff / exact[i];
      error.mean_relative += (r.x + r.y + r.z) / 3.0, ++counted;
    }
  }
  error.mean_relative /= std::max(counted, 1);
  std::printf("%-32s SH9 irradiance error: mean %.2f%%, max %.2f%% of the maximum; per normal %.1f%% on average\n",
              file.c_str(), 100 * error.mean, 100 * error.max, 100 * error.mean_relative);
  return error;
}

TEST(Sh9ProbesTest, WithinRamamoorthiHanrahansErrorOnRealProbes) {
  for (const char* file : {"galileo_latlong_1024x512.hdr", "stpeters_latlong_1024x512.hdr",
                           "uffizi-large_1024x512.hdr", "potsdamer_platz_1k.hdr"}) {
    const ProbeError e = Sh9Error(file);
    EXPECT_LE(e.mean, 0.025) << file;
    EXPECT_LE(e.max, 0.08) << file;
  }
}

TEST(Sh9ProbesTest, AVisibleSunIsWhySH9MustLeaveTheSunOut) {
  // Rooitou Park: a clear sky with the sun 10° high, 68% of the power within 3° of it. Relative
  // to the maximum SH9 still looks fine; per normal, away from the sun, where a surface is lit by
  // the dim sky alone, it is far off (the lobe of the sun rings into the dark side).
  const ProbeError sun = Sh9Error("rooitou_park_1k.hdr");
  const ProbeError overcast = Sh9Error("potsdamer_platz_1k.hdr");  // an overcast plaza
  EXPECT_GT(sun.mean_relative, 0.15);      // measured 26.6%
  EXPECT_LT(overcast.mean_relative, 0.05);  // measured 1.8%
}

}  // namespace
}  // namespace daylit::sh
