// The shipped skin scenes (data/scenes/skin_*.json, issue 4 item 7) and the "skin" section on the
// default head: the scenes read strictly and round-trip, each *_nowrinkles twin differs only in
// "wrinkles"; with wrinkles the deformed mesh differs from the one without only near the furrows
// of the face-setup file, and only where the skin is compressed (r = 0: a neutral face has no
// furrows; r > 0: it has); the contraction track interpolates between its keys; bad skin keys
// fail with the JSON path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/skin/skin_json.hpp"
#include "scene_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;
using ::testing::HasSubstr;

namespace {

// Errors that need the face-setup file (expression, wrinkle and muscle names): resolving the pose.
std::string pose_error(const Json& j) {
  Context ctx(1);
  try {
    auto s = Session::from_json(j, scenes_dir(), "x.json", ctx);
    (void)s.skin_pose(0, 0);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// A quicker rig: one refinement level (the wrinkle geometry is the same, just coarser).
Json quick(Json j) {
  j["skin"][0]["refine"]["max_levels"] = 1;
  return j;
}

geom::TriMesh skin_mesh_of(const Json& j, const Context& ctx) {
  auto s = Session::from_json(j, scenes_dir(), "test", ctx);
  return *s.skin_mesh(0, 0);
}

// One texture coordinate per position vertex (the first corner that uses it).
std::vector<Vec2> vertex_uvs(const geom::TriMesh& m) {
  std::vector<Vec2> uv(m.positions.size(), Vec2(-1, -1));
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k)
      uv[std::size_t(m.faces[f][k])] = m.uvs[std::size_t(m.uv_faces[f][k])];
  return uv;
}

Vec2 bezier(const std::array<Vec2, 4>& c, double t) {
  const double s = 1 - t;
  return s * s * s * c[0] + 3 * s * s * t * c[1] + 3 * s * t * t * c[2] + t * t * t * c[3];
}

double uv_distance_to_wrinkles(const Vec2& uv, const std::vector<skin::LargeWrinkle>& ws) {
  double best = 1e9;
  for (const auto& w : ws)
    for (int i = 0; i <= 200; ++i)
      best = std::min(best, (bezier(w.control, i / 200.0) - uv).norm());
  return best;
}

double max_displacement(const geom::TriMesh& a, const geom::TriMesh& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    d = std::max(d, (a.positions[i] - b.positions[i]).norm());
  return d;
}

const char* kSkinScenes[] = {"skin_thinking", "skin_thinking_nowrinkles",
                             "skin_smile",    "skin_smile_nowrinkles",
                             "skin_troubled", "skin_troubled_nowrinkles",
                             "skin_angry",    "skin_angry_nowrinkles",
                             "skin_aged",     "skin_track",
                             "default",       "skin_fine_forehead"};

}  // namespace

TEST(SkinScene, ShippedScenesReadAndRoundTrip) {
  for (const char* n : kSkinScenes) {
    const Scene s = read_scene(scene_json(n), JsonSource{n});
    ASSERT_EQ(s.skin.size(), 1u) << n;
    EXPECT_EQ(s.skin[0].mesh, "head") << n;
    EXPECT_FALSE(s.description.empty()) << n;
    const Json w = write_scene(s);
    EXPECT_EQ(write_scene(read_scene(w, JsonSource{n})), w) << n;
  }
  EXPECT_TRUE(read_scene(scene_json("skin_track"), JsonSource{"t"}).animation);
  EXPECT_GT(read_scene(scene_json("skin_aged"), JsonSource{"a"}).skin[0].wrinkle_r.value_or(0), 0);
  EXPECT_TRUE(read_scene(scene_json("default"), JsonSource{"d"}).skin[0].wrinkles);
}

TEST(SkinScene, NoWrinklesTwinsDifferOnlyInTheWrinkleSwitch) {
  for (const char* e : {"thinking", "smile", "troubled", "angry"}) {
    const std::string name = std::string("skin_") + e;
    Scene with = read_scene(scene_json(name), JsonSource{name});
    Scene without = read_scene(scene_json(name + "_nowrinkles"), JsonSource{name});
    EXPECT_TRUE(with.skin[0].wrinkles) << e;
    EXPECT_FALSE(without.skin[0].wrinkles) << e;
    without.skin[0].wrinkles = true;
    without.description = with.description;
    without.outputs = with.outputs;
    EXPECT_EQ(write_scene(without), write_scene(with)) << e;
  }
}

TEST(SkinScene, WrinklesMoveTheSkinOnlyNearTheFurrows) {
  Context ctx(2);
  const Json j = quick(scene_json("skin_troubled"));
  Json jn = j;
  jn["skin"][0]["wrinkles"] = false;
  const auto with = skin_mesh_of(j, ctx);
  const auto without = skin_mesh_of(jn, ctx);
  ASSERT_EQ(with.positions.size(), without.positions.size());
  ASSERT_TRUE(with.has_uvs());
  const auto setup =
      skin::load_face_setup(test::source_dir() / "data" / "muscles" / "lee_perry_smith.json");
  const auto uv = vertex_uvs(with);
  std::size_t moved = 0;
  double far_max = 0, deepest = 0;
  for (std::size_t i = 0; i < with.positions.size(); ++i) {
    const double d = (with.positions[i] - without.positions[i]).norm();
    deepest = std::max(deepest, d);
    if (d > 1e-5) ++moved;
    if (uv_distance_to_wrinkles(uv[i], setup.wrinkles) > 0.06) far_max = std::max(far_max, d);
  }
  EXPECT_GT(deepest, 5e-4) << "troubled: the forehead and glabella furrows are visible";
  // The furrow profile has a smooth tail: far from every furrow the skin moves by < 1% of the
  // deepest furrow (a few micrometres).
  EXPECT_LT(far_max, 0.01 * deepest) << "skin away from every furrow must not move";
  EXPECT_LT(double(moved) / double(with.positions.size()), 0.3);
}

TEST(SkinScene, FurrowsAppearOnlyWhereTheSkinCompresses) {
  Context ctx(2);
  // r = 0 (the face-setup file): a neutral face has no furrows at all.
  Json neutral = quick(scene_json("skin_troubled"));
  neutral["skin"][0]["expression"] = "neutral";
  Json flat = neutral;
  flat["skin"][0]["wrinkles"] = false;
  EXPECT_LT(max_displacement(skin_mesh_of(neutral, ctx), skin_mesh_of(flat, ctx)), 1e-9);
  // r > 0 (aged skin): the same neutral face shows its furrows at rest.
  Json aged = neutral;
  aged["skin"][0]["wrinkle_r"] = 0.3;
  EXPECT_GT(max_displacement(skin_mesh_of(aged, ctx), skin_mesh_of(flat, ctx)), 1e-4);
}

TEST(SkinScene, TrackInterpolatesBetweenItsKeys) {
  Context ctx(1);
  auto s = Session::load(scenes_dir() / "skin_track.json", ctx);
  const auto setup =
      skin::load_face_setup(test::source_dir() / "data" / "muscles" / "lee_perry_smith.json");
  const auto& set = setup.muscles;
  auto expr = [&](const std::string& name) {
    for (const auto& e : set.expressions)
      if (e.name == name) return skin::pose_from_expression(set, e, 1.0);
    ADD_FAILURE() << "no expression " << name;
    return skin::MusclePose{};
  };
  const auto& track = s.scene().skin[0].track;
  ASSERT_GE(track.size(), 3u);
  const auto frame_at = [&](double t) { return int(std::lround(t * s.scene().animation->fps)); };
  const std::size_t fi = std::size_t(set.muscle_index("frontalis_inner_L"));
  const std::size_t co = std::size_t(set.muscle_index("corrugator_L"));
  // First key: neutral; last frame: angry; a frame between the neutral and surprise keys lies
  // strictly between them.
  const auto p0 = s.skin_pose(0, 0);
  for (double k : p0.contractions) EXPECT_NEAR(k, 0.0, 1e-12);
  // At a key time the pose is the key's (the first "angry" key; its time is on a frame).
  const auto angry = expr("angry");
  double t_angry = -1;
  for (const auto& key : track)
    if (key.expression == "angry" && t_angry < 0) t_angry = key.t;
  ASSERT_GT(t_angry, 0.0);
  ASSERT_NEAR(t_angry * s.scene().animation->fps, double(frame_at(t_angry)), 1e-9);
  const auto at_angry = s.skin_pose(0, frame_at(t_angry));
  for (std::size_t m = 0; m < angry.contractions.size(); ++m)
    EXPECT_NEAR(at_angry.contractions[m], angry.contractions[m], 1e-9) << m;
  // The last frame holds the anger (within the smooth spline's small overshoot after the
  // change of pose: < 1e-3 in contractions of 0.03 .. 0.32).
  const auto last = s.skin_pose(0, s.frame_count() - 1);
  for (std::size_t m = 0; m < angry.contractions.size(); ++m)
    EXPECT_NEAR(last.contractions[m], angry.contractions[m], 1e-3) << m;
  const auto surprise = expr("surprise");
  ASSERT_GT(surprise.contractions[fi], 0.0);
  double t_neutral = -1, t_surprise = -1;
  for (std::size_t k = 0; k + 1 < track.size(); ++k)
    if (track[k].expression == "neutral" && track[k + 1].expression == "surprise") {
      t_neutral = track[k].t;
      t_surprise = track[k + 1].t;
    }
  ASSERT_GE(t_neutral, 0.0) << "the track goes from neutral to surprise";
  const auto mid = s.skin_pose(0, frame_at(0.5 * (t_neutral + t_surprise)));
  EXPECT_GT(mid.contractions[fi], 0.05 * surprise.contractions[fi]);
  EXPECT_LT(mid.contractions[fi], 0.95 * surprise.contractions[fi]);
  EXPECT_NEAR(mid.contractions[co], 0.0, 1e-12);  // the corrugator waits for the anger
  const auto at_surprise = s.skin_pose(0, frame_at(t_surprise));
  EXPECT_NEAR(at_surprise.contractions[fi], surprise.contractions[fi],
              0.02 * surprise.contractions[fi]);
}

TEST(SkinScene, BadSkinKeysFailWithJsonPath) {
  Json j = scene_json("skin_angry");
  j["skin"][0]["expression"] = "angery";
  std::string e = pose_error(j);
  EXPECT_THAT(e, HasSubstr("skin[0].expression"));
  EXPECT_THAT(e, HasSubstr("angry"));  // did you mean

  j = scene_json("skin_angry");
  j["skin"][0]["wrinkle_overrides"] = Json::array({{{"name", "forehead_9"}, {"depth", 0.01}}});
  EXPECT_THAT(pose_error(j), HasSubstr("skin[0].wrinkle_overrides[0].name"));

  j = scene_json("skin_angry");
  j["skin"][0]["contractions"] = {{"frontalis_middle_L", 0.02}};
  EXPECT_THAT(pose_error(j), HasSubstr("skin[0].contractions.frontalis_middle_L"));

  j = scene_json("skin_track");
  j["skin"][0]["track"][2]["expression"] = "suprise";
  EXPECT_THAT(pose_error(j), HasSubstr("skin[0].track[2].expression"));

  j = scene_json("skin_track");
  j.erase("animation");
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].track"));

  j = scene_json("skin_angry");
  j["skin"][0]["wrinkel_r"] = 0.2;
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].wrinkel_r"));

  j = scene_json("skin_angry");
  j["skin"][0]["mesh"] = "haed";
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].mesh"));
}
