// The GPU path of image relighting (relight::ImageRelighter): the per-pixel terms of both suns
// live in textures, uploaded when a sun moves; each frame uploads the linear frame and the six
// light parts, and a fragment shader forms E_now and E_new, floors E_now, and multiplies. The
// same arithmetic as the CPU path, in float; needs a current GL context.
#pragma once

#include <array>
#include <vector>

#include "relight/image_relight.h"
#include "render/gl_program.h"

namespace daylit::render {

class ImageRelightGl {
 public:
  ImageRelightGl(int width, int height);
  ~ImageRelightGl();
  ImageRelightGl(const ImageRelightGl&) = delete;
  ImageRelightGl& operator=(const ImageRelightGl&) = delete;

  // Uploads the terms (after each ImageRelighter::SetSuns that returned true).
  void SetTerms(const relight::RatioTerms& terms);
  // As relight::ApplyRatio: `rgb` (width × height × 3, linear) times E_new / E_now, in place.
  relight::RelightStats Apply(const relight::RatioTerms& terms, const estimation::LightParts& now,
                              const estimation::LightParts& next, float* rgb);

 private:
  int width_, height_;
  GlProgram program_;
  GlVertexArray vao_;
  GlFramebuffer framebuffer_;
  GlTexture target_;                   // RGBA32F: the relit frame, alpha 1 where E_now was floored
  GlTexture frame_;                    // RGB32F
  std::array<GlTexture, 6> terms_;     // now sun (alpha: the pixel's kind), clear, overcast; new sun, clear, overcast
  size_t model_pixels_ = 0;
  std::vector<float> readback_;
};

}  // namespace daylit::render
