// Fine-scale wrinkles on the face in scenes (issue 5, Bando 2002 §2.6): the optional "fine" key of
// the skin section. Only with "fine" does the skin's render material carry a relief (bump map over
// the refined mesh's UVs); the relief is the rest relief (M = r) when "modulate" is false, and
// with modulation it follows the shrinkage (2.3, 2.4) of the expression, departing from the rest
// relief more for a compressing expression than for the neutral face; bad keys fail with their
// JSON path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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

// The forehead scene with a quicker rig and smaller height images.
Json forehead() {
  Json j = parse_json_file(scenes_dir() / "skin_fine_forehead.json");
  j["skin"][0]["refine"]["max_levels"] = 1;
  j["skin"][0]["fine"]["resolution"] = 256;
  j["skin"][0]["fine"]["unit_mm"] = 0.0;  // one texel: furrows at this resolution
  return j;
}

const render::MeshItem& skin_item(const render::RenderScene& rs) {
  if (rs.meshes.size() != 1) fail("expected one mesh item, got {}", rs.meshes.size());
  return rs.meshes[0];
}

std::string relief_error(const Json& j) {
  Context ctx(1);
  try {
    auto s = Session::from_json(j, scenes_dir(), "x.json", ctx);
    (void)s.skin_fine_relief(0, 0);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

double max_abs_diff(const image::ImageF& a, const image::ImageF& b) {
  double m = 0;
  for (std::size_t i = 0; i < a.storage().size(); ++i)
    m = std::max(m, double(std::abs(a.storage()[i] - b.storage()[i])));
  return m;
}

}  // namespace

TEST(FaceFineScene, ReliefOnTheMaterialOnlyWithFine) {
  Context ctx(2);
  Json without = forehead();
  without["skin"][0].erase("fine");
  auto s0 = Session::from_json(without, scenes_dir(), "without", ctx);
  const auto rs0 = s0.render_scene(0);
  EXPECT_FALSE(skin_item(rs0).material.height_map);
  EXPECT_FALSE(s0.skin_fine_relief(0, 0));

  const Json with = forehead();
  auto s1 = Session::from_json(with, scenes_dir(), "with", ctx);
  const auto rs1 = s1.render_scene(0);
  const auto& item = skin_item(rs1);
  ASSERT_TRUE(item.material.height_map);
  EXPECT_DOUBLE_EQ(item.material.bump_strength,
                   with["skin"][0]["fine"]["bump_strength"].get<double>());
  // The bump map applies through the refined mesh's texture coordinates.
  ASSERT_TRUE(item.mesh);
  EXPECT_TRUE(item.mesh->has_uvs());
  EXPECT_EQ(item.mesh->uv_faces.size(), item.mesh->faces.size());
  // The same face geometry with and without fine wrinkles (they are a bump map only).
  EXPECT_EQ(item.mesh->positions, skin_item(rs0).mesh->positions);
  // Relief: 0 on untouched skin, furrows below it, never deeper than both fields at M = 1.
  const image::ImageF& h = *item.material.height_map;
  EXPECT_EQ(h.width(), 256);
  const double depth = with["skin"][0]["fine"]["depth_m"].get<double>();
  const auto [lo, hi] = std::minmax_element(h.storage().begin(), h.storage().end());
  EXPECT_LE(*hi, 0.0f);
  EXPECT_LT(*lo, -0.1 * depth) << "no furrows carved";
  EXPECT_GE(*lo, -2.0 * depth - 1e-12);
  const auto furrowed = std::count_if(h.storage().begin(), h.storage().end(),
                                      [&](float x) { return x < -0.01 * depth; });
  EXPECT_GT(double(furrowed) / double(h.storage().size()), 0.02);
  // Cached per frame: the same image for the same (still) frame.
  EXPECT_EQ(s1.skin_fine_relief(0, 0).get(), item.material.height_map.get());
}

TEST(FaceFineScene, ModulationFollowsTheExpressionsShrinkage) {
  Context ctx(2);
  auto relief = [&](const std::string& expression, bool modulate) {
    Json j = forehead();
    j["skin"][0]["expression"] = expression;
    j["skin"][0]["fine"]["modulate"] = modulate;
    auto s = Session::from_json(j, scenes_dir(), "m", ctx);
    return *s.skin_fine_relief(0, 0);
  };
  const auto rest = relief("troubled", false);
  const auto troubled = relief("troubled", true);
  const auto neutral = relief("neutral", true);
  const auto surprise = relief("surprise", true);
  const double depth = forehead()["skin"][0]["fine"]["depth_m"].get<double>();
  // Without modulation the expression does not matter: the rest relief (M = r everywhere).
  EXPECT_EQ(max_abs_diff(rest, relief("neutral", false)), 0.0);
  // The neutral face barely shrinks the skin (tissue only): close to the rest relief; the
  // contracting muscles shrink and stretch the skin (2.3): M(s) moves away from r (2.4).
  const double d_neutral = max_abs_diff(neutral, rest);
  const double d_troubled = max_abs_diff(troubled, rest);
  const double d_surprise = max_abs_diff(surprise, rest);
  EXPECT_GT(d_troubled, 0.05 * depth);
  EXPECT_GT(d_surprise, 0.05 * depth);
  EXPECT_LT(d_neutral, 0.5 * d_troubled);
}

TEST(FaceFineScene, BadFineKeysFailWithJsonPath) {
  Json j = forehead();
  j["skin"][0]["fine"]["field0"][1]["vertex"] = 3;  // has "uv" too
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].fine.field0[1]"));

  j = forehead();
  j["skin"][0]["fine"]["field0"][0].erase("uv");  // neither
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].fine.field0[0]"));

  j = forehead();
  j["skin"][0]["fine"]["field1"][2]["direction"] = {0.9, 0.9};
  std::string e = read_error(j);
  EXPECT_THAT(e, HasSubstr("skin[0].fine.field1[2].direction"));
  EXPECT_THAT(e, HasSubstr("[0, 1]"));

  j = forehead();
  j["skin"][0]["fine"]["field1"] = Json::array();
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].fine.field1"));

  j = forehead();
  j["skin"][0]["fine"]["resolutoin"] = 512;
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].fine.resolutoin"));

  j = forehead();
  j["skin"][0]["fine"]["resolution"] = 8;
  EXPECT_THAT(read_error(j), HasSubstr("skin[0].fine.resolution"));

  j = forehead();
  j["skin"][0]["fine"]["field0"][0].erase("uv");
  j["skin"][0]["fine"]["field0"][0]["vertex"] = 10000000;
  e = relief_error(j);
  EXPECT_THAT(e, HasSubstr("skin[0].fine.field0[0].vertex"));
  EXPECT_THAT(e, HasSubstr("uv vertices"));
}

