#pragma once
// Scene section for expressive skin (Bando 2002 §2.5, §2.7): `"skin": [...]`, one face rig per
// mesh asset: Waters muscles from a face-setup file (data/muscles/*.json), an expression or
// explicit contractions, subcutaneous tissue, large-scale wrinkles (switchable, editable, r for
// aged skin), skin colour (2.6) and the shading model; plus an optional contraction track
// (keyframes of expressions / per-muscle contractions over the scene's animation clock).
// Same pattern as scene.hpp: every struct lists its keys once in visit().
#include <array>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/texture_mapping_bando2002.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/skin/adaptive_refine_volino1999.hpp"
#include "follicle/skin/fine_wrinkles_bando2002.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"
#include "follicle/skin/skin_color_bando2002.hpp"
#include "follicle/skin/tissue_bando2002.hpp"
#include "follicle/skin/wrinkle_transfer.hpp"

namespace follicle::scene {

enum class SkinShading { Lafortune, BlinnPhong };
constexpr std::array<std::pair<SkinShading, const char*>, 2> follicle_enum_names(SkinShading) {
  return {{{SkinShading::Lafortune, "lafortune"}, {SkinShading::BlinnPhong, "blinn_phong"}}};
}

enum class SkinAlbedo { SkinColor, Texture };
constexpr std::array<std::pair<SkinAlbedo, const char*>, 2> follicle_enum_names(SkinAlbedo) {
  return {{{SkinAlbedo::SkinColor, "skin_color"}, {SkinAlbedo::Texture, "texture"}}};
}

/// Skin colour c = b - m a_m - h a_h (2.6): a preset, optionally with its own m and h.
struct SkinColorSpec {
  std::string preset = "caucasian";
  std::optional<double> melanin;
  std::optional<double> hemoglobin;

  template <class V>
  void visit(V&& v) {
    v("preset", preset,
      ParamInfo{"colour preset: pale, caucasian, asian, tanned, african (Bando 2002 §2.7)"});
    v("melanin", melanin, ParamInfo{"amount of melanin m (default: the preset's)", "", 0.0, 1.0});
    v("hemoglobin", hemoglobin,
      ParamInfo{"amount of hemoglobin h (default: the preset's)", "", 0.0, 1.0});
  }
  /// The preset with the overrides applied; throws follicle::Error for an unknown preset.
  skin::SkinColorParams resolve() const;
};

/// Edits one wrinkle of the face-setup file, found by name; absent keys keep the file's value.
struct WrinkleOverride {
  static constexpr const char* kRequired[] = {"name"};
  std::string name;
  std::optional<double> depth, width, r, end_taper;
  std::optional<Vec2> p0, p1, p2, p3;

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"name of a wrinkle of the face-setup file"});
    v("depth", depth, ParamInfo{"furrow depth d", "m", 0.0, 0.1});
    v("width", width, ParamInfo{"furrow width w", "m", 1e-6, 0.1});
    v("r", r,
      ParamInfo{"rest amplitude ratio r of (2.4) (r > 0: visible at rest, aged skin)", "", 0.0,
                1.0});
    v("end_taper", end_taper, ParamInfo{"end taper fraction", "", 0.0, 0.5});
    v("p0", p0, ParamInfo{"Bezier control point 0 (texture space)", "", -10.0, 10.0});
    v("p1", p1, ParamInfo{"Bezier control point 1 (texture space)", "", -10.0, 10.0});
    v("p2", p2, ParamInfo{"Bezier control point 2 (texture space)", "", -10.0, 10.0});
    v("p3", p3, ParamInfo{"Bezier control point 3 (texture space)", "", -10.0, 10.0});
  }
};

/// One key of a contraction track: a pose (expression * weight, then explicit contractions and
/// jaw angle) at time t. Poses between keys are interpolated per muscle (anim::KeyframeTrack).
struct SkinKey {
  static constexpr const char* kRequired[] = {"t"};
  double t = 0.0;
  std::string expression = "neutral";
  double weight = 1.0;
  std::map<std::string, double> contractions;
  std::optional<double> jaw_angle;
  std::map<std::string, double> shapes;

