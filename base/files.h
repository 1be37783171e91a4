// Whether a path the user gave can be read as a file, and if not, why, in the user's terms.
#pragma once

#include <filesystem>
#include <string>

namespace daylit {

// "" when `path` is a regular file (through symbolic links); else why not: "no such file", "is a
// folder", "is not a regular file (a device, a FIFO or a socket)", or the system's own words (a
// loop of symbolic links, a folder that may not be searched).
std::string WhyNotAFile(const std::filesystem::path& path);

// Throws InputError "<path>: <why>" unless `path` is a regular file.
void RequireRegularFile(const std::filesystem::path& path);

// `path` absolute, through every symbolic link that exists (the final name included), normalised.
// An empty path is the working folder (the folder of a bare file name).
std::filesystem::path ResolvedPath(const std::filesystem::path& path);
// Whether `path` is `folder` or lies inside it, both resolved (ResolvedPath).
bool IsWithin(const std::filesystem::path& path, const std::filesystem::path& folder);

}  // namespace daylit
