#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/image/raster.hpp"
#include "follicle/skin/fine_wrinkles_bando2002.hpp"
#include "follicle/skin/wrinkle_shape_bando2002.hpp"

using namespace follicle;
using namespace follicle::skin;

namespace {

// A flat n x n grid over [x0, x0 + w] x [0, 1] (metres scaled by `size`), uv = its own (x, y)
// mapped into [0,1]^2 of the part's texture.
geom::TriMesh grid(int n, double x0 = 0.0, double w = 1.0, double size = 0.02) {
  geom::TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double u = double(i) / n, v = double(j) / n;
      m.positions.emplace_back((x0 + w * u) * size, v * size, 0.0);
      m.uvs.emplace_back(u, v);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      m.faces.emplace_back(a, b, d);
      m.faces.emplace_back(a, d, c);
    }
  m.uv_faces = m.faces;
  return m;
}

std::vector<DirectionKey> uniform_keys(const geom::TriMesh& m, const Vec2& d) {
  return {{0, d}, {int(m.uvs.size()) - 1, d}, {int(std::sqrt(m.uvs.size())) - 1, d}};
}

bool proper_cross(const Vec2f& p, const Vec2f& q, const Vec2f& a, const Vec2f& b) {
  auto orient = [](const Vec2f& o, const Vec2f& x, const Vec2f& y) {
    return double(x.x() - o.x()) * (y.y() - o.y()) - double(x.y() - o.y()) * (y.x() - o.x());
  };
  const double d1 = orient(p, q, a), d2 = orient(p, q, b), d3 = orient(a, b, p),
               d4 = orient(a, b, q);
  const double eps = 1e-3;  // points are stored as floats: T-junctions are off by ~1e-5 px
  return ((d1 > eps && d2 < -eps) || (d1 < -eps && d2 > eps)) &&
         ((d3 > eps && d4 < -eps) || (d3 < -eps && d4 > eps));
}

FineWrinkleParams small_params(int res = 256) {
  FineWrinkleParams p;
  p.resolution = res;
  return p;
}

}  // namespace

TEST(FineWrinkles, Eq25Parameters) {
  const auto a = furrow_parameters(0.0, 1.0);
  EXPECT_EQ(a.N, 30);
  EXPECT_DOUBLE_EQ(a.theta, 0.5);
  EXPECT_DOUBLE_EQ(a.D, 4.0);
  EXPECT_DOUBLE_EQ(a.I, 1.0);
  EXPECT_DOUBLE_EQ(a.Wh, 0.0);
  EXPECT_DOUBLE_EQ(a.Wo, 1.0);
  const auto b = furrow_parameters(0.5, -0.5);
  EXPECT_EQ(b.N, 20);
  EXPECT_DOUBLE_EQ(b.theta, -0.15);
  EXPECT_DOUBLE_EQ(b.D, 5.0);
  EXPECT_DOUBLE_EQ(b.I, 0.75);
  EXPECT_DOUBLE_EQ(b.Wh, 1.0);
  EXPECT_DOUBLE_EQ(b.Wo, 7.0);
}

TEST(FineWrinkles, DirectionFieldKeepsKeysAndInterpolates) {
  const auto m = grid(10);
  const std::vector<DirectionKey> keys = {{0, Vec2(0.8, 0)}, {120, Vec2(0, 0.4)}};
  const auto d = interpolate_direction_field(m, keys);
  EXPECT_LT((d[0] - Vec2(0.8, 0)).norm(), 1e-12);
  EXPECT_LT((d[120] - Vec2(0, 0.4)).norm(), 1e-12);
  for (const Vec2& v : d) EXPECT_LE(v.norm(), 1.0 + 1e-12);
  // A constant field stays constant.
  const auto c = interpolate_direction_field(m, uniform_keys(m, Vec2(0.3, 0.4)));
  for (const Vec2& v : c) EXPECT_LT((v - Vec2(0.3, 0.4)).norm(), 1e-9);
  EXPECT_THROW(interpolate_direction_field(m, {{-1, Vec2(0, 0)}}), Error);
  EXPECT_THROW(interpolate_direction_field(m, {{0, Vec2(2, 0)}}), Error);
}

