// Scene structs: version check, strict keys, cross-field validation, write/read round trip, and
// docs/scene-format.md in sync with the field lists.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/scene/scene.hpp"
#include "follicle/scene/scene_docs.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::scene;
using ::testing::HasSubstr;

namespace {

Scene parse(const std::string& text) {
  return read_scene(parse_json_text(text, "s.json"), JsonSource{"s.json"});
}

std::string error_of(const std::string& text) {
  try {
    parse(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

const char* kMinimal = R"({"follicle_scene": 1,
  "assets": {"meshes": [{"name": "head", "path": "head.obj", "units": "mm",
                         "transform": {"rotate_deg": [0, 90, 0], "scale": 2}}]},
  "camera": {"eye": [0, 0, 1], "target": [0, 0, 0], "fov_deg": 40},
  "lights": [{"name": "key", "direction": [0, -1, -1], "shadow": true}],
  "render": {"width": 64, "height": 32},
  "outputs": [{"type": "image", "path": "out/x.png"}]})";

}  // namespace

TEST(SceneFile, ReadsMinimalScene) {
  const Scene s = parse(kMinimal);
  ASSERT_EQ(s.assets.meshes.size(), 1u);
  EXPECT_EQ(s.assets.meshes[0].units, LengthUnit::mm);
  EXPECT_EQ(s.camera.fov_deg, 40.0);
  EXPECT_EQ(s.render.width, 64);
  EXPECT_EQ(s.render.supersample, 2);  // default
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_TRUE(s.lights[0].shadow);
  ASSERT_EQ(s.outputs.size(), 1u);
  EXPECT_EQ(s.outputs[0].path, "out/x.png");
}

TEST(SceneFile, TransformAppliesScaleThenRotationThenTranslation) {
  Transform t;
  t.scale = 2.0;
  t.rotate_deg = Vec3(0, 90, 0);
  t.translate = Vec3(1, 0, 0);
  // (1,0,0) scaled to (2,0,0), rotated +90 deg about y to (0,0,-2), translated to (1,0,-2).
  const Vec3 p = t.matrix() * Vec3(1, 0, 0);
  EXPECT_NEAR(p.x(), 1.0, 1e-12);
  EXPECT_NEAR(p.y(), 0.0, 1e-12);
  EXPECT_NEAR(p.z(), -2.0, 1e-12);
  // x then y then z: rotating (0,1,0) by 90 about x gives (0,0,1), then 90 about z leaves it.
  Transform r;
  r.rotate_deg = Vec3(90, 0, 90);
  const Vec3 q = r.matrix() * Vec3(0, 1, 0);
  EXPECT_NEAR((q - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
}

TEST(SceneFile, VersionIsCheckedFirst) {
  EXPECT_THAT(error_of(R"({"camera": {}})"), HasSubstr("missing required key \"follicle_scene\""));
  EXPECT_THAT(error_of(R"({"follicle_scene": 2, "bogus": 1})"),
              HasSubstr("unsupported scene format version 2: this Follicle reads version 1"));
  EXPECT_THAT(error_of(R"({"follicle_scene": "1"})"), HasSubstr("expected the integer"));
  EXPECT_THAT(error_of(R"([])"), HasSubstr("expected a JSON object"));
}

TEST(SceneFile, StrictKeysWithPaths) {
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "camra": {}})"),
              HasSubstr("s.json: camra: unknown key \"camra\" (did you mean \"camera\"?)"));
  EXPECT_THAT(
      error_of(R"({"follicle_scene": 1, "assets": {"meshes": [{"path": "a.obj", "unit": "mm"}]}})"),
      HasSubstr("assets.meshes[0].unit: unknown key \"unit\" (did you mean \"units\"?)"));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "assets": {"meshes": [{"path": "a.obj"}]}})"),
              HasSubstr("assets.meshes[0]: missing required key \"units\""));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "camera": {"fov_deg": "wide"}})"),
              HasSubstr("camera.fov_deg: expected a number, got a string \"wide\""));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "camera": {"fov_deg": 180}})"),
              HasSubstr("camera.fov_deg: value 180 is out of range"));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "lights": [{"color": [1, 1, 2]}]})"),
              HasSubstr("lights[0].color[2]: value 2 is out of range"));
  EXPECT_THAT(
      error_of(R"({"follicle_scene": 1, "assets": {"meshes": [{"path": "a", "units": "inch"}]}})"),
      HasSubstr("assets.meshes[0].units: unknown value \"inch\""));
  EXPECT_THAT(
      error_of(R"({"follicle_scene": 1, "render": {"strand_pass": "vulkan"}})"),
      HasSubstr("render.strand_pass: unknown value \"vulkan\"; expected \"cpu\" or \"gpu\""));
}

TEST(SceneFile, CrossFieldValidation) {
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "camera": {"near": 5, "far": 1}})"),
              HasSubstr("camera.far: far (1) must be greater than near (5)"));
  EXPECT_THAT(
      error_of(R"({"follicle_scene": 1, "camera": {"eye": [1, 2, 3], "target": [1, 2, 3]}})"),
      HasSubstr("camera.target"));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "camera": {"up": [0, 0, -1]}})"),
              HasSubstr("camera.up: up vector is parallel"));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "lights": [{"direction": [0, 0, 0]}]})"),
              HasSubstr("lights[0].direction"));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "outputs": [{"type": "image", "path": "a.jpg"}]})"),
              HasSubstr("outputs[0].path: an image output must end in .png"));
  EXPECT_THAT(error_of(R"({"follicle_scene": 1, "assets": {"meshes": [
      {"name": "a", "path": "x.obj", "units": "m"}, {"name": "a", "path": "y.obj", "units": "m"}]}})"),
              HasSubstr("assets.meshes[1].name: duplicate mesh name"));
}

