// Hair splatting (Bando 2003 §3.4): the CPU formulas, and the GL passes measured on renders
// (GL tests skip when no EGL context can be made).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "follicle/image/image_io.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/splat_bando2003.hpp"
#include "render_test_util.hpp"

using namespace follicle;
using namespace follicle::render;
using namespace follicle::render::testutil;

namespace {

void maybe_save(const image::ImageRGBA8& img, const std::string& name) {
  if (const char* d = std::getenv("FOLLICLE_RENDER_TEST_OUT"))
    image::write_png(std::filesystem::path(d) / name, img);
}

RenderSettings settings(int w, int h) {
  RenderSettings r;
  r.width = w;
  r.height = h;
  r.supersample = 1;
  r.shadow_map_size = 1024;
  r.hair_light_map_size = 256;
  return r;
}

/// Mean luminance over a pixel rectangle [x0, x1) x [y0, y1).
double mean_lum(const image::ImageRGBA8& img, int x0, int y0, int x1, int y1) {
  double s = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += luminance(img, x, y);
  return s / double((x1 - x0) * (y1 - y0));
}

/// A cube of particles of side `side` centred at `c` (n^3 of them), directions `t`.
std::shared_ptr<geom::ParticleSet> particle_block(const Vec3& c, double side, int n,
                                                  const Vec3f& t = Vec3f(0, 1, 0)) {
  auto ps = std::make_shared<geom::ParticleSet>();
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 p = c + side * (Vec3(i, j, k) / (n - 1) - Vec3::Constant(0.5));
        ps->positions.push_back(p.cast<float>());
        ps->directions.push_back(t);
      }
  return ps;
}

ParticleItem hair_item(std::shared_ptr<geom::ParticleSet> ps, double radius, double opacity) {
  ParticleItem it;
  it.particles = std::move(ps);
  it.shading = ParticleShading::HairSplat;
  it.color = Vec3(0.8, 0.7, 0.6);
  it.radius = radius;
  it.opacity = opacity;
  return it;
}

/// A slab of particles lit from +x (the light travels towards -x), seen from +z.
RenderScene slab_scene(bool self_shadow) {
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.camera.fov_y = 0.5;
  s.background = Vec3(0, 0, 0);
  s.ambient_color = Vec3(0, 0, 0);
  DirectionalLight l;
  l.direction = Vec3(-1, 0, 0);
  s.lights.push_back(l);
  ParticleItem it = hair_item(particle_block(Vec3::Zero(), 1.0, 12), 0.06, 0.5);
  it.splat.self_shadow = self_shadow;
  it.splat.specular = 0;  // diffuse only: Kajiya-Kay sin(t, l) = 1 for every particle
  s.particles.push_back(it);
  return s;
}

}  // namespace

// ---- CPU formulas -----------------------------------------------------------------------------

