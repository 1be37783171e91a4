// An OpenGL core context without a window, for replays and tests: EGL on a GPU's EGL device
// when there is one, else Mesa's surfaceless platform (llvmpipe). Render into your own FBO.
#pragma once

#include <memory>
#include <string>

namespace daylit::render {

class HeadlessGlContext {
 public:
  // Creates a 4.5 core context (3.3 core if 4.5 is refused) and makes it current on this
  // thread. Returns null and sets `why` when no EGL display or context can be had.
  static std::unique_ptr<HeadlessGlContext> Create(std::string* why);
  ~HeadlessGlContext();
  HeadlessGlContext(const HeadlessGlContext&) = delete;
  HeadlessGlContext& operator=(const HeadlessGlContext&) = delete;

  void MakeCurrent() const;
  std::string renderer() const;  // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string version() const;   // GL_VERSION
  const std::string& platform() const { return platform_; }  // "EGL device" or "surfaceless"
  int gl_version() const;        // 45 for 4.5

 private:
  HeadlessGlContext() = default;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string platform_;
};

}  // namespace daylit::render
