// Blendshape targets (skin/blendshapes): the delta blend is linear in the weights and sums
// targets; inserted vertices of a refinement take their parents' mean offset; a face rig driven by
// a target that holds a muscle expression's surface wrinkles like the muscles themselves; targets
// of another topology are refused with what differs.
#include "follicle/skin/blendshapes.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

#include "follicle/core/error.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/forehead_validation.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::skin;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace {

geom::TriMesh patch() {
  return make_cylinder_patch(0.08, 0.06, 0.08, 0.003);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// The forehead patch of face_rig_test: a frontalis pulling up across one furrow.
MuscleSet frontalis() {
  MuscleSet set;
  LinearMuscle m;
  m.name = "frontalis";
  m.origin = Vec3(0, 0.06, 0.075);
  m.insertion = Vec3(0, -0.02, 0.08);
  m.falloff_start = 0.005;
  m.falloff_end = 0.09;
  m.zone = 0.6;
  set.linear.push_back(m);
  return set;
}

LargeWrinkle furrow() {
  LargeWrinkle w;
  w.control = {Vec2(0.2, 0.4), Vec2(0.4, 0.42), Vec2(0.6, 0.42), Vec2(0.8, 0.4)};
  w.depth = 0.004;
  w.width = 0.003;
  return w;
}

}  // namespace

TEST(Blendshapes, BlendIsLinearInTheWeightsAndSumsTargets) {
  Context ctx(2);
  const geom::TriMesh n = patch();
  geom::TriMesh a = n, b = n;
  for (std::size_t i = 0; i < n.positions.size(); ++i) {
    a.positions[i] += Vec3(0, 0.001 * n.positions[i].x(), 0);  // a shear
    if (i % 3 == 0) b.positions[i] += Vec3(0.0005, 0, 0);      // a few vertices only
  }
  const auto bs = Blendshapes::from_meshes(n, {"a", "b"}, {a, b}, "test");
  ASSERT_EQ(bs.size(), 2u);
  EXPECT_EQ(bs.index("b"), 1);
  EXPECT_EQ(bs.index("c"), -1);
  EXPECT_LE(bs.moved(1), (n.positions.size() + 2) / 3);  // stored sparse
  EXPECT_NEAR(bs.max_offset(1), 0.0005, 1e-15);
  auto p = n.positions;
  bs.accumulate(ctx, {1.0, 0.0}, p);
  for (std::size_t i = 0; i < p.size(); ++i) EXPECT_LT((p[i] - a.positions[i]).norm(), 1e-15);
  p = n.positions;
  bs.accumulate(ctx, {0.5, 2.0}, p);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 want = n.positions[i] + 0.5 * (a.positions[i] - n.positions[i]) +
                      2.0 * (b.positions[i] - n.positions[i]);
    EXPECT_LT((p[i] - want).norm(), 1e-15);
  }
  p = n.positions;
  bs.accumulate(ctx, {}, p);  // no weights: no change
  EXPECT_EQ(p, n.positions);
  EXPECT_THAT(error_of([&] { bs.accumulate(ctx, {1.0}, p); }), HasSubstr("1 weights for 2"));
  // The same sums for any thread count, to the bit.
  Context one(1);
  auto q = n.positions;
  p = n.positions;
  bs.accumulate(one, {0.3, -0.7}, q);
  bs.accumulate(ctx, {0.3, -0.7}, p);
  EXPECT_EQ(p, q);
}

TEST(Blendshapes, RefinedVerticesTakeTheirParentsMeanOffset) {
  const geom::TriMesh n = patch();
  geom::TriMesh a = n;
  for (auto& v : a.positions) v += Vec3(0.002 * v.y(), 0, 0.001);  // linear in position
  const auto bs = Blendshapes::from_meshes(n, {"a"}, {a}, "test");
  RefineParams rp;
  const RefinedMesh ref = refine_around_wrinkles(n, {furrow()}, rp);
  ASSERT_GT(ref.mesh.positions.size(), n.positions.size());
  const auto rb = bs.refined(ref);
  EXPECT_EQ(rb.num_vertices(), ref.mesh.positions.size());
  Context ctx(1);
  auto p = ref.mesh.positions;
  rb.accumulate(ctx, {1.0}, p);
  // A field linear in position is carried exactly by the midpoint rule.
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& v = ref.mesh.positions[i];
    EXPECT_LT((p[i] - (v + Vec3(0.002 * v.y(), 0, 0.001))).norm(), 1e-10) << i;
  }
}