TEST(FaceFineScene, ExportMapsWritesTheFaceRelief) {
  // `follicle export --maps` on a face with "fine": rest and frame maps of skin[0], the frame's
  // height map equal to the material's relief (metres -> relief units, + 1).
  Context ctx(2);
  auto s = Session::from_json(forehead(), scenes_dir(), "f.json", ctx);
  ASSERT_TRUE(s.has_wrinkle_maps());
  const auto dir = test::scratch_dir("face_maps");
  EXPECT_EQ(s.export_wrinkle_maps(dir, -1), std::vector<std::string>{"skin0_rest"});
  EXPECT_EQ(s.export_wrinkle_maps(dir, 0), std::vector<std::string>{"skin0_frame_0000"});
  const auto rest = image::read_exr_gray(dir / "skin0_rest_height.exr");
  const auto frame = image::read_exr_gray(dir / "skin0_frame_0000_height.exr");
  ASSERT_EQ(rest.width(), 256);
  ASSERT_EQ(frame.width(), 256);
  EXPECT_EQ(image::read_png_rgba(dir / "skin0_frame_0000_normal.png").width(), 256);
  const auto relief = s.skin_fine_relief(0, 0);
  ASSERT_TRUE(relief);
  const double depth = 60e-6;  // fine.depth_m default
  double worst = 0, carved = 0;
  for (std::size_t i = 0; i < frame.storage().size(); ++i) {
    const double want = relief->storage()[i] / depth + 1.0;
    worst = std::max(worst, std::abs(frame.storage()[i] - want));
    carved = std::min(carved, double(rest.storage()[i]) - 1.0);
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(carved, -0.1);                     // the rest relief has furrows
  EXPECT_GT(max_abs_diff(rest, frame), 1e-3);  // the troubled face modulates them
}