TEST(SceneFile, WriteReadRoundTrip) {
  const Scene s = parse(kMinimal);
  const Json j = write_scene(s);
  EXPECT_EQ(j["follicle_scene"], 1);
  const Scene back = read_scene(j, JsonSource{"mem"});
  EXPECT_EQ(write_scene(back), j);
  EXPECT_EQ(back.assets.meshes[0].transform.rotate_deg, Vec3(0, 90, 0));
}

TEST(SceneFile, ShippedScenesAreValid) {
  const auto dir = test::source_dir() / "data" / "scenes";
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().string());
    EXPECT_NO_THROW(load_scene_file(e.path()));
    ++n;
  }
  EXPECT_GE(n, 1);
}

TEST(SceneDocs, EveryKeyIsDocumented) {
  // Every key of every section appears in a generated table.
  const auto blocks = scene_doc_blocks();
  std::string all;
  for (const auto& [name, table] : blocks) all += table;
  for (const char* key : {"`follicle_scene`", "`camera.fov_deg`", "`assets.meshes[].units`",
                          "`assets.meshes[].material.texture`", "`lights[].direction`",
                          "`render.supersample`", "`outputs[].path`"})
    EXPECT_THAT(all, HasSubstr(key));
}

TEST(SceneDocs, SceneFormatDocIsInSync) {
  const auto doc = test::source_dir() / "docs" / "scene-format.md";
  if (const char* u = std::getenv("FOLLICLE_UPDATE_DOCS"); u && *u == '1')
    write_file_atomically(doc, update_scene_doc(read_file(doc)));
  const auto stale = stale_scene_doc_blocks(read_file(doc));
  std::string names;
  for (const auto& s : stale) names += s + " ";
  EXPECT_TRUE(stale.empty()) << "docs/scene-format.md is out of date in blocks: " << names
                             << "\nrun: follicle docs scene-format --write docs/scene-format.md";
  // Updating an in-sync doc changes nothing; updating an empty doc adds every block.
  EXPECT_EQ(update_scene_doc(read_file(doc)), read_file(doc));
  EXPECT_TRUE(stale_scene_doc_blocks(update_scene_doc("# x\n")).empty());
}

TEST(SceneDocs, FaceSetupDocIsInSyncAndCoversEveryKey) {
  const auto doc = test::source_dir() / "docs" / "face-setup.md";
  if (const char* u = std::getenv("FOLLICLE_UPDATE_DOCS"); u && *u == '1')
    write_file_atomically(doc, update_doc("face-setup", read_file(doc)));
  const auto stale = stale_doc_blocks("face-setup", read_file(doc));
  std::string names;
  for (const auto& s : stale) names += s + " ";
  EXPECT_TRUE(stale.empty()) << "docs/face-setup.md is out of date in blocks: " << names
                             << "\nrun: follicle docs face-setup --write docs/face-setup.md";
  std::string all;
  for (const auto& [name, table] : doc_blocks("face-setup")) all += table;
  for (const char* key :
       {"`follicle_face`", "`muscles.linear[].origin`", "`muscles.sphincter[].semi_axis_a`",
        "`muscles.jaw.pivot`", "`muscles.expressions[].contractions`", "`wrinkles[].p3`",
        "`wrinkles[].r`"})
    EXPECT_THAT(all, HasSubstr(key));
  // Every key the shipped setup uses is documented (comments excepted).
  const auto shipped = nlohmann::json::parse(
      read_file(test::source_dir() / "data" / "muscles" / "lee_perry_smith.json"));
  std::function<void(const nlohmann::json&, const std::string&)> walk =
      [&](const nlohmann::json& j, const std::string& prefix) {
        if (j.is_array()) {
          for (const auto& e : j) walk(e, prefix + "[]");
          return;
        }
        if (!j.is_object() || prefix.ends_with(".contractions")) return;
        for (const auto& [k, v] : j.items()) {
          if (k.starts_with("//")) continue;
          const std::string key = prefix.empty() ? k : prefix + "." + k;
          EXPECT_THAT(all, HasSubstr("`" + key + "`"));
          walk(v, key);
        }
      };
  walk(shipped, "");
  EXPECT_THROW((void)doc_blocks("no-such-topic"), Error);
}

TEST(SceneDocs, ExampleInTheDocIsTheShippedDefaultScene) {
  const std::string doc = read_file(test::source_dir() / "docs" / "scene-format.md");
  const auto b = doc.find("```json\n");
  ASSERT_NE(b, std::string::npos);
  const auto e = doc.find("```", b + 8);
  ASSERT_NE(e, std::string::npos);
  const std::string example = doc.substr(b + 8, e - b - 8);
  EXPECT_NO_THROW(read_scene(parse_json_text(example, "example"), JsonSource{"example"}));
  EXPECT_EQ(parse_json_text(example, "example"),
            parse_json_file(test::source_dir() / "data" / "scenes" / "default.json"));
}
