// Golden image of data/scenes/hand_flex.json (Bando 2002 Fig. 2.17 b: flexed MakeHuman hand with
// joint and fine wrinkles, bump-mapped) at a reduced size, compared with
// tests/golden/scene/hand_flex.png within hand_flex.tolerance.json. Skipped without GL.
// Regenerate (after a deliberate change, and look at it): FOLLICLE_UPDATE_GOLDEN=1 test_scene
// --gtest_filter=HandGolden.*
#include <gtest/gtest.h>

#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "scene_golden.hpp"
#include "testing/gl_testing.hpp"

using namespace follicle;

TEST(HandGolden, FlexedHandMatchesWithinTolerance) {
  Context ctx(2);
  FOLLICLE_HEADLESS_RENDERER_OR_SKIP(renderer, ctx);
  const auto scenes = test::source_dir() / "data" / "scenes";
  scene::Json j = scene::parse_json_file(scenes / "hand_flex.json");
  j["hand"]["rig"]["fine"]["resolution"] = 512;
  j["render"]["width"] = 256;
  j["render"]["height"] = 256;
  auto session = scene::Session::from_json(j, scenes, "hand_flex", ctx);
  const auto rs = session.render_scene(0);
  ASSERT_EQ(rs.meshes.size(), 1u);
  const auto img = renderer->render(rs, session.render_settings());
  // The hand covers a good part of the image (the camera frames it).
  std::size_t skin = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      if (img.at(x, y, 0) > img.at(x, y, 2) + 20) ++skin;
  EXPECT_GT(double(skin) / double(img.num_pixels()), 0.1);
  test::expect_matches_golden("hand_flex", img);
}
