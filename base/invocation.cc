#include "base/invocation.h"

#include <chrono>
#include <filesystem>
#include <string_view>
#include <system_error>

#include "base/utc_time.h"

namespace daylit {
namespace {

Invocation& Recorded() {
  static Invocation invocation;
  return invocation;
}

std::string ShellWord(const std::string& word) {
  if (word.empty()) return "''";
  bool plain = true;
  for (const char c : word) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    std::string_view("-_./=:,+@%").find(c) != std::string_view::npos;
    plain = plain && ok;
  }
  if (plain) return word;
  std::string out = "'";
  for (const char c : word) {
    if (c == '\'') {
      out.append("'\\''");  // close, an escaped quote, reopen
    } else {
      out.push_back(c);
    }
  }
  out.push_back('\'');
  return out;
}

}  // namespace

std::string Invocation::CommandLine() const {
  std::string out;
  for (const std::string& word : argv) {
    if (!out.empty()) out.push_back(' ');
    out.append(ShellWord(word));
  }
  return out;
}

void RecordInvocation(int argc, const char* const* argv) {
  Invocation& r = Recorded();
  r.argv.assign(argv, argv + argc);
  std::error_code ec;
  r.cwd = std::filesystem::current_path(ec).string();
  const auto now = std::chrono::system_clock::now();
  const double seconds = std::chrono::duration<double>(now.time_since_epoch()).count();
  r.started_utc = FormatUtcTime(UtcFromUnixSeconds(seconds), 0);
}

const Invocation& CurrentInvocation() { return Recorded(); }

}  // namespace daylit
