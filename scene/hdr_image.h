// Linear HDR images: reading OpenEXR (float, any compression) and Radiance .hdr, writing
// multi-channel OpenEXR (named layers such as "albedo.R", "V.Y") atomically.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "base/hdr_image.h"

namespace daylit::scene {

// Relative luminance of linear Rec.709 RGB (the primaries of every image here).
inline float Luminance(const float* rgb) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }


// Reads R, G, B (or Y, as grey) as 32-bit floats from an OpenEXR file, or decodes a Radiance
// .hdr with OpenCV. Throws InputError naming the file when it cannot be read.
HdrImage ReadHdrImage(const std::filesystem::path& path);

// Checks an environment map: 2:1, then CheckLightProbe. Throws InputError naming the file.
void CheckEnvMap(const HdrImage& image, const std::string& name);

// A light probe of either shape (latitude-longitude or square angular map): at least
// kMinProbeWidth texels wide and half as high, every texel finite and ≥ 0 (else InputError
// naming the count of bad texels and the first one: "envmap.exr: 12 texels are NaN or infinite,
// first at (u 40, v 3)"), and some light in it (a texel > 0).
inline constexpr int kMinProbeWidth = 64;
void CheckLightProbe(const HdrImage& image, const std::string& name);

// The value part of CheckLightProbe, for images of any shape.
void CheckRadianceValues(const HdrImage& image, const std::string& name);

enum class ExrPixelType { kHalf, kFloat, kUint };

// One planar channel to write: `data` points to width·height values of the given type
// (uint16_t bits for kHalf is not supported: pass floats and kHalf converts).
struct ExrChannel {
  std::string name;
  ExrPixelType type = ExrPixelType::kFloat;
  const float* floats = nullptr;     // kFloat, kHalf
  const uint32_t* uints = nullptr;   // kUint
};

// Writes a multi-channel OpenEXR (ZIP compressed) to a temporary file and renames it to `path`.
void WriteExr(const std::filesystem::path& path, int width, int height, const std::vector<ExrChannel>& channels);

// Writes interleaved RGB floats (width·height·3, row-major from the top) as a float R, G, B
// OpenEXR, through WriteExr.
void WriteRgbExr(const std::filesystem::path& path, int width, int height, const float* rgb);

// Named channels of an OpenEXR file, read in one pass: float ones (HALF and FLOAT converted by
// OpenEXR) and UINT ones exactly. Throws InputError naming the file and a missing channel.
struct ExrChannels {
  int width = 0;
  int height = 0;
  std::vector<std::vector<float>> planes;      // in the order asked
  std::vector<std::vector<uint32_t>> uints;    // in the order asked
};
ExrChannels ReadExrChannels(const std::filesystem::path& path, const std::vector<std::string>& names,
                            const std::vector<std::string>& uint_names = {});

}  // namespace daylit::scene
