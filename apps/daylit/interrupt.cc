#include <atomic>
#include <csignal>

#include "apps/daylit/commands.h"

namespace daylit::app {
namespace {

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted = true; }

}  // namespace

StopOnInterrupt::StopOnInterrupt() {
  g_interrupted = false;
  std::signal(SIGINT, OnInterrupt);
}

StopOnInterrupt::~StopOnInterrupt() { std::signal(SIGINT, SIG_DFL); }

const std::atomic<bool>* StopOnInterrupt::flag() const { return &g_interrupted; }

}  // namespace daylit::app
