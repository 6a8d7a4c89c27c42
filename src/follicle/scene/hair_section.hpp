#pragma once
// Scene sections for hair (Anjyo, Usami, Kurihara 1992) and animation: `"hair": [...]` groups
// grown on a mesh asset, and `"animation": {...}` (frame rate, length, rigid head motion, wind).
// Same pattern as scene.hpp: every struct lists its keys once in visit().
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/hair/hairdressing_anjyo1992.hpp"
#include "follicle/hair/projective_anjyo1992.hpp"
#include "follicle/hair/shading_anjyo1992.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/sim/ellipsoid.hpp"

namespace follicle::scene {

enum class HairModel { Anjyo1992 };
constexpr std::array<std::pair<HairModel, const char*>, 1> follicle_enum_names(HairModel) {
  return {{{HairModel::Anjyo1992, "anjyo1992"}}};
}

/// An explicit ellipsoid hull (Anjyo 1992 §2 step [α]) replacing the automatic fit. Scene
/// (world) coordinates of the mesh at rest, i.e. after the mesh asset's transform.
struct HullSpec {
  static constexpr const char* kRequired[] = {"centre", "radii"};
  Vec3 centre{0.0, 0.0, 0.0};
  Vec3 radii{0.08, 0.1, 0.1};
  Vec3 rotate_deg{0.0, 0.0, 0.0};

  template <class V>
  void visit(V&& v) {
    v("centre", centre, ParamInfo{"hull centre", "m", -1e3, 1e3});
    v("radii", radii,
      ParamInfo{"semi-axes along the hull's local x (left), y (up), z (face)", "m", 1e-4, 10.0});
    v("rotate_deg", rotate_deg,
      ParamInfo{"rotation of the local axes about the fixed x, then y, then z axis", "deg", -360.0,
                360.0});
  }
  sim::Ellipsoid ellipsoid() const;
};

/// "style": either a preset name ("bob", "swept_back", "ponytail", "short_cut") or a full
/// HairStyle object (parts with pores, beam, fields, cuts, tie).
struct HairStyleSpec {
  using DocObject = hair::HairStyle;
  std::string preset = "bob";             // used when `custom` is empty
  std::optional<hair::HairStyle> custom;  // the object form

  void read_json_custom(const Json& j, const std::string& path, const JsonSource& src);
  Json to_json_custom() const;
  static std::string doc_type_custom() {
    return "string (preset: \"bob\", \"swept_back\", \"ponytail\", \"short_cut\") or object";
  }
  /// The style to grow, densities multiplied by `density_scale`.
  hair::HairStyle resolve(double density_scale) const;
};

struct HairRenderParams {
  double width_px = 1.0;
  double opacity = 1.0;

  template <class V>
  void visit(V&& v) {
    v("width_px", width_px,
      ParamInfo{"line width in output pixels (narrower lines fade by coverage)", "px", 0.01, 64.0});
    v("opacity", opacity, ParamInfo{"hair opacity", "", 0.0, 1.0});
  }
};

/// One hair group grown on a mesh asset.
struct HairGroupSpec {
  static constexpr const char* kRequired[] = {"mesh"};
  std::string name = "hair";
  HairModel model = HairModel::Anjyo1992;
  std::string mesh;
  std::optional<HullSpec> hull;
  sim::EllipsoidFitParams hull_fit;
  HairStyleSpec style;
  double density_scale = 1.0;
  hair::ProjectiveParams dynamics;
  hair::AnjyoShadingParams shading;
  HairRenderParams render;
  uint64_t seed = 1;

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"label of the group"});
    v("model", model, ParamInfo{"hair model"});
    v("mesh", mesh, ParamInfo{"name of the mesh asset (assets.meshes[].name) the hair grows on"});
    v("hull", hull,
      ParamInfo{"explicit ellipsoid hull (default: fitted automatically to the mesh)"});
    v("hull_fit", hull_fit, ParamInfo{"automatic hull fit"});
    v("style", style, ParamInfo{"hairstyle: preset name or full style (Anjyo 1992 §2)"});
    v("density_scale", density_scale,
      ParamInfo{"multiplies every pore density of the style (previews, tests)", "", 1e-4, 100.0});
    v("dynamics", dynamics, ParamInfo{"projective dynamics (Anjyo 1992 §3)"});
    v("shading", shading, ParamInfo{"anisotropic shading (Anjyo 1992 §4, eqs. 8-9)"});
    v("render", render, ParamInfo{"how the strands are drawn"});
    v("seed", seed, ParamInfo{"random seed of pores, lengths, k_a and fluctuation"});
  }
};

