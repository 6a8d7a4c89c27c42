// The "hair" and "animation" scene sections: strict reading (JSON paths in errors), round trips,
// hair in the Session (styled on the head, dynamics deterministic from frame 0, strand cache).
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

// A small, quick version of a shipped scene (few strands, short clip).
Session small_session(const std::string& name, const Context& ctx, double density = 0.05,
                      int frames = 0) {
  Json j = scene_json(name);
  j["hair"][0]["density_scale"] = density;
  if (frames > 0 && j.contains("animation")) j["animation"]["frames"] = frames;
  return Session::from_json(j, scenes_dir(), name, ctx);
}

}  // namespace

TEST(HairScene, ShippedScenesReadAndRoundTrip) {
  for (const char* n : {"anjyo_bob", "anjyo_swept_back", "anjyo_ponytail", "anjyo_short_cut",
                        "anjyo_wind", "anjyo_shake"}) {
    const Scene s = read_scene(scene_json(n), JsonSource{n});
    ASSERT_EQ(s.hair.size(), 1u) << n;
    const Json w = write_scene(s);
    const Scene s2 = read_scene(w, JsonSource{n});
    EXPECT_EQ(write_scene(s2), w) << n;
  }
}

TEST(HairScene, StyleIsAPresetNameOrAnObject) {
  Json j = scene_json("anjyo_bob");
  j["hair"][0]["style"] = {{"name", "mine"},
                           {"parts", {{{"name", "a"}, {"pores", {{{"length", 0.1}}}}}}}};
  const Scene s = read_scene(j, JsonSource{"x.json"});
  ASSERT_TRUE(s.hair[0].style.custom);
  EXPECT_EQ(s.hair[0].style.custom->name, "mine");
  EXPECT_DOUBLE_EQ(s.hair[0].style.custom->parts[0].pores[0].length, 0.1);
  // The object form is written back as an object and reads back the same.
  const Json w = write_scene(s);
  EXPECT_TRUE(w["hair"][0]["style"].is_object());
  EXPECT_EQ(write_scene(read_scene(w, JsonSource{})), w);
  // A preset stays a name.
  EXPECT_EQ(write_scene(read_scene(scene_json("anjyo_bob"), {}))["hair"][0]["style"], "bob");
}

TEST(HairScene, BadKeysNameTheJsonPath) {
  Json j = scene_json("anjyo_bob");
  j["hair"][0]["dynamics"]["dtt"] = 0.01;
  EXPECT_THAT(read_error(j), HasSubstr("hair[0].dynamics"));
  EXPECT_THAT(read_error(j), HasSubstr("\"dt\""));

  j = scene_json("anjyo_bob");
  j["hair"][0]["style"] = "bobb";
  EXPECT_THAT(read_error(j), HasSubstr("hair[0].style"));
  EXPECT_THAT(read_error(j), HasSubstr("did you mean \"bob\""));

  j = scene_json("anjyo_bob");
  j["hair"][0]["style"] = 3;
  EXPECT_THAT(read_error(j), HasSubstr("hair[0].style"));

  j = scene_json("anjyo_bob");
  j["hair"][0]["style"] = {{"parts", {{{"pores", {{{"density", -1.0}}}}}}}};
  EXPECT_THAT(read_error(j), HasSubstr("hair[0].style.parts[0].pores[0].density"));

  j = scene_json("anjyo_bob");
  j["hair"][0]["mesh"] = "hed";
  EXPECT_THAT(read_error(j), HasSubstr("hair[0].mesh"));
  EXPECT_THAT(read_error(j), HasSubstr("did you mean \"head\""));

  j = scene_json("anjyo_bob");
  j["hair"][0].erase("mesh");
  EXPECT_THAT(read_error(j), HasSubstr("missing required key \"mesh\""));

  j = scene_json("anjyo_bob");
  j["hair"][0]["shading"]["ks"] = "shiny";
  EXPECT_THAT(read_error(j), HasSubstr("hair[0].shading.ks"));

  j = scene_json("anjyo_wind");
  j["animation"]["wind"]["gust"]["swtch_time"] = 1;
  EXPECT_THAT(read_error(j), HasSubstr("animation.wind.gust"));

  j = scene_json("anjyo_shake");
  j["animation"]["head_motion"]["kind"] = "nod";
  EXPECT_THAT(read_error(j), HasSubstr("animation.head_motion.kind"));

  j = scene_json("anjyo_shake");
  j["animation"]["head_motion"]["t1"] = 0.1;
  EXPECT_THAT(read_error(j), HasSubstr("animation.head_motion.t1"));
}

