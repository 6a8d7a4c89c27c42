#pragma once
// The scene file (`"follicle_scene": 1`) as plain structs. Every struct lists its keys once in
// visit(); the strict JSON reader, the writer, validation and docs/scene-format.md all come from
// those lists (json_params.hpp). Units in the file: metres and degrees where a key says so
// (`rotate_deg`, `fov_deg`); mesh files declare their own length unit.
//
// Adding a section later (hair groups, skin, animation): add a struct with visit()/validate()
// and one line `v("hair", hair, ParamInfo{...})` in Scene::visit(); the reader, writer and docs
// pick it up, and tests/unit/scene/scene_docs_test.cpp fails until docs/scene-format.md has the
// generated table (`follicle docs scene-format --write docs/scene-format.md`).
#include <array>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/core/units.hpp"
#include "follicle/scene/hair_section.hpp"
#include "follicle/scene/hand_section.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/scene/skin_section.hpp"

namespace follicle::scene {

/// The scene format version this build reads and writes.
inline constexpr int kSceneVersion = 1;

enum class Shading { BlinnPhong, Unlit };
constexpr std::array<std::pair<Shading, const char*>, 2> follicle_enum_names(Shading) {
  return {{{Shading::BlinnPhong, "blinn_phong"}, {Shading::Unlit, "unlit"}}};
}

enum class OutputType { Image };
constexpr std::array<std::pair<OutputType, const char*>, 1> follicle_enum_names(OutputType) {
  return {{{OutputType::Image, "image"}}};
}

/// x' = translate + R (scale x), R = Rz * Ry * Rx (rotate about fixed x, then y, then z).
struct Transform {
  Vec3 translate{0, 0, 0};   // [m]
  Vec3 rotate_deg{0, 0, 0};  // [deg]
  double scale = 1.0;

  template <class V>
  void visit(V&& v) {
    v("translate", translate, ParamInfo{"translation, applied last", "m"});
    v("rotate_deg", rotate_deg,
      ParamInfo{"rotation about the fixed x, then y, then z axis", "deg", -360.0, 360.0});
    v("scale", scale, ParamInfo{"uniform scale factor, applied first", "", 1e-6, 1e6});
  }
  Affine3 matrix() const;
};

struct Material {
  Shading shading = Shading::BlinnPhong;
  Vec3 base_color{0.8, 0.65, 0.55};
  std::string texture;  // relative to the scene file; "" = none
  double specular = 0.15;
  double shininess = 32.0;
  double ambient = 0.15;

  template <class V>
  void visit(V&& v) {
    v("shading", shading, ParamInfo{"shading model"});
    v("base_color", base_color,
      ParamInfo{"linear RGB colour used where there is no texture", "", 0.0, 1.0});
    v("texture", texture,
      ParamInfo{"albedo texture (PNG/JPEG, sRGB) over the mesh UVs, relative to the scene file"});
    v("specular", specular, ParamInfo{"Blinn-Phong specular weight", "", 0.0, 1.0});
    v("shininess", shininess, ParamInfo{"Blinn-Phong exponent", "", 1.0, 10000.0});
    v("ambient", ambient, ParamInfo{"ambient weight", "", 0.0, 1.0});
  }
};

struct MeshAsset {
  static constexpr const char* kRequired[] = {"path", "units"};
  std::string name;  // optional id other sections refer to (e.g. hair grows on "head")
  std::string path;  // relative to the scene file
  LengthUnit units = LengthUnit::m;
  Transform transform;
  Material material;
  bool cast_shadow = true;
  bool visible = true;
  // The head's orientation in the file's own frame: hair hulls, styles and colliders are laid out
  // in the head frame (x left = up x front, y up, z towards the face), whatever way the file faces.
  Vec3 up{0.0, 1.0, 0.0};
  Vec3 front{0.0, 0.0, 1.0};

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"identifier other sections use to refer to this mesh"});
    v("path", path, ParamInfo{"mesh file (.obj, .ply, .gltf, .glb), relative to the scene file"});
    v("units", units, ParamInfo{"length unit of the coordinates in the file"});
    v("up", up,
      ParamInfo{"the head's up direction in the file's frame (hair hull, styles, colliders)", "",
                -1e3, 1e3});
    v("front", front,
      ParamInfo{"the direction the face looks in the file's frame (made orthogonal to up)", "",
                -1e3, 1e3});
    v("transform", transform, ParamInfo{"placement in the scene"});
    v("material", material, ParamInfo{"surface appearance"});
    v("cast_shadow", cast_shadow, ParamInfo{"whether the mesh casts shadows"});
    v("visible", visible, ParamInfo{"whether the mesh is drawn"});
  }
};

