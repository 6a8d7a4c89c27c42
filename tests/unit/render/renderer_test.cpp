#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "follicle/image/image_io.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/lafortune.hpp"
#include "render_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

namespace {

RenderScene sphere_scene() {
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 4);
  s.camera.target = Vec3(0, 0, 0);
  s.camera.fov_y = 0.7;
  s.background = Vec3(0.1, 0.2, 0.3);
  DirectionalLight l;
  l.direction = Vec3(-1, 0, 0);  // travels towards -x: lights the +x side
  l.cast_shadow = false;
  s.lights.push_back(l);
  MeshItem m;
  m.mesh = make_sphere(1.0);
  m.material.base_color = Vec3(0.8, 0.8, 0.8);
  m.material.ambient = 0.05;
  s.meshes.push_back(m);
  return s;
}

RenderSettings small(int w = 128, int h = 128) {
  RenderSettings r;
  r.width = w;
  r.height = h;
  r.supersample = 2;
  r.shadow_map_size = 1024;
  return r;
}

void maybe_save(const image::ImageRGBA8& img, const std::string& name) {
  if (const char* d = std::getenv("FOLLICLE_RENDER_TEST_OUT"))
    image::write_png(std::filesystem::path(d) / name, img);
}

}  // namespace

TEST(Camera, ProjectsKnownPoints) {
  Camera c;
  c.eye = Vec3(0, 0, 4);
  c.target = Vec3(0, 0, 0);
  c.fov_y = 0.8;
  const auto centre = project_to_pixel(c, 200, 100, Vec3(0, 0, 0));
  ASSERT_TRUE(centre);
  EXPECT_NEAR(centre->x(), 100.0, 1e-9);
  EXPECT_NEAR(centre->y(), 50.0, 1e-9);
  // A point on the top edge of the view frustum at distance 4.
  const auto top = project_to_pixel(c, 200, 100, Vec3(0, 4 * std::tan(0.4), 0));
  EXPECT_NEAR(top->y(), 0.0, 1e-9);
  // x scales with the aspect ratio: the right edge is at tan(fov/2) * aspect.
  const auto right = project_to_pixel(c, 200, 100, Vec3(4 * std::tan(0.4) * 2.0, 0, 0));
  EXPECT_NEAR(right->x(), 200.0, 1e-9);
  EXPECT_FALSE(project_to_pixel(c, 200, 100, Vec3(0, 0, 5)));
}

TEST(Camera, InvalidCameraIsError) {
  Camera c;
  c.target = c.eye;
  EXPECT_THROW(c.validate(), Error);
  Camera d;
  d.up = Vec3(0, 0, 1);  // parallel to the view direction
  EXPECT_THROW(d.validate(), Error);
}

TEST(Lafortune, DirectionalAlbedoMatchesOracle) {
  const LafortuneBrdf b = lafortune_skin_marschner();
  const Vec3 a0 = lafortune_directional_albedo(b, 0.0);
  EXPECT_NEAR(a0.x(), 0.4597, 0.01 * 0.4597);
  EXPECT_NEAR(a0.y(), 0.3238, 0.01 * 0.3238);
  EXPECT_NEAR(a0.z(), 0.3536, 0.01 * 0.3536);
  const Vec3 a60 = lafortune_directional_albedo(b, 60 * kPi / 180);
  EXPECT_NEAR(a60.x(), 0.4915, 0.01 * 0.4915);
  EXPECT_NEAR(a60.y(), 0.3689, 0.01 * 0.3689);
  EXPECT_NEAR(a60.z(), 0.3957, 0.01 * 0.3957);
  const Vec3 a80 = lafortune_directional_albedo(b, 80 * kPi / 180);
  EXPECT_NEAR(a80.x(), 0.5955, 0.01 * 0.5955);
}

TEST(Lafortune, MirrorValueAndReciprocity) {
  const LafortuneBrdf b = lafortune_skin_marschner();
  const double s = std::sqrt(0.5);
  const Vec3 wi(s, 0, s), wo(-s, 0, s);
  const Vec3 f = eval_lafortune(b, wo, wi);
  EXPECT_NEAR(f.x(), 0.204, 0.002);
  EXPECT_NEAR(f.y(), 0.161, 0.002);
  EXPECT_NEAR(f.z(), 0.165, 0.002);
  const Vec3 u = Vec3(0.3, -0.2, 0.9).normalized(), v = Vec3(-0.5, 0.4, 0.6).normalized();
  EXPECT_TRUE(eval_lafortune(b, u, v).isApprox(eval_lafortune(b, v, u), 1e-12));
  EXPECT_EQ(eval_lafortune(b, Vec3(0, 0, -1), wi), Vec3::Zero());
}