enum class HeadMotionKind { None, Turn, Shake, Keyframes };
constexpr std::array<std::pair<HeadMotionKind, const char*>, 4> follicle_enum_names(
    HeadMotionKind) {
  return {{{HeadMotionKind::None, "none"},
           {HeadMotionKind::Turn, "turn"},
           {HeadMotionKind::Shake, "shake"},
           {HeadMotionKind::Keyframes, "keyframes"}}};
}

struct HeadKey {
  static constexpr const char* kRequired[] = {"t"};
  double t = 0.0;
  Vec3 translate{0.0, 0.0, 0.0};
  Vec3 rotate_deg{0.0, 0.0, 0.0};

  template <class V>
  void visit(V&& v) {
    v("t", t, ParamInfo{"key time", "s", 0.0, 1e6});
    v("translate", translate, ParamInfo{"offset of the head", "m", -1e3, 1e3});
    v("rotate_deg", rotate_deg,
      ParamInfo{"rotation vector (axis * angle) about the pivot", "deg", -3600.0, 3600.0});
  }
};

/// Rigid head motion: hair groups and the meshes they grow on follow it.
struct HeadMotionSpec {
  HeadMotionKind kind = HeadMotionKind::None;
  Vec3 axis{0.0, 1.0, 0.0};
  double angle_deg = 30.0;
  int cycles = 2;
  double t0 = 0.0;
  double t1 = 1.0;
  std::optional<Vec3> pivot;
  std::vector<HeadKey> keys;
  std::string interp = "smooth";

  template <class V>
  void visit(V&& v) {
    v("kind", kind, ParamInfo{"none, turn (0 to angle), shake (oscillation) or keyframes"});
    v("axis", axis, ParamInfo{"rotation axis of turn/shake (world)", "", -1.0, 1.0});
    v("angle_deg", angle_deg, ParamInfo{"turn angle / shake amplitude", "deg", -360.0, 360.0});
    v("cycles", cycles, ParamInfo{"shake oscillations", "", 1, 1000});
    v("t0", t0, ParamInfo{"motion start", "s", 0.0, 1e6});
    v("t1", t1, ParamInfo{"motion end", "s", 0.0, 1e6});
    v("pivot", pivot,
      ParamInfo{"rotation pivot (default: the bottom of the fitted hull, about the neck)", "m",
                -1e3, 1e3});
    v("keys", keys, ParamInfo{"keyframes (kind \"keyframes\")"});
    v("interp", interp, ParamInfo{"keyframe interpolation: step, linear, smooth"});
  }
};

struct WindSpec {
  Vec3 uniform{0.0, 0.0, 0.0};
  std::optional<hair::GustParams> gust;

  template <class V>
  void visit(V&& v) {
    v("uniform", uniform, ParamInfo{"constant wind force per unit mass", "m/s^2", -1e4, 1e4});
    v("gust", gust, ParamInfo{"time-varying gust of Anjyo 1992 Fig. 10, added to uniform"});
  }
  Vec3 at(double t) const { return uniform + (gust ? gust->at(t) : Vec3::Zero()); }
};

struct AnimationSpec {
  double fps = 24.0;
  int frames = 0;
  double duration = 0.0;
  Vec3 gravity{0.0, -9.81, 0.0};
  HeadMotionSpec head_motion;
  WindSpec wind;

  template <class V>
  void visit(V&& v) {
    v("fps", fps, ParamInfo{"frames per second", "1/s", 1.0, 1000.0});
    v("frames", frames, ParamInfo{"number of frames (0: from duration)", "", 0, 1000000});
    v("duration", duration, ParamInfo{"clip length when frames is 0", "s", 0.0, 1e5});
    v("gravity", gravity, ParamInfo{"gravity acceleration of the dynamics", "m/s^2", -100, 100});
    v("head_motion", head_motion, ParamInfo{"rigid head motion"});
    v("wind", wind, ParamInfo{"wind force field"});
  }
  /// Number of frames of the clip (at least 1).
  int frame_count() const;
};

}  // namespace follicle::scene
