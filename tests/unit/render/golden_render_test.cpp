// Golden image of a procedural scene (sphere, shadow-receiving quad, strands, particles) at
// 160x120. llvmpipe is deterministic, but other GL paths/drivers differ slightly, so the
// comparison uses the tolerances in tests/golden/render/scene_basic.tolerance.json. Regenerate
// with FOLLICLE_UPDATE_GOLDEN=1 (and look at the image before committing it).
#include <gtest/gtest.h>

#include <fstream>

#include "follicle/core/atomic_file.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/image/metrics.hpp"
#include "render_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

namespace {

RenderScene basic_scene() {
  RenderScene s;
  s.camera.eye = Vec3(0.5, 2.5, 6);
  s.camera.target = Vec3(0, -0.5, 0);
  s.camera.fov_y = 0.7;
  DirectionalLight key;
  key.direction = Vec3(0.7, -1, -0.4);
  s.lights.push_back(key);
  DirectionalLight fill;
  fill.direction = Vec3(-1, -0.2, -0.5);
  fill.intensity = 0.3;
  fill.cast_shadow = false;
  s.lights.push_back(fill);
  MeshItem ground;
  ground.mesh = make_quad(Vec3(0, -1, 0), Vec3(6, 0, 0), Vec3(0, 0, -6));
  ground.material.base_color = Vec3(0.6, 0.62, 0.65);
  s.meshes.push_back(ground);
  MeshItem ball;
  ball.mesh = make_sphere(0.8);
  ball.material.base_color = Vec3(0.8, 0.4, 0.3);
  s.meshes.push_back(ball);
  auto st = std::make_shared<geom::StrandSet>();
  for (int i = 0; i < 40; ++i) {
    const float a = float(i) * 0.157f;
    st->add_strand({Vec3f(0.8f * std::cos(a), 0.3f, 0.8f * std::sin(a)),
                    Vec3f(1.1f * std::cos(a), -0.2f, 1.1f * std::sin(a)),
                    Vec3f(1.2f * std::cos(a), -0.9f, 1.2f * std::sin(a))});
  }
  StrandItem si;
  si.strands = st;
  si.material.width_px = 1.5;
  s.strands.push_back(si);
  auto ps = std::make_shared<geom::ParticleSet>();
  for (int i = 0; i < 12; ++i) ps->positions.emplace_back(-2.0f + 0.3f * float(i), -0.9f, 1.2f);
  ParticleItem pi;
  pi.particles = ps;
  pi.radius = 0.08;
  pi.color = Vec3(0.2, 0.5, 0.9);
  s.particles.push_back(pi);
  return s;
}

// Reads `"key": number` from the small flat tolerance file (no JSON library in this test).
double json_number(const std::string& text, const std::string& key) {
  const auto at = text.find("\"" + key + "\"");
  if (at == std::string::npos) throw Error("tolerance file has no key " + key);
  const auto colon = text.find(':', at);
  if (colon == std::string::npos) throw Error("tolerance file: no value for " + key);
  return std::stod(text.substr(colon + 1));
}

}  // namespace

class GoldenRender : public RenderTest {};

TEST_F(GoldenRender, BasicSceneMatchesGolden) {
  RenderSettings rs;
  rs.width = 160;
  rs.height = 120;
  rs.shadow_map_size = 1024;
  const auto img = renderer().render(basic_scene(), rs);
  const auto dir = test::source_dir() / "tests/golden/render";
  const auto golden = dir / "scene_basic.png";
  if (std::getenv("FOLLICLE_UPDATE_GOLDEN")) {
    image::write_png(golden, img);
    GTEST_SKIP() << "golden image written to " << golden;
  }
  ASSERT_TRUE(std::filesystem::exists(golden)) << "no golden image " << golden;
  const std::string tol = read_file(dir / "scene_basic.tolerance.json");
  image::DiffOptions opt;
  opt.threshold = json_number(tol, "pixel_threshold");
  const auto d = image::compare_images(img, image::read_png_rgba(golden), opt);
  EXPECT_GE(d.psnr, json_number(tol, "min_psnr_db"));
  EXPECT_LE(d.share_over, json_number(tol, "max_share_over"));
}
