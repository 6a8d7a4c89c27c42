// Blendshape faces wrinkle too (issue 21 item 5): the ICT FaceKit neutral head (another scan,
// topology and unit than ours, no face-setup file) animated by its brow-raise targets gets
// forehead furrows from the shrinkage of that deformation, where the brows compress the forehead,
// and none on the neutral face; the blend reproduces the target; a track interpolates the
// weights; targets of another topology, unknown weight names and missing files fail with the
// JSON path. Needs ../shared/data/ict-facekit (skips without it).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/scene/session.hpp"
#include "scene_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;
using ::testing::AllOf;
using ::testing::HasSubstr;

namespace {

std::filesystem::path ict(const std::string& file) {
  return test::shared_data_dir() / "ict-facekit" / file;
}

const char* kTargets[] = {"browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R"};

// Two horizontal forehead lines across the face (ICT: cm, y up, the face looks along +z; the
// inner brows sit at y ~ 5.3 cm, x ~ +-2 cm): 9 points each, on the front-most skin at (x, y).
Json forehead_lines(const geom::TriMesh& head) {
  Json lines = Json::array();
  int k = 0;
  for (double y : {0.074, 0.086}) {
    Json pts = Json::array();
    for (int i = 0; i < 9; ++i) {
      const double x = -0.035 + 0.07 * i / 8.0;
      Vec3 best(0, 0, -1e9);
      for (std::size_t v = 0; v < 9409; ++v) {  // the face area (ICT README)
        const Vec3& p = head.positions[v];
        if (std::abs(p.x() - x) < 0.004 && std::abs(p.y() - y) < 0.004 && p.z() > best.z())
          best = p;
      }
      pts.push_back({x, y, best.z()});
    }
    lines.push_back({{"name", "forehead_" + std::to_string(k++)},
                     {"points", pts},
                     {"depth", 0.0015},
                     {"width", 0.003}});
  }
  return lines;
}

Json ict_scene() {
  static const geom::TriMesh head =
      geom::load_mesh(ict("generic_neutral_mesh.obj"), LengthUnit::cm);
  Json j = scene_json("skin_smile");
  j["assets"]["meshes"][0] = {
      {"name", "ict"}, {"path", ict("generic_neutral_mesh.obj").string()}, {"units", "cm"}};
  Json shapes = Json::array();
  Json weights = Json::object();
  for (const char* t : kTargets) {
    shapes.push_back({{"name", t}, {"path", ict(std::string(t) + ".obj").string()}});
    weights[t] = 1.0;
  }
  j["skin"][0] = {{"mesh", "ict"},          {"blendshapes", shapes},
                  {"shapes", weights},      {"add_surface_wrinkles", forehead_lines(head)},
                  {"albedo", "skin_color"}, {"refine", {{"max_levels", 1}}}};
  return j;
}

}  // namespace

TEST(SkinBlendshape, BrowRaiseFurrowsTheForeheadOfTheIctHead) {
  FOLLICLE_REQUIRE_SHARED("ict-facekit/browInnerUp_L.obj");
  Context ctx(2);
  const Json j = ict_scene();
  Json flat = j;
  flat["skin"][0]["wrinkles"] = false;
  Json neutral = j;
  neutral["skin"][0]["shapes"] = Json::object();
  auto s = Session::from_json(j, scenes_dir(), "ict.json", ctx);
  auto sf = Session::from_json(flat, scenes_dir(), "flat.json", ctx);
  auto sn = Session::from_json(neutral, scenes_dir(), "neutral.json", ctx);
  const auto with = s.skin_mesh(0, 0);
  const auto without = sf.skin_mesh(0, 0);
  const auto rest = sn.skin_mesh(0, 0);
  const auto& rig = s.face_rig(0);
  ASSERT_EQ(rig.blendshapes().size(), 4u);
  ASSERT_EQ(rig.wrinkle_layer().num_wrinkles(), 2u);
  // The furrows: deepest on the forehead, between and above the brows.
  double deepest = 0;
  Vec3 at = Vec3::Zero();
  for (std::size_t i = 0; i < with->positions.size(); ++i) {
    const double d = (with->positions[i] - without->positions[i]).norm();
    if (d > deepest) {
      deepest = d;
      at = rig.rest_mesh().positions[i];
    }
  }
  EXPECT_GT(deepest, 3e-4);
  EXPECT_LT(deepest, 3e-3);
  EXPECT_GT(at.y(), 0.065);
  EXPECT_LT(at.y(), 0.095);
  EXPECT_LT(std::abs(at.x()), 0.04);
  // The neutral face has none (r = 0) and is the mesh itself (no muscles, no shapes).
  for (std::size_t i = 0; i < rest->positions.size(); ++i)
    ASSERT_LT((rest->positions[i] - rig.rest_mesh().positions[i]).norm(), 1e-12) << i;
}

