#include "render/gl_program.h"

#include <stdexcept>

#include <fmt/format.h>

namespace daylit::render {

const char* const kFullScreenTriangle = R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
})";
namespace {

// Compile and link errors are the program's own bugs, not bad input: std::logic_error.
GLuint Compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
    glDeleteShader(shader);
    throw std::logic_error(fmt::format("{} shader does not compile: {}", type == GL_VERTEX_SHADER ? "vertex" : "fragment", log));
  }
  return shader;
}

}  // namespace

GlProgram::GlProgram(const char* vertex_source, const char* fragment_source) {
  const GLuint vs = Compile(GL_VERTEX_SHADER, vertex_source);
  const GLuint fs = Compile(GL_FRAGMENT_SHADER, fragment_source);
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(id_, sizeof(log), nullptr, log);
    glDeleteProgram(id_);
    throw std::logic_error(fmt::format("shader program does not link: {}", log));
  }
}

GlProgram::~GlProgram() { glDeleteProgram(id_); }

namespace {

GLuint Generate(void (*gen)(GLsizei, GLuint*)) {
  GLuint id = 0;
  gen(1, &id);
  return id;
}

}  // namespace

GlTexture NewTexture() { return GlTexture(Generate(glGenTextures)); }
GlBuffer NewBuffer() { return GlBuffer(Generate(glGenBuffers)); }
GlFramebuffer NewFramebuffer() { return GlFramebuffer(Generate(glGenFramebuffers)); }
GlRenderbuffer NewRenderbuffer() { return GlRenderbuffer(Generate(glGenRenderbuffers)); }
GlVertexArray NewVertexArray() { return GlVertexArray(Generate(glGenVertexArrays)); }

}  // namespace daylit::render
