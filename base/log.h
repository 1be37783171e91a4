// The one logger of daylit. Logs and errors go to stderr; results go to stdout or files.
#pragma once

#include <spdlog/spdlog.h>

namespace daylit {

// The process-wide logger, writing to stderr. Also installed as spdlog's default logger so a
// stray spdlog::info() cannot end up on stdout. Thread-safe.
spdlog::logger& Log();

// Sets the level: 0 = warnings and errors only, 1 = info (default), 2 = debug.
void SetLogVerbosity(int verbosity);

}  // namespace daylit