TEST(SkinBlendshape, TheBlendIsTheTargetAndTracksInterpolateTheWeights) {
  FOLLICLE_REQUIRE_SHARED("ict-facekit/browInnerUp_L.obj");
  Context ctx(1);
  Json j = ict_scene();
  j["skin"][0]["shapes"] = {{"browOuterUp_L", 1.0}};
  j["skin"][0]["wrinkles"] = false;
  j["skin"][0]["tissue"] = {{"enabled", false}};
  auto s = Session::from_json(j, scenes_dir(), "ict.json", ctx);
  const auto m = s.skin_mesh(0, 0);
  const auto target = geom::load_mesh(ict("browOuterUp_L.obj"), LengthUnit::cm);
  double gap = 0;
  for (std::size_t i = 0; i < target.positions.size(); ++i)
    gap = std::max(gap, (m->positions[i] - target.positions[i]).norm());
  EXPECT_LT(gap, 1e-12);

  Json t = ict_scene();
  t["animation"] = {{"fps", 10}, {"duration", 1.0}};
  t["skin"][0]["interp"] = "linear";
  t["skin"][0]["track"] = {{{"t", 0.0}}, {{"t", 1.0}, {"shapes", {{"browInnerUp_R", 0.8}}}}};
  auto st = Session::from_json(t, scenes_dir(), "track.json", ctx);
  const auto mid = st.skin_pose(0, 5);
  ASSERT_EQ(mid.shape_weights.size(), 4u);
  EXPECT_NEAR(mid.shape_weights[1], 0.4, 1e-12);
  EXPECT_EQ(mid.shape_weights[0], 0.0);
  EXPECT_TRUE(st.skin_pose(0, 0).contractions.empty());  // no face-setup file: no muscles
}

TEST(SkinBlendshape, BadTargetsAndNamesFailWithTheJsonPath) {
  FOLLICLE_REQUIRE_SHARED("ict-facekit/browInnerUp_L.obj");
  Json j = ict_scene();
  j["skin"][0]["blendshapes"][1]["path"] =
      (test::source_dir() / "data/meshes/lee_perry_smith/head.obj").string();
  EXPECT_THAT(rig_error(j), AllOf(HasSubstr("skin[0]"), HasSubstr("\"browInnerUp_R\""),
                                  HasSubstr("26719"), HasSubstr("same mesh")));
  Json missing = ict_scene();
  missing["skin"][0]["blendshapes"][0]["path"] = "nowhere.obj";
  EXPECT_THAT(rig_error(missing),
              AllOf(HasSubstr("skin[0].blendshapes[0].path"), HasSubstr("not found")));
  Json typo = ict_scene();
  typo["skin"][0]["shapes"] = {{"browInnerUp_l", 1.0}};
  EXPECT_THAT(read_error(typo), AllOf(HasSubstr("skin[0].shapes.browInnerUp_l"),
                                      HasSubstr("did you mean \"browInnerUp_L\"")));
  Json track = ict_scene();
  track["animation"] = {{"fps", 10}, {"duration", 1.0}};
  track["skin"][0]["track"] = {{{"t", 0.0}, {"shapes", {{"smile", 1.0}}}}};
  EXPECT_THAT(read_error(track), HasSubstr("skin[0].track[0].shapes.smile"));
  Json dup = ict_scene();
  dup["skin"][0]["blendshapes"][1]["name"] = "browInnerUp_L";
  EXPECT_THAT(read_error(dup),
              AllOf(HasSubstr("skin[0].blendshapes[1].name"), HasSubstr("two targets")));
  Json none = ict_scene();
  none["skin"][0].erase("blendshapes");
  none["skin"][0].erase("shapes");
  EXPECT_THAT(read_error(none), AllOf(HasSubstr("skin[0].muscles"), HasSubstr("blendshape")));
}