TEST(SplatFormulas, GoldmanKappaSeparatesReflectionAndTransmission) {
  const Vec3 t(0, 1, 0);
  EXPECT_NEAR(goldman_kappa(t, Vec3(1, 0, 0), Vec3(1, 0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(goldman_kappa(t, Vec3(1, 0, 0), Vec3(-1, 0, 0)), -1.0, 1e-12);
  EXPECT_NEAR(goldman_kappa(t, Vec3(1, 0, 0), Vec3(0, 0, 1)), 0.0, 1e-12);
  // Components along t do not change the planes.
  EXPECT_NEAR(goldman_kappa(t, Vec3(1, 2, 0).normalized(), Vec3(1, -3, 0).normalized()), 1.0,
              1e-12);
  EXPECT_EQ(goldman_kappa(t, t, Vec3(1, 0, 0)), 0.0);  // degenerate: t parallel to l
  EXPECT_NEAR(goldman_directionality(t, Vec3(1, 0, 0), Vec3(1, 0, 0), 0.9, 0.2), 0.9, 1e-12);
  EXPECT_NEAR(goldman_directionality(t, Vec3(1, 0, 0), Vec3(-1, 0, 0), 0.9, 0.2), 0.2, 1e-12);
  EXPECT_NEAR(goldman_directionality(t, Vec3(1, 0, 0), Vec3(0, 0, 1), 0.9, 0.2), 0.55, 1e-12);
}

TEST(SplatFormulas, KajiyaGoldmanMatchesHandValues) {
  SplatMaterial m;
  m.diffuse = 0.5;
  m.specular = 0.25;
  m.shininess = 2;
  m.reflect = 1;
  m.transmit = 0.5;
  const Vec3 t(0, 1, 0), col(1, 0.5, 0.25);
  // l perpendicular to t, e at 45 degrees in the same plane: sin(t,l) = 1, t.l = 0,
  // sin(t,e) = cos(t,e) = 1/sqrt2 -> spec = (1/sqrt2)^2 = 0.5; kappa = 1.
  const Vec3 l(1, 0, 0), e = Vec3(1, 1, 0).normalized();
  const Vec3 v = kajiya_goldman(t, l, e, col, m);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(v[c], 0.5 * col[c] + 0.25 * 0.5, 1e-12);
  // Seen from the other side: kappa = -1, everything scaled by transmit.
  const Vec3 w = kajiya_goldman(t, l, Vec3(-1, 1, 0).normalized(), col, m);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(w[c], 0.5 * v[c], 1e-12);
  // Light along the hair: no diffuse, and the specular cone has collapsed onto -t.
  const Vec3 z = kajiya_goldman(t, t, Vec3(1, 0, 0), col, m);
  EXPECT_NEAR(z.norm(), 0.0, 1e-12);
}

TEST(SplatFormulas, OpacityScalesWithInverseSinThetaAndIsClamped) {
  const Vec3 dp(0, 0, -1);
  EXPECT_NEAR(splat_opacity(0.2, Vec3(1, 0, 0), dp, 0.25), 0.2, 1e-12);
  const double th = 30 * kPi / 180;  // angle between t and d_p
  EXPECT_NEAR(splat_opacity(0.2, Vec3(std::sin(th), 0, std::cos(th)), dp, 0.25), 0.4, 1e-12);
  EXPECT_NEAR(splat_opacity(0.2, Vec3(0, 0, 1), dp, 0.25), 0.8, 1e-12);  // sin clamped
  EXPECT_NEAR(splat_opacity(0.5, Vec3(0, 0, 1), dp, 0.25), 1.0, 1e-12);  // opacity clamped
  EXPECT_NEAR(splat_sin_theta(Vec3(0, 0, 1), dp, 0.25), 0.25, 1e-12);
}

TEST(SplatFormulas, HairTextureHasThinStreaksAndIsDeterministic) {
  const auto a = make_hair_texture(64, 128, 9, 7);
  const auto b = make_hair_texture(64, 128, 9, 7);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a == make_hair_texture(64, 128, 9, 8));
  // Border: transparent. Middle row: several separate streaks (alpha maxima across).
  for (int x = 0; x < 64; ++x) {
    EXPECT_EQ(a.at(x, 0, 3), 0);
    EXPECT_EQ(a.at(x, 127, 3), 0);
  }
  for (int y = 0; y < 128; ++y) EXPECT_EQ(a.at(0, y, 3), 0);
  int peaks = 0, amax = 0;
  for (int x = 1; x < 63; ++x) {
    const int m = a.at(x, 64, 3);
    amax = std::max(amax, m);
    if (m > 40 && m >= a.at(x - 1, 64, 3) && m > a.at(x + 1, 64, 3)) ++peaks;
  }
  EXPECT_GE(peaks, 3);
  EXPECT_GT(amax, 150);
  // Streaks run along the vertical axis: alpha varies far more across than along.
  double across = 0, along = 0;
  for (int y = 40; y < 88; ++y)
    for (int x = 10; x < 54; ++x) {
      across += std::abs(a.at(x + 1, y, 3) - a.at(x, y, 3));
      along += std::abs(a.at(x, y + 1, 3) - a.at(x, y, 3));
    }
  EXPECT_GT(across, 4 * along);
  EXPECT_THROW(make_hair_texture(2, 64), Error);
  EXPECT_THROW(make_hair_texture(64, 64, 0), Error);
}

TEST(SplatFormulas, BadParametersFail) {
  ParticleItem it;
  EXPECT_NO_THROW(it.validate());
  it.splat.min_sin_theta = 0;
  EXPECT_THROW(it.validate(), Error);
  it = ParticleItem{};
  it.splat.length_scale = -1;
  EXPECT_THROW(it.validate(), Error);
  it = ParticleItem{};
  it.splat.diffuse = std::nan("");
  EXPECT_THROW(it.validate(), Error);
  it = ParticleItem{};
  it.opacity = 1.5;
  try {
    it.validate();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("opacity"), std::string::npos) << e.what();
  }
  RenderSettings rs;
  rs.hair_light_slices = 0;
  EXPECT_THROW(rs.validate(), Error);
  rs = RenderSettings{};
  EXPECT_EQ(rs.hair_light_pass, "cpu");
  rs.hair_light_pass = "GPU";
  EXPECT_THROW(rs.validate(), Error);
  EXPECT_THROW(make_hair_sheet_scene(0), Error);
}

TEST(SplatFormulas, SheetSceneHasTheRequestedParticles) {
  const RenderScene s = make_hair_sheet_scene(2000);
  ASSERT_EQ(s.particles.size(), 1u);
  const auto& ps = *s.particles[0].particles;
  EXPECT_EQ(ps.positions.size(), 2000u);
  ASSERT_EQ(ps.directions.size(), ps.positions.size());
  for (std::size_t i = 0; i < ps.positions.size(); ++i) {
    EXPECT_GT(ps.positions[i].norm(), 0.1f);  // outside the head
    EXPECT_NEAR(ps.directions[i].norm(), 1.0f, 1e-5f);
  }
  const RenderScene t = make_hair_sheet_scene(2000);
  EXPECT_TRUE(t.particles[0].particles->positions == ps.positions);
}

// ---- GL passes --------------------------------------------------------------------------------

class Splat : public RenderTest {};

TEST_F(Splat, SelfShadowDarkensTheFarSideOfASlab) {
  const int w = 128, h = 128;
  const auto on = renderer().render(slab_scene(true), settings(w, h));
  const auto off = renderer().render(slab_scene(false), settings(w, h));
  maybe_save(on, "splat_slab_self_shadow.png");
  maybe_save(off, "splat_slab_no_self_shadow.png");
  // The slab spans x in [-0.5, 0.5]: compare a band near the lit side with one near the far side.
  const Vec2 lit = *project_to_pixel(slab_scene(true).camera, w, h, Vec3(0.35, 0, 0.5));
  const Vec2 far = *project_to_pixel(slab_scene(true).camera, w, h, Vec3(-0.35, 0, 0.5));
  auto band = [&](const image::ImageRGBA8& img, const Vec2& c) {
    return mean_lum(img, int(c.x()) - 4, h / 2 - 20, int(c.x()) + 4, h / 2 + 20);
  };
  const double on_lit = band(on, lit), on_far = band(on, far);
  const double off_lit = band(off, lit), off_far = band(off, far);
  EXPECT_GT(on_lit, 40.0);
  EXPECT_LT(on_far, 0.5 * on_lit) << on_lit << " " << on_far;
  // Without self-shadowing the light is the same everywhere: no gradient.
  EXPECT_NEAR(off_far / off_lit, 1.0, 0.08) << off_lit << " " << off_far;
  EXPECT_GT(off_far, 2.0 * on_far);
  // Monotone: the brightness falls across the slab from the lit side.
  double prev = 1e9;
  int drops = 0;
  for (double x : {0.35, 0.15, -0.05, -0.25}) {
    const Vec2 c = *project_to_pixel(slab_scene(true).camera, w, h, Vec3(x, 0, 0.5));
    const double b = band(on, c);
    if (b < prev) ++drops;
    prev = b;
  }
  EXPECT_EQ(drops, 4);
}

TEST_F(Splat, PerParticleReadMatchesTheSlicedLightPass) {
  // The "gpu" pass: hair_light_slices >= particle count is the paper's per-particle read; the
  // default slicing must give nearly the same image.
  const int w = 96, h = 96;
  RenderSettings exact = settings(w, h);
  exact.hair_light_pass = "gpu";
  exact.hair_light_slices = 1 << 20;
  RenderSettings sliced = settings(w, h);
  sliced.hair_light_pass = "gpu";
  RenderScene s = slab_scene(true);
  s.particles[0].particles = particle_block(Vec3::Zero(), 1.0, 8);
  const auto a = renderer().render(s, exact);
  const auto b = renderer().render(s, sliced);
  double diff = 0, sum = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      diff += std::abs(luminance(a, x, y) - luminance(b, x, y));
      sum += luminance(a, x, y);
    }
  EXPECT_GT(sum, 0);
  EXPECT_LT(diff / sum, 0.05);
}

