// Session on the shipped default scene and on small scenes with their own meshes.
#include "follicle/scene/session.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "follicle/geom/mesh_io.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using ::testing::HasSubstr;

namespace {

std::filesystem::path default_scene() {
  return test::source_dir() / "data" / "scenes" / "default.json";
}

// A unit right triangle in centimetres, with UVs.
void write_triangle(const std::filesystem::path& p) {
  std::ofstream(p) << "v 0 0 0\nv 100 0 0\nv 0 100 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
}

}  // namespace

TEST(Session, DefaultSceneBuildsARenderScene) {
  Context ctx(1);
  auto s = Session::load(default_scene(), ctx);
  ASSERT_EQ(s.scene().assets.meshes.size(), 1u);
  const auto rs = s.render_scene(0);
  ASSERT_EQ(rs.meshes.size(), 1u);
  const auto& item = rs.meshes[0];
  ASSERT_TRUE(item.mesh);
  EXPECT_TRUE(item.mesh->has_uvs());
  EXPECT_TRUE(item.mesh->has_normals());
  ASSERT_TRUE(item.material.albedo_map);
  EXPECT_GT(item.material.albedo_map->width(), 0);
  // Millimetres were converted: the head is about 0.2-0.4 m across, not 200-400.
  const auto box = item.mesh->bounds();
  const Vec3 ext = box.max() - box.min();
  EXPECT_GT(ext.maxCoeff(), 0.15);
  EXPECT_LT(ext.maxCoeff(), 0.6);
  // The camera looks at the head: the target lies inside the mesh bounds.
  EXPECT_TRUE(box.contains(rs.camera.target));
  EXPECT_NEAR(rs.camera.fov_y, s.scene().camera.fov_deg * kPi / 180.0, 1e-15);
  EXPECT_EQ(rs.lights.size(), s.scene().lights.size());
  for (const auto& l : rs.lights) EXPECT_NEAR(l.direction.norm(), 1.0, 1e-12);
  const auto settings = s.render_settings();
  EXPECT_EQ(settings.width, s.scene().render.width);
  EXPECT_EQ(settings.supersample, s.scene().render.supersample);
}

TEST(Session, MeshesAndTexturesAreCached) {
  Context ctx(1);
  auto s = Session::load(default_scene(), ctx);
  const auto a = s.render_scene(0);
  const auto b = s.render_scene(3);
  EXPECT_EQ(a.meshes[0].mesh.get(), b.meshes[0].mesh.get());
  EXPECT_EQ(a.meshes[0].material.albedo_map.get(), b.meshes[0].material.albedo_map.get());
  // A mesh with a face rig (the default head) is drawn deformed: the rig's cached mesh.
  const std::size_t head = s.mesh_index("head");
  const auto rig = s.skin_rig_of_mesh(head);
  EXPECT_EQ(rig ? s.skin_mesh(*rig, 0).get() : s.mesh(head).get(), a.meshes[0].mesh.get());
  EXPECT_THROW(s.render_scene(-1), Error);
  try {
    s.mesh_index("haed");
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("did you mean \"head\"?"));
  }
}

TEST(Session, UnitsTransformAndRelativePaths) {
  const auto dir = test::scratch_dir("session");
  std::filesystem::create_directories(dir / "meshes");
  write_triangle(dir / "meshes" / "tri.obj");
  std::ofstream(dir / "s.json") << R"({"follicle_scene": 1,
    "assets": {"meshes": [
      {"name": "a", "path": "meshes/tri.obj", "units": "cm",
       "transform": {"translate": [0, 0, 1], "rotate_deg": [0, 0, 90], "scale": 2},
       "material": {"shading": "unlit", "base_color": [1, 0, 0]}},
      {"name": "b", "path": "meshes/tri.obj", "units": "cm", "visible": false}]}})";
  Context ctx(1);
  auto s = Session::load(dir / "s.json", ctx);
  const auto rs = s.render_scene();
  ASSERT_EQ(rs.meshes.size(), 1u);  // "b" is hidden
  const auto& m = *rs.meshes[0].mesh;
  EXPECT_NEAR(m.positions[1].x(), 1.0, 1e-12);  // 100 cm
  // (1,0,0) m -> scale 2 -> rotate 90 deg about z -> (0,2,0) -> translate -> (0,2,1).
  const Vec3 p = rs.meshes[0].transform * m.positions[1];
  EXPECT_NEAR((p - Vec3(0, 2, 1)).norm(), 0.0, 1e-12);
  EXPECT_EQ(rs.meshes[0].material.shading, render::MeshShading::Unlit);
  EXPECT_EQ(rs.meshes[0].material.base_color, Vec3(1, 0, 0));
  // Both assets name the same file and units: loaded once.
  EXPECT_EQ(s.mesh(0).get(), s.mesh(1).get());
}

TEST(Session, MissingAndBrokenAssetsNameTheJsonPath) {
  const auto dir = test::scratch_dir("session-bad");
  std::ofstream(dir / "missing.json")
      << R"({"follicle_scene": 1, "assets": {"meshes": [{"path": "nope.obj", "units": "m"}]}})";
  Context ctx(1);
  try {
    Session::load(dir / "missing.json", ctx);
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("missing.json: assets.meshes[0].path"));
    EXPECT_THAT(std::string(e.what()), HasSubstr("mesh file not found"));
  }
  write_triangle(dir / "tri.obj");
  std::ofstream(dir / "notex.json") << R"({"follicle_scene": 1, "assets": {"meshes": [
      {"path": "tri.obj", "units": "m", "material": {"texture": "nope.png"}}]}})";
  try {
    Session::load(dir / "notex.json", ctx);
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("assets.meshes[0].material.texture"));
  }
  std::ofstream(dir / "broken.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";
  std::ofstream(dir / "broken.json")
      << R"({"follicle_scene": 1, "assets": {"meshes": [{"path": "broken.obj", "units": "m"}]}})";
  auto s = Session::load(dir / "broken.json", ctx);  // lazily loaded: fails on first use
  EXPECT_THROW(s.load_all_assets(), Error);
}

TEST(Session, EditedSceneIsRevalidated) {
  Context ctx(1);
  auto s = Session::load(default_scene(), ctx);
  s.scene().render.width = 0;
  EXPECT_THROW(s.validate(), Error);
  s.scene().render.width = 100;
  s.scene().camera.near = 50.0;
  EXPECT_THROW(s.validate(), Error);
}
