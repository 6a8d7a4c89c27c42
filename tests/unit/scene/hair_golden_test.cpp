// Golden images of data/scenes/anjyo_bob.json and anjyo_ponytail.json (Anjyo 1992 Fig. 3 and
// Fig. 6c) at a reduced hair density (<= 100k segments) and size, compared with
// tests/golden/scene/anjyo_<name>.png within anjyo_<name>.tolerance.json. Skipped without GL.
// Regenerate (after a deliberate change, and look at it): FOLLICLE_UPDATE_GOLDEN=1 test_scene
// --gtest_filter=HairGolden.*
#include <gtest/gtest.h>

#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "scene_golden.hpp"
#include "testing/gl_testing.hpp"
#include "testing/testing.hpp"

using namespace follicle;

namespace {

void check_golden(const std::string& name, double density) {
  Context ctx(2);
  FOLLICLE_HEADLESS_RENDERER_OR_SKIP(renderer, ctx);
  const auto scenes = test::source_dir() / "data" / "scenes";
  scene::Json j = scene::parse_json_file(scenes / ("anjyo_" + name + ".json"));
  j["hair"][0]["density_scale"] = density;
  j["render"]["width"] = 320;
  j["render"]["height"] = 320;
  j["render"]["supersample"] = 2;
  auto session = scene::Session::from_json(j, scenes, name, ctx);
  const auto rs = session.render_scene(0);
  ASSERT_EQ(rs.strands.size(), 1u);
  const auto& hair = *rs.strands[0].strands;
  EXPECT_LE(hair.num_points() - hair.num_strands(), 100000u);  // segments: keep the test fast
  const auto img = renderer->render(rs, session.render_settings());

  test::expect_matches_golden("anjyo_" + name, img);
  // Hair is visible: many pixels darker than the skin and background, in the hair colour.
  std::size_t hairlike = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const int r = img.at(x, y, 0), g = img.at(x, y, 1), b = img.at(x, y, 2);
      if (r > b + 8 && r < 200 && g < 170 && r + g + b > 40) ++hairlike;
    }
  EXPECT_GT(double(hairlike) / double(img.num_pixels()), 0.05);
}

}  // namespace

TEST(HairGolden, BobMatchesWithinTolerance) {
  check_golden("bob", 0.4);
}
TEST(HairGolden, PonytailMatchesWithinTolerance) {
  check_golden("ponytail", 0.25);
}