class Renderer_ : public RenderTest {};

TEST_F(Renderer_, DescribesDevice) {
  EXPECT_FALSE(renderer().device_description().empty());
}

TEST_F(Renderer_, LitSphereAndBackground) {
  const RenderScene s = sphere_scene();
  const auto img = renderer().render(s, small());
  maybe_save(img, "sphere.png");
  ASSERT_EQ(img.width(), 128);
  ASSERT_EQ(img.height(), 128);
  // The lit (+x, right) side is much brighter than the unlit left side.
  EXPECT_GT(luminance(img, 84, 64), luminance(img, 44, 64) + 60);
  // Background where nothing is drawn: sRGB of the linear background colour.
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(img.at(2, 2, c), linear_to_srgb8(s.background[c]), 1.0) << c;
  EXPECT_EQ(img.at(2, 2, 3), 255);
}

TEST_F(Renderer_, KnownPointProjectsWhereExpected) {
  RenderScene s = sphere_scene();
  s.meshes.clear();
  s.background = Vec3(0, 0, 0);
  const Vec3 p(0.7, 0.45, -0.3);
  MeshItem m;
  m.mesh = make_sphere(0.05, 16, 8, p);
  m.material.shading = MeshShading::Unlit;
  m.material.base_color = Vec3(1, 1, 1);
  s.meshes.push_back(m);
  const int w = 160, h = 120;
  const auto img = renderer().render(s, small(w, h));
  double sx = 0, sy = 0, sw = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double v = img.at(x, y, 0);
      sx += v * (x + 0.5);
      sy += v * (y + 0.5);
      sw += v;
    }
  ASSERT_GT(sw, 0);
  const auto expect = project_to_pixel(s.camera, w, h, p);
  ASSERT_TRUE(expect);
  EXPECT_NEAR(sx / sw, expect->x(), 0.5);
  EXPECT_NEAR(sy / sw, expect->y(), 0.5);
}

TEST_F(Renderer_, SphereCastsShadowOnQuad) {
  RenderScene s;
  s.camera.eye = Vec3(0, 3, 6);
  s.camera.target = Vec3(0, -1, 0);
  s.camera.fov_y = 0.8;
  DirectionalLight l;
  l.direction = Vec3(1, -1, 0);  // the shadow of the sphere falls at (+1, -1, 0)
  s.lights.push_back(l);
  MeshItem ground;
  ground.mesh = make_quad(Vec3(0, -1, 0), Vec3(6, 0, 0), Vec3(0, 0, -6));
  ground.material.base_color = Vec3(0.7, 0.7, 0.7);
  ground.material.specular = 0;
  s.meshes.push_back(ground);
  MeshItem ball;
  ball.mesh = make_sphere(0.5);
  s.meshes.push_back(ball);
  const int w = 160, h = 120;
  const auto shadowed = renderer().render(s, small(w, h));
  maybe_save(shadowed, "shadow.png");
  const Vec2 in = *project_to_pixel(s.camera, w, h, Vec3(1, -1, 0));
  const Vec2 out = *project_to_pixel(s.camera, w, h, Vec3(-1, -1, 0));
  const double lum_in = luminance(shadowed, int(in.x()), int(in.y()));
  const double lum_out = luminance(shadowed, int(out.x()), int(out.y()));
  EXPECT_LT(lum_in, 0.6 * lum_out);
  s.lights[0].cast_shadow = false;
  const auto lit = renderer().render(s, small(w, h));
  EXPECT_NEAR(luminance(lit, int(in.x()), int(in.y())), lum_out, 3.0);
}

// Both strand passes (RenderSettings::strand_pass): the CPU pass (default, antialiased lines
// blended in depth order) and GL lines draw the same colours at the same places and width.
class RendererStrandPass : public RenderTest, public ::testing::WithParamInterface<const char*> {
 protected:
  /// `s` rendered at w x h with this test's strand pass (saved as `name`_pass.png).
  image::ImageRGBA8 render_pass(const RenderScene& s, int w, int h, const std::string& name) {
    RenderSettings rs = small(w, h);
    rs.strand_pass = GetParam();
    auto img = renderer().render(s, rs);
    maybe_save(img, fmt::format("{}_{}.png", name, GetParam()));
    return img;
  }
};

