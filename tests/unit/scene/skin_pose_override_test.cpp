// Session::set_skin_pose (scripting: Python, the viewer): the set pose replaces the scene's
// expression or track for every frame, equals the pose the scene file would give for the same
// expression, moves the hair riding the skin, keeps the strand cache out of it, and clearing it
// restores the scene's pose bit for bit. Unknown names fail naming the face setup's names.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "follicle/core/error.hpp"
#include "follicle/scene/session.hpp"
#include "scene_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;
using ::testing::HasSubstr;

namespace {

// The default scene (skin rig with hair riding it), one refinement level to keep it quick.
Json quick_default() {
  Json j = scene_json("default");
  j["skin"][0]["refine"]["max_levels"] = 1;
  return j;
}

double max_diff(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, (a[i] - b[i]).norm());
  return d;
}

}  // namespace

TEST(SkinPoseOverride, EqualsTheSceneFileWithThatExpressionAndClearsBitForBit) {
  Context ctx(2);
  Json j = quick_default();
  auto s = Session::from_json(j, scenes_dir(), "default.json", ctx);
  const auto scene_mesh = s.skin_mesh(0, 0)->positions;
  const auto scene_hair = s.hair_strands(0, 0)->points;

  j["skin"][0]["expression"] = "smile";
  j["skin"][0]["weight"] = 0.7;
  auto smiling = Session::from_json(j, scenes_dir(), "smile.json", ctx);
  s.set_skin_pose(0, "smile", 0.7);
  const auto set_mesh = s.skin_mesh(0, 0)->positions;
  EXPECT_EQ(set_mesh, smiling.skin_mesh(0, 0)->positions);
  EXPECT_GT(max_diff(set_mesh, scene_mesh), 1e-4);
  // Every frame has the set pose (a still face).
  EXPECT_EQ(s.skin_mesh(0, 5)->positions, set_mesh);
  // The hair rides the newly posed skin: its roots are on their targets.
  const auto hair = s.hair_strands(0, 0);
  const auto targets = s.hair_root_targets(0, 0);
  for (std::size_t k = 0; k < hair->num_strands(); ++k)
    ASSERT_LT((hair->points[hair->strand_begin(k)].cast<double>() - targets[k]).norm(), 1e-5) << k;

  s.clear_skin_pose(0);
  EXPECT_EQ(s.skin_mesh(0, 0)->positions, scene_mesh);
  EXPECT_EQ(s.hair_strands(0, 0)->points, scene_hair);
}

TEST(SkinPoseOverride, ContractionsAloneAndTheJawStartFromARelaxedFace) {
  Context ctx(2);
  Json j = quick_default();
  j["skin"][0]["expression"] = "neutral";
  j["skin"][0]["contractions"] = Json::object({{"corrugator_L", 0.8}});
  j["skin"][0]["jaw_angle"] = 0.1;
  auto from_file = Session::from_json(j, scenes_dir(), "x.json", ctx);
  auto s = Session::from_json(quick_default(), scenes_dir(), "default.json", ctx);
  s.set_skin_pose(0, "", 0.0, {{"corrugator_L", 0.8}}, 0.1);
  const auto pose = s.skin_pose(0, 3);
  const auto names = s.skin_muscle_names(0);
  ASSERT_EQ(pose.contractions.size(), names.size());
  for (std::size_t m = 0; m < names.size(); ++m)
    EXPECT_EQ(pose.contractions[m], names[m] == "corrugator_L" ? 0.8 : 0.0) << names[m];
  EXPECT_EQ(pose.jaw_angle, 0.1);
  // "neutral" in the shipped setup relaxes every muscle: the same face as the file's.
  EXPECT_EQ(s.skin_mesh(0, 0)->positions, from_file.skin_mesh(0, 0)->positions);
}

TEST(SkinPoseOverride, ReplacesATrackAtEveryFrameAndKeepsTheStrandCacheOut) {
  Context ctx(2);
  Json j = scene_json("hair_expression");
  j["skin"][0]["refine"]["max_levels"] = 1;
  j["animation"]["duration"] = 0.5;
  auto s = Session::from_json(j, scenes_dir(), "hair_expression.json", ctx);
  const auto dir = test::scratch_dir("skin_pose_override_cache");
  s.set_strand_cache(dir);
  s.set_skin_pose(0, "angry", 1.0);
  const auto a = s.skin_mesh(0, 2)->positions;
  EXPECT_EQ(s.skin_mesh(0, 9)->positions, a);
  (void)s.hair_strands(0, 3);
  EXPECT_EQ(s.hair_stats().cache_writes, 0u);
  EXPECT_FALSE(std::filesystem::exists(dir / "cache_key.json"));
  s.clear_skin_pose(0);
  EXPECT_NE(s.skin_mesh(0, 9)->positions, a);  // the track again
}

TEST(SkinPoseOverride, UnknownNamesAndBadValuesFailClearly) {
  Context ctx(1);
  auto s = Session::from_json(quick_default(), scenes_dir(), "default.json", ctx);
  try {
    s.set_skin_pose(0, "smiel", 1.0);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown expression \"smiel\" (did you mean \"smile\"?)"));
    EXPECT_THAT(e.what(), HasSubstr("\"troubled\""));
  }
  EXPECT_THROW(s.set_skin_pose(0, "smile", 1.0, {{"zygomatic", 1.0}}), Error);
  EXPECT_THROW(s.set_skin_pose(0, "smile", std::nan("")), Error);
  EXPECT_THROW(s.set_skin_pose(2, "smile", 1.0), Error);
  EXPECT_THROW(s.clear_skin_pose(1), Error);
  EXPECT_THAT(s.skin_expression_names(0), ::testing::Contains("surprise"));
}
