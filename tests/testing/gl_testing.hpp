#pragma once
// Headless renderer for GL tests: skips the test only when no OpenGL context can exist on this
// machine (render::ContextUnavailable), and fails even then when $FOLLICLE_REQUIRE_GL is set.
// Any other renderer error is a real failure.
#include <gtest/gtest.h>

#include <memory>

#include "follicle/render/renderer.hpp"
#include "testing/testing.hpp"

#define FOLLICLE_HEADLESS_RENDERER_OR_SKIP(var, ctx)           \
  std::unique_ptr<::follicle::render::Renderer> var;           \
  try {                                                        \
    var = ::follicle::render::Renderer::create_headless(ctx);  \
  } catch (const ::follicle::render::ContextUnavailable& e_) { \
    if (::follicle::test::gl_required()) FAIL() << e_.what();  \
    GTEST_SKIP() << "no headless OpenGL 3.3: " << e_.what();   \
  }