TEST_P(RendererStrandPass, StrandsWithVertexColoursAppear) {
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.background = Vec3(0, 0, 0);
  auto st = std::make_shared<geom::StrandSet>();
  st->add_strand({Vec3f(-1, 0.5f, 0), Vec3f(0, 0.5f, 0), Vec3f(1, 0.5f, 0)});
  st->add_strand({Vec3f(-1, -0.5f, 0), Vec3f(1, -0.5f, 0)});
  st->color = {Vec3f(1, 0, 0), Vec3f(1, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 1, 0)};
  StrandItem it;
  it.strands = st;
  it.material.shading = StrandShading::VertexColor;
  it.material.width_px = 2.0;
  s.strands.push_back(it);
  const int w = 128, h = 128;
  const auto img = render_pass(s, w, h, "lines");
  const Vec2 top = *project_to_pixel(s.camera, w, h, Vec3(0.3, 0.5, 0));
  const Vec2 bot = *project_to_pixel(s.camera, w, h, Vec3(0.3, -0.5, 0));
  // Sum a 1x5 column across the line: a 2-px wide line gives about 2 px of full colour.
  auto column = [&](const Vec2& p, int c) {
    double sum = 0;
    for (int dy = -2; dy <= 2; ++dy) sum += srgb_to_linear(img.at(int(p.x()), int(p.y()) + dy, c));
    return sum;
  };
  EXPECT_NEAR(column(top, 0), 2.0, 0.35);
  EXPECT_LT(column(top, 1), 0.01);
  EXPECT_NEAR(column(bot, 1), 2.0, 0.35);
  EXPECT_LT(column(bot, 0), 0.01);
  EXPECT_EQ(img.at(64, 64, 0), 0);  // between the lines
  // Kajiya-Kay shading and per-point radii (ribbons) also draw.
  s.strands[0].material.shading = StrandShading::KajiyaKay;
  s.lights.push_back(DirectionalLight{});
  auto st2 = std::make_shared<geom::StrandSet>(*st);
  st2->radius.assign(st2->points.size(), 0.01f);
  s.strands[0].strands = st2;
  const auto img2 = render_pass(s, w, h, "ribbons");
  EXPECT_GT(img2.at(int(top.x()), int(top.y()), 0), 30);
}

// Items with and without per-point radii together (in the CPU pass one segment list holds
// both: HairSegments::kNoRadius): each keeps its own width.
TEST_P(RendererStrandPass, ItemsWithAndWithoutRadiiDrawTogether) {
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.background = Vec3(0, 0, 0);
  auto line = [](float y, Vec3f c, float radius) {
    auto st = std::make_shared<geom::StrandSet>();
    st->add_strand({Vec3f(-1, y, 0), Vec3f(0, y, 0), Vec3f(1, y, 0)});
    st->color.assign(3, c);
    if (radius > 0) st->radius.assign(3, radius);
    StrandItem it;
    it.strands = st;
    it.material.shading = StrandShading::VertexColor;
    it.material.width_px = 1.0;
    return it;
  };
  s.strands.push_back(line(0.5f, Vec3f(1, 0, 0), 0));       // 1 px
  s.strands.push_back(line(-0.5f, Vec3f(0, 1, 0), 0.02f));  // 4 cm wide: several pixels
  s.strands.push_back(line(0.0f, Vec3f(0, 0, 1), 0));       // 1 px again, after the radii
  const int w = 128, h = 128;
  const auto img = render_pass(s, w, h, "mixed_radii");
  auto column = [&](float y, int c) {
    const Vec2 p = *project_to_pixel(s.camera, w, h, Vec3(0.3, y, 0));
    double sum = 0;
    for (int dy = -8; dy <= 8; ++dy) sum += srgb_to_linear(img.at(int(p.x()), int(p.y()) + dy, c));
    return sum;
  };
  // Pixels per metre at the strands' depth: h / (2 tan(fov / 2) 3 m).
  const double px_per_m = h / (2 * std::tan(0.5 * s.camera.fov_y) * 3.0);
  EXPECT_NEAR(column(0.5f, 0), 1.0, 0.25);
  EXPECT_NEAR(column(0.0f, 2), 1.0, 0.25);
  EXPECT_NEAR(column(-0.5f, 1), 0.04 * px_per_m, 0.25 * 0.04 * px_per_m);
}