/// A groom file (strands): any hair model of a hair[] entry can run it ("groom": name).
struct GroomAsset {
  static constexpr const char* kRequired[] = {"name", "path", "units"};
  std::string name;  // hair[].groom refers to it
  std::string path;  // relative to the scene file
  LengthUnit units = LengthUnit::m;
  Transform transform;

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"identifier hair[].groom uses to refer to this groom"});
    v("path", path,
      ParamInfo{"strand file (.hair, .tfx, .usda BasisCurves, OBJ polylines), relative to the "
                "scene file"});
    v("units", units,
      ParamInfo{"length unit of the coordinates in the file (a .usda's metersPerUnit wins)"});
    v("transform", transform,
      ParamInfo{"placement in the scene (use the same as the mesh the hair grows on)"});
  }
};

struct Assets {
  std::vector<MeshAsset> meshes;
  std::vector<GroomAsset> grooms;

  template <class V>
  void visit(V&& v) {
    v("meshes", meshes, ParamInfo{"triangle meshes"});
    v("grooms", grooms, ParamInfo{"groom files any hair model can run (hair[].groom)"});
  }
};

struct CameraSpec {
  Vec3 eye{0, 0, 1};
  Vec3 target{0, 0, 0};
  Vec3 up{0, 1, 0};
  double fov_deg = 30.0;
  double near = 0.01;
  double far = 100.0;

  template <class V>
  void visit(V&& v) {
    v("eye", eye, ParamInfo{"camera position", "m"});
    v("target", target, ParamInfo{"point the camera looks at", "m"});
    v("up", up, ParamInfo{"up direction (need not be unit or orthogonal to the view)"});
    v("fov_deg", fov_deg, ParamInfo{"vertical field of view", "deg", 1.0, 179.0});
    v("near", near, ParamInfo{"near clipping distance", "m", 1e-6, 1e6});
    v("far", far, ParamInfo{"far clipping distance", "m", 1e-6, 1e9});
  }
};

struct LightSpec {
  std::string name;
  Vec3 direction{-0.3, -0.5, -1.0};
  Vec3 color{1, 1, 1};
  double intensity = 1.0;
  bool shadow = false;

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"label (e.g. \"key\", \"fill\", \"rim\")"});
    v("direction", direction,
      ParamInfo{"direction the light travels, from the light into the scene (any length)"});
    v("color", color, ParamInfo{"linear RGB colour", "", 0.0, 1.0});
    v("intensity", intensity, ParamInfo{"multiplier on colour", "", 0.0, 100.0});
    v("shadow", shadow, ParamInfo{"casts a shadow map"});
  }
};

struct RenderSpec {
  int width = 800;
  int height = 800;
  int supersample = 2;
  Vec3 background{0.12, 0.12, 0.14};
  Vec3 ambient_color{1, 1, 1};
  int shadow_map_size = 2048;
  std::string hair_light_pass = "cpu";  // render::RenderSettings::hair_light_pass
  std::string hair_view_pass = "cpu";   // render::RenderSettings::hair_view_pass
  std::string strand_pass = "cpu";      // render::RenderSettings::strand_pass

