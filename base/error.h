// Errors caused by what the user gave us (files, fields, values). The command line prints the
// message on one line and exits with kInputErrorExitCode; nothing else catches these. Broken
// invariants are DAYLIT_CHECK (base/check.h); expected outcomes of real data are status values.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace daylit {

inline constexpr int kInputErrorExitCode = 2;

// A message that names what is wrong and where: "scene.json: camera.fx: must be > 0 (got -3)".
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// Text from the user's input as an error quotes it: at most `most` characters, then "…" and how
// long it was (a 5 MB token is not echoed whole).
inline std::string Excerpt(std::string_view text, size_t most = 60) {
  if (text.size() <= most) return std::string(text);
  return fmt::format("{}… ({} characters)", text.substr(0, most), text.size());
}

template <typename... Args>
[[noreturn]] void ThrowInputError(fmt::format_string<Args...> format, Args&&... args) {
  throw InputError(fmt::format(format, std::forward<Args>(args)...));
}

// The machine, not the input and not daylit: a GL driver without what daylit needs, a device that
// fails. The command line prints the message on one line and exits with 1.
class SystemError : public std::runtime_error {
 public:
  explicit SystemError(const std::string& message) : std::runtime_error(message) {}
};

template <typename... Args>
[[noreturn]] void ThrowSystemError(fmt::format_string<Args...> format, Args&&... args) {
  throw SystemError(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace daylit