// The CPU pass's strands cast shadows onto the meshes when cast_shadow is set (as GL lines do
// through the shadow map), and none without it.
TEST_P(RendererStrandPass, CastingStrandsShadowTheGround) {
  RenderScene s;
  s.camera.eye = Vec3(0, 3, 6);
  s.camera.target = Vec3(0, -1, 0);
  s.camera.fov_y = 0.8;
  DirectionalLight l;
  l.direction = Vec3(0, -1, 0);  // straight down: the strands' shadow lies under them
  s.lights.push_back(l);
  MeshItem ground;
  ground.mesh = make_quad(Vec3(0, -1, 0), Vec3(6, 0, 0), Vec3(0, 0, -6));
  ground.material.base_color = Vec3(0.7, 0.7, 0.7);
  ground.material.specular = 0;
  s.meshes.push_back(ground);
  // A dense flat mat of strands at y = 0 over x in [-0.5, 0.5], z in [-0.5, 0.5].
  auto st = std::make_shared<geom::StrandSet>();
  for (int i = 0; i <= 200; ++i) {
    const float z = -0.5f + 0.005f * float(i);
    st->add_strand({Vec3f(-0.5f, 0, z), Vec3f(0.5f, 0, z)});
  }
  StrandItem it;
  it.strands = st;
  it.material.width_px = 1.0;
  s.strands.push_back(it);
  const int w = 160, h = 120;
  const auto img = render_pass(s, w, h, "strand_shadow");
  // A ground point under the mat that the camera sees past the mat's front edge (the ray to it
  // crosses y = 0 at z = 1.7), against one beside the mat.
  const Vec2 under = *project_to_pixel(s.camera, w, h, Vec3(0, -1, 0.3));
  const Vec2 beside = *project_to_pixel(s.camera, w, h, Vec3(1.5, -1, 0.3));
  const double lum_under = luminance(img, int(under.x()), int(under.y()));
  const double lum_beside = luminance(img, int(beside.x()), int(beside.y()));
  EXPECT_LT(lum_under, 0.6 * lum_beside);
  s.strands[0].cast_shadow = false;
  const auto lit = render_pass(s, w, h, "strand_no_shadow");
  EXPECT_NEAR(luminance(lit, int(under.x()), int(under.y())), lum_beside, 3.0);
}

INSTANTIATE_TEST_SUITE_P(Passes, RendererStrandPass, ::testing::Values("cpu", "gpu"));

