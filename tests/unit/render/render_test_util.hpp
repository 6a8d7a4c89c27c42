#pragma once
// Shared helpers for the renderer tests: procedural meshes and a renderer that skips the test
// when no EGL context can be made.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "follicle/core/context.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/render/renderer.hpp"
#include "testing/testing.hpp"

namespace follicle::render::testutil {

/// UV sphere with per-vertex normals and UVs (u around y, v from bottom to top).
inline std::shared_ptr<geom::TriMesh> make_sphere(double r, int nu = 48, int nv = 24,
                                                  Vec3 centre = Vec3::Zero()) {
  auto m = std::make_shared<geom::TriMesh>();
  for (int j = 0; j <= nv; ++j) {
    const double th = kPi * j / nv;  // from the north pole
    for (int i = 0; i <= nu; ++i) {
      const double ph = 2 * kPi * i / nu;
      const Vec3 n(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
      m->positions.push_back(centre + r * n);
      m->normals.push_back(n);
      m->uvs.emplace_back(double(i) / nu, 1.0 - double(j) / nv);
    }
  }
  auto id = [&](int i, int j) { return j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const Vec3i a(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      const Vec3i b(id(i, j), id(i + 1, j + 1), id(i + 1, j));
      m->faces.push_back(a);
      m->faces.push_back(b);
      m->uv_faces.push_back(a);
      m->uv_faces.push_back(b);
    }
  return m;
}

/// Axis-aligned quad through `centre` spanned by edge vectors a (u direction) and b (v);
/// normal a x b; UV (0,0) at centre - a/2 - b/2.
inline std::shared_ptr<geom::TriMesh> make_quad(const Vec3& centre, const Vec3& a, const Vec3& b) {
  auto m = std::make_shared<geom::TriMesh>();
  const Vec3 o = centre - 0.5 * a - 0.5 * b;
  m->positions = {o, o + a, o + a + b, o + b};
  const Vec3 n = a.cross(b).normalized();
  m->normals = {n, n, n, n};
  m->uvs = {Vec2(0, 0), Vec2(1, 0), Vec2(1, 1), Vec2(0, 1)};
  m->faces = {Vec3i(0, 1, 2), Vec3i(0, 2, 3)};
  m->uv_faces = m->faces;
  return m;
}

inline double srgb_to_linear(double c8) {
  const double c = c8 / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
inline double linear_to_srgb8(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return 255.0 * (c <= 0.0031308 ? c * 12.92 : 1.055 * std::pow(c, 1 / 2.4) - 0.055);
}
inline double luminance(const image::ImageRGBA8& img, int x, int y) {
  return 0.2126 * img.at(x, y, 0) + 0.7152 * img.at(x, y, 1) + 0.0722 * img.at(x, y, 2);
}

/// One renderer per test program (EGL context creation is the slow part).
class RenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (s_tried) return;
    s_tried = true;
    s_ctx = std::make_unique<Context>(2, 1);
    try {
      s_renderer = Renderer::create_headless(*s_ctx);
    } catch (const ContextUnavailable& e) {
      s_reason = e.what();  // no GL on this machine: skip (unless GL is required)
    } catch (const Error& e) {
      s_reason = e.what();  // any other error (a shader that fails to compile...) is a failure
      s_broken = true;
    }
  }
  void SetUp() override {
    if (s_renderer) return;
    if (s_broken || ::follicle::test::gl_required())
      FAIL() << "renderer could not be created: " << s_reason;
    GTEST_SKIP() << "no headless OpenGL context: " << s_reason;
  }
  Renderer& renderer() { return *s_renderer; }
  static inline bool s_tried = false;
  static inline std::unique_ptr<Context> s_ctx;
  static inline std::unique_ptr<Renderer> s_renderer;
  static inline std::string s_reason;
  static inline bool s_broken = false;
};

}  // namespace follicle::render::testutil