  template <class V>
  void visit(V&& v) {
    v("t", t, ParamInfo{"key time", "s", 0.0, 1e6});
    v("expression", expression,
      ParamInfo{"expression of the face-setup file (\"\": none, only the contractions)"});
    v("weight", weight, ParamInfo{"expression weight (0 neutral, 1 full)", "", -2.0, 2.0});
    v("contractions", contractions,
      ParamInfo{"per-muscle contractions by name, replacing the expression's", "", -10.0, 10.0});
    v("jaw_angle", jaw_angle,
      ParamInfo{"jaw opening, replacing the expression's", "rad", -1.5, 1.5});
    v("shapes", shapes,
      ParamInfo{"blendshape weights by target name (skin[].blendshapes; unnamed targets 0)", "",
                -2.0, 2.0});
  }
};

/// One blendshape target of a skin rig: the rig's mesh with its vertices moved (same vertex count,
/// order and faces), read in the mesh asset's units.
struct BlendshapeSpec {
  static constexpr const char* kRequired[] = {"name", "path"};
  std::string name;
  std::string path;
  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"target name (skin[].shapes, track[].shapes)"});
    v("path", path,
      ParamInfo{"mesh file of the target (OBJ, PLY, glTF; same topology as the rig's mesh, in "
                "its units), relative to the scene file"});
  }
};

/// One user-given direction of a fine-wrinkle field (skin::DirectionKey, Bando 2002 §2.6.1): at a
/// uv vertex of the mesh asset, given by its index, as the uv vertex nearest a texture position,
/// or as the vertex nearest a point on the skin; the direction in texture space or as a tangent
/// on the skin. Keys in the mesh's own texture space are carried to a new layout
/// (skin[].mapping) through the surface; a mesh without UVs takes only point and tangent.
struct FineDirectionKeySpec {
  std::optional<int> vertex;
  std::optional<Vec2> uv;
  std::optional<Vec3> point;
  std::optional<Vec2> direction;
  std::optional<Vec3> tangent;

  template <class V>
  void visit(V&& v) {
    v("vertex", vertex,
      ParamInfo{"uv vertex index of the mesh asset's own layout (give one of vertex, uv, point)",
                "", 0.0, 1e9});
    v("uv", uv,
      ParamInfo{"texture position in the mesh asset's own layout; the key goes to the nearest uv "
                "vertex (give one of vertex, uv, point)",
                "", -10.0, 10.0});
    v("point", point,
      ParamInfo{"point on the skin (metres, the mesh's frame); the key goes to the nearest vertex "
                "(give one of vertex, uv, point)",
                "m", -100.0, 100.0});
    v("direction", direction,
      ParamInfo{"furrow direction in texture space (u, v) of the mesh asset's own layout; its "
                "magnitude m in [0, 1] sets depth, width and length of the furrows (2.5) (give "
                "direction or tangent)",
                "", -1.0, 1.0});
    v("tangent", tangent,
      ParamInfo{"furrow direction on the skin (mesh frame; projected onto the surface), magnitude "
                "m in [0, 1] as for direction (give direction or tangent)",
                "", -1.0, 1.0});
  }
};

/// Fine-scale wrinkles on the face (Bando 2002 §2.6): two direction fields interpolated from keys
/// over the mesh asset (the rig's base mesh), furrows carved into two height images, modulated
/// per frame by M(s) (2.4) of the shrinkage (2.3) perpendicular to each field and bump-mapped.
struct FineWrinkleSpec {
  std::vector<FineDirectionKeySpec> field0, field1;
  skin::FineWrinkleParams params{1024, 1.0, 0.3, 200, true, 60e-6, 0.5};
  uint64_t seed = 1;
  double bump_strength = 1.0;
  bool modulate = true;

  template <class V>
  void visit(V&& v) {
    v("field0", field0, ParamInfo{"direction keys of the first field (at least one)"});
    v("field1", field1, ParamInfo{"direction keys of the second field (at least one)"});
    params.visit(v);  // resolution, unit_texels, unit_mm, max_failures, fill_pass, depth_m, r
    v("seed", seed, ParamInfo{"random seed of the furrow carving"});
    v("bump_strength", bump_strength,
      ParamInfo{"bump-map strength of the fine relief on the render material", "", 0.0, 100.0});
    v("modulate", modulate,
      ParamInfo{"modulate the relief per frame by M(s) (2.4) of the shrinkage (false: the rest "
                "relief, M = r)"});
  }
};

