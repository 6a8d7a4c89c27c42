// The skeleton-animated MakeHuman hand (Bando 2002 §2.7, paper §8): texture space, rest pose,
// joint-wrinkle and fine-wrinkle response to finger flexion.
#include "follicle/skin/hand_rig.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/skin/wrinkle_maps.hpp"
#include "follicle/skin/wrinkle_shape_bando2002.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::skin;

namespace {

std::filesystem::path mh_dir() {
  return test::source_dir() / "data" / "makehuman";
}

HandRigParams small_params() {
  HandRigParams p;
  p.fine.resolution = 512;
  p.fine.unit_mm = 0.5;
  return p;
}

/// Mean of M(s) over the entries of wrinkle i that lie on the furrow (l < w), i.e. the amplitude
/// of the furrow relative to d.
double furrow_amplitude(const Context& ctx, const WrinkleLayer& layer, std::size_t i,
                        const std::vector<Vec3>& x) {
  std::vector<double> s;
  layer.shrinkage(ctx, i, x, s);
  const auto& e = layer.influence(i).entries;
  double sum = 0;
  int n = 0;
  for (std::size_t k = 0; k < e.size(); ++k)
    if (e[k].l < layer.wrinkle(i).width) {
      sum += amplitude_modulation(s[k], layer.wrinkle(i).r);
      ++n;
    }
  return n ? sum / n : std::nan("");
}

double mean_shrinkage(const Context& ctx, const WrinkleLayer& layer, std::size_t i,
                      const std::vector<Vec3>& x) {
  std::vector<double> s;
  layer.shrinkage(ctx, i, x, s);
  double sum = 0;
  for (double v : s) sum += v;
  return s.empty() ? 0.0 : sum / double(s.size());
}

}  // namespace

TEST(HandRig, HandTextureFillsTheSquare) {
  const auto base = anim::load_makehuman_obj(mh_dir() / "base.obj");
  const auto skel = anim::load_mhskel(mh_dir() / "default.mhskel", base.positions);
  const auto w = anim::load_mhw(mh_dir() / "default_weights.mhw", skel, base.positions.size());
  for (auto side : {anim::Side::left, anim::Side::right}) {
    const auto hand = anim::extract_hand(base, skel, w, side);
    Eigen::AlignedBox2d box;
    for (const Vec3i& T : hand.mesh.uv_faces)
      for (int c = 0; c < 3; ++c) box.extend(hand.mesh.uvs[T[c]]);
    // The island is rescaled to fill the square (2% margin) along its longer side.
    EXPECT_NEAR(box.sizes().maxCoeff(), 0.96, 1e-9);
    double at = 0;  // texture-space area of the island
    for (const Vec3i& T : hand.mesh.uv_faces) {
      const Vec2 e1 = hand.mesh.uvs[T[1]] - hand.mesh.uvs[T[0]];
      const Vec2 e2 = hand.mesh.uvs[T[2]] - hand.mesh.uvs[T[0]];
      at += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
    }
    EXPECT_GT(at, 0.3);
    EXPECT_GE(box.min().minCoeff(), 0.0);
    EXPECT_LE(box.max().maxCoeff(), 1.0);
    Context ctx(2);
    const TexelMap t = rasterize_texture_space(ctx, hand.mesh, 256);
    // The hm08 hand island (fingers spread) covers 37% of its own bounding square, so a rescale
    // that keeps the aspect ratio covers about 0.35 of the texture; before the fix (a stray
    // wrist face from another UV chart stretched the box) it was below 0.05.
    EXPECT_GT(texel_coverage(t), 0.3);
    // Texel size: a hand is ~0.03 m^2 of skin; at 1024^2 a texel is a fraction of a millimetre.
    EXPECT_GT(t.metres_per_texel * 256 / 1024, 0.15e-3);
    EXPECT_LT(t.metres_per_texel * 256 / 1024, 0.5e-3);
  }
}

class HandRigTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Context ctx(2);
    HandRigParams p = small_params();
    p.joint_r = 0.5;
    p.palmar_creases = true;
    rig = HandRig::load(ctx, mh_dir(), p).release();
  }
  static void TearDownTestSuite() { delete rig; }
  static HandRig* rig;
};
HandRig* HandRigTest::rig = nullptr;