TEST(FineWrinkles, OccupancyOutsideMeshAndNoCrossings) {
  // Mesh covering only the left 60% of the texture.
  auto m = grid(12);
  for (auto& t : m.uvs) t.x() *= 0.6;
  Context ctx(1, 7);
  auto p = small_params(200);
  const auto w = generate_fine_wrinkles(
      ctx, m, {uniform_keys(m, Vec2(0.5, 0.2)), uniform_keys(m, Vec2(-0.1, 0.6))}, p);
  for (int k = 0; k < 2; ++k) {
    const HeightField& f = w.fields[k];
    EXPECT_GT(f.furrows.size(), 20u);
    // Texels right of the mapped mesh: occupied, never carved.
    for (int y = 0; y < 200; y += 7)
      for (int x = 125; x < 200; x += 5) {
        EXPECT_EQ(f.occupancy.at(x, y), 1.0f);
        EXPECT_EQ(f.height.at(x, y), 1.0f);
      }
    // Furrows of one field never properly cross each other.
    const auto& pl = f.furrows;
    std::vector<std::array<Vec2f, 2>> segs;
    std::vector<int> owner;
    for (std::size_t a = 0; a < pl.size(); ++a)
      for (uint32_t j = pl.offsets[a]; j + 1 < pl.offsets[a + 1]; ++j) {
        segs.push_back({pl.points[j], pl.points[j + 1]});
        owner.push_back(int(a));
      }
    int crossings = 0;
    for (std::size_t i = 0; i < segs.size(); ++i)
      for (std::size_t j = i + 1; j < segs.size(); ++j)
        if (owner[i] != owner[j] && proper_cross(segs[i][0], segs[i][1], segs[j][0], segs[j][1]))
          ++crossings;
    EXPECT_EQ(crossings, 0) << "field " << k;
  }
}

TEST(FineWrinkles, CarvedImagesAreTheStrokesOfTheFurrows) {
  // With one magnitude everywhere every segment has the same I, W_h and W_o (2.5), so steps 5
  // and 6 can be redone from the furrow polylines with image::draw_line: the carver's own
  // stroke rasterizers (capsule spans, filled core runs) must give the same texels.
  const auto m = grid(8);
  Context ctx(1, 11);
  auto p = small_params(160);
  p.unit_texels = 1.7;  // W_h = 1.7 texels, W_o = 11.9 texels (m = 0.5)
  const auto w = generate_fine_wrinkles(
      ctx, m, {uniform_keys(m, Vec2(0.4, 0.3)), uniform_keys(m, Vec2(-0.1, 0.5))}, p);
  for (int k = 0; k < 2; ++k) {
    const HeightField& f = w.fields[k];
    const double mag = f.directions[0].norm();
    const FurrowParameters fp = furrow_parameters(mag, 0.0);
    image::ImageF h(160, 160, 1.0f), occ(160, 160, 0.0f);
    const auto& pl = f.furrows;
    ASSERT_GT(pl.size(), 10u);
    for (std::size_t a = 0; a < pl.size(); ++a)
      for (uint32_t j = pl.offsets[a]; j + 1 < pl.offsets[a + 1]; ++j) {
        const Vec2 P = pl.points[j].cast<double>(), Q = pl.points[j + 1].cast<double>();
        image::draw_line(h, P, Q, fp.Wh * p.unit_texels, float(fp.I), image::Blend::Min);
        image::draw_line(occ, P, Q, fp.Wo * p.unit_texels, 1.0f, image::Blend::Max);
      }
    // Polyline points are stored as floats (~1e-5 texel): allow that much in coverage.
    int height_off = 0, occ_off = 0, carved = 0;
    for (int y = 0; y < 160; ++y)
      for (int x = 0; x < 160; ++x) {
        if (std::abs(h.at(x, y) - f.height.at(x, y)) > 1e-3f) ++height_off;
        if (f.height.at(x, y) < 1.0f) ++carved;
        if ((occ.at(x, y) >= 0.5f) != (f.occupancy.at(x, y) >= 0.5f)) ++occ_off;
      }
    EXPECT_GT(carved, 2000) << "field " << k;
    EXPECT_EQ(height_off, 0) << "field " << k;
    EXPECT_LE(occ_off, 20) << "field " << k;
  }
}

