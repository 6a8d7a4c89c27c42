// The "lcp" scene section (loosely connected particle hair, Bando 2003 ch. 3): strict reading
// with JSON paths, stepping deterministically from frame 0 with state kept between consecutive
// frames, the parting force of Fig. 3.7, splat render items.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "follicle/core/error.hpp"
#include "follicle/scene/session.hpp"
#include "scene_test_util.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;
using ::testing::HasSubstr;

namespace {

// A quick version of a shipped scene: a few hundred particles, a short clip.
Json small_lcp(const std::string& name, int frames = 4) {
  Json j = scene_json(name);
  j["lcp"]["scenario"]["spacing"] = 0.02;
  j["lcp"]["scenario"]["settle_time"] = 0.1;
  if (j["lcp"]["scenario"].value("wind", false)) j["lcp"]["scenario"]["air_spacing"] = 0.04;
  j["animation"]["frames"] = frames;
  j["render"]["width"] = 96;
  j["render"]["height"] = 96;
  return j;
}

std::vector<Vec3f> positions_at(const Json& j, int frame, int threads = 2) {
  Context ctx(threads);
  auto s = Session::from_json(j, scenes_dir(), "x", ctx);
  return s.lcp_particles(frame)->positions;
}

}  // namespace

TEST(LcpScene, ShippedScenesReadAndRoundTrip) {
  for (const char* n : {"lcp_back_hair", "lcp_back_hair_nointeraction", "lcp_shake", "lcp_wind"}) {
    const Scene s = read_scene(scene_json(n), JsonSource{n});
    ASSERT_TRUE(s.lcp) << n;
    ASSERT_TRUE(s.animation) << n;
    const Json w = write_scene(s);
    EXPECT_EQ(write_scene(read_scene(w, JsonSource{n})), w) << n;
  }
  EXPECT_TRUE(read_scene(scene_json("lcp_back_hair"), JsonSource{"a"}).lcp->dynamics.hair_hair);
  EXPECT_FALSE(read_scene(scene_json("lcp_back_hair_nointeraction"), JsonSource{"a"})
                   .lcp->dynamics.hair_hair);
  EXPECT_TRUE(read_scene(scene_json("lcp_shake"), JsonSource{"a"}).lcp->scenario.shake);
  EXPECT_TRUE(read_scene(scene_json("lcp_wind"), JsonSource{"a"}).lcp->scenario.wind);
}

TEST(LcpScene, BadKeysFailWithJsonPath) {
  Json j = scene_json("lcp_back_hair");
  j["lcp"]["dynamics"]["hair_hiar"] = false;
  EXPECT_THAT(read_error(j), HasSubstr("lcp.dynamics.hair_hiar"));
  j = scene_json("lcp_back_hair");
  j["lcp"]["scenario"]["spacing"] = -1.0;
  EXPECT_THAT(read_error(j), HasSubstr("lcp.scenario.spacing"));
  j = scene_json("lcp_back_hair");
  j["lcp"]["render"]["splat"]["self_shadow"] = 3;
  EXPECT_THAT(read_error(j), HasSubstr("lcp.render.splat.self_shadow"));
  j = scene_json("lcp_back_hair");
  j["lcp"]["steps_per_frame"] = 0;
  EXPECT_THAT(read_error(j), HasSubstr("lcp.steps_per_frame"));
  j = scene_json("lcp_back_hair");
  j["lcp"]["part"]["t1"] = 0.0;
  EXPECT_THAT(read_error(j), HasSubstr("part.t1"));
  j = scene_json("lcp_back_hair");
  j["lcp"]["scenario"]["shake"] = true;  // part is for gravity only
  EXPECT_THAT(read_error(j), HasSubstr("lcp"));
}

TEST(LcpScene, ConsecutiveFramesContinueAndAnyOrderGivesTheSameFrame) {
  const Json j = small_lcp("lcp_shake", 4);
  Context ctx(2);
  auto s = Session::from_json(j, scenes_dir(), "x", ctx);
  const int spf = s.scene().lcp->steps_per_frame;
  const auto p0 = s.lcp_particles(0)->positions;
  EXPECT_EQ(s.lcp_steps(), 0u);
  s.lcp_particles(1);
  s.lcp_particles(2);
  EXPECT_EQ(s.lcp_steps(), std::size_t(2 * spf));  // frame 2 continued from frame 1
  const auto p3 = s.lcp_particles(3)->positions;
  EXPECT_EQ(s.lcp_steps(), std::size_t(3 * spf));
  EXPECT_NE(p0, p3);  // the head shakes, the hair moves
  // Going back restarts from frame 0; the result is the same as a fresh session's.
  EXPECT_EQ(s.lcp_particles(1)->positions, positions_at(j, 1));
  EXPECT_EQ(p3, positions_at(j, 3));
}

