#include "render/headless.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <fmt/format.h>

#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/gl.h"

namespace throng::render {

struct HeadlessContext::State {
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLContext context = EGL_NO_CONTEXT;
};

namespace {

// EGL displays are per process: eglTerminate would end every context on
// one, so each is terminated only when its last HeadlessContext goes.
std::mutex display_mutex;
std::map<EGLDisplay, int>& display_users() {
  static std::map<EGLDisplay, int> users;
  return users;
}
void acquire_display(EGLDisplay d) {
  const std::lock_guard<std::mutex> lock(display_mutex);
  ++display_users()[d];
}
// Terminates `d` unless another context still uses it.
void release_display(EGLDisplay d) {
  const std::lock_guard<std::mutex> lock(display_mutex);
  auto& users = display_users();
  const auto it = users.find(d);
  if (it != users.end() && --it->second > 0) return;
  if (it != users.end()) users.erase(it);
  eglTerminate(d);
}

bool has_extension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n) {
    const bool starts = p == list || p[-1] == ' ';
    const bool ends = p[n] == '\0' || p[n] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

std::string egl_error_text() { return fmt::format("EGL error 0x{:04x}", eglGetError()); }

// Initialises `display` and creates a core-profile context; on failure
// terminates the display and appends why to `why`.
EGLContext try_context(EGLDisplay display, const HeadlessOptions& o, const std::string& label, std::string& why) {
  if (display == EGL_NO_DISPLAY) {
    why += fmt::format("{}: no display; ", label);
    return EGL_NO_CONTEXT;
  }
  acquire_display(display);
  EGLint major = 0, minor = 0;
  if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
    why += fmt::format("{}: eglInitialize failed ({}); ", label, egl_error_text());
    return EGL_NO_CONTEXT;
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    why += fmt::format("{}: no desktop OpenGL API ({}); ", label, egl_error_text());
    release_display(display);
    return EGL_NO_CONTEXT;
  }
  const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                               o.gl_major,
                               EGL_CONTEXT_MINOR_VERSION,
                               o.gl_minor,
                               EGL_CONTEXT_OPENGL_PROFILE_MASK,
                               EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                               EGL_NONE};
  // No config: EGL_KHR_no_config_context (Mesa and NVIDIA both have it);
  // otherwise the first pbuffer-capable config for desktop GL.
  EGLConfig config = nullptr;
  if (!has_extension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) {
    const EGLint wanted[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
    EGLint count = 0;
    if (eglChooseConfig(display, wanted, &config, 1, &count) != EGL_TRUE || count < 1) {
      why += fmt::format("{}: no desktop OpenGL config; ", label);
      release_display(display);
      return EGL_NO_CONTEXT;
    }
  }
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
  if (context == EGL_NO_CONTEXT) {
    why += fmt::format("{}: no OpenGL {}.{} core context ({}); ", label, o.gl_major, o.gl_minor, egl_error_text());
    release_display(display);
    return EGL_NO_CONTEXT;
  }
  if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
    why += fmt::format("{}: cannot make the context current without a surface ({}); ", label, egl_error_text());
    eglDestroyContext(display, context);
    release_display(display);
    return EGL_NO_CONTEXT;
  }
  return context;
}

bool software_renderer() {
  const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string s = r != nullptr ? r : "";
  return s.find("llvmpipe") != std::string::npos || s.find("softpipe") != std::string::npos ||
         s.find("swrast") != std::string::npos;
}

}  // namespace

HeadlessContext::HeadlessContext(const HeadlessOptions& o) : state_(std::make_unique<State>()) {
  if (o.gl_major * 10 + o.gl_minor < 43)
    throw Error(fmt::format("OpenGL {}.{} requested; the renderer needs 4.3 or later", o.gl_major, o.gl_minor),
                at_field("gl_version"));
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr || !has_extension(client, "EGL_EXT_platform_base"))
    throw Error("EGL has no platform displays (EGL_EXT_platform_base): install libegl1 and libegl-mesa0");

  std::string why;
  // 1. Hardware EGL devices (skipping Mesa's software device).
  if (o.prefer_hardware && has_extension(client, "EGL_EXT_platform_device")) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto query_device_string =
        reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    EGLint count = 0;
    std::vector<EGLDeviceEXT> devices(16);
    if (query_devices != nullptr &&
        query_devices(static_cast<EGLint>(devices.size()), devices.data(), &count) == EGL_TRUE) {
      for (EGLint i = 0; i < count && state_->context == EGL_NO_CONTEXT; ++i) {
        const char* ext = query_device_string != nullptr
                              ? query_device_string(devices[static_cast<std::size_t>(i)], EGL_EXTENSIONS)
                              : nullptr;
        if (has_extension(ext, "EGL_MESA_device_software")) continue;
        EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[static_cast<std::size_t>(i)], nullptr);
        EGLContext c = try_context(d, o, fmt::format("EGL device {}", i), why);
        if (c != EGL_NO_CONTEXT) {
          state_->display = d;
          state_->context = c;
          description_ = fmt::format("EGL device {}: {}", i, gl_description());
        }
      }
    }
  }
  // 2. Mesa's surfaceless platform (llvmpipe without a GPU).
  if (state_->context == EGL_NO_CONTEXT && has_extension(client, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLContext c = try_context(d, o, "EGL surfaceless", why);
    if (c != EGL_NO_CONTEXT) {
      state_->display = d;
      state_->context = c;
      description_ = fmt::format("EGL surfaceless: {}", gl_description());
    }
  }
  if (state_->context == EGL_NO_CONTEXT)
    throw Error(fmt::format(
        "no headless OpenGL {}.{} context: {}install Mesa's EGL (libegl-mesa0, libgl1-mesa-dri) or a GPU driver",
        o.gl_major, o.gl_minor, why));
  software_ = software_renderer();
  check_gl_version();
  pin_gl_libraries();
}

HeadlessContext::~HeadlessContext() {
  if (state_ && state_->display != EGL_NO_DISPLAY) {
    if (eglGetCurrentContext() == state_->context)
      eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(state_->display, state_->context);
    release_display(state_->display);
  }
}

void HeadlessContext::make_current() const {
  if (eglMakeCurrent(state_->display, EGL_NO_SURFACE, EGL_NO_SURFACE, state_->context) != EGL_TRUE)
    throw Error("cannot make the headless OpenGL context current: " + egl_error_text());
}

}  // namespace throng::render
