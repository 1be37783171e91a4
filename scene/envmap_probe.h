// The size and kind of an HDR environment map, read from its header where the format allows.
#pragma once

#include <filesystem>
#include <string>

namespace daylit::scene {

struct EnvMapHeader {
  int width = 0;
  int height = 0;
  std::string format;    // "OpenEXR" or "Radiance HDR"
  std::string channels;  // e.g. "RGB", "RGBA"
};

// Reads the header of an OpenEXR file (OpenEXR) or decodes a Radiance .hdr (OpenCV). Throws
// InputError naming the file when it is not a readable HDR image.
EnvMapHeader ProbeEnvMap(const std::filesystem::path& path);

}  // namespace daylit::scene
