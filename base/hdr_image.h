// The plain linear image every module passes around: RGB floats, row-major, row 0 at the top.
// Reading and writing files (OpenEXR, Radiance .hdr) is scene/hdr_image.h's.
#pragma once

#include <cstddef>
#include <vector>

namespace daylit {

// RGB float image, row-major, row 0 at the top.
struct HdrImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // 3 floats per pixel

  const float* Pixel(int x, int y) const { return &rgb[(static_cast<size_t>(y) * width + x) * 3]; }
  float* Pixel(int x, int y) { return &rgb[(static_cast<size_t>(y) * width + x) * 3]; }
};

}  // namespace daylit
