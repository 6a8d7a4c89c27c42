// The hair-model harness (scene/harness.hpp, issue 20): analytic cases (hair nothing can move
// has zero stretch, zero drift, zero kinetic energy and the potential energy of its rest shape;
// roots ride a turning head), the report lists every field for every model, bad options fail
// with a clear message, and the sheet shows one picture per model and sheet frame.
#include "follicle/scene/harness.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "follicle/core/error.hpp"
#include "follicle/image/plot.hpp"
#include "follicle/scene/session.hpp"
#include "scene_test_util.hpp"
#include "testing/gl_testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;
using ::testing::HasSubstr;

namespace {

// anjyo_shake at a low hair density, `frames` frames and a tiny image.
Json small_scene(int frames) {
  Json j = scene_json("anjyo_shake");
  j["hair"][0]["density_scale"] = 0.03;
  j["animation"]["frames"] = frames;
  j["render"]["width"] = 64;
  j["render"]["height"] = 48;
  j["render"]["supersample"] = 1;
  return j;
}

// Nothing can move the hair: no gravity, no wind, no head motion, and the paper's hull
// collision (the mesh collision would push the styled roots' first nodes, which start up to
// ~0.8 mm inside the head mesh, out of it in the first step).
Json rigid_scene(int frames) {
  Json j = small_scene(frames);
  j["animation"]["gravity"] = {0.0, 0.0, 0.0};
  j["animation"]["head_motion"] = {{"kind", "none"}};
  j["hair"][0]["dynamics"]["collision"] = "hull";
  return j;
}

Scene to_scene(const Json& j) {
  return read_scene(j, JsonSource{"harness.json"});
}

HarnessOptions no_pictures() {
  HarnessOptions o;
  o.thumb_size = 0;
  return o;
}

HarnessReport run(const Json& j, const HarnessOptions& o, const Context& ctx) {
  return run_harness(to_scene(j), scenes_dir(), "harness.json", ctx, o);
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Total rest length of the groom of hair[0] [m].
double groom_length(const Json& j, const Context& ctx) {
  Session s = Session::from_json(j, scenes_dir(), "harness.json", ctx);
  const auto& st = s.hair_groom(0)->strands;
  double l = 0.0;
  for (std::size_t k = 0; k < st.num_strands(); ++k)
    for (uint32_t i = st.offsets[k]; i + 1 < st.offsets[k + 1]; ++i)
      l += (st.points[i + 1] - st.points[i]).cast<double>().norm();
  return l;
}

double max_abs_diff(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x - v.front()));
  return m;
}

}  // namespace

TEST(Harness, HairNothingCanMoveHasNoStretchNoDriftAndConstantEnergy) {
  const Context ctx(2, 1);
  HarnessOptions o = no_pictures();
  o.models = {"anjyo1992"};
  const HarnessReport rep = run(rigid_scene(5), o, ctx);
  ASSERT_EQ(rep.models.size(), 1u);
  const auto& r = rep.models[0];
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.frames, 5);
  ASSERT_EQ(r.time_s.size(), 5u);
  EXPECT_GT(r.strands, 20u);
  EXPECT_EQ(r.strands, rep.groom_strands);
  EXPECT_TRUE(r.rest_from_groom);
  EXPECT_LT(r.max_stretch_percent, 1e-4);
  EXPECT_LT(r.root_drift_mm, 1e-3);
  // "Still": the kinetic energy of the whole hair moving at 1 um/s (float32 rounding of the
  // positions between frames is ~0.1 um/s).
  const double mass = rep.linear_density * groom_length(rigid_scene(5), ctx);
  const double still = 0.5 * mass * 1e-12;
  for (std::size_t k = 0; k < r.time_s.size(); ++k) {
    EXPECT_NEAR(r.time_s[k], double(k) / rep.fps, 1e-12);
    EXPECT_EQ(r.potential_j[k], 0.0);  // no gravity
    EXPECT_GE(r.kinetic_j[k], 0.0);
    EXPECT_LT(r.kinetic_j[k], still) << k;
    EXPECT_DOUBLE_EQ(r.total_j[k], r.kinetic_j[k] + r.potential_j[k]);
  }
  EXPECT_LT(max_abs_diff(r.total_j), still);
  EXPECT_GE(r.max_penetration_mm, 0.0);
  EXPECT_GE(r.ms_per_simulated_second, 0.0);
}