TEST_F(Splat, HairShadowsTheHeadUnderIt) {
  // A sphere lit from above with a slab of hair above its top.
  RenderScene s;
  s.camera.eye = Vec3(0, 0.4, 4);
  s.camera.target = Vec3(0, 0.3, 0);
  s.camera.fov_y = 0.8;
  s.background = Vec3(0, 0, 0);
  s.ambient_color = Vec3(0, 0, 0);
  DirectionalLight l;
  l.direction = Vec3(0, -1, 0);
  s.lights.push_back(l);
  MeshItem m;
  m.mesh = make_sphere(1.0);
  m.material.base_color = Vec3(0.8, 0.8, 0.8);
  m.material.specular = 0;
  m.material.ambient = 0;
  s.meshes.push_back(m);
  // Hair along x: Kajiya-Kay's sin(t, l) = 1 for the light from above.
  s.particles.push_back(
      hair_item(particle_block(Vec3(-0.5, 1.4, 0.45), 0.5, 8, Vec3f(1, 0, 0)), 0.08, 0.6));
  const int w = 128, h = 128;
  RenderSettings rs = settings(w, h);
  const auto with = renderer().render(s, rs);
  s.particles[0].splat.cast_shadow = false;
  const auto without = renderer().render(s, rs);
  maybe_save(with, "splat_head_shadow.png");
  // Under the slab (x = -0.5 on the sphere's front-top) vs the mirrored point (x = +0.5).
  const Vec3 under(-0.5, std::sqrt(1 - 0.25 - 0.45 * 0.45), 0.45), free(0.5, under.y(), 0.45);
  const Vec2 pu = *project_to_pixel(s.camera, w, h, under);
  const Vec2 pf = *project_to_pixel(s.camera, w, h, free);
  const double u_with =
      mean_lum(with, int(pu.x()) - 2, int(pu.y()) - 2, int(pu.x()) + 3, int(pu.y()) + 3);
  const double u_without =
      mean_lum(without, int(pu.x()) - 2, int(pu.y()) - 2, int(pu.x()) + 3, int(pu.y()) + 3);
  const double f_with =
      mean_lum(with, int(pf.x()) - 2, int(pf.y()) - 2, int(pf.x()) + 3, int(pf.y()) + 3);
  const double f_without =
      mean_lum(without, int(pf.x()) - 2, int(pf.y()) - 2, int(pf.x()) + 3, int(pf.y()) + 3);
  EXPECT_GT(u_without, 100.0);
  EXPECT_LT(u_with, 0.6 * u_without) << u_with << " " << u_without;
  EXPECT_NEAR(f_with, f_without, 2.0);     // not under the hair: unchanged
  EXPECT_NEAR(u_without, f_without, 3.0);  // symmetric without the hair shadow
}

