#include "scene/json_fields.h"

#include <cmath>

#include "base/csv.h"
#include "base/error.h"
#include "base/log.h"

namespace daylit::scene {
namespace {

std::string TypeName(const nlohmann::json& v) { return v.type_name(); }

}  // namespace

bool JsonField::Has(const std::string& key) const {
  return value_->is_object() && value_->contains(key);
}

JsonField JsonField::Get(const std::string& key) const {
  std::optional<JsonField> field = Find(key);
  if (!field) {
    JsonField(*value_, file_, path_.empty() ? key : path_ + "." + key).Fail("missing");
  }
  return *field;
}

std::optional<JsonField> JsonField::Find(const std::string& key) const {
  if (!value_->is_object()) Fail("expected an object, got " + TypeName(*value_));
  const auto it = value_->find(key);
  if (it == value_->end()) return std::nullopt;
  return JsonField(*it, file_, path_.empty() ? key : path_ + "." + key);
}

std::vector<JsonField> JsonField::Elements() const {
  if (!value_->is_array()) Fail("expected an array, got " + TypeName(*value_));
  std::vector<JsonField> out;
  for (size_t i = 0; i < value_->size(); ++i) {
    out.emplace_back((*value_)[i], file_, path_ + "[" + std::to_string(i) + "]");
  }
  return out;
}

void JsonField::WarnUnknownKeys(std::initializer_list<const char*> known) const {
  if (!value_->is_object()) return;  // reading its fields says what it should be
  for (const auto& item : value_->items()) {
    const std::string& key = item.key();
    if (std::find_if(known.begin(), known.end(), [&](const char* k) { return key == k; }) ==
        known.end()) {
      Log().warn("{}: {}{}: unknown field, ignored", file_, path_.empty() ? "" : path_ + ".", key);
    }
  }
}

double JsonField::Number() const {
  if (!value_->is_number()) Fail("expected a number, got " + TypeName(*value_));
  const double v = value_->get<double>();
  if (!std::isfinite(v)) Fail("not a finite number");
  return v;
}

int JsonField::Integer() const {
  const double v = Number();
  if (v != std::floor(v) || std::abs(v) > 1e9) Fail(fmt::format("expected an integer, got {}", v));
  return static_cast<int>(v);
}

std::string JsonField::String() const {
  if (!value_->is_string()) Fail("expected a string, got " + TypeName(*value_));
  return value_->get<std::string>();
}

std::vector<double> JsonField::Numbers() const {
  std::vector<double> out;
  for (const JsonField& e : Elements()) out.push_back(e.Number());
  return out;
}

glm::dvec3 JsonField::Vec3() const {
  const std::vector<double> v = Numbers();
  if (v.size() != 3) Fail(fmt::format("expected 3 numbers, got {}", v.size()));
  return {v[0], v[1], v[2]};
}

glm::dmat3 JsonField::Matrix3() const {
  const std::vector<JsonField> rows = Elements();
  if (rows.size() != 3) Fail(fmt::format("expected 3 rows, got {}", rows.size()));
  glm::dmat3 m(0.0);
  for (int r = 0; r < 3; ++r) {
    const glm::dvec3 row = rows[static_cast<size_t>(r)].Vec3();
    for (int c = 0; c < 3; ++c) m[c][r] = row[c];
  }
  return m;
}

void JsonField::Fail(const std::string& message) const {
  ThrowInputError("{}: {}: {}", file_, path_.empty() ? "(top level)" : path_, message);
}

nlohmann::json ReadJsonFile(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // syntax, or a number beyond double range
    ThrowInputError("{}: invalid JSON: {}", path.string(), e.what());
  }
}

}  // namespace daylit::scene
