// Small RAII wrappers for GL objects the renderer owns, and shader programs that say what went
// wrong when they do not compile. Need a current context.
#pragma once

#include <epoxy/gl.h>

#include <string>

namespace daylit::render {

// A vertex shader that covers the viewport with one triangle (draw 3 vertices, no buffers), for
// fragment shaders that work per pixel.
extern const char* const kFullScreenTriangle;

class GlProgram {
 public:
  GlProgram(const char* vertex_source, const char* fragment_source);
  ~GlProgram();
  GlProgram(const GlProgram&) = delete;
  GlProgram& operator=(const GlProgram&) = delete;
  GLuint id() const { return id_; }
  GLint Uniform(const char* name) const { return glGetUniformLocation(id_, name); }

 private:
  GLuint id_ = 0;
};

// One GL name and the call that deletes it.
template <void (*Delete)(GLsizei, const GLuint*)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint id) : id_(id) {}
  ~GlName() {
    if (id_ != 0) Delete(1, &id_);
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  GlName(GlName&& other) noexcept : id_(other.id_) { other.id_ = 0; }
  GlName& operator=(GlName&& other) noexcept {
    std::swap(id_, other.id_);
    return *this;
  }
  GLuint get() const { return id_; }

 private:
  GLuint id_ = 0;
};

inline void DeleteTextures(GLsizei n, const GLuint* ids) { glDeleteTextures(n, ids); }
inline void DeleteBuffers(GLsizei n, const GLuint* ids) { glDeleteBuffers(n, ids); }
inline void DeleteFramebuffers(GLsizei n, const GLuint* ids) { glDeleteFramebuffers(n, ids); }
inline void DeleteRenderbuffers(GLsizei n, const GLuint* ids) { glDeleteRenderbuffers(n, ids); }
inline void DeleteVertexArrays(GLsizei n, const GLuint* ids) { glDeleteVertexArrays(n, ids); }

using GlTexture = GlName<DeleteTextures>;
using GlBuffer = GlName<DeleteBuffers>;
using GlFramebuffer = GlName<DeleteFramebuffers>;
using GlRenderbuffer = GlName<DeleteRenderbuffers>;
using GlVertexArray = GlName<DeleteVertexArrays>;

GlTexture NewTexture();
GlBuffer NewBuffer();
GlFramebuffer NewFramebuffer();
GlRenderbuffer NewRenderbuffer();
GlVertexArray NewVertexArray();

}  // namespace daylit::render
