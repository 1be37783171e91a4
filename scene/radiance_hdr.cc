#include "scene/radiance_hdr.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>

namespace daylit::scene {

bool DecodeRadianceHdr(const std::filesystem::path& path, int* width, int* height, std::vector<float>* rgb, std::string* why) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *why = "cannot be opened";
    return false;
  }
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const auto fail = [&](std::string reason) {
    *why = std::move(reason);
    return false;
  };
  if (bytes.compare(0, 2, "#?") != 0) return fail("no \"#?\" signature");
  // The header: lines up to an empty one.
  size_t at = 0;
  for (int lines = 0;; ++lines) {
    const size_t end = bytes.find('\n', at);
    if (end == std::string::npos || lines > 256) return fail("no end to its header");
    const std::string line = bytes.substr(at, end - at);
    at = end + 1;
    if (line.empty()) break;
    if (line.rfind("FORMAT=", 0) == 0 && line != "FORMAT=32-bit_rle_rgbe") return fail("not RGBE (" + line + ")");
  }
  const size_t end = bytes.find('\n', at);
  if (end == std::string::npos) return fail("no resolution line");
  int h = 0, w = 0;
  char tail = 0;
  if (std::sscanf(bytes.substr(at, end - at).c_str(), "-Y %d +X %d%c", &h, &w, &tail) != 2 || w <= 0 || h <= 0) {
    return fail("its resolution line is not \"-Y height +X width\"");
  }
  at = end + 1;
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  const size_t size = bytes.size();
  std::vector<uint8_t> line(static_cast<size_t>(w) * 4);
  rgb->assign(static_cast<size_t>(w) * static_cast<size_t>(h) * 3, 0.0f);
  for (int y = 0; y < h; ++y) {
    const bool run_length = w >= 8 && w < 32768 && at + 4 <= size && data[at] == 2 && data[at + 1] == 2 &&
                            ((data[at + 2] << 8) | data[at + 3]) == w;
    if (run_length) {
      // Four channels one after the other, each as runs (count > 128: one value count − 128
      // times) and dumps (count ≤ 128: that many values), never past the line's end.
      at += 4;
      for (int c = 0; c < 4; ++c) {
        for (int x = 0; x < w;) {
          if (at >= size) return fail("ends inside scan line " + std::to_string(y));
          const int count = data[at++];
          const bool run = count > 128;
          const int n = run ? count - 128 : count;
          if (n == 0 || n > w - x) return fail("a run of " + std::to_string(n) + " in scan line " + std::to_string(y));
          if (at + (run ? 1 : static_cast<size_t>(n)) > size) return fail("ends inside scan line " + std::to_string(y));
          for (int k = 0; k < n; ++k, ++x) line[static_cast<size_t>(x) * 4 + c] = run ? data[at] : data[at + k];
          at += run ? 1 : static_cast<size_t>(n);
        }
      }
    } else {
      if (at + line.size() > size) return fail("ends inside scan line " + std::to_string(y));
      std::copy(data + at, data + at + line.size(), line.begin());
      at += line.size();
    }
    float* out = rgb->data() + static_cast<size_t>(y) * static_cast<size_t>(w) * 3;
    for (int x = 0; x < w; ++x) {
      const uint8_t* texel = &line[static_cast<size_t>(x) * 4];
      const float scale = texel[3] == 0 ? 0.0f : std::ldexp(1.0f, texel[3] - 136);
      for (int c = 0; c < 3; ++c) out[3 * x + c] = texel[c] * scale;
    }
  }
  *width = w, *height = h;
  return true;
}

}  // namespace daylit::scene
