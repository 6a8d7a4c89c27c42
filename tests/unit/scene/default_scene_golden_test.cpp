// Golden image of data/scenes/default.json, rendered through Session + Renderer and compared
// with tests/golden/scene/default.png within tests/golden/scene/default.tolerance.json.
// Regenerate (after a deliberate change, and look at it): FOLLICLE_UPDATE_GOLDEN=1 test_scene
// --gtest_filter=DefaultSceneGolden.*
#include <gtest/gtest.h>

#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "scene_golden.hpp"
#include "testing/gl_testing.hpp"
#include "testing/testing.hpp"

using namespace follicle;

TEST(DefaultSceneGolden, MatchesWithinTolerance) {
  Context ctx(2);
  FOLLICLE_HEADLESS_RENDERER_OR_SKIP(renderer, ctx);
  auto session = scene::Session::load(test::source_dir() / "data" / "scenes" / "default.json", ctx);
  const auto img = renderer->render(session.render_scene(0), session.render_settings());
  ASSERT_EQ(img.width(), session.scene().render.width);
  ASSERT_EQ(img.height(), session.scene().render.height);

  test::expect_matches_golden("default", img);
  // The image is not blank: the head covers a good part of the frame.
  std::size_t differs_from_bg = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      if (std::abs(int(img.at(x, y, 0)) - int(img.at(0, 0, 0))) > 20) ++differs_from_bg;
  EXPECT_GT(double(differs_from_bg) / double(img.num_pixels()), 0.2);
}
