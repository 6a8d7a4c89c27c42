#pragma once
// Golden-image check shared by the scene golden tests (default, hair, hand, lcp, skin, face
// region): compares a render
// with tests/golden/scene/<name>.png within <name>.tolerance.json; FOLLICLE_UPDATE_GOLDEN=1
// rewrites the golden instead (look at it after a deliberate change).
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "follicle/image/image_io.hpp"
#include "follicle/image/metrics.hpp"
#include "follicle/scene/json_params.hpp"
#include "testing/testing.hpp"

namespace follicle::test {

struct SceneGoldenTolerance {
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

inline void expect_matches_golden(const std::string& name, const image::ImageRGBA8& img) {
  const auto dir = source_dir() / "tests" / "golden" / "scene";
  const auto golden_path = dir / (name + ".png");
  if (const char* u = std::getenv("FOLLICLE_UPDATE_GOLDEN"); u && *u == '1') {
    image::write_png(golden_path, img);
    GTEST_SKIP() << "wrote " << golden_path;
  }
  ASSERT_TRUE(std::filesystem::exists(golden_path)) << "missing " << golden_path;
  SceneGoldenTolerance tol;
  const auto tol_path = dir / (name + ".tolerance.json");
  scene::read_json(scene::parse_json_file(tol_path), "", tol, scene::JsonSource{tol_path.string()});
  const auto golden = image::read_png_rgba(golden_path);
  ASSERT_EQ(golden.width(), img.width());
  ASSERT_EQ(golden.height(), img.height());
  image::DiffOptions opt;
  opt.threshold = tol.pixel_threshold;
  opt.ignore_alpha = true;
  const auto d = image::compare_images(img, golden, opt);
  if (!(d.rmse <= tol.max_rmse && d.psnr >= tol.min_psnr && d.share_over <= tol.max_share_over)) {
    const auto out = scratch_dir("golden") / (name + "_actual.png");
    image::write_png(out, img);
    ADD_FAILURE() << "render differs from " << golden_path << ": rmse " << d.rmse << ", psnr "
                  << d.psnr << " dB, share over " << d.share_over << "; actual image: " << out;
  }
}

}  // namespace follicle::test
