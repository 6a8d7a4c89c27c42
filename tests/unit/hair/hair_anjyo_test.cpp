#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/hair/hairdressing_anjyo1992.hpp"
#include "follicle/hair/pores.hpp"
#include "follicle/hair/shading_anjyo1992.hpp"
#include "follicle/hair/strand_cache.hpp"
#include "follicle/image/image.hpp"
#include "follicle/image/image_io.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::hair;

static sim::Ellipsoid sphere_hull(double r) {
  sim::Ellipsoid e;
  e.radii = Vec3(r, r, r);
  return e;
}

TEST(Pores, CountMatchesDensityTimesAreaAndStayInRegion) {
  Context ctx(2, 1);
  const auto hull = sphere_hull(0.1);
  PoreRegion r;
  r.azimuth_min = 2.5;  // wraps through the back
  r.azimuth_max = -2.5;
  r.zenith_min = 0.5;
  r.zenith_max = 1.5;
  r.density = 1e5;
  r.length = 0.1;
  r.length_jitter = 0.2;
  const double area = 0.01 * r.solid_angle();  // sphere: dA = r^2 dΩ
  EXPECT_NEAR(region_area(hull, r), area, 1e-9);
  const HairRoots roots = sample_pores(ctx, hull, {r}, 7);
  EXPECT_EQ(double(roots.size()), std::round(area * r.density));
  for (std::size_t i = 0; i < roots.size(); ++i) {
    EXPECT_TRUE(r.contains(roots.polar[i].x(), roots.polar[i].y()));
    EXPECT_NEAR(roots.position[i].norm(), 0.1, 1e-12);
    EXPECT_GE(roots.length[i], 0.08 - 1e-12);
    EXPECT_LE(roots.length[i], 0.12 + 1e-12);
    EXPECT_NEAR(roots.direction[i].dot(roots.position[i].normalized()), 1.0, 1e-9);
  }
}

TEST(Pores, RootsMoveToTheScalp) {
  Context ctx(1, 1);
  geom::TriMesh plane;  // a large square at y = 0.05 under the crown
  plane.positions = {Vec3(-1, 0.05, -1), Vec3(1, 0.05, -1), Vec3(1, 0.05, 1), Vec3(-1, 0.05, 1)};
  plane.faces = {Vec3i(0, 2, 1), Vec3i(0, 3, 2)};
  PoreRegion r;
  r.zenith_max = 0.3;
  r.density = 2e4;
  const HairRoots roots =
      sample_pores(ctx, sphere_hull(0.1), {r}, 1, brute_force_closest_point(plane));
  ASSERT_GT(roots.size(), 0u);
  for (const auto& p : roots.position) EXPECT_NEAR(p.y(), 0.05, 1e-12);
}

TEST(Hairdressing, ThresholdCutEndsExactlyAtTheCut) {
  Context ctx(1, 1);
  const auto hull = sphere_hull(0.1);
  HairPart part;
  part.pores = {};
  CutRule c;
  c.threshold = -0.5;  // q_y = -0.5 -> y = -0.05
  part.cuts = {c};
  HairRoots roots;
  roots.position = {Vec3(0.1, 0, 0)};
  roots.direction = {Vec3(1, 0, 0)};
  roots.polar = {Vec2(kPi / 2, kPi / 2)};
  roots.length = {0.3};
  roots.region = {0};
  geom::StrandSet out;
  style_roots(ctx, hull, part, roots, 1, out);
  ASSERT_EQ(out.num_strands(), 1u);
  ASSERT_GE(out.strand_size(0), 2u);
  EXPECT_NEAR(out.points.back().y(), -0.05, 1e-6);
  for (const auto& p : out.points) EXPECT_GE(p.y(), -0.05 - 1e-6);
}

