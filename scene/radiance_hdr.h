// Radiance RGBE (.hdr) pixels, decoded here with every length checked against the file.
// Neither library at hand survives hostile files (both found by fuzz_hdr): OpenCV's imread picks
// a decoder by the bytes, so a ".hdr" holding a DICOM signature went to GDCM, which asserts; and
// stb_image's decoder loops forever on a run-length count of 0 (or a file that ends inside a
// scan line). The format is small: a text header, a resolution line, then scan lines flat or in
// the "new" run-length encoding (Greg Ward, Graphics Gems II, "Real Pixels").
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace daylit::scene {

// Decodes `path` to linear RGB floats (width·height·3, row-major from the top): each RGBE texel
// is (R, G, B)·2^(E−136), 0 where E is 0. The header must start "#?", may say FORMAT=
// 32-bit_rle_rgbe (XYZE is refused), and its resolution line must be "-Y H +X W" (rows from the
// top, the orientation every lat-long map uses). False with `why` naming the problem otherwise.
bool DecodeRadianceHdr(const std::filesystem::path& path, int* width, int* height, std::vector<float>* rgb, std::string* why);

}  // namespace daylit::scene