TEST_F(HandRigTest, BuildsJointWrinklesAndRefines) {
  // Two joints on each of five fingers, dorsal and palmar, three creases each (a few may be
  // dropped where a UV seam crosses the arc).
  EXPECT_GE(rig->joint_wrinkles().size(), 40u);
  EXPECT_LE(rig->joint_wrinkles().size(), 60u);
  EXPECT_GT(rig->rest_mesh().faces.size(), 2 * rig->hand().mesh.faces.size());
  for (const auto& w : rig->joint_wrinkles()) {
    EXPECT_GE(w.depth, 0.5e-3);
    EXPECT_LE(w.depth, 1e-3);
    for (const Vec2& c : w.control) {
      EXPECT_GT(c.minCoeff(), -0.1);
      EXPECT_LT(c.maxCoeff(), 1.1);
    }
  }
  EXPECT_EQ(rig->weights().num_vertices(), rig->rest_mesh().positions.size());
}

TEST_F(HandRigTest, RestPoseReproducesTheMeshExactly) {
  Context ctx(2);
  HandState s;
  rig->update(ctx, 0.0, s);
  ASSERT_EQ(s.animated.size(), rig->rest_mesh().positions.size());
  for (std::size_t i = 0; i < s.animated.size(); ++i)
    ASSERT_EQ(s.animated[i], rig->rest_mesh().positions[i]) << i;
  // Rest shrinkage is zero, so joint wrinkles sit at r * S(l) and fine wrinkles at M = r.
  std::vector<double> rest_h;
  rig->wrinkle_layer().rest_heights(rest_h);
  for (std::size_t i = 0; i < rest_h.size(); ++i) ASSERT_NEAR(s.joint_height[i], rest_h[i], 1e-12);
  for (int k = 0; k < 2; ++k)
    for (float v : s.fine_shrinkage[k]) ASSERT_NEAR(v, 0.0f, 1e-6f);
}

TEST_F(HandRigTest, JointWrinklesRiseOnTheCompressedSideAndFadeOnTheStretchedSide) {
  Context ctx(2);
  HandState s;
  rig->update(ctx, 1.0, s);
  const auto& layer = rig->wrinkle_layer();
  int dorsal = 0, palmar = 0;
  for (std::size_t i = 0; i < layer.num_wrinkles(); ++i) {
    const auto& info = rig->joint_wrinkle_info()[i];
    if (info.crease != 1) continue;  // the middle crease sits on the joint
    const double a0 = furrow_amplitude(ctx, layer, i, rig->rest_mesh().positions);
    const double a1 = furrow_amplitude(ctx, layer, i, s.animated);
    EXPECT_NEAR(a0, 0.5, 1e-9) << layer.wrinkle(i).name;
    const double sm = mean_shrinkage(ctx, layer, i, s.animated);
    if (info.palmar) {
      EXPECT_GT(sm, 0.05) << layer.wrinkle(i).name;
      EXPECT_GT(a1, a0 + 0.03) << layer.wrinkle(i).name;
      ++palmar;
    } else {
      EXPECT_LT(sm, -0.05) << layer.wrinkle(i).name;
      EXPECT_LT(a1, a0 - 0.03) << layer.wrinkle(i).name;
      ++dorsal;
    }
  }
  EXPECT_GE(dorsal, 8);
  EXPECT_GE(palmar, 8);
}

