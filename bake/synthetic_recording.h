// Small recordings written on the fly for the bake's tests: a ground plane (plus optional
// geometry) under a uniform sky, a camera looking straight down, one frame.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "base/atomic_file.h"
#include "scene/hdr_image.h"
#include "base/latlong.h"

namespace daylit::bake::testing {

struct SyntheticRecording {
  std::filesystem::path dir;
  nlohmann::json scene;
  std::string obj;          // model.obj text
  int env_width = 256;
  // Radiance of the env map per direction (default: sky 1 above the horizon, ground 0.4 below:
  // an open ground of albedo 0.4 under a uniform sky of radiance 1 has exactly that radiance).
  std::function<glm::vec3(const glm::dvec3&)> env = [](const glm::dvec3& d) {
    return d.z > 0.0 ? glm::vec3(1.0f) : glm::vec3(0.4f);
  };

  explicit SyntheticRecording(const std::string& name) {
    dir = std::filesystem::temp_directory_path() / ("daylit_synth_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir / "frames");
    obj = "o ground\nv -100 -100 0\nv 100 -100 0\nv 100 100 0\nv -100 100 0\nf 1 2 3 4\n";
    // Night at (0°, 0°): the sun is far below the horizon, so only the sky lights the scene.
    scene = {{"format", "daylit-recording/1"},
             {"location", {{"latitude_deg", 0.0}, {"longitude_deg", 0.0}}},
             {"model", {{"file", "model.obj"}}},
             {"diffuse_surfaces", {"ground"}},
             {"camera", {{"width", 64}, {"height", 48}, {"fx", 40.0}, {"fy", 40.0}, {"cx", 31.5}, {"cy", 23.5},
                         {"world_to_camera", {{"rotation", {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}}, {"translation", {0, 0, 5}}}}}},
             {"envmap", {{"file", "envmap.exr"}, {"position", {0.0, 0.0, 1.5}}, {"time_utc", "2026-06-21T00:00:00Z"},
                         {"sun_irradiance_rgb", {0.0, 0.0, 0.0}}}},
             {"frames", {{"images", "frames/%06d.png"}, {"timestamps", "frames.csv"}}},
             {"volume", {{"min", {-1, -1, 0.5}}, {"max", {1, 1, 1.5}}, {"resolution", {2, 2, 2}}}}};
  }
  ~SyntheticRecording() { std::filesystem::remove_all(dir); }

  // Writes everything and returns the scene.json path.
  std::filesystem::path Write(int env_height_override = 0) const {
    const int h = env_height_override > 0 ? env_height_override : env_width / 2;
    std::vector<float> r(static_cast<size_t>(env_width) * h), g(r.size()), b(r.size());
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < env_width; ++u) {
        const glm::vec3 l = env(LatLongDirection(u, v, env_width, h));
        const size_t i = static_cast<size_t>(v) * env_width + u;
        r[i] = l.x, g[i] = l.y, b[i] = l.z;
      }
    }
    scene::WriteExr(dir / "envmap.exr", env_width, h,
                    {{"R", scene::ExrPixelType::kFloat, r.data(), nullptr},
                     {"G", scene::ExrPixelType::kFloat, g.data(), nullptr},
                     {"B", scene::ExrPixelType::kFloat, b.data(), nullptr}});
    cv::imwrite((dir / "frames" / "000000.png").string(), cv::Mat(48, 64, CV_8UC3, cv::Scalar(120, 120, 120)));
    WriteFileAtomically(dir / "frames.csv", "frame,time_utc\n0,2026-06-21T00:00:00Z\n");
    WriteFileAtomically(dir / "model.obj", obj);
    WriteFileAtomically(dir / "scene.json", scene.dump(1));
    return dir / "scene.json";
  }
};

}  // namespace daylit::bake::testing