TEST(FineWrinkles, NoFurrowStartsInsideOccupiedTexelsAndFillPassCovers) {
  const auto m = grid(8);
  Context ctx(1, 3);
  auto p = small_params(128);
  const auto w = generate_fine_wrinkles(
      ctx, m, {uniform_keys(m, Vec2(0.6, 0)), uniform_keys(m, Vec2(0, 0.6))}, p);
  // Replaying starts: every furrow's start point (the first point of its forward half) must have
  // been free before that furrow; equivalently, after the fill pass nothing mapped is free.
  for (const auto& f : w.fields) {
    for (uint32_t i : w.texels.covered) ASSERT_EQ(f.occupancy.data()[i], 1.0f);
    EXPECT_GT(f.fill_furrows + f.random_furrows, 0);
  }
  // Direct check: a start point inside an occupied region is refused (carving with the first
  // field as a seam-locked initial state leaves no free texel, so no furrow is generated).
  SeamInit all;
  all.height.resize(128, 128, 1.0f);
  all.locked.assign(128 * 128, 1);
  const auto f = carve_furrows(ctx, m, w.texels, w.fields[0].directions, 1.0, p, 11, &all);
  EXPECT_EQ(f.random_furrows + f.fill_furrows, 0);
  EXPECT_EQ(f.segments, 0);
}

namespace {
// Mean spacing of furrows of a field running along x: crossings of vertical lines by furrows.
double mean_spacing(const HeightField& f, int n) {
  int crossings = 0, lines = 0;
  const auto& pl = f.furrows;
  for (int x = n / 4; x < 3 * n / 4; x += 8) {
    ++lines;
    const float c = float(x) + 0.5f;
    for (std::size_t a = 0; a < pl.size(); ++a)
      for (uint32_t j = pl.offsets[a]; j + 1 < pl.offsets[a + 1]; ++j) {
        const float x0 = pl.points[j].x(), x1 = pl.points[j + 1].x();
        if ((x0 < c && x1 >= c) || (x1 < c && x0 >= c)) ++crossings;
      }
  }
  return crossings > 0 ? double(n) * lines / crossings : 1e9;
}
}  // namespace

TEST(FineWrinkles, SpacingGrowsWithWo) {
  // W_o = 1 + 12m grows with m; W_h = 2m too, so compare at fixed unit for m = 0.3 and 0.9.
  const auto m = grid(8);
  Context ctx(1, 5);
  auto p = small_params(256);
  const auto lo = generate_fine_wrinkles(ctx, m, {uniform_keys(m, Vec2(0.3, 0)), {}}, p);
  const auto hi = generate_fine_wrinkles(ctx, m, {uniform_keys(m, Vec2(0.9, 0)), {}}, p);
  const double s_lo = mean_spacing(lo.fields[0], 256), s_hi = mean_spacing(hi.fields[0], 256);
  EXPECT_GT(s_hi, 1.5 * s_lo) << s_lo << " " << s_hi;
  // Larger unit (texels per (2.5) unit) spreads furrows too.
  p.unit_texels = 2.0;
  const auto big = generate_fine_wrinkles(ctx, m, {uniform_keys(m, Vec2(0.3, 0)), {}}, p);
  EXPECT_GT(mean_spacing(big.fields[0], 256), 1.5 * s_lo);
}

