#include <cstddef>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "apps/daylit/commands.h"
#include "base/error.h"

namespace daylit::app {

void RefuseSharedOutputs(const std::vector<std::pair<std::string, std::filesystem::path>>& outputs) {
  namespace fs = std::filesystem;
  std::vector<fs::path> resolved;
  for (const auto& [option, path] : outputs) {
    std::error_code ec;
    const fs::path p = path.empty() ? path : fs::weakly_canonical(fs::absolute(path), ec);
    resolved.push_back(ec ? fs::absolute(path).lexically_normal() : p);
  }
  for (size_t i = 0; i < outputs.size(); ++i) {
    for (size_t j = i + 1; j < outputs.size(); ++j) {
      if (resolved[i].empty() || resolved[i] != resolved[j]) continue;
      ThrowInputError("{} and {} both name {}: two outputs of one run need two names", outputs[i].first,
                      outputs[j].first, outputs[i].second.string());
    }
  }
}

}  // namespace daylit::app
