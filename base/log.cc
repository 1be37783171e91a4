#include "base/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>

namespace daylit {
namespace {

std::shared_ptr<spdlog::logger> MakeLogger() {
  auto logger = spdlog::stderr_color_mt("daylit");
  logger->set_pattern("%^[%l]%$ %v");
  logger->set_level(spdlog::level::info);
  spdlog::set_default_logger(logger);
  return logger;
}

}  // namespace

spdlog::logger& Log() {
  static const std::shared_ptr<spdlog::logger> logger = MakeLogger();
  return *logger;
}

void SetLogVerbosity(int verbosity) {
  const spdlog::level::level_enum level = verbosity <= 0   ? spdlog::level::warn
                                          : verbosity == 1 ? spdlog::level::info
                                                           : spdlog::level::debug;
  Log().set_level(level);
}

}  // namespace daylit
