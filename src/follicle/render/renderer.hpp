#pragma once
// The OpenGL 3.3 core renderer. create_headless() makes an EGL context (a hardware EGL device
// when there is one, else Mesa surfaceless / llvmpipe) and renders into an FBO. The same scene
// and settings give the same bytes on the same machine.
#include <memory>
#include <string>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/image/image.hpp"
#include "follicle/render/render_scene.hpp"

namespace follicle::render {

/// Thrown when no headless OpenGL 3.3 core context can be made at all (no EGL, no Mesa). Tests
/// skip on this error only (or fail when $FOLLICLE_REQUIRE_GL is set, as tools/test.sh does);
/// every other renderer error is a real failure.
class ContextUnavailable : public Error {
 public:
  using Error::Error;
};

class Renderer {
 public:
  /// Throws follicle::Error with a clear message when no EGL/OpenGL 3.3 context can be made.
  static std::unique_ptr<Renderer> create_headless(const Context& ctx);
  /// For the viewer: use the caller's current GL 3.3 context (no EGL).
  static std::unique_ptr<Renderer> create_with_current_context(const Context& ctx);
  virtual ~Renderer() = default;

  /// Renders to an RGBA8 (sRGB-encoded) image of settings.width x settings.height.
  /// Not thread-safe: call from one thread at a time (it makes its GL context current).
  /// Throws follicle::Error on invalid settings/scene data (naming the item) or a GL error.
  virtual image::ImageRGBA8 render(const RenderScene& scene, const RenderSettings& settings) = 0;
  /// For the viewer: renders like render() and blits the sRGB-encoded result to (0, 0) of the
  /// caller's framebuffer object `target_fbo` (0 = default framebuffer), leaving it bound.
  virtual void render_to_framebuffer(const RenderScene& scene, const RenderSettings& settings,
                                     unsigned target_fbo) = 0;
  /// "GL_VERSION / GL_RENDERER", for logs and `follicle info`.
  virtual std::string device_description() const = 0;
};

}  // namespace follicle::render
