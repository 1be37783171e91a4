// Broken invariants: a caller passed what the contract rules out (a size mismatch, a null output,
// options that fail their Check()). Unlike assert() these run in every build, NDEBUG included,
// and throw InvariantError, which the command line reports as an internal error (exit 3), never
// as the user's bad input. Bad input is InputError (base/error.h); an expected outcome of real
// data (a cloudy frame, no convergence) is a status in the result.
#pragma once

#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace daylit {

inline constexpr int kInternalErrorExitCode = 3;

class InvariantError : public std::logic_error {
 public:
  explicit InvariantError(const std::string& message) : std::logic_error(message) {}
};

namespace detail {
[[noreturn]] inline void FailCheck(const char* file, int line, const char* condition, const std::string& why) {
  throw InvariantError(fmt::format("{}:{}: check failed: {}{}{}", file, line, condition, why.empty() ? "" : ": ", why));
}
}  // namespace detail

}  // namespace daylit

// DAYLIT_CHECK(a.size() == b.size(), "{} vs {} texels", a.size(), b.size());
#define DAYLIT_CHECK(condition, ...)                                                               \
  do {                                                                                             \
    if (!(condition)) ::daylit::detail::FailCheck(__FILE__, __LINE__, #condition, fmt::format("" __VA_ARGS__)); \
  } while (false)
