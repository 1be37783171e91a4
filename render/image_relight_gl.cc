#include "render/image_relight_gl.h"

#include <glm/gtc/type_ptr.hpp>

#include "base/error.h"

namespace daylit::render {
namespace {

// Rows as uploaded: texture row y is the image's row y, and so is the framebuffer's, which
// glReadPixels returns first row first: no flip anywhere.
const char* kRelightFragment = R"(#version 330 core
uniform sampler2D frame;
uniform sampler2D now_sun, now_clear, now_overcast, new_sun, new_clear, new_overcast;
uniform vec3 e_now[3], e_new[3], floor_now;
out vec4 color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 rgb = texelFetch(frame, p, 0).rgb;
  vec4 sun = texelFetch(now_sun, p, 0);  // alpha: the pixel's kind
  if (sun.a > 1.5) { color = vec4(rgb, 0.0); return; }
  vec3 now = e_now[0] * sun.rgb + e_now[1] * texelFetch(now_clear, p, 0).rgb +
             e_now[2] * texelFetch(now_overcast, p, 0).rgb;
  vec3 next = e_new[0] * texelFetch(new_sun, p, 0).rgb + e_new[1] * texelFetch(new_clear, p, 0).rgb +
              e_new[2] * texelFetch(new_overcast, p, 0).rgb;
  float floored = 0.0;
  if (sun.a < 0.5) {
    floored = any(lessThan(now, floor_now)) ? 1.0 : 0.0;
    now = max(now, floor_now);
  } else {
    now = max(now, vec3(1e-20));
  }
  color = vec4(rgb * next / now, floored);
})";

void Allocate(const GlTexture& texture, GLint internal, int w, int h, GLenum format, GLenum type) {
  glBindTexture(GL_TEXTURE_2D, texture.get());
  glTexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, type, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
}

void Upload(const GlTexture& texture, int w, int h, GLenum format, GLenum type, const void* data) {
  glBindTexture(GL_TEXTURE_2D, texture.get());
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, format, type, data);
}

}  // namespace

ImageRelightGl::ImageRelightGl(int width, int height)
    : width_(width), height_(height), program_(kFullScreenTriangle, kRelightFragment), vao_(NewVertexArray()),
      framebuffer_(NewFramebuffer()), target_(NewTexture()), frame_(NewTexture()),
      terms_{NewTexture(), NewTexture(), NewTexture(), NewTexture(), NewTexture(), NewTexture()} {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  Allocate(target_, GL_RGBA32F, width, height, GL_RGBA, GL_FLOAT);
  Allocate(frame_, GL_RGBA32F, width, height, GL_RGB, GL_FLOAT);
  for (const GlTexture& t : terms_) Allocate(t, GL_RGBA32F, width, height, GL_RGB, GL_FLOAT);
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target_.get(), 0);
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!complete || glGetError() != GL_NO_ERROR) ThrowSystemError("OpenGL: setting up image relighting failed");
  glUseProgram(program_.id());
  const char* names[] = {"frame", "now_sun", "now_clear", "now_overcast", "new_sun", "new_clear", "new_overcast"};
  for (int i = 0; i < 7; ++i) glUniform1i(program_.Uniform(names[i]), i);
  glUseProgram(0);
  readback_.resize(static_cast<size_t>(width) * static_cast<size_t>(height) * 4);
}

ImageRelightGl::~ImageRelightGl() = default;

void ImageRelightGl::SetTerms(const relight::RatioTerms& terms) {
  if (terms.width != width_ || terms.height != height_) {
    ThrowInputError("image relighting: terms of {}x{} for a {}x{} frame", terms.width, terms.height, width_, height_);
  }
  // The now sun's terms carry the pixel's kind in alpha (one fetch fewer).
  const size_t n = terms.kind.size();
  std::vector<glm::vec4> with_kind(n);
  for (size_t p = 0; p < n; ++p) with_kind[p] = glm::vec4(terms.now.sun[p], static_cast<float>(terms.kind[p]));
  Upload(terms_[0], width_, height_, GL_RGBA, GL_FLOAT, with_kind.data());
  const std::vector<glm::vec3>* maps[5] = {&terms.now.clear, &terms.now.overcast, &terms.next.sun, &terms.next.clear,
                                           &terms.next.overcast};
  for (size_t m = 0; m < 5; ++m) Upload(terms_[m + 1], width_, height_, GL_RGB, GL_FLOAT, maps[m]->data());
  model_pixels_ = 0;
  for (const uint8_t k : terms.kind) model_pixels_ += k == relight::kModelPixel ? 1 : 0;
}

relight::RelightStats ImageRelightGl::Apply(const relight::RatioTerms& terms, const estimation::LightParts& now,
                                            const estimation::LightParts& next, float* rgb) {
  Upload(frame_, width_, height_, GL_RGB, GL_FLOAT, rgb);
  glUseProgram(program_.id());
  const glm::vec3 e_now[3] = {now.sun, now.clear, now.overcast}, e_new[3] = {next.sun, next.clear, next.overcast};
  glUniform3fv(program_.Uniform("e_now"), 3, glm::value_ptr(e_now[0]));
  glUniform3fv(program_.Uniform("e_new"), 3, glm::value_ptr(e_new[0]));
  glUniform3fv(program_.Uniform("floor_now"), 1, glm::value_ptr(terms.FloorOf(now)));
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, frame_.get());
  for (size_t i = 0; i < terms_.size(); ++i) {
    glActiveTexture(GL_TEXTURE1 + static_cast<GLenum>(i));
    glBindTexture(GL_TEXTURE_2D, terms_[i].get());
  }
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_.get());
  glViewport(0, 0, width_, height_);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glBindVertexArray(vao_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_FLOAT, readback_.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glActiveTexture(GL_TEXTURE0);
  if (glGetError() != GL_NO_ERROR) ThrowSystemError("OpenGL: image relighting failed");
  relight::RelightStats stats;
  stats.model_pixels = model_pixels_;
  const size_t n = static_cast<size_t>(width_) * static_cast<size_t>(height_);
  for (size_t p = 0; p < n; ++p) {
    const float* v = &readback_[4 * p];
    rgb[3 * p] = v[0], rgb[3 * p + 1] = v[1], rgb[3 * p + 2] = v[2];
    stats.clamped += v[3] > 0.5f ? 1 : 0;
  }
  return stats;
}

}  // namespace daylit::render
