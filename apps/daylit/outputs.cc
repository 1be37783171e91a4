#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <filesystem>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "apps/daylit/commands.h"
#include "base/error.h"
#include "base/files.h"

#include <fmt/format.h>

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

void RefuseInputsAsOutputs(const std::vector<std::filesystem::path>& inputs,
                           const std::vector<std::filesystem::path>& input_folders,
                           const std::vector<std::pair<std::string, std::filesystem::path>>& outputs) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  for (const auto& f : inputs) files.push_back(ResolvedPath(f));
  for (const auto& [option, path] : outputs) {
    if (path.empty()) continue;
    const fs::path out = ResolvedPath(path);
    std::error_code ec;
    const bool exists = fs::exists(out, ec);
    for (size_t i = 0; i < files.size(); ++i) {
      // The same name, or the same file by another (a hard link): device and inode.
      if (out != files[i] && !(exists && fs::equivalent(out, files[i], ec))) continue;
      ThrowInputError("{}: {} names a file this run reads ({}): daylit does not write over its input (name another file)",
                      option, path.string(), inputs[i].string());
    }
    for (size_t i = 0; i < input_folders.size(); ++i) {
      if (!IsWithin(out, input_folders[i])) continue;
      ThrowInputError("{}: {} lies in {}, which this run reads: daylit does not write into its input (name another "
                      "folder)",
                      option, path.string(), input_folders[i].string());
    }
  }
}

void RefuseInputsAsOutputs(const scene::Scene& scene,
                           const std::vector<std::pair<std::string, std::filesystem::path>>& outputs) {
  const scene::SceneInputs in = scene::InputsOf(scene);
  RefuseInputsAsOutputs(in.files, in.folders, outputs);
  // Any file already in the recording's folder is the user's, read by this run or not (a glTF's
  // buffers and textures, an OBJ's .mtl, notes): never replaced. New names there may be written.
  for (const auto& [option, path] : outputs) {
    std::error_code ec;
    if (path.empty() || !std::filesystem::exists(path, ec) || !IsWithin(path, scene.folder)) continue;
    ThrowInputError("{}: {} is a file of the recording in {}: daylit does not replace a recording's files (name "
                    "another file)",
                    option, path.string(), scene.folder.string());
  }
}

void RequireValid(const std::string& what, const std::string& problem) {
  if (!problem.empty()) ThrowInputError("{}: {}", what, problem);
}

void RequireWritable(const std::string& option, const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return;
  std::error_code ec;
  if (fs::is_directory(path, ec)) ThrowInputError("{}: {} is a folder, not a file to write", option, path.string());
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (!fs::is_directory(folder, ec)) ThrowInputError("{}: {}: no such folder", option, folder.string());
  // A file made and removed there says it (access() would say yes to root even on /proc).
  const fs::path probe = folder / (".daylit-write-test-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0600);
  if (fd < 0) ThrowInputError("{}: {}: may not be written to", option, folder.string());
  ::close(fd);
  ::unlink(probe.c_str());
}

CLI::Validator FrameCount() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const bool digits = !text.empty() && text.size() <= 9 && text.find_first_not_of("0123456789") == std::string::npos;
        if (digits && std::stoi(text) >= 1) return {};
        return fmt::format("{} is not a number of frames", text.substr(0, 40));
      },
      "N");
}

}  // namespace daylit::app
