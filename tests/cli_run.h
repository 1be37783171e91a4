// Runs the `daylit` binary of this build as a user would, from a shell: its exit code, stdout
// and stderr (for cli_test and live_device_test).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include "base/csv.h"

namespace daylit::cli_testing {

struct CliRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline CliRun Daylit(const std::string& args, const std::string& environment = "") {
  static int counter = 0;
  namespace fs = std::filesystem;
  const fs::path err_file = fs::temp_directory_path() /
                            ("daylit_cli_err_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
  const std::string command = environment + std::string(DAYLIT_BINARY_DIR "/bin/daylit ") + args + " 2>" + err_file.string();
  CliRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer;
  size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.err = ReadTextFile(err_file);
  fs::remove(err_file);
  return run;
}

}  // namespace daylit::cli_testing
