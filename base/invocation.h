// How this process was run: its command line as typed, the folder it was run in and when it
// started. main() records it once; a run's report (evaluation/run_report.h) saves it beside the
// results, so that the run can be repeated from its output folder (with the version, base/version.h).
#pragma once

#include <string>
#include <vector>

namespace daylit {

struct Invocation {
  std::vector<std::string> argv;  // as given, program name first
  std::string cwd;                // the folder relative paths are taken from
  std::string started_utc;        // ISO 8601
  // The command line as one line a POSIX shell reads back into the same words: each word that
  // holds anything but letters, digits and -_./=:,+@% in single quotes.
  std::string CommandLine() const;
};

// Records this process's command line, working folder and the time now (main(), once).
void RecordInvocation(int argc, const char* const* argv);
// What RecordInvocation recorded; empty argv when nothing was (a library caller, a test).
const Invocation& CurrentInvocation();

}  // namespace daylit