TEST(FineWrinkles, FurrowsFollowTheField) {
  const auto m = grid(8);
  Context ctx(1, 9);
  auto p = small_params(256);
  const Vec2 d(std::cos(0.6), std::sin(0.6));
  const auto w = generate_fine_wrinkles(ctx, m, {uniform_keys(m, 0.8 * d), {}}, p);
  const auto& pl = w.fields[0].furrows;
  const Vec2 dt(d.x(), -d.y());  // texel space
  double sum = 0;
  int cnt = 0, far = 0;
  for (std::size_t a = 0; a < pl.size(); ++a)
    for (uint32_t j = pl.offsets[a]; j + 1 < pl.offsets[a + 1]; ++j) {
      const Vec2 s = (pl.points[j + 1] - pl.points[j]).cast<double>();
      if (s.norm() < 2.0) continue;  // shortened at an intersection
      const double ang = std::acos(std::min(1.0, std::abs(s.normalized().dot(dt))));
      sum += ang;
      ++cnt;
      // theta = (0.5 - 0.4 m) r = at most 0.18 rad for m = 0.8
      if (ang > 0.18 + 0.02) ++far;
    }
  ASSERT_GT(cnt, 100);
  EXPECT_LT(sum / cnt, 0.12);
  EXPECT_EQ(far, 0);
}

TEST(FineWrinkles, SameSeedSameImagesAnyThreads) {
  const auto m = grid(8);
  auto p = small_params(160);
  const std::array<std::vector<DirectionKey>, 2> keys = {uniform_keys(m, Vec2(0.5, 0.1)),
                                                         uniform_keys(m, Vec2(0.1, -0.5))};
  Context c1(1, 42), c2(2, 42), c3(2, 43);
  const auto a = generate_fine_wrinkles(c1, m, keys, p);
  const auto b = generate_fine_wrinkles(c2, m, keys, p);
  const auto c = generate_fine_wrinkles(c3, m, keys, p);
  for (int k = 0; k < 2; ++k) {
    EXPECT_TRUE(a.fields[k].height == b.fields[k].height);
    EXPECT_TRUE(a.fields[k].occupancy == b.fields[k].occupancy);
  }
  EXPECT_FALSE(a.fields[0].height == c.fields[0].height);
}

TEST(FineWrinkles, SeamContinuity) {
  // Part A covers x in [0, 0.6], part B x in [0.4, 1.0] of one plane: they share [0.4, 0.6].
  const int n = 12;  // vertex spacing 0.05: the grids share the columns x in [0.4, 0.6]
  const auto A = grid(n, 0.0, 0.6), B = grid(n, 0.4, 0.6);
  // Shared strip: columns i >= 2n/3 in A equal columns i - 2n/3... use exact vertex positions.
  SharedStrip strip;
  for (std::size_t fa = 0; fa < A.faces.size(); ++fa) {
    Vec3 ca = Vec3::Zero();
    for (int c = 0; c < 3; ++c) ca += A.positions[A.faces[fa][c]] / 3.0;
    for (std::size_t fb = 0; fb < B.faces.size(); ++fb) {
      bool same = true;
      for (int c = 0; c < 3; ++c)
        same &= (A.positions[A.faces[fa][c]] - B.positions[B.faces[fb][c]]).norm() < 1e-12;
      if (same) {
        strip.faces_a.push_back(int(fa));
        strip.faces_b.push_back(int(fb));
      }
    }
  }
  ASSERT_GT(strip.faces_a.size(), 20u);
  Context ctx(2, 1);
  auto p = small_params(256);
  const std::array<std::vector<DirectionKey>, 2> keys = {uniform_keys(A, Vec2(0.6, 0.2)),
                                                         uniform_keys(A, Vec2(-0.2, 0.6))};
  const auto wa = generate_fine_wrinkles(ctx, A, keys, p);
  const TexelMap tb = rasterize_texture_space(ctx, B, p.resolution);
  const SeamInit s0 = make_seam_init(A, wa, 0, B, tb, strip);
  const SeamInit s1 = make_seam_init(A, wa, 1, B, tb, strip);
  EXPECT_FALSE(s0.directions.empty());
  const auto wb = generate_fine_wrinkles(ctx, B, {std::vector<DirectionKey>{}, {}}, p, {&s0, &s1});
  // Compare heights at the same surface points in the middle of the strip (x = 0.5).
  double diff = 0;
  int cnt = 0;
  for (int k = 0; k < 2; ++k)
    for (int j = 5; j < 250; ++j) {
      const double y = j + 0.5;
      // surface x = 0.5 -> A's u = 0.5/0.6, B's u = 0.1/0.6.
      const int xa = int(0.5 / 0.6 * 256), xb = int(0.1 / 0.6 * 256);
      diff += std::abs(wa.fields[k].height.at(xa, int(y)) - wb.fields[k].height.at(xb, int(y)));
      ++cnt;
    }
  EXPECT_LT(diff / cnt, 0.05);
  // B also has furrows of its own outside the strip.
  EXPECT_GT(wb.fields[0].random_furrows + wb.fields[0].fill_furrows, 5);
}

