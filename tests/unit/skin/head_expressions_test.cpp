// The default head (data/meshes/lee_perry_smith) with its authored muscles and wrinkles
// (data/muscles/lee_perry_smith.json): furrows appear only where and when the skin compresses.
#include <gtest/gtest.h>

#include "follicle/core/context.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/skin_json.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::skin;

namespace {
const FaceRig& head_rig() {
  static const FaceRig rig(
      geom::load_mesh(test::source_dir() / "data/meshes/lee_perry_smith/head.obj", LengthUnit::mm),
      load_face_setup(test::source_dir() / "data/muscles/lee_perry_smith.json").muscles,
      load_face_setup(test::source_dir() / "data/muscles/lee_perry_smith.json").wrinkles,
      FaceRigParams{});
  return rig;
}

// Mean wrinkle height on the furrow centre line (vertices within 0.5 mm of the curve, away
// from the tapered ends) of wrinkle i.
double centre_height(const FaceRig& rig, const FaceState& s, std::size_t i) {
  const auto& layer = rig.wrinkle_layer();
  double sum = 0;
  int n = 0;
  for (const auto& e : layer.influence(i).entries)
    if (e.l < 0.5e-3 && e.shape < -0.9 * layer.wrinkle(i).depth) {
      sum += s.wrinkle_height[std::size_t(e.vertex)];
      ++n;
    }
  EXPECT_GT(n, 0) << layer.wrinkle(i).name;
  return n > 0 ? sum / n : 0.0;
}
}  // namespace

TEST(HeadExpressions, NeutralPoseLeavesTheMeshUnchanged) {
  Context ctx(2);
  const FaceRig& rig = head_rig();
  FaceState s;
  rig.update(ctx, rig.neutral_pose(), s);
  const auto& rest = rig.rest_mesh().positions;
  ASSERT_EQ(s.positions.size(), rest.size());
  double worst = 0;
  for (std::size_t i = 0; i < rest.size(); ++i)
    worst = std::max(worst, (s.positions[i] - rest[i]).norm());
  EXPECT_LT(worst, 1e-12);  // no muscle, no tissue change, r = 0 wrinkles invisible
  // The "neutral" expression of the file is the same pose.
  FaceState t;
  rig.update(ctx, rig.expression_pose("neutral"), t);
  EXPECT_EQ(t.positions, s.positions);
}

TEST(HeadExpressions, ForeheadFurrowsAppearWhenTheFrontalisContracts) {
  Context ctx(2);
  const FaceRig& rig = head_rig();
  const auto& layer = rig.wrinkle_layer();
  FaceState neutral, raised, half;
  rig.update(ctx, rig.neutral_pose(), neutral);
  rig.update(ctx, rig.expression_pose("raised_brows"), raised);
  rig.update(ctx, rig.expression_pose("raised_brows", 0.5), half);
  int forehead = 0;
  for (std::size_t i = 0; i < layer.num_wrinkles(); ++i) {
    if (layer.wrinkle(i).name.rfind("forehead", 0) != 0) continue;
    ++forehead;
    const double d = layer.wrinkle(i).depth;
    EXPECT_NEAR(centre_height(rig, neutral, i), 0.0, 1e-12) << layer.wrinkle(i).name;
    const double h = centre_height(rig, raised, i), hh = centre_height(rig, half, i);
    EXPECT_LT(h, -0.08 * d) << layer.wrinkle(i).name;  // depth M(s) d with s > 0.08
    EXPECT_LT(h, hh) << layer.wrinkle(i).name;         // deeper with stronger contraction
    EXPECT_LT(hh, 0.0) << layer.wrinkle(i).name;
  }
  EXPECT_EQ(forehead, 4);
  // Glabella lines stay shallow when only the frontalis acts, and deepen with the corrugators.
  FaceState angry;
  rig.update(ctx, rig.expression_pose("angry"), angry);
  for (std::size_t i = 0; i < layer.num_wrinkles(); ++i) {
    if (layer.wrinkle(i).name.rfind("glabella", 0) != 0) continue;
    const double d = layer.wrinkle(i).depth;
    EXPECT_LT(centre_height(rig, angry, i), -0.1 * d) << layer.wrinkle(i).name;
    EXPECT_GT(centre_height(rig, raised, i), -0.05 * d) << layer.wrinkle(i).name;
  }
}

TEST(WatersMuscle, SmoothProfileReachesZeroWithZeroSlope) {
  LinearMuscle m;
  m.profile = "smooth";
  m.origin = Vec3(0, 0, 0);
  m.insertion = Vec3(0, -0.05, 0);
  m.falloff_start = 0.02;
  m.falloff_end = 0.05;
  m.zone = 0.5;
  m.validate();
  const double h = 1e-8;
  // On the axis inside fs: factor -1 (k is the axial strain).
  EXPECT_NEAR(linear_muscle_factor(m, Vec3(0, -0.01, 0)), -1.0, 1e-12);
  // Radially at fe and angularly at the zone edge: value and slope vanish.
  const Vec3 fe(0, -m.falloff_end, 0);
  EXPECT_NEAR(linear_muscle_factor(m, fe - Vec3(0, -h, 0)), 0.0, 1e-9);
  EXPECT_NEAR((linear_muscle_factor(m, fe) - linear_muscle_factor(m, fe - Vec3(0, -h, 0))) / h, 0.0,
              1e-3);
  const double r = 0.015;
  auto at = [&](double th) {
    return linear_muscle_factor(m, Vec3(r * std::sin(th), -r * std::cos(th), 0));
  };
  EXPECT_NEAR(at(m.zone - h), 0.0, 1e-9);
  EXPECT_NEAR((at(m.zone - h) - at(m.zone - 2 * h)) / h, 0.0, 1e-4);
  EXPECT_EQ(at(m.zone + h), 0.0);
  LinearMuscle bad = m;
  bad.profile = "smoooth";
  EXPECT_THROW(bad.validate(), Error);
}
