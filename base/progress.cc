#include "base/progress.h"

#include <unistd.h>

#include <cstdio>

#include <fmt/format.h>

#include "base/log.h"

namespace daylit {

Progress::Progress(std::string label, size_t total)
    : label_(std::move(label)),
      total_(total == 0 ? 1 : total),
      tty_(::isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { Draw(done_.load(), true); }

void Progress::SetSuffix(std::string suffix) {
  std::lock_guard<std::mutex> lock(mutex_);
  suffix_ = std::move(suffix);
}

void Progress::Advance(size_t done) {
  const size_t now = done_.fetch_add(done) + done;
  Draw(now, false);
}

void Progress::Draw(size_t done, bool final) {
  if (Log().level() > spdlog::level::info) return;
  std::lock_guard<std::mutex> lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_));
  const double seconds = std::chrono::duration<double>(now - start_).count();
  if (tty_) {
    if (!final && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    const int filled = static_cast<int>(fraction * 30.0);
    std::fprintf(stderr, "\r%s [%s%s] %3.0f%% %.1f s %s%s", label_.c_str(), std::string(static_cast<size_t>(filled), '#').c_str(),
                 std::string(static_cast<size_t>(30 - filled), '.').c_str(), fraction * 100.0, seconds, suffix_.c_str(),
                 final ? "\n" : "");
    std::fflush(stderr);
    return;
  }
  const int decile = static_cast<int>(fraction * 10.0);
  if (decile == last_decile_ && !final) return;
  if (final && last_decile_ == 10) return;
  last_decile_ = final ? 10 : decile;
  std::fprintf(stderr, "%s %3.0f%% %.1f s %s\n", label_.c_str(), fraction * 100.0, seconds, suffix_.c_str());
}

}  // namespace daylit