TEST(FineWrinkles, ModulationFadesWhenExpandingAcrossTheField) {
  const auto m = grid(10);
  Context ctx(2, 4);
  auto p = small_params(128);
  // Field 0 runs along x, field 1 along y.
  const auto w = generate_fine_wrinkles(
      ctx, m, {uniform_keys(m, Vec2(0.7, 0)), uniform_keys(m, Vec2(0, 0.7))}, p);
  FineWrinkleAnimator anim(m, w);
  std::array<std::vector<float>, 2> s;
  anim.shrinkage(ctx, m.positions, s);
  for (int k = 0; k < 2; ++k)
    for (float v : s[k]) ASSERT_NEAR(v, 0.0f, 1e-6f);
  // Stretch the plane by 1.5 along y (perpendicular to field 0, along field 1).
  std::vector<Vec3> x = m.positions;
  for (auto& q : x) q.y() *= 1.5;
  anim.shrinkage(ctx, x, s);
  for (std::size_t v = 0; v < s[0].size(); ++v) {
    EXPECT_NEAR(s[0][v], 1.0 - 1.5, 1e-5);  // (2.3): s = 1 - L'/L
    EXPECT_NEAR(s[1][v], 0.0, 1e-5);
  }
  image::ImageF rest, frame;
  anim.rest_relief(ctx, rest);
  anim.modulate(ctx, s, frame);
  // Per field: field 0 fades by M(-0.5)/M(0), field 1 unchanged.
  const double fade = amplitude_modulation(-0.5, 0.5) / amplitude_modulation(0.0, 0.5);
  double e0 = 0, e1 = 0;
  for (uint32_t i : w.texels.covered) {
    e0 += 1.0 - w.fields[0].height.data()[i];
    e1 += 1.0 - w.fields[1].height.data()[i];
  }
  double rest_sum = 0, frame_sum = 0;
  for (uint32_t i : w.texels.covered) {
    rest_sum += rest.data()[i];
    frame_sum += frame.data()[i];
  }
  EXPECT_NEAR(rest_sum, -0.5 * (e0 + e1), 1e-3 * (e0 + e1));
  EXPECT_NEAR(frame_sum, -0.5 * (fade * e0 + e1), 1e-3 * (e0 + e1));
  // Shrinkage texture interpolates the vertex values.
  image::ImageF st;
  anim.shrinkage_texture(ctx, s[0], st);
  EXPECT_NEAR(st.at(64, 64), -0.5f, 1e-5f);
}

TEST(FineWrinkles, BadInputs) {
  auto m = grid(4);
  Context ctx(1);
  auto p = small_params(64);
  p.resolution = 10;
  EXPECT_THROW(generate_fine_wrinkles(ctx, m, {}, p), Error);
  p = small_params(64);
  geom::TriMesh no_uv = m;
  no_uv.uvs.clear();
  no_uv.uv_faces.clear();
  EXPECT_THROW(generate_fine_wrinkles(ctx, no_uv, {}, p), Error);
  EXPECT_THROW(carve_furrows(ctx, m, rasterize_texture_space(ctx, m, 64), {}, 1.0, p, 1), Error);
}