TEST_F(Renderer_, ParticlesDrawAsDiscs) {
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.background = Vec3(0, 0, 0);
  auto ps = std::make_shared<geom::ParticleSet>();
  ps->positions = {Vec3f(0, 0, 0), Vec3f(0.8f, 0, 0)};
  ps->color = {Vec3f(0, 0, 1), Vec3f(1, 1, 0)};
  ps->radius = {0.2f, 0.1f};
  ParticleItem it;
  it.particles = ps;
  s.particles.push_back(it);
  const int w = 128, h = 128;
  const auto img = renderer().render(s, small(w, h));
  EXPECT_EQ(img.at(64, 64, 2), 255);
  EXPECT_EQ(img.at(64, 64, 0), 0);
  const Vec2 p = *project_to_pixel(s.camera, w, h, Vec3(0.8, 0, 0));
  EXPECT_EQ(img.at(int(p.x()), int(p.y()), 0), 255);
  // Outside the radius of the disc: background.
  const Vec2 q = *project_to_pixel(s.camera, w, h, Vec3(0, 0.3, 0));
  EXPECT_EQ(img.at(int(q.x()), int(q.y()), 2), 0);
  // Hair splats draw something where the particles are.
  s.particles[0].shading = ParticleShading::HairSplat;
  ps->directions = {Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
  const auto img2 = renderer().render(s, small(w, h));
  EXPECT_GT(img2.at(64, 64, 2), 100);
}

TEST_F(Renderer_, SameSceneGivesSameBytes) {
  RenderScene s = sphere_scene();
  s.lights[0].cast_shadow = true;
  auto st = std::make_shared<geom::StrandSet>();
  for (int i = 0; i < 50; ++i) {
    const float a = float(i) * 0.12f;
    st->add_strand({Vec3f(std::cos(a), 1.0f, std::sin(a)),
                    Vec3f(1.3f * std::cos(a), 0.2f, 1.3f * std::sin(a)),
                    Vec3f(1.4f * std::cos(a), -0.6f, 1.4f * std::sin(a))});
  }
  StrandItem it;
  it.strands = st;
  s.strands.push_back(it);
  auto ps = std::make_shared<geom::ParticleSet>();
  for (int i = 0; i < 30; ++i) ps->positions.emplace_back(float(i) * 0.05f - 0.7f, -1.1f, 0.5f);
  ParticleItem pi;
  pi.particles = ps;
  pi.opacity = 0.5;
  pi.radius = 0.05;
  s.particles.push_back(pi);
  const auto a = renderer().render(s, small(96, 80));
  const auto b = renderer().render(s, small(96, 80));
  EXPECT_TRUE(a == b);
  // A different size in between (re-allocated targets) does not change the result either.
  (void)renderer().render(s, small(50, 50));
  const auto c = renderer().render(s, small(96, 80));
  EXPECT_TRUE(a == c);
}

TEST_F(Renderer_, LafortuneShaderMatchesCpuBrdf) {
  // A quad facing the camera, lit at 40 degrees; the centre pixel sees wo = normal.
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.camera.fov_y = 0.5;
  s.background = Vec3(0, 0, 0);
  const double th = 40 * kPi / 180;
  DirectionalLight l;
  l.direction = -Vec3(std::sin(th), 0, std::cos(th));
  l.intensity = 1.2;
  l.cast_shadow = false;
  s.lights.push_back(l);
  MeshItem m;
  m.mesh = make_quad(Vec3::Zero(), Vec3(2, 0, 0), Vec3(0, 2, 0));
  m.material.shading = MeshShading::LafortuneSkin;
  m.material.lafortune = lafortune_skin_marschner();
  m.material.ambient = 0;
  s.meshes.push_back(m);
  const auto img = renderer().render(s, small(64, 64));
  const Vec3 wi(std::sin(th), 0, std::cos(th));
  const Vec3 expect =
      kPi * eval_lafortune(m.material.lafortune, Vec3(0, 0, 1), wi) * std::cos(th) * 1.2;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(img.at(32, 32, c), linear_to_srgb8(expect[c]), 1.5) << c;
}

TEST_F(Renderer_, AlbedoTextureIsOrientedByUv) {
  // Top half of the image red, bottom half blue; UV v = 1 is the image's top row.
  auto tex = std::make_shared<image::ImageRGBA8>(8, 8, uint8_t(255));
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      tex->at(x, y, 0) = y < 4 ? 255 : 0;
      tex->at(x, y, 1) = 0;
      tex->at(x, y, 2) = y < 4 ? 0 : 255;
    }
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  MeshItem m;
  m.mesh = make_quad(Vec3::Zero(), Vec3(2, 0, 0), Vec3(0, 2, 0));
  m.material.shading = MeshShading::Unlit;
  m.material.albedo_map = tex;
  s.meshes.push_back(m);
  const auto img = renderer().render(s, small(64, 64));
  const Vec2 up = *project_to_pixel(s.camera, 64, 64, Vec3(0, 0.6, 0));
  const Vec2 dn = *project_to_pixel(s.camera, 64, 64, Vec3(0, -0.6, 0));
  EXPECT_GT(img.at(int(up.x()), int(up.y()), 0), 250);
  EXPECT_LT(img.at(int(up.x()), int(up.y()), 2), 5);
  EXPECT_GT(img.at(int(dn.x()), int(dn.y()), 2), 250);
}

