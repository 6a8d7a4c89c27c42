#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/forehead_validation.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

using namespace follicle;
using namespace follicle::skin;

namespace {
// Flat 60 x 60 mm patch, 1.5 mm grid, horizontal furrow through the middle.
struct Patch {
  geom::TriMesh mesh = make_cylinder_patch(0.06, 0.06, 0.0, 0.0015);
  LargeWrinkle w;
  Patch() {
    w.control = {Vec2(0.1, 0.5), Vec2(0.4, 0.5), Vec2(0.6, 0.5), Vec2(0.9, 0.5)};
    w.depth = 0.003;
    w.width = 0.002;
    w.r = 0.4;
  }
};
double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}
}  // namespace

TEST(Shrinkage, RigidMotionGivesZeroShrinkageAndUnchangedWrinkles) {
  Context ctx(2);
  Patch p;
  WrinkleLayer layer(p.mesh, {p.w});
  ASSERT_GT(layer.influence(0).entries.size(), 100u);
  const Affine3 xf =
      Eigen::Translation3d(0.1, -0.2, 0.3) * Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized());
  std::vector<Vec3> moved = p.mesh.positions;
  for (auto& q : moved) q = xf * q;
  std::vector<double> s;
  layer.shrinkage(ctx, 0, moved, s);
  EXPECT_LT(max_abs(s), 1e-12);
  std::vector<double> h, h0;
  layer.heights(ctx, moved, h);
  layer.rest_heights(h0);
  ASSERT_EQ(h.size(), h0.size());
  for (std::size_t i = 0; i < h.size(); ++i) EXPECT_NEAR(h[i], h0[i], 1e-12);
}

TEST(Shrinkage, AlongFurrowKeepsAmplitudeAcrossRaisesIt) {
  Context ctx(1);
  Patch p;
  WrinkleLayer layer(p.mesh, {p.w});
  std::vector<double> h0, h_along, h_across, s_along, s_across;
  layer.rest_heights(h0);
  std::vector<Vec3> along = p.mesh.positions, across = p.mesh.positions;
  for (auto& q : along) q.x() *= 0.7;   // shrink parallel to the (horizontal) furrow
  for (auto& q : across) q.y() *= 0.7;  // shrink perpendicular to it
  layer.shrinkage(ctx, 0, along, s_along);
  layer.shrinkage(ctx, 0, across, s_across);
  EXPECT_LT(max_abs(s_along), 1e-9);
  for (double s : s_across) EXPECT_NEAR(s, 0.3, 1e-9);
  layer.heights(ctx, along, h_along);
  layer.heights(ctx, across, h_across);
  const double a0 = max_abs(h0), a1 = max_abs(h_along), a2 = max_abs(h_across);
  EXPECT_NEAR(a1, a0, 1e-12);
  EXPECT_NEAR(a2 / a0, amplitude_modulation(0.3, 0.4) / amplitude_modulation(0.0, 0.4), 1e-9);
  EXPECT_GT(a2, 1.4 * a0);
}

TEST(Shrinkage, ExpansionLowersAmplitudeAndRZeroHidesWrinkles) {
  Context ctx(1);
  Patch p;
  p.w.r = 0.0;
  WrinkleLayer layer(p.mesh, {p.w});
  std::vector<Vec3> expand = p.mesh.positions;
  for (auto& q : expand) q.y() *= 1.2;
  std::vector<double> h;
  layer.heights(ctx, expand, h);
  EXPECT_EQ(max_abs(h), 0.0);
  layer.heights(ctx, p.mesh.positions, h);
  EXPECT_EQ(max_abs(h), 0.0);  // r = 0: invisible at rest
}

TEST(Shrinkage, OnlyAffectedVerticesRecomputedOnEdit) {
  Patch p;
  LargeWrinkle other = p.w;
  other.control = {Vec2(0.1, 0.2), Vec2(0.4, 0.2), Vec2(0.6, 0.2), Vec2(0.9, 0.2)};
  WrinkleLayer layer(p.mesh, {p.w, other});
  const auto before = layer.influence(1).entries.size();
  LargeWrinkle edited = p.w;
  edited.depth = 0.001;
  const std::size_t n = layer.set_wrinkle(0, edited);
  EXPECT_LT(n, p.mesh.positions.size() / 2);
  EXPECT_EQ(layer.influence(1).entries.size(), before);
  EXPECT_DOUBLE_EQ(layer.wrinkle(0).depth, 0.001);
}

TEST(Shrinkage, PaperEdgeScalingAgreesWhenEdgesScaleAlike) {
  Context ctx(1);
  Patch p;
  WrinkleLayer paper(p.mesh, {p.w}, 10.0, ShrinkageMethod::edge_scaling);
  WrinkleLayer exact(p.mesh, {p.w}, 10.0, ShrinkageMethod::deformation);
  std::vector<Vec3> iso = p.mesh.positions;
  for (auto& q : iso) q = Vec3(0.8 * q.x(), 0.8 * q.y(), q.z());  // uniform in-plane shrink
  std::vector<double> a, b;
  paper.shrinkage(ctx, 0, iso, a);
  exact.shrinkage(ctx, 0, iso, b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i], 0.2, 1e-9);
    EXPECT_NEAR(b[i], 0.2, 1e-9);
  }
}