TEST(Harness, PotentialEnergyIsThatOfTheRestShapeUnderGravity) {
  // Frame 0 is the groom at rest: E_p = -sum over segments of lambda l g . (a + b) / 2.
  const Context ctx(2, 1);
  Json j = rigid_scene(2);
  j["animation"]["gravity"] = {0.5, -9.81, 1.0};
  HarnessOptions o = no_pictures();
  o.models = {"anjyo1992"};
  o.hair_radius = 50e-6;
  const HarnessReport rep = run(j, o, ctx);
  ASSERT_EQ(rep.models.at(0).error, "");
  const double lambda = 1300.0 * kPi * 50e-6 * 50e-6;
  EXPECT_NEAR(rep.linear_density, lambda, 1e-15);

  Session s = Session::from_json(j, scenes_dir(), "harness.json", ctx);
  const auto groom = s.hair_groom(0);
  const Vec3 g(0.5, -9.81, 1.0);
  double expected = 0.0, length = 0.0;
  const auto& st = groom->strands;
  for (std::size_t k = 0; k < st.num_strands(); ++k)
    for (uint32_t i = st.offsets[k]; i + 1 < st.offsets[k + 1]; ++i) {
      const Vec3 a = st.points[i].cast<double>(), b = st.points[i + 1].cast<double>();
      const double l = (b - a).norm();
      length += l;
      expected -= lambda * l * g.dot(0.5 * (a + b));
    }
  ASSERT_GT(length, 1.0);
  // The model outputs float32 points: the same up to their rounding (~1e-8 relative).
  EXPECT_NEAR(rep.models[0].potential_j[0], expected, 1e-6 * std::abs(expected));
}

TEST(Harness, RootsRideATurningHead) {
  const Context ctx(2, 1);
  Json j = small_scene(9);
  j["animation"]["head_motion"] = {
      {"kind", "turn"}, {"axis", {0.0, 1.0, 0.0}}, {"angle_deg", 40.0}, {"t0", 0.0}, {"t1", 0.35}};
  HarnessOptions o = no_pictures();
  o.models = {"anjyo1992"};
  const HarnessReport rep = run(j, o, ctx);
  const auto& r = rep.models.at(0);
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.frames, 9);
  EXPECT_LT(r.root_drift_mm, 0.1);
  // The head turns 40 degrees: the hair moves, so it has kinetic energy inside the motion.
  double kmax = 0.0;
  for (double k : r.kinetic_j) kmax = std::max(kmax, k);
  EXPECT_GT(kmax, 1e-12);
  // Anjyo 1992 hair is a chain of rigid sticks: segment lengths hold.
  EXPECT_LT(r.max_stretch_percent, 1e-3);
  for (std::size_t k = 0; k < r.total_j.size(); ++k)
    EXPECT_DOUBLE_EQ(r.total_j[k], r.kinetic_j[k] + r.potential_j[k]);
}