TEST(LcpScene, IdenticalForOneAndTwoThreads) {
  const Json j = small_lcp("lcp_back_hair", 3);
  EXPECT_EQ(positions_at(j, 2, 1), positions_at(j, 2, 2));
}

TEST(LcpScene, PartingForceSplitsTheHair) {
  // Mean |x| of the free hair grows while the parting force acts (Fig. 3.7 a-b).
  Json j = small_lcp("lcp_back_hair", 16);
  auto spread = [&](const Json& jj) {
    const auto p = positions_at(jj, 15);
    double s = 0;
    for (const auto& x : p) s += std::abs(x.x());
    return s / double(p.size());
  };
  const double with = spread(j);
  j["lcp"].erase("part");
  const double without = spread(j);
  EXPECT_GT(with, without * 1.1);
}

TEST(LcpScene, RenderSceneHasSplatHairAndHead) {
  Context ctx(2);
  auto s = Session::from_json(small_lcp("lcp_back_hair", 2), scenes_dir(), "x", ctx);
  const auto rs = s.render_scene(1);
  ASSERT_EQ(rs.particles.size(), 1u);
  EXPECT_EQ(rs.particles[0].shading, render::ParticleShading::HairSplat);
  const auto& ps = *rs.particles[0].particles;
  EXPECT_GT(ps.size(), 50u);
  EXPECT_EQ(ps.directions.size(), ps.size());
  for (const auto& t : ps.directions) EXPECT_NEAR(t.norm(), 1.0f, 1e-3f);
  ASSERT_EQ(rs.meshes.size(), 1u);  // the head asset, textured
  EXPECT_TRUE(rs.meshes[0].material.albedo_map);
  EXPECT_TRUE(rs.particles[0].splat.self_shadow);
  // The hair grows on the head: every particle lies within the hair length of the mesh's box.
  Eigen::AlignedBox3d box = rs.meshes[0].mesh->bounds();
  box.extend(box.min() - Vec3::Constant(s.scene().lcp->scenario.hair_length));
  box.extend(box.max() + Vec3::Constant(s.scene().lcp->scenario.hair_length));
  for (const auto& p : ps.positions) EXPECT_TRUE(box.contains(p.cast<double>()));
}

TEST(LcpScene, MeshHeadTurnsWithTheShake) {
  Context ctx(2);
  auto s = Session::from_json(small_lcp("lcp_shake", 12), scenes_dir(), "x", ctx);
  const auto rs0 = s.render_scene(0);
  const auto rs = s.render_scene(11);
  ASSERT_EQ(rs.meshes.size(), 1u);
  EXPECT_TRUE(rs0.meshes[0].transform.isApprox(Affine3::Identity()));
  // The head rotates about +y through the pivot: the mesh transform is a rotation about y.
  const Mat3 r = rs.meshes[0].transform.linear();
  EXPECT_GT((r - Mat3::Identity()).norm(), 0.05);
  EXPECT_NEAR((r * Vec3::UnitY() - Vec3::UnitY()).norm(), 0.0, 1e-9);
}

TEST(LcpScene, UnknownMeshNameFailsWithJsonPath) {
  Json j = scene_json("lcp_back_hair");
  j["lcp"]["mesh"] = "haed";
  const std::string e = read_error(j);
  EXPECT_THAT(e, HasSubstr("lcp.mesh"));
  EXPECT_THAT(e, HasSubstr("did you mean \"head\""));
  j = scene_json("lcp_back_hair");
  j["lcp"]["scenario"]["mesh_head"]["curve1"][0] = Json::array({0.0, 0.0, 0.0});
  Context ctx(1);
  auto s = Session::from_json(j, scenes_dir(), "x", ctx);
  try {
    s.lcp_particles(0);
    ADD_FAILURE() << "an open scalp loop was accepted";
  } catch (const Error& err) {
    EXPECT_THAT(std::string(err.what()), HasSubstr("mesh_head.curve0"));
  }
}

TEST(LcpScene, SettlingBeforeFrameZeroCalmsTheFirstFrame) {
  // The largest particle displacement over the first frame is smaller after settling.
  auto first_move = [&](double settle) {
    Json j = small_lcp("lcp_back_hair", 2);
    j["lcp"].erase("part");
    j["lcp"]["scenario"]["settle_time"] = settle;
    const auto a = positions_at(j, 0), b = positions_at(j, 1);
    double m = 0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, double((a[i] - b[i]).norm()));
    return m;
  };
  const double raw = first_move(0.0), settled = first_move(0.6);
  EXPECT_LT(settled, 0.5 * raw) << raw << " " << settled;
}

TEST(LcpScene, StillSceneHasOnlyFrameZero) {
  Context ctx(1);
  Json j = small_lcp("lcp_back_hair", 2);
  j.erase("animation");
  auto s = Session::from_json(j, scenes_dir(), "x", ctx);
  EXPECT_GT(s.lcp_particles(0)->size(), 0u);
  EXPECT_THROW(s.lcp_particles(1), Error);
}