TEST(Blendshapes, ATargetHoldingAMuscleExpressionWrinklesLikeTheMuscles) {
  Context ctx(2);
  const geom::TriMesh n = patch();
  FaceRigParams fp;
  fp.tissue.enabled = false;
  fp.refine.max_levels = 0;  // the rig's mesh is the base mesh: the target is exact everywhere
  const MuscleSet set = frontalis();
  FaceRig muscles(n, set, {furrow()}, fp);
  MusclePose raise{{3.0}, 0.0, {}};
  FaceState ms;
  muscles.update(ctx, raise, ms);
  geom::TriMesh target = n;
  target.positions = ms.animated;  // the expression sculpted, without the furrow

  FaceRig shapes(n, MuscleSet{}, {furrow()}, fp);
  shapes.set_blendshapes(Blendshapes::from_meshes(n, {"raise"}, {target}, "test"));
  FaceState ss;
  shapes.update(ctx, MusclePose{{}, 0.0, {1.0}}, ss);
  double hmax = 0, dmax = 0;
  for (std::size_t i = 0; i < ss.positions.size(); ++i) {
    hmax = std::max(hmax, std::abs(ms.wrinkle_height[i]));
    dmax = std::max(dmax, std::abs(ss.wrinkle_height[i] - ms.wrinkle_height[i]));
    EXPECT_LT((ss.positions[i] - ms.positions[i]).norm(), 1e-12);
  }
  EXPECT_GT(hmax, 1e-4);  // the furrow is there
  EXPECT_LT(dmax, 1e-12);
  // Half the target: less shrinkage, a shallower furrow (M(s) grows with the shrinkage).
  shapes.update(ctx, MusclePose{{}, 0.0, {0.5}}, ss);
  double half = 0;
  for (double h : ss.wrinkle_height) half = std::max(half, std::abs(h));
  EXPECT_GT(half, 1e-6);
  EXPECT_LT(half, hmax);
  // Weight 0: the neutral face, no furrow (r = 0).
  shapes.update(ctx, MusclePose{{}, 0.0, {0.0}}, ss);
  for (double h : ss.wrinkle_height) EXPECT_EQ(h, 0.0);
  EXPECT_THAT(error_of([&] {
                shapes.update(ctx, MusclePose{{}, 0.0, {1.0, 1.0}}, ss);
              }),
              HasSubstr("2 shape weights and the rig 1 blendshape targets"));

  // With refinement the inserted vertices follow the target linearly (it knows the deformation
  // only at the base vertices), not the smooth muscle field: the strain is piecewise constant per
  // base triangle, so the furrow's amplitude varies along it where the muscles' does not. The
  // furrow is as deep overall (within 15 %) and lies where the muscles put it.
  fp.refine = RefineParams{};
  FaceRig mr(n, set, {furrow()}, fp);
  FaceRig sr(n, MuscleSet{}, {furrow()}, fp);
  sr.set_blendshapes(Blendshapes::from_meshes(n, {"raise"}, {target}, "test"));
  mr.update(ctx, raise, ms);
  sr.update(ctx, MusclePose{{}, 0.0, {1.0}}, ss);
  double mmax = 0, smax = 0, msum = 0, ssum = 0;
  Vec3 mc = Vec3::Zero(), sc = Vec3::Zero();  // depth-weighted centres of the furrow
  for (std::size_t i = 0; i < ss.positions.size(); ++i) {
    const double hm = std::abs(ms.wrinkle_height[i]), hs = std::abs(ss.wrinkle_height[i]);
    mmax = std::max(mmax, hm);
    smax = std::max(smax, hs);
    msum += hm;
    ssum += hs;
    mc += hm * mr.rest_mesh().positions[i];
    sc += hs * sr.rest_mesh().positions[i];
  }
  // Measured: deepest 0.175 vs 0.197 mm, summed depth within 1.2 %; the centres agree within 1 mm.
  EXPECT_GT(mmax, 1e-4);
  EXPECT_NEAR(smax, mmax, 0.15 * mmax);
  EXPECT_NEAR(ssum, msum, 0.05 * msum);
  EXPECT_LT((mc / msum - sc / ssum).norm(), 1e-3);
}

TEST(Blendshapes, TargetsOfAnotherTopologyAreRefused) {
  const geom::TriMesh n = patch();
  geom::TriMesh fewer = n;
  fewer.positions.pop_back();
  EXPECT_THAT(error_of([&] { Blendshapes::from_meshes(n, {"smile"}, {fewer}, "scene: skin[0]"); }),
              AllOf(HasSubstr("scene: skin[0]"), HasSubstr("\"smile\""),
                    HasSubstr(std::to_string(n.positions.size() - 1) + " vertices")));
  // Another mesh with as many vertices and triangles: its triangles use other vertices.
  geom::TriMesh other = n;
  for (auto& f : other.faces) f = Vec3i(f[0], f[2], (f[1] + 97) % int(n.positions.size()));
  EXPECT_THAT(error_of([&] { Blendshapes::from_meshes(n, {"x"}, {other}, "w"); }),
              AllOf(HasSubstr("at triangle"), HasSubstr("not the same topology")));
  // A quad cut along its other diagonal (as the readers do when a target bends it) is the same
  // mesh: accepted.
  geom::TriMesh recut = n;
  {
    const Vec3i a = n.faces[10], b = n.faces[11];
    std::vector<int> quad;
    for (int v : {a[0], a[1], a[2], b[0], b[1], b[2]})
      if (std::find(quad.begin(), quad.end(), v) == quad.end()) quad.push_back(v);
    ASSERT_EQ(quad.size(), 4u);  // the patch's faces come in quad pairs
    recut.faces[10] = Vec3i(quad[1], quad[2], quad[3]);
    recut.faces[11] = Vec3i(quad[1], quad[3], quad[0]);
  }
  EXPECT_EQ(error_of([&] { Blendshapes::from_meshes(n, {"recut"}, {recut}, "w"); }), "");
  EXPECT_THAT(error_of([&] {
                Blendshapes::from_meshes(n, {"a", "a"}, {n, n}, "w");
              }),
              HasSubstr("two blendshapes are named \"a\""));
  geom::TriMesh nan = n;
  nan.positions[3].x() = std::nan("");
  EXPECT_THAT(error_of([&] { Blendshapes::from_meshes(n, {"bad"}, {nan}, "w"); }),
              HasSubstr("non-finite vertex 3"));
}
