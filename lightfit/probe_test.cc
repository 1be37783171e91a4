#include "lightfit/probe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "base/error.h"
#include "sh/exact_irradiance.h"
#include "lightfit/lights.h"
#include "base/latlong.h"

namespace daylit::lightfit {
namespace {

namespace fs = std::filesystem;

fs::path TempDir() {
  const fs::path dir = fs::path(DAYLIT_BINARY_DIR) / "probe_test";
  fs::create_directories(dir);
  return dir;
}

fs::path WriteImage(const std::string& name, const HdrImage& image) {
  const fs::path path = TempDir() / name;
  scene::WriteRgbExr(path, image.width, image.height, image.rgb.data());
  return path;
}

HdrImage Constant(int width, int height, float value) {
  HdrImage image;
  image.width = width, image.height = height;
  image.rgb.assign(static_cast<size_t>(width) * height * 3, value);
  return image;
}

std::string ErrorOf(const fs::path& path) {
  try {
    LoadProbe(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ProbeTest, AngularMapLandsInDaylitsFrame) {
  // Debevec's layout: the centre looks forward, up is up, right is right, radius ∝ angle. A bright
  // dot at the gallery's "up" (half way out, straight above the centre) must become daylit's
  // zenith (+Z); one at its "right" becomes +X; forward becomes +Y.
  const int size = 400;
  for (const auto& [px, py, expected] : std::vector<std::tuple<int, int, glm::dvec3>>{
           {size / 2, size / 4, {0, 0, 1}}, {3 * size / 4, size / 2, {1, 0, 0}}, {size / 2, size / 2, {0, 1, 0}}}) {
    HdrImage angular = Constant(size, size, 0.01f);
    for (int dy = -1; dy <= 0; ++dy) {
      for (int dx = -1; dx <= 0; ++dx) {
        float* p = angular.Pixel(px + dx, py + dy);
        p[0] = p[1] = p[2] = 1000.0f;
      }
    }
    const HdrImage map = AngularToLatLong(angular, 512, 256);
    size_t brightest = 0;
    for (size_t i = 0; i < map.rgb.size() / 3; ++i) {
      if (map.rgb[3 * i] > map.rgb[3 * brightest]) brightest = i;
    }
    const glm::dvec3 d = LatLongDirection(static_cast<double>(brightest % 512), static_cast<double>(brightest / 512), 512, 256);
    EXPECT_GT(glm::dot(d, expected), std::cos(glm::radians(1.5))) << "dot at (" << px << ", " << py << ") lands at ("
                                                                  << d.x << ", " << d.y << ", " << d.z << ")";
  }
}

TEST(ProbeTest, ConvertedGalileoProbeHasTheGallerysLatLongIrradiance) {
  // galileo_probe.hdr is the gallery's 1000×1000 angular map; galileo_latlong_1024x512.hdr was
  // resampled from it independently (probes/SOURCES.md) with the same conventions.
  const Probe probe = LoadProbe(DAYLIT_SOURCE_DIR "/probes/galileo_probe.hdr");
  EXPECT_TRUE(probe.converted_from_angular);
  EXPECT_EQ(probe.map.width, 1024);
  EXPECT_EQ(probe.map.height, 512);
  const Probe latlong = LoadProbe(DAYLIT_SOURCE_DIR "/probes/galileo_latlong_1024x512.hdr");
  EXPECT_FALSE(latlong.converted_from_angular);
  const std::vector<glm::vec3> normals = sh::IcosahedronNormals(4);
  const ApproximationError e = RelativeError(sh::ExactIrradiance(latlong.map, normals), sh::ExactIrradiance(probe.map, normals));
  std::printf("converted angular vs gallery lat-long: irradiance differs by %.3f%% mean, %.3f%% max\n", 100 * e.mean, 100 * e.max);
  EXPECT_LT(e.mean, 0.01);
  EXPECT_LT(e.max, 0.03);
}

TEST(ProbeTest, RealProbesLoadWithoutWarnings) {
  for (const char* file : {"galileo_latlong_1024x512.hdr", "stpeters_latlong_1024x512.hdr", "uffizi-large_1024x512.hdr",
                           "rooitou_park_1k.hdr", "potsdamer_platz_1k.hdr", "galileo_probe.hdr"}) {
    const Probe probe = LoadProbe(std::string(DAYLIT_SOURCE_DIR "/probes/") + file);
    EXPECT_TRUE(probe.warnings.empty()) << file << ": " << (probe.warnings.empty() ? "" : probe.warnings[0]);
  }
}

TEST(ProbeTest, AClippedSunIsAWarning) {
  // Rooitou Park's sun, cut at a thousandth of its peak, as when the shortest exposure of a
  // bracket still saturates on the sun.
  HdrImage map = LoadProbe(DAYLIT_SOURCE_DIR "/probes/rooitou_park_1k.hdr").map;
  float peak = 0.0f;
  for (const float v : map.rgb) peak = std::max(peak, v);
  for (float& v : map.rgb) v = std::min(v, 1e-3f * peak);
  const std::string warning = ClippedSourceWarning(map);
  std::printf("%s\n", warning.c_str());
  EXPECT_NE(warning.find("clipped"), std::string::npos);
  const Probe probe = LoadProbe(WriteImage("clipped.exr", map));
  ASSERT_EQ(probe.warnings.size(), 1u);
  EXPECT_NE(probe.warnings[0].find("clipped.exr"), std::string::npos);
}

TEST(ProbeTest, BadValuesAndShapesAreErrorsNamingTheFile) {
  HdrImage nan = Constant(64, 32, 1.0f);
  nan.Pixel(5, 7)[1] = std::numeric_limits<float>::quiet_NaN();
  nan.Pixel(6, 7)[0] = std::numeric_limits<float>::infinity();
  const std::string nan_error = ErrorOf(WriteImage("nan.exr", nan));
  EXPECT_NE(nan_error.find("nan.exr"), std::string::npos) << nan_error;
  EXPECT_NE(nan_error.find("2 texel values are NaN or infinite"), std::string::npos) << nan_error;
  EXPECT_NE(nan_error.find("(u 5, v 7)"), std::string::npos) << nan_error;

  HdrImage negative = Constant(64, 64, 1.0f);  // square: an angular map, still checked
  negative.Pixel(10, 20)[2] = -0.5f;
  const std::string negative_error = ErrorOf(WriteImage("negative.exr", negative));
  EXPECT_NE(negative_error.find("1 are negative, first at (u 10, v 20)"), std::string::npos) << negative_error;

  const std::string shape_error = ErrorOf(WriteImage("wide.exr", Constant(90, 30, 1.0f)));
  EXPECT_NE(shape_error.find("wide.exr: 90x30 is neither a 2:1 latitude-longitude map nor a square angular map"),
            std::string::npos)
      << shape_error;
  const std::string missing = ErrorOf(TempDir() / "missing.hdr");
  EXPECT_NE(missing.find("missing.hdr"), std::string::npos) << missing;
}

}  // namespace
}  // namespace daylit::lightfit