TEST_F(HandRigTest, FineWrinklesAcrossTheFingerFadeOnTheBackOfFlexedJoints) {
  // Field 0 runs around the fingers: on the back of a flexed joint the skin stretches along the
  // finger (perpendicular to field 0), so s < 0 and M(s) < r there (Fig. 2.17).
  Context ctx(2);
  HandState s;
  rig->update(ctx, 1.0, s);
  const geom::TriMesh& m = rig->rest_mesh();
  const auto& layer = rig->wrinkle_layer();
  double sum0 = 0, sum1 = 0;
  int n = 0;
  for (std::size_t i = 0; i < layer.num_wrinkles(); ++i) {
    if (rig->joint_wrinkle_info()[i].palmar || rig->joint_wrinkle_info()[i].crease != 1) continue;
    const CubicBezier2 c{layer.wrinkle(i).control};
    const Vec2 mid = c.eval(0.5);
    for (std::size_t t = 0; t < m.uvs.size(); ++t)
      if ((m.uvs[t] - mid).norm() < 0.01) {
        sum0 += s.fine_shrinkage[0][t];
        sum1 += s.fine_shrinkage[1][t];
        ++n;
      }
  }
  ASSERT_GT(n, 20);
  const double s0 = sum0 / n, s1 = sum1 / n;
  EXPECT_LT(s0, -0.1);
  EXPECT_LT(amplitude_modulation(s0, 0.5), 0.45);
  // Field 1 is tilted toward the finger axis, so it is stretched less across its furrows.
  EXPECT_GT(s1, s0);
  // And the modulated relief over those texels is shallower than at rest.
  image::ImageF rest;
  rig->fine_animator().rest_relief(ctx, rest);
  double r0 = 0, r1 = 0;
  for (std::size_t i = 0; i < layer.num_wrinkles(); ++i) {
    if (rig->joint_wrinkle_info()[i].palmar || rig->joint_wrinkle_info()[i].crease != 1) continue;
    const Vec2 mid = CubicBezier2{layer.wrinkle(i).control}.eval(0.5);
    const int N = rest.width();
    const int cx = int(mid.x() * N), cy = int((1.0 - mid.y()) * N);
    for (int y = cy - 3; y <= cy + 3; ++y)
      for (int x = cx - 3; x <= cx + 3; ++x) {
        r0 += rest.at(x, y);
        r1 += s.relief.at(x, y);
      }
  }
  EXPECT_LT(r0, 0.0);       // furrows carved
  EXPECT_GT(r1, 0.8 * r0);  // at least 20% shallower (relief is negative)
}

TEST_F(HandRigTest, FrameItemsAndDeterminism) {
  Context c1(1), c2(2);
  const HandFrame a = rig->frame(c1, 0.7);
  const HandFrame b = rig->frame(c2, 0.7);
  ASSERT_TRUE(a.mesh && a.height_m);
  EXPECT_TRUE(a.mesh->positions == b.mesh->positions);
  EXPECT_TRUE(a.height_m->storage() == b.height_m->storage());
  EXPECT_EQ(a.height_m->width(), rig->params().fine.resolution);
  EXPECT_GT(a.flexion, 0.5);
  EXPECT_EQ(a.mesh->normals.size(), a.mesh->positions.size());
  // Height map in metres: furrows tens of micrometres deep.
  float lo = 0, hi = -1;
  for (float h : a.height_m->storage()) {
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  EXPECT_LT(lo, -10e-6f);
  EXPECT_GT(lo, -300e-6f);
  EXPECT_LE(hi, 0.0f);
  // A non-flat normal map.
  image::ImageF relief;
  rig->fine_animator().rest_relief(c2, relief);
  const auto nm =
      normal_map_from_relief(c2, relief, rig->relief_depth_m(),
                             rig->fine_animator().metres_per_texel(), rig->params().bump_strength);
  double min_z = 1;
  for (int y = 0; y < nm.height(); ++y)
    for (int x = 0; x < nm.width(); ++x) min_z = std::min(min_z, double(nm.at(x, y, 2)));
  EXPECT_LT(min_z, 0.995);  // tilted by > 5.7 degrees somewhere (flat relief: exactly 1)
  // Without wrinkles: plain skinned mesh, no height map.
  const HandFrame plain = rig->frame(c2, 0.7, false);
  EXPECT_FALSE(plain.height_m);
  double maxd = 0;
  for (std::size_t i = 0; i < plain.mesh->positions.size(); ++i)
    maxd = std::max(maxd, (plain.mesh->positions[i] - a.mesh->positions[i]).norm());
  EXPECT_GT(maxd, 0.2e-3);  // joint wrinkles displace by up to ~d
  EXPECT_LT(maxd, 2e-3);
}

TEST(HandRigParamsTest, BadParams) {
  HandRigParams p;
  p.joint_r = 1.5;
  EXPECT_THROW(p.validate(), Error);
  p = HandRigParams{};
  p.fine.resolution = 10;
  EXPECT_THROW(p.validate(), Error);
  Context ctx(1);
  EXPECT_THROW(HandRig::load(ctx, test::scratch_dir("hand_missing")), Error);
}
