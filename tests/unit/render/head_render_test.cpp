#include <gtest/gtest.h>

#include "follicle/image/image_io.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/framing.hpp"
#include "render_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

class HeadRender : public RenderTest {};

TEST(Framing, BoxFillsTheView) {
  Eigen::AlignedBox3d box(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  const Camera c = frame_box(box, Vec3(0, 0, 1), 0.6, 1.0);
  // The bounding sphere (radius sqrt 3) touches the top of the view.
  const auto top = project_to_pixel(c, 100, 100, Vec3(0, std::sqrt(3.0) / std::cos(0.3), 0));
  ASSERT_TRUE(top);
  EXPECT_NEAR(top->y(), 0.0, 1e-6);
  EXPECT_LT(c.z_near, (c.eye - c.target).norm() - std::sqrt(3.0));
  EXPECT_GT(c.z_far, (c.eye - c.target).norm() + std::sqrt(3.0));
}

TEST_F(HeadRender, DefaultHeadRendersTexturedAndShaded) {
  const auto dir = test::source_dir() / "data/meshes/lee_perry_smith";
  ASSERT_TRUE(std::filesystem::exists(dir / "head.obj")) << "no head mesh";
  for (bool laf : {false, true}) {
    const RenderScene s = make_head_scene(dir, laf);
    RenderSettings rs;
    rs.width = 256;
    rs.height = 256;
    const auto img = renderer().render(s, rs);
    if (const char* d = std::getenv("FOLLICLE_RENDER_TEST_OUT"))
      image::write_png(std::filesystem::path(d) / (laf ? "head_lafortune.png" : "head.png"), img);
    // The head covers the centre; the corners show the background.
    int covered = 0;
    for (int y = 0; y < 256; ++y)
      for (int x = 0; x < 256; ++x) covered += luminance(img, x, y) > 40;
    EXPECT_GT(covered, 256 * 256 / 5);
    EXPECT_GT(luminance(img, 128, 110), 60);
    EXPECT_NEAR(img.at(1, 1, 0), linear_to_srgb8(s.background.x()), 1.0);
  }
}
