// The "hand" scene section (MakeHuman hand rig, Bando 2002 §2.7) and wrinkle-map export:
// strict reading with JSON paths, flexion constant or following the track, wrinkles on/off,
// rest/per-frame maps as EXR + PNG of the expected size.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "follicle/core/error.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/scene/session.hpp"
#include "scene_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;
using ::testing::HasSubstr;

namespace {

// A quick version of a shipped hand scene: small fine-wrinkle maps, little refinement.
Json small_hand(const std::string& name, int frames = 0) {
  Json j = scene_json(name);
  j["hand"]["rig"]["fine"]["resolution"] = 128;
  j["hand"]["rig"]["refine"]["max_levels"] = 1;
  j["render"]["width"] = 96;
  j["render"]["height"] = 96;
  if (frames > 0) j["animation"]["frames"] = frames;
  return j;
}

}  // namespace

TEST(HandScene, ShippedScenesReadAndRoundTrip) {
  for (const char* n : {"hand_rest", "hand_rest_nowrinkles", "hand_flex", "hand_flex_nowrinkles",
                        "hand_flexion_anim"}) {
    const Scene s = read_scene(scene_json(n), JsonSource{n});
    ASSERT_TRUE(s.hand) << n;
    const Json w = write_scene(s);
    EXPECT_EQ(write_scene(read_scene(w, JsonSource{n})), w) << n;
  }
  EXPECT_TRUE(read_scene(scene_json("hand_flexion_anim"), JsonSource{"a"}).animation);
  EXPECT_FALSE(read_scene(scene_json("hand_flex"), JsonSource{"a"}).hand->wrinkles == false);
  EXPECT_FALSE(read_scene(scene_json("hand_flex_nowrinkles"), JsonSource{"a"}).hand->wrinkles);
}

TEST(HandScene, BadKeysFailWithJsonPath) {
  Json j = scene_json("hand_rest");
  j["hand"]["rig"]["fine"]["resolutoin"] = 64;
  EXPECT_THAT(read_error(j), HasSubstr("hand.rig.fine.resolutoin"));
  j = scene_json("hand_rest");
  j["hand"]["flexion"] = 1.5;
  EXPECT_THAT(read_error(j), HasSubstr("hand.flexion"));
  j = scene_json("hand_rest");
  j["hand"]["wrinkles"] = "yes";
  EXPECT_THAT(read_error(j), HasSubstr("hand.wrinkles"));
  j = scene_json("hand_rest");
  j["hand"]["rig"]["joint_r"] = 2.0;
  EXPECT_THAT(read_error(j), HasSubstr("hand.rig.joint_r"));
}

TEST(HandScene, MissingMakeHumanFolderFailsCleanly) {
  Context ctx(1);
  Json j = small_hand("hand_rest");
  j["hand"]["makehuman"] = "no_such_folder";
  try {
    Session::from_json(j, scenes_dir(), "x.json", ctx);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("hand.makehuman"));
  }
}

TEST(HandScene, FlexionFollowsTrackAndWrinklesRespond) {
  Context ctx(2);
  auto s = Session::from_json(small_hand("hand_flexion_anim", 36), scenes_dir(), "anim", ctx);
  const auto rest = s.hand_frame(0);
  EXPECT_EQ(s.hand_flexion(0), 0.0);
  const int mid = 18;  // 0.75 s at 24 fps, track_speed 2/3 -> half way up
  EXPECT_GT(s.hand_flexion(mid), 0.2);
  EXPECT_LE(s.hand_flexion(mid), 1.0);
  const auto flexed = s.hand_frame(mid);
  ASSERT_TRUE(rest.height_m && flexed.height_m);
  ASSERT_EQ(rest.mesh->positions.size(), flexed.mesh->positions.size());
  // The fingers move and the fine relief is modulated differently.
  double moved = 0, dh = 0;
  for (std::size_t i = 0; i < rest.mesh->positions.size(); ++i)
    moved = std::max(moved, (rest.mesh->positions[i] - flexed.mesh->positions[i]).norm());
  for (std::size_t i = 0; i < rest.height_m->storage().size(); ++i)
    dh =
        std::max(dh, double(std::abs(rest.height_m->storage()[i] - flexed.height_m->storage()[i])));
  EXPECT_GT(moved, 0.01);  // fingertips move centimetres
  EXPECT_GT(dh, 1e-6);     // micrometres of relief change
  // The render scene holds the bump-mapped hand.
  const auto rs = s.render_scene(mid);
  ASSERT_EQ(rs.meshes.size(), 1u);
  EXPECT_TRUE(rs.meshes[0].material.height_map);
  EXPECT_GT(rs.meshes[0].material.bump_strength, 0.0);
  // Same frame again (any order): identical.
  const auto again = s.hand_frame(mid);
  EXPECT_EQ(again.mesh->positions, flexed.mesh->positions);
}

TEST(HandScene, WithoutWrinklesThereIsNoHeightMap) {
  Context ctx(2);
  auto s = Session::from_json(small_hand("hand_flex_nowrinkles"), scenes_dir(), "nw", ctx);
  EXPECT_DOUBLE_EQ(s.hand_flexion(0), 0.8);
  const auto rs = s.render_scene(0);
  ASSERT_EQ(rs.meshes.size(), 1u);
  EXPECT_FALSE(rs.meshes[0].material.height_map);
}

TEST(HandScene, ExportMapsWritesReadableImagesOfTheMapSize) {
  Context ctx(2);
  auto s = Session::from_json(small_hand("hand_flexion_anim", 20), scenes_dir(), "anim", ctx);
  const auto dir = test::scratch_dir("hand_maps");
  EXPECT_EQ(s.export_wrinkle_maps(dir, -1), std::vector<std::string>{"hand_rest"});
  EXPECT_EQ(s.export_wrinkle_maps(dir, 15), std::vector<std::string>{"hand_frame_0015"});
  for (const char* stem : {"hand_rest", "hand_frame_0015"}) {
    for (const char* kind : {"height", "displacement"}) {
      const auto base = dir / (std::string(stem) + "_" + kind);
      const auto exr = image::read_exr_gray(base.string() + ".exr");
      EXPECT_EQ(exr.width(), 128);
      EXPECT_EQ(exr.height(), 128);
      const auto png = image::read_png_rgba(base.string() + ".png");
      EXPECT_EQ(png.width(), 128);
    }
    const auto n = image::read_exr_rgba(dir / (std::string(stem) + "_normal.exr"));
    EXPECT_EQ(n.width(), 128);
    EXPECT_EQ(image::read_png_rgba(dir / (std::string(stem) + "_normal.png")).height(), 128);
  }
  // The flexed frame's relief differs from the rest relief.
  const auto a = image::read_exr_gray(dir / "hand_rest_height.exr");
  const auto b = image::read_exr_gray(dir / "hand_frame_0015_height.exr");
  double diff = 0;
  for (std::size_t i = 0; i < a.storage().size(); ++i)
    diff = std::max(diff, double(std::abs(a.storage()[i] - b.storage()[i])));
  EXPECT_GT(diff, 1e-3);
  EXPECT_THROW(s.export_wrinkle_maps(dir, 20), Error);  // past the last frame
}

TEST(HandScene, ExportMapsNeedsAHand) {
  Context ctx(1);
  auto s = Session::from_json(scene_json("default"), scenes_dir(), "default", ctx);
  EXPECT_THROW(s.export_wrinkle_maps(test::scratch_dir("nomaps"), -1), Error);
}