TEST_F(Splat, ParticlesInTheHeadShadowAreDark) {
  // Two particle blocks at the same height; one is under the sphere (light from above).
  RenderScene s;
  s.camera.eye = Vec3(0, -1.5, 5);
  s.camera.target = Vec3(0, -1.5, 0);
  s.camera.fov_y = 0.8;
  s.background = Vec3(0, 0, 0);
  s.ambient_color = Vec3(0, 0, 0);
  DirectionalLight l;
  l.direction = Vec3(0, -1, 0);
  s.lights.push_back(l);
  MeshItem m;
  m.mesh = make_sphere(1.0);
  s.meshes.push_back(m);
  auto a = particle_block(Vec3(0, -1.8, 0), 0.4, 4, Vec3f(1, 0, 0));
  auto b = particle_block(Vec3(1.6, -1.8, 0), 0.4, 4, Vec3f(1, 0, 0));
  a->positions.insert(a->positions.end(), b->positions.begin(), b->positions.end());
  a->directions.insert(a->directions.end(), b->directions.begin(), b->directions.end());
  ParticleItem it = hair_item(a, 0.05, 0.5);
  it.splat.self_shadow = false;
  s.particles.push_back(it);
  const int w = 128, h = 128;
  const auto img = renderer().render(s, settings(w, h));
  maybe_save(img, "splat_in_head_shadow.png");
  const Vec2 pa = *project_to_pixel(s.camera, w, h, Vec3(0, -1.8, 0.2));
  const Vec2 pb = *project_to_pixel(s.camera, w, h, Vec3(1.6, -1.8, 0.2));
  const double la =
      mean_lum(img, int(pa.x()) - 6, int(pa.y()) - 6, int(pa.x()) + 6, int(pa.y()) + 6);
  const double lb =
      mean_lum(img, int(pb.x()) - 6, int(pb.y()) - 6, int(pb.x()) + 6, int(pb.y()) + 6);
  EXPECT_GT(lb, 40.0);
  EXPECT_LT(la, 0.1 * lb) << la << " " << lb;
}

