#include "base/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <string>

#include <atomic>
#include <cstring>
#include <fstream>
#include <system_error>

#include "base/error.h"

namespace daylit {

void RemoveStaleTemporaries(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  const std::string prefix = path.filename().string() + ".tmp-";
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    // "<name>.tmp-<pid>-<n>[...]": stale when no process <pid> lives (ESRCH; EPERM means one does).
    const std::string rest = name.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == 0 || dash == std::string::npos || rest.find_first_not_of("0123456789") != dash) continue;
    const long pid = std::strtol(rest.substr(0, dash).c_str(), nullptr, 10);
    if (pid <= 0 || pid == static_cast<long>(::getpid()) || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code removed;
    if (std::filesystem::is_regular_file(it->path(), removed)) std::filesystem::remove(it->path(), removed);
  }
}

std::filesystem::path ThroughSymlinks(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_symlink(path, ec)) return path;
  const std::filesystem::path target = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : target;
}

std::filesystem::path TemporarySibling(const std::filesystem::path& given) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path path = ThroughSymlinks(given);
  RemoveStaleTemporaries(path);
  std::filesystem::path tmp = path;
  tmp += fmt::format(".tmp-{}-{}", static_cast<long>(::getpid()), counter++);
  return tmp;
}

void CommitTemporary(const std::filesystem::path& from, const std::filesystem::path& given) {
  const std::filesystem::path to = ThroughSymlinks(given);
  std::error_code ec, removed;
  std::filesystem::rename(from, to, ec);
  if (ec) {
    std::filesystem::remove(from, removed);  // its own code: the rename's is the one to tell
    if (std::filesystem::is_directory(to, removed)) ThrowInputError("{}: is a folder, not a file to write", to.string());
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
      // The file could be made, so its folder is writable: a write that fails then is the
      // machine's (a full disk, an I/O error), not the input's.
      const int error = errno;
      ThrowSystemError("{}: write failed: {}", path.string(), error != 0 ? std::strerror(error) : "no space or I/O error");
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