/// A face rig on one mesh asset.
struct SkinSpec {
  static constexpr const char* kRequired[] = {"mesh"};
  std::string mesh;
  std::string muscles;
  std::vector<BlendshapeSpec> blendshapes;
  std::map<std::string, double> shapes;
  std::string expression = "neutral";
  double weight = 1.0;
  std::map<std::string, double> contractions;
  std::optional<double> jaw_angle;
  bool wrinkles = true;
  std::optional<double> wrinkle_r;
  std::vector<WrinkleOverride> wrinkle_overrides;
  std::vector<skin::LargeWrinkle> add_wrinkles;
  std::vector<skin::SurfaceWrinkle> add_surface_wrinkles;
  geom::TextureMappingParams mapping;
  skin::TissueParams tissue;
  skin::RefineParams refine;
  SkinAlbedo albedo = SkinAlbedo::SkinColor;
  SkinColorSpec color;
  SkinShading shading = SkinShading::Lafortune;
  std::vector<SkinKey> track;
  std::string interp = "smooth";
  std::optional<FineWrinkleSpec> fine;

  template <class V>
  void visit(V&& v) {
    v("mesh", mesh, ParamInfo{"name of the mesh asset (assets.meshes[].name) the rig deforms"});
    v("muscles", muscles,
      ParamInfo{"face-setup file (muscles, expressions, wrinkles; e.g. "
                "data/muscles/lee_perry_smith.json), relative to the scene file (\"\": none; "
                "then the rig needs blendshapes)"});
    v("blendshapes", blendshapes,
      ParamInfo{"blendshape targets: the mesh with its vertices moved, blended in by `shapes` on "
                "top of the muscles; wrinkles follow the shrinkage of the whole deformation"});
    v("shapes", shapes,
      ParamInfo{"blendshape weights by target name when there is no track (0 neutral, 1 the "
                "target)",
                "", -2.0, 2.0});
    v("expression", expression,
      ParamInfo{"expression of the face-setup file shown when there is no track (\"\": none, "
                "only the contractions)"});
    v("weight", weight, ParamInfo{"expression weight (0 neutral, 1 full)", "", -2.0, 2.0});
    v("contractions", contractions,
      ParamInfo{"per-muscle contractions by name, replacing the expression's", "", -10.0, 10.0});
    v("jaw_angle", jaw_angle,
      ParamInfo{"jaw opening, replacing the expression's", "rad", -1.5, 1.5});
    v("wrinkles", wrinkles,
      ParamInfo{"apply the large-scale wrinkles (false: the same face without furrows)"});
    v("wrinkle_r", wrinkle_r,
      ParamInfo{"rest amplitude ratio r of (2.4) for every wrinkle (r > 0: aged skin, furrows at "
                "rest)",
                "", 0.0, 1.0});
    v("wrinkle_overrides", wrinkle_overrides,
      ParamInfo{"per-wrinkle edits by name (applied after wrinkle_r)"});
    v("add_wrinkles", add_wrinkles,
      ParamInfo{"extra wrinkles (Bezier furrows in the texture space of the mesh asset's own "
                "layout)"});
    v("add_surface_wrinkles", add_surface_wrinkles,
      ParamInfo{"extra wrinkles given by points on the skin (metres, the mesh's frame)"});
    v("mapping", mapping,
      ParamInfo{"texture space of the rig (Bando 2002 §2.4): the mesh's own UVs, or a planar or "
                "cylindrical projection with harmonic distortion minimization (auto: the mesh's "
                "UVs when it has them)"});
    v("tissue", tissue,
      ParamInfo{"subcutaneous tissue (thickness_map relative to the scene file)"});
    v("refine", refine, ParamInfo{"adaptive refinement around the wrinkles"});
    v("albedo", albedo,
      ParamInfo{"skin_color: the colour of `color` per vertex; texture: the mesh asset's texture"});
    v("color", color, ParamInfo{"skin colour (2.6) from melanin and hemoglobin"});
    v("shading", shading, ParamInfo{"lafortune (skin BRDF, Bando 2002 §2.7) or blinn_phong"});
    v("track", track,
      ParamInfo{"contraction keyframes over the animation clock (needs \"animation\")"});
    v("interp", interp, ParamInfo{"track interpolation: step, linear, smooth"});
    v("fine", fine,
      ParamInfo{"fine-scale wrinkles (Bando 2002 §2.6): two direction fields, bump-mapped relief"});
  }
};

/// Cross-field checks of the skin section (mesh names, track order, colour preset); errors name
/// the file and JSON path. Called by Scene::validate.
void validate_skin_section(const std::vector<SkinSpec>& skin,
                           const std::vector<std::string>& mesh_names, bool has_animation,
                           const JsonSource& src);

}  // namespace follicle::scene
