#include "render/gl_window.h"

#include <epoxy/gl.h>
// GLFW after epoxy: it must not pull in its own GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "render/gl_program.h"

namespace daylit::render {
namespace {

const char* kVertex = R"(#version 330 core
out vec2 uv;
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  uv = vec2(p.x, 1.0 - p.y);  // the image's row 0 at the top
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
})";

const char* kFragment = R"(#version 330 core
uniform sampler2D image;
in vec2 uv;
out vec4 color;
void main() { color = vec4(texture(image, uv).rgb, 1.0); })";

}  // namespace

struct GlWindow::State {
  GLFWwindow* window = nullptr;
  std::unique_ptr<GlProgram> program;
  GlTexture texture;
  GlVertexArray vao;
  int image_width = 0, image_height = 0;
  std::vector<WindowKey> keys;  // since the last TakeInput

  ~State() {
    // GL objects go while the context is still there.
    program.reset();
    texture = GlTexture();
    vao = GlVertexArray();
    if (window != nullptr) glfwDestroyWindow(window);
    glfwTerminate();
  }
};

std::unique_ptr<GlWindow> GlWindow::Create(int width, int height, const std::string& title, std::string* why) {
  if (glfwInit() != GLFW_TRUE) {
    const char* description = nullptr;
    glfwGetError(&description);
    *why = std::string("no display for a window (") + (description != nullptr ? description : "glfwInit failed") +
           "); run without --window, or under xvfb-run";
    return nullptr;
  }
  std::unique_ptr<GlWindow> w(new GlWindow());
  w->state_ = std::make_unique<State>();
  State& s = *w->state_;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  const double fit = std::min({1.0, 1600.0 / width, 900.0 / height});
  s.window = glfwCreateWindow(std::max(1, static_cast<int>(width * fit)), std::max(1, static_cast<int>(height * fit)),
                              title.c_str(), nullptr, nullptr);
  if (s.window == nullptr) {
    const char* description = nullptr;
    glfwGetError(&description);
    *why = std::string("no GL 3.3 core window (") + (description != nullptr ? description : "unknown") + ")";
    return nullptr;
  }
  glfwSetWindowUserPointer(s.window, &s);
  glfwSetKeyCallback(s.window, [](GLFWwindow* window, int key, int /*scancode*/, int action, int /*mods*/) {
    if (action == GLFW_RELEASE) return;
    auto* state = static_cast<State*>(glfwGetWindowUserPointer(window));
    switch (key) {
      case GLFW_KEY_LEFT: state->keys.push_back(WindowKey::kLeft); break;
      case GLFW_KEY_RIGHT: state->keys.push_back(WindowKey::kRight); break;
      case GLFW_KEY_UP: state->keys.push_back(WindowKey::kUp); break;
      case GLFW_KEY_DOWN: state->keys.push_back(WindowKey::kDown); break;
      case GLFW_KEY_BACKSPACE: state->keys.push_back(WindowKey::kBackspace); break;
      default: break;
    }
  });
  glfwMakeContextCurrent(s.window);
  glfwSwapInterval(0);  // the replay paces itself
  s.program = std::make_unique<GlProgram>(kVertex, kFragment);
  s.texture = NewTexture();
  s.vao = NewVertexArray();
  s.image_width = width, s.image_height = height;
  glBindTexture(GL_TEXTURE_2D, s.texture.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, width, height, 0, GL_BGR, GL_UNSIGNED_BYTE, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return w;
}

GlWindow::~GlWindow() = default;

bool GlWindow::Show(const cv::Mat& bgr) {
  State& s = *state_;
  glfwPollEvents();
  if (glfwWindowShouldClose(s.window) || glfwGetKey(s.window, GLFW_KEY_ESCAPE) == GLFW_PRESS ||
      glfwGetKey(s.window, GLFW_KEY_Q) == GLFW_PRESS) {
    return false;
  }
  cv::Mat image = bgr;
  if (image.cols != s.image_width || image.rows != s.image_height) cv::resize(bgr, image, cv::Size(s.image_width, s.image_height));
  if (!image.isContinuous()) image = image.clone();
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, s.texture.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, s.image_width, s.image_height, GL_BGR, GL_UNSIGNED_BYTE, image.data);
  Draw();
  glfwSwapBuffers(s.window);
  return true;
}

WindowInput GlWindow::TakeInput() {
  State& s = *state_;
  WindowInput input;
  input.keys.swap(s.keys);
  if (glfwGetMouseButton(s.window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
    // The cursor is in the window's screen coordinates; the image is stretched over the window.
    double x = 0.0, y = 0.0;
    int w = 0, h = 0;
    glfwGetCursorPos(s.window, &x, &y);
    glfwGetWindowSize(s.window, &w, &h);
    if (w > 0 && h > 0) input.dragging = cv::Point2d(x * s.image_width / w, y * s.image_height / h);
  }
  return input;
}

void GlWindow::Draw() const {
  const State& s = *state_;
  int fb_width = 0, fb_height = 0;
  glfwGetFramebufferSize(s.window, &fb_width, &fb_height);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glViewport(0, 0, fb_width, fb_height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, s.texture.get());
  glUseProgram(s.program->id());
  glUniform1i(s.program->Uniform("image"), 0);
  glBindVertexArray(s.vao.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
}

cv::Mat GlWindow::Screenshot() const {
  // The last image drawn again into the back buffer and read from there (a front buffer's
  // content after a swap is not defined everywhere).
  Draw();
  int w = 0, h = 0;
  glfwGetFramebufferSize(state_->window, &w, &h);
  cv::Mat image(h, w, CV_8UC3);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_BGR, GL_UNSIGNED_BYTE, image.data);
  cv::flip(image, image, 0);
  return image;
}

}  // namespace daylit::render
