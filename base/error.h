// Errors caused by what the user gave us (files, fields, values). The command line prints the
// message on one line and exits with kInputErrorExitCode; nothing else catches these.
#pragma once

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace daylit {

inline constexpr int kInputErrorExitCode = 2;

// A message that names what is wrong and where: "scene.json: camera.fx: must be > 0 (got -3)".
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

template <typename... Args>
[[noreturn]] void ThrowInputError(fmt::format_string<Args...> format, Args&&... args) {
  throw InputError(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace daylit
