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
// .hdr with OpenCV. Throws InputError naming the file when it cannot be read. Before anything is
// allocated, the size its header claims is checked (CheckClaimedSize).
HdrImage ReadHdrImage(const std::filesystem::path& path);

// The most pixels an image daylit reads may claim: a 16384×8192 map (1.6 GB as float RGB).
inline constexpr int64_t kMostImagePixels = int64_t{16384} * 8192;
// Throws InputError naming `path` when its header's `width` × `height` is empty, over
// kMostImagePixels, or more than the file's bytes can hold: no compression an EXR or a Radiance
// file uses packs more than 1032 bytes of samples (deflate's limit) into one, and every pixel has
// at least `bytes_per_pixel` of them.
void CheckClaimedSize(const std::filesystem::path& path, int64_t width, int64_t height, int64_t bytes_per_pixel);

// CheckClaimedSize on an OpenEXR file's data window, read from its header by hand before OpenEXR
// builds anything from it (nothing when the file is not OpenEXR: OpenEXR then says so).
void CheckExrClaimedSize(const std::filesystem::path& path, int64_t bytes_per_pixel);

// The width and height a Radiance .hdr's header gives ("-Y H +X W" after the header lines),
// without decoding it. Throws InputError naming the file when there is none.
void ReadRadianceSize(const std::filesystem::path& path, int* width, int* height);

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

// The same file's bytes, in memory (daylit's lighting server's GET /envmap).
std::string EncodeExr(int width, int height, const std::vector<ExrChannel>& channels);

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