TEST(Hairdressing, HeightDependentCutKeepsLengthByPoreHeight) {
  Context ctx(1, 1);
  const auto hull = sphere_hull(0.1);
  HairPart part;
  CutRule c;
  c.kind = "height_length";
  c.height_low = 0.0;
  c.height_high = 1.0;
  c.length_low = 0.02;
  c.length_high = 0.08;
  part.cuts = {c};
  HairRoots roots;
  for (double ze : {0.0, kPi / 3, kPi / 2}) {
    const Vec3 p = hull.surface_point(0.0, ze);
    roots.position.push_back(p);
    roots.direction.push_back(p.normalized());
    roots.polar.push_back(Vec2(0.0, ze));
    roots.length.push_back(0.2);
    roots.region.push_back(0);
  }
  geom::StrandSet out;
  style_roots(ctx, hull, part, roots, 1, out);
  ASSERT_EQ(out.num_strands(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    double L = 0;
    for (uint32_t i = out.offsets[s] + 1; i < out.offsets[s + 1]; ++i)
      L += (out.points[i] - out.points[i - 1]).cast<double>().norm();
    const double h = roots.position[s].y() / 0.1;
    EXPECT_NEAR(L, 0.02 + 0.06 * std::clamp(h, 0.0, 1.0), 1e-5) << s;
  }
}

TEST(Hairdressing, CombingFieldBendsOnlyTheSelectedRegion) {
  Context ctx(1, 1);
  const auto hull = sphere_hull(0.1);
  HairPart part;
  ForceField f;
  f.vector = Vec3(30, 0, 0);
  f.pores.azimuth_min = 0;  // only the +x half
  f.pores.azimuth_max = kPi;
  part.fields = {f};
  HairRoots roots;
  for (double az : {kPi / 2, -kPi / 2}) {
    const Vec3 p = hull.surface_point(az, 0.3);
    roots.position.push_back(p);
    roots.direction.push_back(p.normalized());
    roots.polar.push_back(Vec2(az, 0.3));
    roots.length.push_back(0.2);
    roots.region.push_back(0);
  }
  geom::StrandSet out, plain;
  style_roots(ctx, hull, part, roots, 1, out);
  HairPart none = part;
  none.fields.clear();
  style_roots(ctx, hull, none, roots, 1, plain);
  auto asym = [](const geom::StrandSet& s) {
    return s.points[s.offsets[1] - 1].x() + s.points[s.offsets[2] - 1].x();
  };
  // Mirror images without the field; the field pushes only the left strand further out.
  EXPECT_NEAR(asym(plain), 0.0, 1e-6);
  EXPECT_GT(asym(out), 0.005);
  EXPECT_NEAR(out.points[out.offsets[2] - 1].x(), plain.points[plain.offsets[2] - 1].x(), 1e-6);
}

TEST(Hairdressing, PresetsValidateAndBadStylesFail) {
  for (const auto& n : style_preset_names()) EXPECT_NO_THROW(style_preset(n).validate()) << n;
  EXPECT_THROW(style_preset("mohawk"), Error);
  HairStyle st = style_preset("bob");
  st.parts[0].fields[0].kind = "vortex";
  EXPECT_THROW(st.validate(), Error);
  st = style_preset("bob");
  st.parts[0].beam.segments = 0;
  EXPECT_THROW(st.validate(), Error);
}

TEST(Shading, SpecularTermAndIntensity) {
  // (8): tangent perpendicular to H -> ks; parallel -> 0.
  EXPECT_NEAR(anjyo_specular(Vec3::UnitX(), Vec3::UnitY(), 0.5, 40), 0.5, 1e-12);
  EXPECT_NEAR(anjyo_specular(Vec3::UnitY(), Vec3::UnitY(), 0.5, 40), 0.0, 1e-12);
  const Vec3 T = Vec3(1, 1, 0).normalized();
  EXPECT_NEAR(anjyo_specular(T, Vec3::UnitY(), 1.0, 4), std::pow(0.5, 2), 1e-12);
  // (9) with ka fixed (sigma 0): colour = Ia ka hair + Is Φs spec.
  geom::StrandSet s;
  s.points = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
  s.offsets = {0, 2};
  AnjyoShadingParams p;
  p.ka_sigma = 0;
  p.ka_mean = 0.5;
  p.hair_color = Vec3(0.2, 0.1, 0.05);
  p.specular_color = Vec3(1, 1, 1);
  p.ks = 0.3;
  Context ctx(1, 1);
  shade_anjyo1992(ctx, s, p, Vec3(0.5, 100, 0), Vec3(0, 1, 0), 1);
  ASSERT_EQ(s.color.size(), 2u);
  // Expected from (8) and (9) with the exact halfway vector at node 0 (T = +x).
  const Vec3 H = (Vec3(0, 1, 0) + Vec3(0.5, 100, 0).normalized()).normalized();
  const double phi = 0.3 * std::pow(1.0 - H.x() * H.x(), 0.5 * p.exponent);
  EXPECT_NEAR(s.color[0].x(), 0.5 * 0.2 + phi, 1e-6);
  EXPECT_NEAR(s.color[0].z(), 0.5 * 0.05 + phi, 1e-6);
  EXPECT_GT(phi, 0.29);
}

TEST(StrandCache, RoundTripAndBadInput) {
  StrandFrame f;
  f.frame = 42;
  f.time = 1.75;
  f.strands.points = {Vec3f(1, 2, 3), Vec3f(4, 5, 6), Vec3f(7, 8, 9)};
  f.strands.offsets = {0, 3};
  f.strands.color = {Vec3f(0.1f, 0.2f, 0.3f), Vec3f(0, 0, 0), Vec3f(1, 1, 1)};
  const auto dir = test::scratch_dir("strand_cache");
  write_strand_frame(dir, f);
  EXPECT_TRUE(has_strand_frame(dir, 42));
  const StrandFrame g = read_strand_frame(dir, 42);
  EXPECT_EQ(g.frame, 42);
  EXPECT_EQ(g.time, 1.75);
  EXPECT_TRUE(g.strands.points == f.strands.points);
  EXPECT_TRUE(g.strands.color == f.strands.color);
  EXPECT_EQ(g.strands.offsets, f.strands.offsets);
  const std::string bytes = serialize_strand_frame(f);
  EXPECT_THROW(parse_strand_frame(bytes.substr(0, bytes.size() - 5), "x"), Error);
  EXPECT_THROW(parse_strand_frame("garbage", "x"), Error);
  std::string wrong = bytes;
  wrong[8] = 9;  // version
  EXPECT_THROW(parse_strand_frame(wrong, "x"), Error);
}

TEST(StrandCache, ANonFiniteCoordinateIsRefusedNamingTheCacheFile) {
  StrandFrame f;
  f.frame = 3;
  f.strands.points = {Vec3f(0, 0, 0), Vec3f(0, std::nanf(""), 0.1f)};
  f.strands.offsets = {0, 2};
  const auto dir = test::scratch_dir("strand_cache_nan");
  write_strand_frame(dir, f);  // the writer does not judge (a blown-up state is stopped earlier)
  try {
    (void)read_strand_frame(dir, 3);
    FAIL() << "a NaN coordinate was accepted";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("strands_000003.fsc"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("strand point 1 is not finite"));
  }
}

// Preview: set FOLLICLE_HAIR_PREVIEW=/tmp/dir to render the four presets on the default head with
// a small CPU z-buffer (orthographic front and side views). Always checks the roots lie on the
// scalp.
TEST(HairPreview, PresetsOnTheDefaultHead) {
  const auto mesh =
      geom::load_mesh(test::source_dir() / "data/meshes/lee_perry_smith/head.obj", LengthUnit::mm);
  const sim::Ellipsoid hull = sim::fit_head_ellipsoid(mesh.positions);
  Context ctx(2, 1);
  const char* out_dir = std::getenv("FOLLICLE_HAIR_PREVIEW");
  const double dens = out_dir ? 1.0 : 0.02;
  const geom::MeshQuery query(mesh);
  const auto scalp = mesh_query_closest_point(query);
  for (const auto& name : style_preset_names()) {
    StyledHair h = build_style(ctx, hull, style_preset(name, dens), 1, scalp);
    ASSERT_GT(h.strands.num_strands(), 10u);
    for (const auto& r : h.roots.position) EXPECT_LT((scalp(r).point - r).norm(), 1e-7);
    if (!out_dir) continue;
    AnjyoShadingParams sp;
    const int W = 512, H = 512;
    for (int view = 0; view < 3; ++view) {
      const double yaw = view == 0 ? 0.0 : (view == 1 ? kPi / 2 : 2.4);
      const Mat3 R = Eigen::AngleAxisd(-yaw, Vec3::UnitY()).toRotationMatrix();
      const Vec3 eye = R.transpose() * Vec3(0, 0.08, 2.0);
      shade_anjyo1992(ctx, h.strands, sp, eye, Vec3(0.3, 0.8, 0.6).normalized(), 2);
      image::ImageRGB8 img(W, H, 235);
      std::vector<float> zb(std::size_t(W * H), -1e9f);
      auto proj = [&](const Vec3& p, double& x, double& y, double& z) {
        const Vec3 q = R * p;
        x = (q.x() + 0.2) / 0.4 * W;
        y = (0.25 - q.y()) / 0.4 * H;
        z = q.z();
      };
      for (const auto& f : mesh.faces) {  // flat-shaded head
        double x[3], y[3], z[3];
        for (int c = 0; c < 3; ++c) proj(mesh.positions[std::size_t(f[c])], x[c], y[c], z[c]);
        const Vec3 n =
            R * (mesh.positions[std::size_t(f[1])] - mesh.positions[std::size_t(f[0])])
                    .cross(mesh.positions[std::size_t(f[2])] - mesh.positions[std::size_t(f[0])]);
        const double sh =
            0.25 + 0.7 * std::max(0.0, n.normalized().dot(Vec3(0.3, 0.5, 0.8).normalized()));
        const int x0 = std::max(0, int(std::min({x[0], x[1], x[2]}))),
                  x1 = std::min(W - 1, int(std::max({x[0], x[1], x[2]})) + 1);
        const int y0 = std::max(0, int(std::min({y[0], y[1], y[2]}))),
                  y1 = std::min(H - 1, int(std::max({y[0], y[1], y[2]})) + 1);
        const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
        if (std::abs(area) < 1e-12) continue;
        for (int py = y0; py <= y1; ++py)
          for (int px = x0; px <= x1; ++px) {
            const double cx = px + 0.5, cy = py + 0.5;
            const double w0 = ((x[1] - cx) * (y[2] - cy) - (x[2] - cx) * (y[1] - cy)) / area;
            const double w1 = ((x[2] - cx) * (y[0] - cy) - (x[0] - cx) * (y[2] - cy)) / area;
            const double w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            const float zz = float(w0 * z[0] + w1 * z[1] + w2 * z[2]);
            float& zr = zb[std::size_t(py * W + px)];
            if (zz <= zr) continue;
            zr = zz;
            uint8_t* pix = img.pixel(px, py);
            pix[0] = uint8_t(255 * sh * 0.93);
            pix[1] = uint8_t(255 * sh * 0.75);
            pix[2] = uint8_t(255 * sh * 0.64);
          }
      }
      for (std::size_t s = 0; s < h.strands.num_strands(); ++s)
        for (uint32_t i = h.strands.offsets[s] + 1; i < h.strands.offsets[s + 1]; ++i) {
          double xa, ya, za, xb, yb, zb2;
          proj(h.strands.points[i - 1].cast<double>(), xa, ya, za);
          proj(h.strands.points[i].cast<double>(), xb, yb, zb2);
          const int steps = int(std::max(std::abs(xb - xa), std::abs(yb - ya))) + 1;
          for (int t = 0; t <= steps; ++t) {
            const double u = double(t) / steps;
            const int px = int(xa + u * (xb - xa)), py = int(ya + u * (yb - ya));
            if (px < 0 || py < 0 || px >= W || py >= H) continue;
            const float zz = float(za + u * (zb2 - za)) + 0.0005f;
            float& zr = zb[std::size_t(py * W + px)];
            if (zz < zr) continue;
            zr = zz;
            const Vec3f c = h.strands.color[i - 1] * float(1 - u) + h.strands.color[i] * float(u);
            uint8_t* pix = img.pixel(px, py);
            for (int k = 0; k < 3; ++k)
              pix[k] = uint8_t(255 * std::pow(std::clamp(c[k], 0.f, 1.f), 1 / 2.2f));
          }
        }
      image::write_png(
          std::filesystem::path(out_dir) / (name + "_" + std::to_string(view) + ".png"), img);
    }
  }
}
