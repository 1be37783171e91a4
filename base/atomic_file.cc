#include "base/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <fstream>
#include <system_error>

#include "base/error.h"

namespace daylit {

std::filesystem::path TemporarySibling(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path tmp = path;
  tmp += fmt::format(".tmp-{}-{}", static_cast<long>(::getpid()), counter++);
  return tmp;
}

void CommitTemporary(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::error_code ec;
  std::filesystem::rename(from, to, ec);
  if (ec) {
    std::filesystem::remove(from, ec);
    ThrowInputError("{}: cannot write: {}", to.string(), ec.message());
  }
}

void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write) {
  const std::filesystem::path tmp = TemporarySibling(path);
  std::error_code ec;
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      ThrowInputError("{}: cannot open for writing", path.string());
    }
    write(out);
    out.flush();
    if (!out) {
      ThrowInputError("{}: write failed (disk full?)", path.string());
    }
  } catch (...) {
    std::filesystem::remove(tmp, ec);
    throw;
  }
  CommitTemporary(tmp, path);
}

void WriteFileAtomically(const std::filesystem::path& path, std::string_view content) {
  WriteFileAtomically(path, [content](std::ostream& out) {
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
  });
}

}  // namespace daylit
