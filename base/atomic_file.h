// Writing result files so that a reader never sees half of one: the content goes to a temporary
// file in the same folder, which is renamed over the target only once it is complete.
#pragma once

#include <filesystem>
#include <functional>
#include <iosfwd>
#include <string_view>

namespace daylit {

// Calls `write` with a stream on a temporary file beside `path`, then renames it to `path`.
// If `write` throws or the stream fails, the temporary file is removed, `path` is untouched,
// and an InputError naming `path` is thrown (or the original exception is rethrown).
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

void WriteFileAtomically(const std::filesystem::path& path, std::string_view content);

// A temporary path beside `path` (same folder, so rename is atomic), unique per process and call:
// "<path>.tmp-<pid>-<n>". Temporaries of `path` that a process no longer running left behind (it
// was killed before it could rename or remove them) are removed first.
std::filesystem::path TemporarySibling(const std::filesystem::path& path);

// Removes the "<path>.tmp-<pid>-..." files beside `path` whose process <pid> is gone.
void RemoveStaleTemporaries(const std::filesystem::path& path);

// `path` itself, or where it leads if it is a symlink: the writers above write the file a link
// names and leave the link in place (TemporarySibling and CommitTemporary both follow it).
std::filesystem::path ThroughSymlinks(const std::filesystem::path& path);

// Renames `from` to `to` (through a symlink `to`), replacing it; throws InputError naming both on
// failure.
void CommitTemporary(const std::filesystem::path& from, const std::filesystem::path& to);

}  // namespace daylit