TEST_F(Splat, OpacityGrowsAsTheViewAlignsWithTheHair) {
  // One particle, white uniform texture: the centre pixel's coverage is the billboard opacity.
  RenderScene s;
  s.camera.eye = Vec3(0, 0, 3);
  s.camera.fov_y = 0.5;
  s.ambient_color = Vec3(0, 0, 0);
  auto tex = std::make_shared<image::ImageRGBA8>(4, 4, uint8_t(255));
  auto alpha_at = [&](const Vec3& t, double opacity, int* extent = nullptr) {
    auto ps = std::make_shared<geom::ParticleSet>();
    ps->positions = {Vec3f(0, 0, 0)};
    ps->directions = {t.normalized().cast<float>()};
    ParticleItem it = hair_item(ps, 0.1, opacity);
    it.hair_texture = tex;
    it.splat.min_sin_theta = 0.25;
    s.particles = {it};
    RenderSettings rs = settings(96, 96);
    rs.transparent_background = true;
    const auto img = renderer().render(s, rs);
    if (extent) {  // rows covered along the (vertical) projected hair direction
      *extent = 0;
      for (int y = 0; y < 96; ++y) *extent += img.at(48, y, 3) > 0 ? 1 : 0;
    }
    return img.at(48, 48, 3) / 255.0;
  };
  int e90 = 0, e30 = 0;
  const double th = 30 * kPi / 180;  // between t and the view direction
  const double a90 = alpha_at(Vec3(0, 1, 0), 0.2, &e90);
  const double a30 = alpha_at(Vec3(0, std::sin(th), std::cos(th)), 0.2, &e30);
  const double a0 = alpha_at(Vec3(0, 0, 1), 0.2);
  EXPECT_NEAR(a90, 0.2, 0.01);
  EXPECT_NEAR(a30, 0.4, 0.015);                           // 1 / sin(30 deg) = 2
  EXPECT_NEAR(a0, 0.8, 0.02);                             // sin clamped at 0.25
  EXPECT_NEAR(alpha_at(Vec3(0, 0, 1), 0.5), 1.0, 0.005);  // opacity clamped at 1
  // ... while the billboard's projected length shrinks by sin(theta).
  EXPECT_NEAR(double(e30) / e90, 0.5, 0.1);
}

TEST_F(Splat, SameSceneGivesSameBytes) {
  const RenderScene s = make_hair_sheet_scene(1500);
  RenderSettings rs = settings(96, 96);
  rs.supersample = 2;
  const auto a = renderer().render(s, rs);
  const auto b = renderer().render(s, rs);
  EXPECT_TRUE(a == b);
}

