// Golden image of a frame of data/scenes/lcp_back_hair.json (Bando 2003 Fig. 3.7: back hair as
// self-shadowed hair splats) with few particles at a small size, compared with
// tests/golden/scene/lcp_back_hair.png within lcp_back_hair.tolerance.json. Skipped without GL.
// Regenerate (after a deliberate change, and look at it): FOLLICLE_UPDATE_GOLDEN=1 test_scene
// --gtest_filter=LcpGolden.*
#include <gtest/gtest.h>

#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "scene_golden.hpp"
#include "testing/gl_testing.hpp"

using namespace follicle;

TEST(LcpGolden, BackHairFrameMatchesWithinTolerance) {
  Context ctx(2);
  FOLLICLE_HEADLESS_RENDERER_OR_SKIP(renderer, ctx);
  const auto scenes = test::source_dir() / "data" / "scenes";
  scene::Json j = scene::parse_json_file(scenes / "lcp_back_hair.json");
  j["lcp"]["scenario"]["spacing"] = 0.014;
  j["render"]["width"] = 192;
  j["render"]["height"] = 192;
  j["animation"]["frames"] = 8;
  auto session = scene::Session::from_json(j, scenes, "lcp_back_hair", ctx);
  const auto rs = session.render_scene(6);
  ASSERT_EQ(rs.particles.size(), 1u);
  const auto img = renderer->render(rs, session.render_settings());
  // Hair is visible: dark brownish pixels.
  std::size_t hairlike = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const int r = img.at(x, y, 0), b = img.at(x, y, 2);
      if (r > b + 4 && r < 160) ++hairlike;
    }
  EXPECT_GT(double(hairlike) / double(img.num_pixels()), 0.05);
  test::expect_matches_golden("lcp_back_hair", img);
}
