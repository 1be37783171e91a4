// A window to watch a replay or a live camera in (GLFW, GL 3.3 core): the composite, encoded as
// the camera would, scaled to the window. Its context is current on the creating thread, so the
// compositor renders in it as it does headless. GL stays inside render/.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace daylit::render {

// What the user did in the window since it was last asked.
enum class WindowKey { kLeft, kRight, kUp, kDown, kBackspace };
struct WindowInput {
  std::vector<WindowKey> keys;          // presses and auto-repeats, in order
  std::optional<cv::Point2d> dragging;  // the cursor while the left button is down, in image pixels
};

class GlWindow {
 public:
  // Opens a width × height window (the camera's size, shrunk to fit 1600 × 900) and makes its
  // context current. Returns null and sets `why` when there is no display or no GL 3.3.
  static std::unique_ptr<GlWindow> Create(int width, int height, const std::string& title, std::string* why);
  ~GlWindow();
  GlWindow(const GlWindow&) = delete;
  GlWindow& operator=(const GlWindow&) = delete;

  // Shows an 8-bit BGR image and handles the window's events. Returns false once the user has
  // closed the window (or pressed Esc or Q).
  bool Show(const cv::Mat& bgr);
  // The keys pressed since the last call, and the cursor if the left button is down now.
  WindowInput TakeInput();
  // What the window shows now, 8-bit BGR at the window's size.
  cv::Mat Screenshot() const;

 private:
  GlWindow() = default;
  void Draw() const;  // the last image, into the back buffer
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace daylit::render
