#include "base/files.h"

#include <algorithm>
#include <iterator>
#include <system_error>

#include "base/error.h"

namespace daylit {

std::string WhyNotAFile(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec && status.type() != std::filesystem::file_type::not_found) return ec.message();
  switch (status.type()) {
    case std::filesystem::file_type::regular: return "";
    case std::filesystem::file_type::not_found: return "no such file";
    case std::filesystem::file_type::directory: return "is a folder";
    default: return "is not a regular file (a device, a FIFO or a socket)";
  }
}

void RequireRegularFile(const std::filesystem::path& path) {
  if (const std::string why = WhyNotAFile(path); !why.empty()) ThrowInputError("{}: {}", path.string(), why);
}

std::filesystem::path ResolvedPath(const std::filesystem::path& path) {
  // An empty path is the current folder here (the folder of a bare file name), as the system's
  // calls take it; std::filesystem::absolute("") throws.
  const std::filesystem::path given = path.empty() ? std::filesystem::path(".") : path;
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(given, ec);
  if (ec) return given.lexically_normal();
  const std::filesystem::path p = std::filesystem::weakly_canonical(absolute, ec);
  return ec ? absolute.lexically_normal() : p;
}

bool IsWithin(const std::filesystem::path& path, const std::filesystem::path& folder) {
  const std::filesystem::path p = ResolvedPath(path), f = ResolvedPath(folder);
  auto [in_folder, in_path] = std::mismatch(f.begin(), f.end(), p.begin(), p.end());
  return in_folder == f.end() || (in_folder->empty() && std::next(in_folder) == f.end());
}

}  // namespace daylit
