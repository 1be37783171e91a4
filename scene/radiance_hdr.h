// Radiance RGBE (.hdr) pixels through stb_image's HDR decoder alone (compiled with STBI_ONLY_HDR,
// static to this library): OpenCV's imread picks a decoder by the bytes, so a ".hdr" whose
// content looks like DICOM went to GDCM, which asserts (found by fuzz_hdr).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace daylit::scene {

// Decodes `path` to linear RGB floats (width·height·3, row-major from the top). False with
// `why` (stb's reason) when it is not a Radiance file stb can read.
bool DecodeRadianceHdr(const std::filesystem::path& path, int* width, int* height, std::vector<float>* rgb, std::string* why);

}  // namespace daylit::scene
