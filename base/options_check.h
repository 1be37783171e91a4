// What the options structs' Check() are made of: each returns "" when the value is in range,
// else "<field>: <value> is outside <range>", so that a Check() is the first non-empty one.
#pragma once

#include <cmath>
#include <initializer_list>
#include <string>

#include <fmt/format.h>

namespace daylit {

// value in [lo, hi].
template <typename T>
std::string InClosed(const char* field, T value, T lo, T hi) {
  if (value >= lo && value <= hi) return {};
  return fmt::format("{}: {} is outside [{}, {}]", field, value, lo, hi);
}

// value in (lo, hi].
template <typename T>
std::string InOpenClosed(const char* field, T value, T lo, T hi) {
  if (value > lo && value <= hi) return {};
  return fmt::format("{}: {} is outside ({}, {}]", field, value, lo, hi);
}

// The first problem of several, "" when there is none.
inline std::string FirstProblem(std::initializer_list<std::string> problems) {
  for (const std::string& p : problems) {
    if (!p.empty()) return p;
  }
  return {};
}

// A nested struct's problem under its field's name: "sampler." + "samples: ...".
inline std::string Nested(const char* field, const std::string& problem) {
  return problem.empty() ? problem : fmt::format("{}.{}", field, problem);
}

}  // namespace daylit
