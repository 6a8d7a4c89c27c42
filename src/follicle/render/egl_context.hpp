#pragma once
// Headless EGL context for OpenGL 3.3 core (internal to the render module). Tries, in order:
// EGL devices (EGL_EXT_device_enumeration) without EGL_MESA_device_software (a GPU), then Mesa
// surfaceless (llvmpipe), then any remaining (software) device.
#include <memory>
#include <string>

namespace follicle::render {

class EglContext {
 public:
  /// Throws follicle::Error listing what was tried when no context can be made.
  static std::unique_ptr<EglContext> create();
  ~EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  void make_current() const;                                  // throws follicle::Error on failure
  const std::string& platform() const { return m_platform; }  // e.g. "device (NVIDIA ...)"

 private:
  EglContext() = default;
  void* m_display = nullptr;
  void* m_context = nullptr;
  std::string m_platform;
};

}  // namespace follicle::render