TEST(HairScene, StillHairIsStyledOnTheHead) {
  Context ctx(2);
  auto s = small_session("anjyo_bob", ctx);
  EXPECT_EQ(s.frame_count(), 1);
  const auto h = s.hair_strands(0, 0);
  ASSERT_GT(h->num_strands(), 50u);
  h->check("hair");
  // Roots are on the head: within the mesh bounds.
  auto box = s.mesh(0)->bounds();
  const Vec3 lo = box.min() * 1.0, hi = box.max();
  for (std::size_t i = 0; i < h->num_strands(); ++i) {
    const Vec3 r = h->points[h->strand_begin(i)].cast<double>();
    EXPECT_TRUE((r.array() >= lo.array() - 1e-3).all() && (r.array() <= hi.array() + 1e-3).all());
  }
  // Still scenes: every frame shows the same hair, styled once.
  EXPECT_EQ(s.hair_strands(0, 3), h);
  EXPECT_EQ(s.hair_stats().builds, 1u);
  const auto rs = s.render_scene(0);
  ASSERT_EQ(rs.strands.size(), 1u);
  EXPECT_EQ(rs.strands[0].material.shading, render::StrandShading::VertexColor);
  EXPECT_EQ(rs.strands[0].strands->color.size(), h->num_points());
}

TEST(HairScene, DynamicsAreDeterministicFromFrameZero) {
  Context c1(1), c2(2);
  auto a = small_session("anjyo_shake", c1, 0.03, 12);
  auto b = small_session("anjyo_shake", c2, 0.03, 12);
  std::shared_ptr<const geom::StrandSet> seq;
  for (int f = 0; f <= 10; ++f) seq = a.hair_strands(0, f);  // consecutive frames
  const auto direct = b.hair_strands(0, 10);                 // straight to frame 10
  EXPECT_TRUE(seq->points == direct->points);
  EXPECT_EQ(a.hair_stats().steps, b.hair_stats().steps);
  // Consecutive frames continued the state: no more steps than one run to frame 10.
  EXPECT_EQ(a.hair_stats().steps, uint64_t(std::llround(10.0 / 24.0 * 120.0)));
  // Going back re-simulates from frame 0 and gives the same result again.
  const auto again = a.hair_strands(0, 4);
  const auto fresh = small_session("anjyo_shake", c1, 0.03, 12).hair_strands(0, 4);
  EXPECT_TRUE(again->points == fresh->points);
  // The hair moved, and the head mesh follows the shake.
  EXPECT_FALSE(direct->points == a.hair_strands(0, 0)->points);
  const auto rs = b.render_scene(10);
  EXPECT_FALSE(rs.meshes[0].transform.matrix().isApprox(Affine3::Identity().matrix()));
}

TEST(HairScene, StrandCacheSkipsTheSimulation) {
  Context ctx(2);
  const auto dir = test::scratch_dir("hair_cache");
  std::filesystem::remove_all(dir);
  auto a = small_session("anjyo_wind", ctx, 0.03, 6);
  a.set_strand_cache(dir);
  const auto fa = a.hair_strands(0, 5);
  EXPECT_GT(a.hair_stats().steps, 0u);
  EXPECT_EQ(a.hair_stats().cache_writes, 6u);  // frames 0..5

  auto b = small_session("anjyo_wind", ctx, 0.03, 6);
  b.set_strand_cache(dir);
  for (int f = 0; f <= 5; ++f) {
    const auto fb = b.hair_strands(0, f);
    if (f == 5) {
      EXPECT_TRUE(fb->points == fa->points);
    }
  }
  EXPECT_EQ(b.hair_stats().steps, 0u);
  EXPECT_EQ(b.hair_stats().cache_reads, 6u);

  // Other settings: the old cache is discarded and the hair simulated again.
  auto c = small_session("anjyo_wind", ctx, 0.03, 6);
  c.scene().hair[0].dynamics.damping = 9.0;
  c.set_strand_cache(dir);
  const auto fc = c.hair_strands(0, 5);
  EXPECT_GT(c.hair_stats().steps, 0u);
  EXPECT_FALSE(fc->points == fa->points);
}
