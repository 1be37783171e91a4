#include <atomic>
#include <csignal>

#include "apps/daylit/commands.h"

namespace daylit::app {
namespace {

std::atomic<bool> g_interrupted{false};
// The first Ctrl-C or SIGTERM asks the run to end with complete outputs; a second one ends the
// process at once, as the default action would (a later run removes what it leaves).
extern "C" void OnInterrupt(int signal) {
  if (g_interrupted.exchange(true)) {
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

}  // namespace

StopOnInterrupt::StopOnInterrupt() {
  g_interrupted = false;
  std::signal(SIGINT, OnInterrupt);
  std::signal(SIGTERM, OnInterrupt);
}

StopOnInterrupt::~StopOnInterrupt() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
}

const std::atomic<bool>* StopOnInterrupt::flag() const { return &g_interrupted; }

}  // namespace daylit::app
