#include "render/gl_context.h"

#include <epoxy/gl.h>
// epoxy/gl.h first; EGL after it.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <vector>

#include "base/log.h"

namespace daylit::render {
namespace {

bool HasExtension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const size_t n = std::strlen(name);
  for (const char* p = std::strstr(extensions, name); p != nullptr; p = std::strstr(p + n, name)) {
    if ((p == extensions || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

// A hardware EGL device (a GPU), if the driver lists one; software devices are skipped so
// that the surfaceless platform stays the one path on machines without a GPU.
EGLDisplay HardwareDeviceDisplay() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!HasExtension(client, "EGL_EXT_device_enumeration") || !HasExtension(client, "EGL_EXT_platform_device")) {
    return EGL_NO_DISPLAY;
  }
  auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (query_devices == nullptr || query_string == nullptr || get_platform_display == nullptr) return EGL_NO_DISPLAY;
  EGLint count = 0;
  if (!query_devices(0, nullptr, &count) || count <= 0) return EGL_NO_DISPLAY;
  std::vector<EGLDeviceEXT> devices(static_cast<size_t>(count));
  query_devices(count, devices.data(), &count);
  for (EGLDeviceEXT device : devices) {
    if (HasExtension(query_string(device, EGL_EXTENSIONS), "EGL_MESA_device_software")) continue;
    EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
    EGLint major = 0, minor = 0;
    if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor)) return display;
  }
  return EGL_NO_DISPLAY;
}

EGLDisplay SurfacelessDisplay() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!HasExtension(client, "EGL_MESA_platform_surfaceless")) return EGL_NO_DISPLAY;
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) return EGL_NO_DISPLAY;
  EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0, minor = 0;
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) return EGL_NO_DISPLAY;
  return display;
}

}  // namespace

std::unique_ptr<HeadlessGlContext> HeadlessGlContext::Create(std::string* why) {
  std::unique_ptr<HeadlessGlContext> gl(new HeadlessGlContext());
  EGLDisplay display = HardwareDeviceDisplay();
  gl->platform_ = "EGL device";
  if (display == EGL_NO_DISPLAY) {
    display = SurfacelessDisplay();
    gl->platform_ = "surfaceless";
  }
  if (display == EGL_NO_DISPLAY) {
    *why = "no EGL display: neither a GPU EGL device nor Mesa's surfaceless platform (install libegl-mesa0)";
    return nullptr;
  }
  gl->display_ = display;
  if (!HasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context") ||
      !eglBindAPI(EGL_OPENGL_API)) {
    *why = "the EGL display cannot make a desktop OpenGL context without a surface";
    return nullptr;
  }
  // No config (EGL_KHR_no_config_context): rendering goes to our own framebuffers.
  for (const EGLint minor : {5, 3}) {
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, minor == 5 ? 4 : 3, EGL_CONTEXT_MINOR_VERSION, minor,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext context = eglCreateContext(display, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attributes);
    if (context != EGL_NO_CONTEXT) {
      gl->context_ = context;
      break;
    }
  }
  if (gl->context_ == nullptr) {
    *why = "EGL refused an OpenGL 4.5 and a 3.3 core context";
    return nullptr;
  }
  gl->MakeCurrent();
  Log().debug("OpenGL {} on {} ({})", gl->version(), gl->renderer(), gl->platform_);
  return gl;
}

HeadlessGlContext::~HeadlessGlContext() {
  if (display_ == nullptr) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_ != nullptr) eglDestroyContext(display_, context_);
  eglTerminate(display_);
}

void HeadlessGlContext::MakeCurrent() const {
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
}

std::string HeadlessGlContext::renderer() const {
  return reinterpret_cast<const char*>(glGetString(GL_RENDERER));
}

std::string HeadlessGlContext::version() const {
  return reinterpret_cast<const char*>(glGetString(GL_VERSION));
}

int HeadlessGlContext::gl_version() const { return epoxy_gl_version(); }

}  // namespace daylit::render