TEST(Harness, AnotherGroupKeepsTheScenesHeadMotion) {
  // Two identical groups: the harness on group 1 (group 0 dropped) sees the same motion, pivot
  // included (the default pivot is the bottom of group 0's hull), so the same energies.
  const Context ctx(2, 1);
  Json j = small_scene(3);
  j["animation"]["head_motion"] = {{"kind", "turn"}, {"angle_deg", 30.0}, {"t0", 0.0}, {"t1", 0.2}};
  j["hair"].push_back(j["hair"][0]);
  j["hair"][1]["name"] = "second";
  HarnessOptions o = no_pictures();
  o.models = {"anjyo1992"};
  const HarnessReport r0 = run(j, o, ctx);
  o.group = 1;
  const HarnessReport r1 = run(j, o, ctx);
  EXPECT_EQ(r1.group_name, "second");
  ASSERT_EQ(r0.models.at(0).frames, 3);
  ASSERT_EQ(r1.models.at(0).frames, 3);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(r0.models[0].potential_j[k], r1.models[0].potential_j[k]) << k;
    EXPECT_DOUBLE_EQ(r0.models[0].kinetic_j[k], r1.models[0].kinetic_j[k]) << k;
  }
}

TEST(Harness, TheReportHasEveryFieldForEveryModel) {
  const Context ctx(2, 1);
  HarnessOptions o = no_pictures();
  o.first_frame = 1;
  o.last_frame = 3;
  const HarnessReport rep = run(small_scene(4), o, ctx);
  const Json j = harness_json(rep);
  const auto names = hair_model_names();
  ASSERT_FALSE(names.empty());
  ASSERT_EQ(j.at("models").size(), names.size());
  EXPECT_EQ(j.at("first_frame"), 1);
  EXPECT_EQ(j.at("last_frame"), 3);
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Json& m = j["models"][i];
    EXPECT_EQ(m.at("model"), names[i]);
    for (const char* key : {"max_stretch_percent", "max_penetration_mm", "root_drift_mm",
                            "ms_per_simulated_second", "strands", "points", "frames"})
      EXPECT_TRUE(m.contains(key)) << names[i] << " " << key;
    const int frames = m.at("frames");
    if (m.at("ok") == true) {
      EXPECT_EQ(frames, 3) << names[i];
      EXPECT_TRUE(m["max_stretch_percent"].is_number());
      EXPECT_GT(m["strands"].get<int>(), 0);
      EXPECT_GT(m["points"].get<int>(), m["strands"].get<int>());
    }
    for (const char* key : {"time_s", "kinetic_j", "potential_j", "total_j", "stretch_percent"}) {
      ASSERT_TRUE(m.contains(key) && m[key].is_array()) << names[i] << " " << key;
      EXPECT_EQ(int(m[key].size()), frames) << names[i] << " " << key;
    }
    if (frames > 0) {
      EXPECT_NEAR(m["time_s"][0].get<double>(), 1.0 / rep.fps, 1e-12);
    }
  }
  // The sheet without pictures still has the plots and a line per model.
  const image::ImageRGB8 sheet = harness_sheet(rep);
  EXPECT_GT(sheet.width(), 3 * 480);
  EXPECT_GT(sheet.height(), 380);
}

TEST(Harness, BadOptionsAreClearErrors) {
  const Context ctx(1, 1);
  Json still = small_scene(4);
  still.erase("animation");
  EXPECT_THAT(error_of([&] { run(still, no_pictures(), ctx); }), HasSubstr("still scene"));

  HarnessOptions o = no_pictures();
  o.models = {"anjyo1992", "hairy"};
  const std::string e = error_of([&] { run(small_scene(4), o, ctx); });
  EXPECT_THAT(e, HasSubstr("\"hairy\""));
  for (const auto& n : hair_model_names()) EXPECT_THAT(e, HasSubstr(n));

  o = no_pictures();
  o.first_frame = 2;
  o.last_frame = 2;
  EXPECT_THAT(error_of([&] { run(small_scene(4), o, ctx); }), HasSubstr("at least two frames"));
  o.last_frame = 9;
  EXPECT_THAT(error_of([&] { run(small_scene(4), o, ctx); }), HasSubstr("frames 0-3"));
  o = no_pictures();
  o.group = 3;
  EXPECT_THAT(error_of([&] { run(small_scene(4), o, ctx); }), HasSubstr("hair group 3"));
  o = HarnessOptions{};
  o.sheet_frames = {7};
  EXPECT_THAT(error_of([&] { run(small_scene(4), o, ctx); }), HasSubstr("sheet frame 7"));
  o = no_pictures();
  o.hair_radius = -1.0;
  EXPECT_THAT(error_of([&] { run(small_scene(4), o, ctx); }), HasSubstr("hair_radius"));
}

