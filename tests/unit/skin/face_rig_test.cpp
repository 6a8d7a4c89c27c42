#include "follicle/skin/face_rig.hpp"

#include <gtest/gtest.h>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/skin/forehead_validation.hpp"
#include "follicle/skin/skin_color_bando2002.hpp"
#include "follicle/skin/skin_json.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::skin;

namespace {
// A forehead patch with a frontalis-like muscle pulling up and one furrow.
struct Rig {
  geom::TriMesh mesh = make_cylinder_patch(0.08, 0.06, 0.08, 0.003);
  MuscleSet set;
  std::vector<LargeWrinkle> wr;
  Rig() {
    LinearMuscle m;
    m.name = "frontalis";
    m.origin = Vec3(0, 0.06, 0.075);
    m.insertion = Vec3(0, -0.02, 0.08);
    m.falloff_start = 0.005;
    m.falloff_end = 0.09;
    m.zone = 0.6;
    set.linear.push_back(m);
    Expression e;
    e.name = "raise";
    e.contractions["frontalis"] = 3.0;
    set.expressions.push_back(e);
    LargeWrinkle w;
    w.control = {Vec2(0.2, 0.4), Vec2(0.4, 0.42), Vec2(0.6, 0.42), Vec2(0.8, 0.4)};
    w.depth = 0.004;
    w.width = 0.003;
    wr.push_back(w);
  }
};
}  // namespace

TEST(FaceRig, NeutralIsRestAndExpressionWrinkles) {
  Context ctx(2);
  Rig r;
  FaceRig rig(r.mesh, r.set, r.wr, FaceRigParams{});
  EXPECT_GT(rig.rest_mesh().faces.size(), r.mesh.faces.size());
  FaceState s;
  rig.update(ctx, rig.neutral_pose(), s);
  for (std::size_t i = 0; i < s.positions.size(); ++i)
    EXPECT_LT((s.positions[i] - rig.rest_mesh().positions[i]).norm(),
              1e-12);  // r = 0, no tissue change
  rig.update(ctx, rig.expression_pose("raise"), s);
  double hmin = 0;
  for (double h : s.wrinkle_height) hmin = std::min(hmin, h);
  EXPECT_LT(hmin, -1e-4);  // a furrow appears when the forehead compresses
  // Tissue lifts compressed skin outward (along +normal ~ radial).
  double lift = 0;
  for (std::size_t i = 0; i < s.animated.size(); ++i)
    lift = std::max(lift, (s.animated[i] - s.muscle_pos[i]).norm());
  EXPECT_GT(lift, 1e-5);
  rig.set_wrinkles_enabled(false);
  FaceState s2;
  rig.update(ctx, rig.expression_pose("raise"), s2);
  for (double h : s2.wrinkle_height) EXPECT_EQ(h, 0.0);
}

TEST(FaceRig, BitIdenticalForAnyThreadCount) {
  Rig r;
  FaceRig rig(r.mesh, r.set, r.wr, FaceRigParams{});
  Context one(1), two(2);
  FaceState a, b;
  rig.update(one, rig.expression_pose("raise", 0.7), a);
  rig.update(two, rig.expression_pose("raise", 0.7), b);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t i = 0; i < a.positions.size(); ++i) EXPECT_EQ(a.positions[i], b.positions[i]);
}

TEST(SkinColor, PlaneModelAndPresets) {
  SkinColorParams p;
  p.melanin = 0;
  p.hemoglobin = 0;
  EXPECT_EQ(skin_color(p), p.base);
  const Vec3 light = skin_color(skin_color_preset("caucasian")),
             dark = skin_color(skin_color_preset("african"));
  EXPECT_LT(dark.sum(), light.sum());
  EXPECT_GT(light.x(), light.z());  // skin is red-dominant
  SkinColorParams q;
  q.melanin = 0.3;
  q.hemoglobin = 0.1;
  const Vec3 c = skin_color(q);
  EXPECT_LT((c - (q.base - 0.3 * q.melanin_absorption - 0.1 * q.hemoglobin_absorption)).norm(),
            1e-15);  // (2.6)
  EXPECT_THROW(skin_color_preset("caucasain"), Error);
}

TEST(SkinJson, DefaultHeadSetupLoads) {
  const FaceSetup s = load_face_setup(test::source_dir() / "data/muscles/lee_perry_smith.json");
  EXPECT_EQ(s.muscles.linear.size(), 14u);
  EXPECT_EQ(s.muscles.sphincter.size(), 3u);
  EXPECT_EQ(s.wrinkles.size(), 10u);
  for (const char* e :
       {"thinking", "smile", "troubled", "angry", "surprise", "raised_brows", "frown"})
    EXPECT_NO_THROW(s.muscles.expression(e)) << e;
  // Round trip.
  const FaceSetup t = face_setup_from_json_text(face_setup_to_json(s), "roundtrip");
  EXPECT_EQ(t.muscles.linear[3].origin, s.muscles.linear[3].origin);
  EXPECT_EQ(t.wrinkles[2].control[1], s.wrinkles[2].control[1]);
}

TEST(SkinJson, MalformedInputFailsCleanly) {
  auto msg = [](const std::string& text) {
    try {
      face_setup_from_json_text(text, "bad.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(msg("{ \"follicle_face\": 1, ").find("bad.json"), std::string::npos);  // syntax
  EXPECT_NE(msg(R"({"follicle_face":1,"muscles":{"linaer":[]}})").find("did you mean 'linear'"),
            std::string::npos);
  EXPECT_NE(
      msg(R"({"follicle_face":1,"muscles":{"linear":[{"name":"a","origin":[0,0],"insertion":[0,0,1]}]}})")
          .find("muscles.linear[0].origin"),
      std::string::npos);
  EXPECT_NE(
      msg(R"({"follicle_face":1,"muscles":{"linear":[{"name":"a","origin":[0,0,0],"insertion":[0,0,0.01],"zone":"wide"}]}})")
          .find("expected a number"),
      std::string::npos);
  EXPECT_NE(msg(R"({"follicle_face":1,"muscles":{"linear":[{"name":"a","origin":[0,0,0]}]}})")
                .find("insertion"),
            std::string::npos);  // missing required key
  EXPECT_NE(
      msg(R"({"follicle_face":1,"muscles":{},"wrinkles":[{"p0":[0,0],"p1":[0,0],"p2":[0,0],"p3":[1,0],"r":2}]})")
          .find("out of range"),
      std::string::npos);
  EXPECT_NE(
      msg(R"({"follicle_face":1,"muscles":{"expressions":[{"name":"x","contractions":{"nope":1}}]}})")
          .find("unknown muscle 'nope'"),
      std::string::npos);
  EXPECT_THROW(wrinkles_from_json_text(R"([{"p0":[0,0]}])"), Error);
}

TEST(FaceSetupJson, ANumberTooLargeForADoubleIsAFollicleError) {
  // Fuzzing reproducer (fuzz/regressions/face_setup/number_overflow.json): nlohmann's
  // out_of_range escaped as a foreign exception (std::terminate in the fuzzer).
  const std::string text =
      read_file(test::source_dir() / "fuzz/regressions/face_setup/number_overflow.json");
  try {
    (void)face_setup_from_json_text(text, "overflow.json");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("overflow.json: invalid JSON"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)wrinkles_from_json_text(text, "overflow.json"), Error);
}
