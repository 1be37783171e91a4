// A progress bar on stderr for long work (bake, replay). On a terminal it redraws one line;
// elsewhere (CI logs) it prints a line every 10%. Thread-safe Advance().
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace daylit {

class Progress {
 public:
  Progress(std::string label, size_t total);
  ~Progress();  // finishes the line
  void Advance(size_t done = 1);
  // Extra text after the bar, e.g. "42 fps".
  void SetSuffix(std::string suffix);

 private:
  void Draw(size_t done, bool final);

  std::string label_;
  size_t total_;
  std::atomic<size_t> done_{0};
  std::mutex mutex_;
  std::string suffix_;
  bool tty_;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace daylit