TEST_F(Splat, BadParticleDataFailsCleanly) {
  RenderScene s = slab_scene(true);
  auto ps = std::make_shared<geom::ParticleSet>(*s.particles[0].particles);
  ps->directions[3] = Vec3f(0, 0, 0);
  s.particles[0].particles = ps;
  try {
    (void)renderer().render(s, settings(32, 32));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("particles[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("direction"), std::string::npos) << e.what();
  }
  RenderScene t = slab_scene(true);
  auto q = std::make_shared<geom::ParticleSet>(*t.particles[0].particles);
  q->radius = {0.1f};  // one radius for many particles
  t.particles[0].particles = q;
  EXPECT_THROW((void)renderer().render(t, settings(32, 32)), Error);
  RenderScene u = slab_scene(true);
  u.particles[0].splat.width_scale = 0;
  EXPECT_THROW((void)renderer().render(u, settings(32, 32)), Error);
  // The renderer still works afterwards.
  EXPECT_NO_THROW((void)renderer().render(slab_scene(true), settings(32, 32)));
}

TEST_F(Splat, HairSheetSceneRenders) {
  // The synthetic head with hanging hair: hair pixels are darker with self-shadowing.
  RenderScene s = make_hair_sheet_scene(3000);
  RenderSettings rs = settings(256, 256);
  rs.supersample = 2;
  rs.shadow_map_size = 2048;
  rs.hair_light_map_size = 512;
  const auto on = renderer().render(s, rs);
  s.particles[0].splat.self_shadow = false;
  const auto off = renderer().render(s, rs);
  maybe_save(on, "splat_sheet.png");
  maybe_save(off, "splat_sheet_no_self_shadow.png");
  double lon = 0, loff = 0;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      lon += luminance(on, x, y);
      loff += luminance(off, x, y);
    }
  EXPECT_LT(lon, 0.97 * loff);
}

TEST_F(Splat, OpaqueHairShowsTheConfiguredColourTimesTheLight) {
  // A dense slab of vertical hair, fully opaque (uniform white texture), lit from the eye: the
  // image is the Kajiya-Kay x Goldman colour of the hair (CPU formula) in linear light, without
  // any tint from the background or the hair texture. With specular on, the highlight adds grey
  // (the Kajiya-Kay highlight is uncoloured), so a dark colour looks paler. The light comes from
  // the eye and the exponent is low, so the highlight hardly varies over the visible particles
  // (their view directions differ by a few degrees).
  const Vec3 colour(0.2, 0.105, 0.05);
  auto white = std::make_shared<image::ImageRGBA8>(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 4; ++c) white->at(x, y, c) = 255;
  for (const double ks : {0.0, 0.25}) {
    RenderScene s;
    s.camera.eye = Vec3(0, 0, 3);
    s.camera.fov_y = 0.5;
    s.background = Vec3(0.6, 0.63, 0.67);
    s.ambient_color = Vec3(0, 0, 0);
    DirectionalLight l;
    l.direction = Vec3(0, 0, -1);
    l.intensity = 1.5;
    s.lights.push_back(l);
    ParticleItem it = hair_item(particle_block(Vec3::Zero(), 0.6, 10), 0.06, 1.0);
    it.color = colour;
    it.hair_texture = white;
    it.splat.self_shadow = false;
    it.splat.specular = ks;
    it.splat.shininess = 4;
    s.particles.push_back(it);
    const auto img = renderer().render(s, settings(96, 96));
    maybe_save(img, ks > 0 ? "splat_colour_specular.png" : "splat_colour.png");
    Vec3 mean = Vec3::Zero();
    int n = 0;
    for (int y = 40; y < 56; ++y)
      for (int x = 40; x < 56; ++x, ++n)
        for (int c = 0; c < 3; ++c) mean[c] += srgb_to_linear(img.at(x, y, c));
    mean /= double(n);
    const Vec3 to_eye = (s.camera.eye - Vec3::Zero()).normalized();
    const Vec3 expect =
        l.intensity * kajiya_goldman(Vec3(0, 1, 0), -l.direction, to_eye, colour, it.splat);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(mean[c], expect[c], 0.02 * expect.maxCoeff() + 0.004)
          << "ks " << ks << " channel " << c;
    if (ks == 0.0) {  // the hue is the configured one: channel ratios as in `colour`
      EXPECT_NEAR(mean[1] / mean[0], colour[1] / colour[0], 0.05);
      EXPECT_NEAR(mean[2] / mean[0], colour[2] / colour[0], 0.05);
    }
  }
}
