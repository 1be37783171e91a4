#include "evaluation/run_report.h"

#include <fmt/format.h>

#include "base/atomic_file.h"

namespace daylit::evaluation {

void RunReport::Say(const std::string& line) {
  fmt::print("{}\n", line);
  text_ += line;
  text_ += '\n';
}

void RunReport::Write(const std::filesystem::path& file) const { WriteFileAtomically(file, text_); }

}  // namespace daylit::evaluation
