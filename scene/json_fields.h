// Reading scene.json fields with errors that name the file and the field path
// ("scene.json: camera.world_to_camera.rotation[1][2]: expected a number, got string").
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace daylit::scene {

// A JSON value and where it sits. Accessors throw InputError naming file and path.
class JsonField {
 public:
  JsonField(const nlohmann::json& value, std::string file, std::string path)
      : value_(&value), file_(std::move(file)), path_(std::move(path)) {}

  const nlohmann::json& value() const { return *value_; }
  const std::string& path() const { return path_; }
  bool IsObject() const { return value_->is_object(); }
  bool IsString() const { return value_->is_string(); }

  bool Has(const std::string& key) const;
  JsonField Get(const std::string& key) const;  // throws "missing" if absent
  std::optional<JsonField> Find(const std::string& key) const;
  std::vector<JsonField> Elements() const;  // this must be an array
  // Logs a warning for each key of this object not in `known` (forward compatibility).
  void WarnUnknownKeys(std::initializer_list<const char*> known) const;

  double Number() const;  // finite
  int Integer() const;
  std::string String() const;
  glm::dvec3 Vec3() const;
  glm::dmat3 Matrix3() const;  // rows as in the file; returned column-major for glm
  std::vector<double> Numbers() const;

  // Throws "<file>: <path>: <message>".
  [[noreturn]] void Fail(const std::string& message) const;

 private:
  const nlohmann::json* value_;
  std::string file_;
  std::string path_;
};

// Parses a JSON file; throws InputError naming the file (and line/column) on failure.
nlohmann::json ReadJsonFile(const std::filesystem::path& path);

}  // namespace daylit::scene
