// A writable copy of the bundled recording's scene.json beside links to its files, so that
// tests can break one field at a time.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "base/atomic_file.h"
#include "base/csv.h"

namespace daylit::scene::testing {

class SceneSandbox {
 public:
  explicit SceneSandbox(const std::string& name) {
    namespace fs = std::filesystem;
    const fs::path source = fs::path(DAYLIT_SOURCE_DIR) / "recordings" / "courtyard-a";
    dir_ = fs::temp_directory_path() / ("daylit_scene_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    for (const char* f : {"model.obj", "frames.csv", "video.mp4", "envmap.exr", "groundtruth.csv",
                          "groundtruth"}) {
      fs::create_symlink(source / f, dir_ / f);
    }
    json_ = nlohmann::json::parse(ReadTextFile(source / "scene.json"));
  }
  ~SceneSandbox() { std::filesystem::remove_all(dir_); }

  nlohmann::json& json() { return json_; }
  const std::filesystem::path& dir() const { return dir_; }
  std::filesystem::path Write() const {
    WriteFileAtomically(dir_ / "scene.json", json_.dump(1));
    return dir_ / "scene.json";
  }
  std::filesystem::path WriteText(const std::string& name, const std::string& text) const {
    WriteFileAtomically(dir_ / name, text);
    return dir_ / name;
  }

 private:
  std::filesystem::path dir_;
  nlohmann::json json_;
};

}  // namespace daylit::scene::testing
