// Golden images of data/scenes/anjyo_bob.json and anjyo_ponytail.json (Anjyo 1992 Fig. 3 and
// Fig. 6c) at a reduced hair density (<= 100k segments) and size, compared with
// tests/golden/scene/anjyo_<name>.png within anjyo_<name>.tolerance.json. Skipped without GL.
// Regenerate (after a deliberate change, and look at it): FOLLICLE_UPDATE_GOLDEN=1 test_scene
// --gtest_filter=HairGolden.*
#include <gtest/gtest.h>

#include <cstdlib>

#include "follicle/image/image_io.hpp"
#include "follicle/image/metrics.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/scene/session.hpp"
#include "testing/gl_testing.hpp"
#include "testing/testing.hpp"

using namespace follicle;

namespace {

struct GoldenTolerance {
  double max_rmse = 2.0;
  double min_psnr = 38.0;
  double pixel_threshold = 32.0;
  double max_share_over = 0.003;
  template <class V>
  void visit(V&& v) {
    v("max_rmse", max_rmse, ParamInfo{"largest RMSE over RGB", "8-bit levels", 0.0, 255.0});
    v("min_psnr", min_psnr, ParamInfo{"smallest PSNR", "dB", 0.0, 200.0});
    v("pixel_threshold", pixel_threshold, ParamInfo{"per-channel difference", "", 0.0, 255.0});
    v("max_share_over", max_share_over,
      ParamInfo{"share of pixels over the threshold", "", 0.0, 1.0});
  }
};

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

  const auto dir = test::source_dir() / "tests" / "golden" / "scene";
  const auto golden_path = dir / ("anjyo_" + name + ".png");
  if (const char* u = std::getenv("FOLLICLE_UPDATE_GOLDEN"); u && *u == '1') {
    image::write_png(golden_path, img);
    GTEST_SKIP() << "wrote " << golden_path;
  }
  ASSERT_TRUE(std::filesystem::exists(golden_path)) << "missing " << golden_path;
  GoldenTolerance tol;
  const auto tol_path = dir / ("anjyo_" + name + ".tolerance.json");
  scene::read_json(scene::parse_json_file(tol_path), "", tol, scene::JsonSource{tol_path.string()});
  const auto golden = image::read_png_rgba(golden_path);
  ASSERT_EQ(golden.width(), img.width());
  ASSERT_EQ(golden.height(), img.height());
  image::DiffOptions opt;
  opt.threshold = tol.pixel_threshold;
  opt.ignore_alpha = true;
  const auto d = image::compare_images(img, golden, opt);
  if (!(d.rmse <= tol.max_rmse && d.psnr >= tol.min_psnr && d.share_over <= tol.max_share_over)) {
    const auto out = test::scratch_dir("golden") / ("anjyo_" + name + "_actual.png");
    image::write_png(out, img);
    ADD_FAILURE() << "render differs from " << golden_path << ": rmse " << d.rmse << ", psnr "
                  << d.psnr << " dB, share over " << d.share_over << "; actual image: " << out;
  }
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