  template <class V>
  void visit(V&& v) {
    v("width", width, ParamInfo{"image width", "px", 1, 16384});
    v("height", height, ParamInfo{"image height", "px", 1, 16384});
    v("supersample", supersample,
      ParamInfo{"render at this multiple of the size and box-filter down", "", 1, 8});
    v("background", background, ParamInfo{"linear RGB background colour", "", 0.0, 1.0});
    v("ambient_color", ambient_color,
      ParamInfo{"linear RGB ambient light (scaled by each material's ambient)", "", 0.0, 10.0});
    v("shadow_map_size", shadow_map_size, ParamInfo{"shadow map resolution", "px", 256, 16384});
    v("hair_light_pass", hair_light_pass,
      ParamInfo{"hair splat light pass (Bando 2003 §3.4): \"cpu\" exact per particle, or "
                "\"gpu\" in depth slices"});
    v("hair_view_pass", hair_view_pass,
      ParamInfo{"hair splat view pass (Bando 2003 §3.4): \"cpu\" billboards blended on the "
                "CPU (fast on a software rasteriser), or \"gpu\" drawn with GL"});
    v("strand_pass", strand_pass,
      ParamInfo{"strand hair (Anjyo, Daldegan, imported grooms): \"cpu\" antialiased lines "
                "blended in depth order on the CPU (Daldegan 1993 §4; fast on a software "
                "rasteriser), or \"gpu\" GL lines (Daldegan-shaded and shadowed hair stays on "
                "the CPU)"});
  }
};

struct OutputSpec {
  static constexpr const char* kRequired[] = {"type", "path"};
  OutputType type = OutputType::Image;
  std::string path;  // relative to the current working directory

  template <class V>
  void visit(V&& v) {
    v("type", type, ParamInfo{"what to write"});
    v("path", path,
      ParamInfo{"output file (.png), relative to the working directory; `follicle render -o` "
                "overrides it"});
  }
};

struct Scene {
  static constexpr const char* kRequired[] = {"follicle_scene"};
  int follicle_scene = kSceneVersion;
  std::string description;
  Assets assets;
  CameraSpec camera;
  std::vector<LightSpec> lights;
  RenderSpec render;
  std::vector<OutputSpec> outputs;
  std::vector<HairGroupSpec> hair;
  std::optional<AnimationSpec> animation;
  std::vector<SkinSpec> skin;  // skin_section.hpp
  std::optional<HandSpec> hand;
  std::optional<LcpSpec> lcp;

  template <class V>
  void visit(V&& v) {
    v("follicle_scene", follicle_scene,
      ParamInfo{"scene format version", "", double(kSceneVersion), double(kSceneVersion)});
    v("description", description, ParamInfo{"free text"});
    v("assets", assets, ParamInfo{"files the scene uses"});
    v("camera", camera, ParamInfo{"perspective camera"});
    v("lights", lights, ParamInfo{"directional lights"});
    v("render", render, ParamInfo{"image settings"});
    v("outputs", outputs, ParamInfo{"files `follicle render` writes when no -o is given"});
    v("hair", hair, ParamInfo{"hair groups grown on mesh assets (Anjyo 1992)"});
    v("animation", animation,
      ParamInfo{"frame rate, clip length, head motion and wind (absent: a still scene)"});
    v("skin", skin,
      ParamInfo{"face rigs on mesh assets: muscles, tissue, wrinkles, skin colour (Bando 2002)"});
    v("hand", hand,
      ParamInfo{"skeleton-animated MakeHuman hand with joint and fine wrinkles (Bando 2002 §2.7)"});
    v("lcp", lcp, ParamInfo{"loosely connected particle hair (Bando 2003 ch. 3)"});
  }

  /// Cross-field checks the per-key ranges cannot express (near < far, eye != target, unique
  /// mesh names, ...). Errors name the file and the JSON path.
  void validate(const JsonSource& src) const;
};

/// Reads a scene from parsed JSON: checks the version first (clear message for a missing or
/// newer version), then every key strictly, then Scene::validate().
Scene read_scene(const Json& j, const JsonSource& src);
/// parse_json_file + read_scene.
Scene load_scene_file(const std::filesystem::path& path);
/// Scene -> JSON (every key, defaults included); read_scene(write_scene(s)) == s.
Json write_scene(const Scene& s);

}  // namespace follicle::scene
