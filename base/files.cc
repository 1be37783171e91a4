#include "base/files.h"

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

}  // namespace daylit
