#include "follicle/render/egl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/render/renderer.hpp"

namespace follicle::render {
namespace {

bool has_ext(const char* list, const char* ext) {
  if (!list) return false;
  const std::size_t n = std::strlen(ext);
  for (const char* p = std::strstr(list, ext); p; p = std::strstr(p + 1, ext)) {
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

/// Initialises `dpy` and makes a 3.3 core context on it, or returns EGL_NO_CONTEXT (and
/// appends the reason to `why`).
EGLContext try_context(EGLDisplay dpy, std::string& why) {
  if (dpy == EGL_NO_DISPLAY) {
    why += " no display;";
    return EGL_NO_CONTEXT;
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(dpy, &major, &minor)) {
    why += " eglInitialize failed;";
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    why += " no desktop OpenGL API;";
    return EGL_NO_CONTEXT;
  }
  const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                            3,
                            EGL_CONTEXT_MINOR_VERSION,
                            3,
                            EGL_CONTEXT_OPENGL_PROFILE_MASK,
                            EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                            EGL_NONE};
  EGLContext ctx = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
  if (ctx == EGL_NO_CONTEXT) {
    why += " eglCreateContext(3.3 core) failed;";
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
    eglDestroyContext(dpy, ctx);
    why += " surfaceless eglMakeCurrent failed;";
    return EGL_NO_CONTEXT;
  }
  return ctx;
}

}  // namespace

std::unique_ptr<EglContext> EglContext::create() {
  auto get_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  auto query_devices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  auto query_device_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(
      eglGetProcAddress("eglQueryDeviceStringEXT"));
  if (!get_display)
    throw ContextUnavailable(
        "EGL: eglGetPlatformDisplayEXT is not available (no EGL_EXT_platform_base)");

  std::unique_ptr<EglContext> out(new EglContext());
  std::string why;
  auto attempt = [&](EGLDisplay dpy, const std::string& name) {
    std::string reason;
    EGLContext ctx = try_context(dpy, reason);
    if (ctx == EGL_NO_CONTEXT) {
      why += " [" + name + ":" + reason + "]";
      return false;
    }
    out->m_display = dpy;
    out->m_context = ctx;
    out->m_platform = name;
    return true;
  };

  std::vector<EGLDeviceEXT> software;
  if (query_devices) {
    EGLint n = 0;
    if (query_devices(0, nullptr, &n) && n > 0) {
      std::vector<EGLDeviceEXT> devs(static_cast<std::size_t>(n));
      query_devices(n, devs.data(), &n);
      for (EGLint i = 0; i < n; ++i) {
        const char* exts = query_device_string
                               ? query_device_string(devs[std::size_t(i)], EGL_EXTENSIONS)
                               : nullptr;
        if (has_ext(exts, "EGL_MESA_device_software")) {
          software.push_back(devs[std::size_t(i)]);
          continue;
        }
        if (attempt(get_display(EGL_PLATFORM_DEVICE_EXT, devs[std::size_t(i)], nullptr),
                    "EGL device " + std::to_string(i))) {
          return out;
        }
      }
    }
  }
  if (attempt(get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
              "Mesa surfaceless")) {
    return out;
  }
  for (std::size_t i = 0; i < software.size(); ++i) {
    if (attempt(get_display(EGL_PLATFORM_DEVICE_EXT, software[i], nullptr),
                "EGL software device " + std::to_string(i))) {
      return out;
    }
  }
  throw ContextUnavailable(
      fmt::format("cannot create a headless OpenGL 3.3 core context with EGL:{}", why));
}

EglContext::~EglContext() {
  if (m_context) {
    // The display is shared process-wide (other renderers may use it), so it is not terminated.
    eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(m_display, m_context);
  }
}

void EglContext::make_current() const {
  if (eglGetCurrentContext() == m_context) return;
  if (!eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, m_context)) {
    fail("EGL: cannot make the renderer's context current (error 0x{:x})", eglGetError());
  }
}

}  // namespace follicle::render