TEST_F(Renderer_, BumpAndNormalMapsTiltTheNormal) {
  // Height rising along +u (= +x) tilts the normal towards -x: a light from -x gets brighter.
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.background = Vec3(0, 0, 0);
  DirectionalLight l;
  l.direction = Vec3(1, 0, -1);  // from the -x side
  l.cast_shadow = false;
  s.lights.push_back(l);
  MeshItem m;
  m.mesh = make_quad(Vec3::Zero(), Vec3(2, 0, 0), Vec3(0, 2, 0));
  m.material.specular = 0;
  m.material.ambient = 0;
  m.material.base_color = Vec3(0.5, 0.5, 0.5);
  s.meshes.push_back(m);
  const auto flat = renderer().render(s, small(64, 64));
  auto h = std::make_shared<image::ImageF>(32, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      h->at(x, y) = 0.5f * (x + 0.5f) / 32.0f;  // slope 0.5 per UV = 0.25 per m
  s.meshes[0].material.height_map = h;
  const auto bumped = renderer().render(s, small(64, 64));
  // Expected: n' = normalize(-0.25, 0, 1); diffuse = 0.5 * n'.L with L = (-1, 0, 1)/sqrt2.
  const Vec3 n = Vec3(-0.25, 0, 1).normalized(), L = Vec3(-1, 0, 1).normalized();
  EXPECT_NEAR(bumped.at(32, 32, 0), linear_to_srgb8(0.5 * n.dot(L)), 2.0);
  EXPECT_GT(bumped.at(32, 32, 0), flat.at(32, 32, 0) + 5);
  // A tangent-space normal map with the same tilt gives the same shade.
  s.meshes[0].material.height_map.reset();
  auto nm = std::make_shared<image::ImageRGBF>(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) nm->at(x, y, c) = float(n[c]);
  s.meshes[0].material.normal_map = nm;
  const auto mapped = renderer().render(s, small(64, 64));
  EXPECT_NEAR(mapped.at(32, 32, 0), bumped.at(32, 32, 0), 1.0);
}

TEST_F(Renderer_, BadInputIsError) {
  RenderScene s = sphere_scene();
  RenderSettings bad = small();
  bad.width = 0;
  EXPECT_THROW(renderer().render(s, bad), Error);
  auto broken = std::make_shared<geom::TriMesh>(*s.meshes[0].mesh);
  broken->faces[3][1] = 999999;
  s.meshes[0].mesh = broken;
  EXPECT_THROW(renderer().render(s, small()), Error);
  RenderScene t = sphere_scene();
  t.meshes[0].vertex_colors.resize(3);
  EXPECT_THROW(renderer().render(t, small()), Error);
  RenderScene u = sphere_scene();
  u.lights[0].direction = Vec3::Zero();
  EXPECT_THROW(renderer().render(u, small()), Error);
  // The renderer still works afterwards.
  EXPECT_EQ(renderer().render(sphere_scene(), small()).width(), 128);
}

TEST_F(Renderer_, MeshBuffersKeptBetweenFramesFollowTheirMeshAndColours) {
  // The renderer keeps a mesh's vertex buffer while the same mesh is drawn again. A new mesh, new
  // vertex colours, or two items of one mesh with different colours in one frame must still draw
  // what they hold (a stale buffer would show the old colours or geometry).
  RenderScene s = sphere_scene();
  s.lights[0].cast_shadow = true;
  const auto first = renderer().render(s, small());
  EXPECT_TRUE(renderer().render(s, small()) == first);  // cached: same bytes
  const std::size_t nv = s.meshes[0].mesh->positions.size();
  s.meshes[0].vertex_colors.assign(nv, Vec3f(1.0f, 0.0f, 0.0f));  // red, same mesh object
  const auto red = renderer().render(s, small());
  EXPECT_GT(red.at(84, 64, 0), red.at(84, 64, 1) + 60);
  // Two items of the same mesh, red on the left and green on the right, in one frame.
  MeshItem green = s.meshes[0];
  green.vertex_colors.assign(nv, Vec3f(0.0f, 1.0f, 0.0f));
  s.meshes[0].transform = Affine3(Eigen::Translation3d(-1.1, 0, 0)) * Eigen::Scaling(0.5);
  green.transform = Affine3(Eigen::Translation3d(1.1, 0, 0)) * Eigen::Scaling(0.5);
  s.meshes.push_back(green);
  const auto both = renderer().render(s, small());
  maybe_save(both, "cache_two_items.png");
  EXPECT_GT(both.at(30, 64, 0), both.at(30, 64, 1) + 30);    // left: red
  EXPECT_GT(both.at(112, 64, 1), both.at(112, 64, 0) + 30);  // right: green
  // A new mesh object (a smaller sphere): its own geometry, not the cached one.
  RenderScene t = sphere_scene();
  t.meshes[0].mesh = make_sphere(0.3);
  const auto small_sphere = renderer().render(t, small());
  auto covered = [&](const image::ImageRGBA8& img) {
    int n = 0;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x)
        n += std::abs(luminance(img, x, y) - luminance(img, 2, 2)) > 5.0;
    return n;
  };
  EXPECT_LT(covered(small_sphere), covered(first) / 4);  // 0.3^2 of the area, not the old sphere
}
