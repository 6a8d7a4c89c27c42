// Golden image of data/scenes/default.json, rendered through Session + Renderer and compared
// with tests/golden/scene/default.png within tests/golden/scene/default.tolerance.json.
// Regenerate (after a deliberate change, and look at it): FOLLICLE_UPDATE_GOLDEN=1 test_scene
// --gtest_filter=DefaultSceneGolden.*
#include <gtest/gtest.h>

#include <cstdlib>

#include "follicle/core/atomic_file.hpp"
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
  double max_rmse = 2.0;          // 8-bit levels
  double min_psnr = 38.0;         // dB
  double pixel_threshold = 32.0;  // a pixel is "off" when a channel differs by more
  double max_share_over = 0.003;  // share of "off" pixels
  template <class V>
  void visit(V&& v) {
    v("max_rmse", max_rmse, ParamInfo{"largest RMSE over RGB", "8-bit levels", 0.0, 255.0});
    v("min_psnr", min_psnr, ParamInfo{"smallest PSNR", "dB", 0.0, 200.0});
    v("pixel_threshold", pixel_threshold, ParamInfo{"per-channel difference", "", 0.0, 255.0});
    v("max_share_over", max_share_over,
      ParamInfo{"share of pixels over the threshold", "", 0.0, 1.0});
  }
};

}  // namespace

TEST(DefaultSceneGolden, MatchesWithinTolerance) {
  Context ctx(2);
  FOLLICLE_HEADLESS_RENDERER_OR_SKIP(renderer, ctx);
  auto session = scene::Session::load(test::source_dir() / "data" / "scenes" / "default.json", ctx);
  const auto img = renderer->render(session.render_scene(0), session.render_settings());
  ASSERT_EQ(img.width(), session.scene().render.width);
  ASSERT_EQ(img.height(), session.scene().render.height);

  const auto dir = test::source_dir() / "tests" / "golden" / "scene";
  const auto golden_path = dir / "default.png";
  if (const char* u = std::getenv("FOLLICLE_UPDATE_GOLDEN"); u && *u == '1') {
    image::write_png(golden_path, img);
    GTEST_SKIP() << "wrote " << golden_path;
  }
  ASSERT_TRUE(std::filesystem::exists(golden_path)) << "missing " << golden_path;
  GoldenTolerance tol;
  const auto tol_path = dir / "default.tolerance.json";
  scene::read_json(scene::parse_json_file(tol_path), "", tol, scene::JsonSource{tol_path.string()});

  const auto golden = image::read_png_rgba(golden_path);
  ASSERT_EQ(golden.width(), img.width());
  ASSERT_EQ(golden.height(), img.height());
  image::DiffOptions opt;
  opt.threshold = tol.pixel_threshold;
  opt.ignore_alpha = true;
  const auto d = image::compare_images(img, golden, opt);
  const bool ok =
      d.rmse <= tol.max_rmse && d.psnr >= tol.min_psnr && d.share_over <= tol.max_share_over;
  if (!ok) {
    const auto out = test::scratch_dir("golden") / "default_actual.png";
    image::write_png(out, img);
    ADD_FAILURE() << "render differs from " << golden_path << ": rmse " << d.rmse << ", psnr "
                  << d.psnr << " dB, share over " << d.share_over << "; actual image: " << out;
  }
  // The image is not blank: the head covers a good part of the frame.
  std::size_t differs_from_bg = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      if (std::abs(int(img.at(x, y, 0)) - int(img.at(0, 0, 0))) > 20) ++differs_from_bg;
  EXPECT_GT(double(differs_from_bg) / double(img.num_pixels()), 0.2);
}