TEST(Harness, TheSheetShowsEveryModelAtEverySheetFrame) {
  const Context ctx(2, 1);
  FOLLICLE_HEADLESS_RENDERER_OR_SKIP(renderer, ctx);
  HarnessOptions o;
  o.thumb_size = 96;
  o.sheet_frames = {0, 3};
  const HarnessReport rep = run_harness(to_scene(small_scene(4)), scenes_dir(), "harness.json", ctx,
                                        o, nullptr, renderer.get());
  EXPECT_EQ(rep.sheet_frames, (std::vector<int>{0, 3}));
  for (const auto& r : rep.models) {
    if (!r.error.empty()) continue;
    ASSERT_EQ(r.pictures.size(), 2u) << r.model;
    EXPECT_EQ(r.pictures[0].width(), 96);
    EXPECT_EQ(r.pictures[0].height(), 72);  // the scene's aspect (64x48)
    // Not a blank picture: the head and hair differ from the background somewhere.
    const auto& p = r.pictures[1];
    bool varied = false;
    for (std::size_t i = 3; i < p.storage().size() && !varied; ++i)
      varied = p.storage()[i] != p.storage()[i % 3];
    EXPECT_TRUE(varied) << r.model;
  }
  const image::ImageRGB8 sheet = harness_sheet(rep);
  EXPECT_GE(sheet.width(), 2 * 96);
  EXPECT_GE(sheet.height(), int(rep.models.size()) * 72 + 380);
}

TEST(Harness, EveryModelKeepsTheRootsOfSomebodyElsesGroomOnTheShakingBust) {
  // The Sintel bust and her TressFX guide strands (not a groom we made): the file's roots sit up
  // to ~9 mm off the low-poly scalp, which is the groom's rest offset, not drift; through the
  // head shake every model keeps each root at its binding point plus that offset.
  const Context ctx(2, 1);
  Json j = scene_json("sintel_bando");
  j["animation"]["duration"] = 0.5;
  HarnessOptions o = no_pictures();
  o.last_frame = 8;
  const HarnessReport rep = run(j, o, ctx);
  ASSERT_EQ(rep.models.size(), 3u);
  for (const auto& r : rep.models) {
    ASSERT_EQ(r.error, "") << r.model;
    EXPECT_EQ(r.strands, 228u) << r.model;
    EXPECT_LT(r.root_drift_mm, 0.1) << r.model;
    EXPECT_LT(r.max_penetration_mm, 15.0) << r.model;
  }
}

TEST(Harness, RootsStayOnTheHeadWhenFramesFallBetweenSteps) {
  // Regression: at 24 fps with Anjyo's dt = 1/60 s every other frame lies between two steps, and
  // the hair was placed by the head pose at the model's time instead of the frame's: 3 mm of
  // root drift on odd frames of a shake (the hair jittered against the moving head).
  const Context ctx(2, 1);
  Json j = small_scene(9);
  j["animation"]["fps"] = 24;
  j["hair"][0]["dynamics"]["dt"] = 1.0 / 60.0;
  j["animation"]["head_motion"] = {
      {"kind", "turn"}, {"axis", {0.0, 1.0, 0.0}}, {"angle_deg", 40.0}, {"t0", 0.0}, {"t1", 0.35}};
  HarnessOptions o = no_pictures();
  o.models = {"anjyo1992"};
  const HarnessReport rep = run(j, o, ctx);
  const auto& r = rep.models.at(0);
  ASSERT_EQ(r.error, "");
  EXPECT_LT(r.root_drift_mm, 0.1);
}
