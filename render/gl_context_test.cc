// A real GL context on this machine (llvmpipe without a GPU): a missing context is a failure,
// never a skip.
#include "render/gl_context.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <vector>

#include "render/gl_program.h"

namespace daylit::render {
namespace {

TEST(GlContextTest, CoreContextRendersExactFloatsIntoAnFbo) {
  std::string why;
  const std::unique_ptr<HeadlessGlContext> gl = HeadlessGlContext::Create(&why);
  ASSERT_NE(gl, nullptr) << why;
  EXPECT_GE(gl->gl_version(), 33) << gl->version();
  std::printf("OpenGL %s on %s (%s)\n", gl->version().c_str(), gl->renderer().c_str(), gl->platform().c_str());

  constexpr int kW = 64, kH = 32;
  GLuint fbo = 0, color = 0, vao = 0;
  glGenTextures(1, &color);
  glBindTexture(GL_TEXTURE_2D, color);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, kW, kH, 0, GL_RGBA, GL_FLOAT, nullptr);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color, 0);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));

  // A full-screen triangle from gl_VertexID (core profile still needs a bound VAO).
  const GlProgram program(R"(#version 330 core
    void main() {
      vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
      gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
    })",
                          R"(#version 330 core
    uniform vec2 size;
    out vec4 color;
    void main() { color = vec4(gl_FragCoord.xy / size, 37.5, 1.0); })");
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glViewport(0, 0, kW, kH);
  glUseProgram(program.id());
  glUniform2f(program.Uniform("size"), static_cast<float>(kW), static_cast<float>(kH));
  glDrawArrays(GL_TRIANGLES, 0, 3);

  std::vector<float> pixels(kW * kH * 4);
  glReadPixels(0, 0, kW, kH, GL_RGBA, GL_FLOAT, pixels.data());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const float* p = &pixels[static_cast<size_t>((y * kW + x) * 4)];
      ASSERT_NEAR(p[0], (static_cast<float>(x) + 0.5f) / kW, 1e-6f) << x << "," << y;
      ASSERT_NEAR(p[1], (static_cast<float>(y) + 0.5f) / kH, 1e-6f) << x << "," << y;
      ASSERT_EQ(p[2], 37.5f);  // HDR values survive: no clamping to [0, 1]
    }
  }
  glDeleteVertexArrays(1, &vao);
  glDeleteFramebuffers(1, &fbo);
  glDeleteTextures(1, &color);
}

}  // namespace
}  // namespace daylit::render
