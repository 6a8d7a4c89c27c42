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
#include "follicle/geom/trimesh.hpp"
#include "follicle/hair/hair_model_bando2003.hpp"
#include "follicle/hair/hair_model_daldegan1993.hpp"
#include "follicle/hair/hairdressing_anjyo1992.hpp"
#include "follicle/hair/hairstyler_daldegan1993.hpp"
#include "follicle/hair/projective_anjyo1992.hpp"
#include "follicle/hair/shading_anjyo1992.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/sim/ellipsoid.hpp"

namespace follicle::scene {

// The hair models every hair[] entry can run on its groom (ADR 0010); the model table is
// make_simulation in session_hair.cpp.
enum class HairModel { Anjyo1992, Daldegan1993, Bando2003 };
constexpr std::array<std::pair<HairModel, const char*>, 3> follicle_enum_names(HairModel) {
  return {{{HairModel::Anjyo1992, "anjyo1992"},
           {HairModel::Daldegan1993, "daldegan1993"},
           {HairModel::Bando2003, "bando2003"}}};
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

/// "style": either a preset name ("bob", "swept_back", "ponytail", "short_cut"), a preset with
/// whole-style settings ({"preset": "bob", "avoid_mesh": true, "collision_margin": 0.004}: every
/// part's beam avoids the real head mesh, e.g. its ears, with that clearance), or a full
/// HairStyle object (parts with pores, beam, fields, cuts, tie; "avoid_mesh" and
/// "collision_margin" may be given beside them too).
struct HairStyleSpec {
  using DocObject = hair::HairStyle;
  std::string preset = "bob";             // used when `custom` is empty
  std::optional<hair::HairStyle> custom;  // the full object form
  std::optional<bool> avoid_mesh;         // whole-style settings, applied to every part's beam
  std::optional<double> collision_margin;

  void read_json_custom(const Json& j, const std::string& path, const JsonSource& src);
  Json to_json_custom() const;
  static std::string doc_type_custom() {
    return "string (preset: \"bob\", \"swept_back\", \"ponytail\", \"short_cut\") or object "
           "(a full style, or {\"preset\", \"avoid_mesh\", \"collision_margin\"})";
  }
  /// The style to grow, densities multiplied by `density_scale`.
  hair::HairStyle resolve(double density_scale) const;
};

/// "styler": the HairStyler of Daldegan et al. 1993 §2 grows the groom: a preset name ("long",
/// "beard", "moustache", "eyebrows", "fur": regions placed from landmarks of the mesh, facing the
/// hull's z axis with its y axis up) or a style object; an object with "preset" starts from that
/// preset and replaces the keys it gives.
struct HairStylerSpec {
  using DocObject = hair::HairStylerParams;
  std::string preset;               // "" = none
  Json overrides = Json::object();  // the object's keys besides "preset"

  void read_json_custom(const Json& j, const std::string& path, const JsonSource& src);
  Json to_json_custom() const;
  static std::string doc_type_custom() {
    return "string (preset: \"long\", \"beard\", \"moustache\", \"eyebrows\", \"fur\") or "
           "object (optionally with \"preset\")";
  }
  bool operator==(const HairStylerSpec&) const = default;
  /// The style on `mesh` (scene coordinates) facing `front` with `up` up; `path` is the JSON path
  /// of this spec for messages.
  hair::HairStylerParams resolve(const geom::TriMesh& mesh, const Vec3& up, const Vec3& front,
                                 const std::string& path, const JsonSource& src) const;
};

struct HairRenderParams {
  double width_px = 1.0;
  double opacity = 1.0;
  bool shadow = false;

  template <class V>
  void visit(V&& v) {
    v("width_px", width_px,
      ParamInfo{"line width in output pixels (narrower lines fade by coverage)", "px", 0.01, 64.0});
    v("opacity", opacity, ParamInfo{"hair opacity", "", 0.0, 1.0});
    v("shadow", shadow,
      ParamInfo{"hair shadow buffers (Daldegan 1993 §4): the hair shadows itself and the meshes, "
                "drawn by the CPU hair pass; always on for daldegan1993"});
  }
};

/// One hair group grown on a mesh asset.
struct HairGroupSpec {
  static constexpr const char* kRequired[] = {"mesh"};
  std::string name = "hair";
  HairModel model = HairModel::Anjyo1992;
  std::string mesh;
  std::string groom;  // assets.grooms[].name; "" = generated by `styler` or `style`
  std::optional<HairStylerSpec> styler;
  double segment_length = 0.0;  // [m] resampling of an imported groom (0 = its own points)
  std::optional<HullSpec> hull;
  sim::EllipsoidFitParams hull_fit;
  HairStyleSpec style;
  double density_scale = 1.0;
  double max_strands = 2e6;  // budget: a style that would grow more fails before growing
  hair::ProjectiveParams dynamics;
  hair::DaldeganParams daldegan;
  hair::BandoParams bando;
  hair::AnjyoShadingParams shading;
  HairRenderParams render;
  uint64_t seed = 1;

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"label of the group"});
    v("model", model, ParamInfo{"hair model"});
    v("mesh", mesh,
      ParamInfo{"name of the mesh asset (assets.meshes[].name) the hair grows on; an imported "
                "groom's roots bind to its nearest points"});
    v("groom", groom,
      ParamInfo{"name of a groom asset (assets.grooms[].name) to run instead of generating the "
                "hair from `style`"});
    v("segment_length", segment_length,
      ParamInfo{"resample every strand of the imported groom by arc length to this segment "
                "length, keeping its length (0: keep the file's points)",
                "m", 0.0, 1.0});
    v("hull", hull,
      ParamInfo{"explicit ellipsoid hull (default: fitted automatically to the mesh)"});
    v("hull_fit", hull_fit, ParamInfo{"automatic hull fit"});
    v("styler", styler,
      ParamInfo{"grow the groom with the HairStyler (Daldegan 1993 §2) instead of `style`"});
    v("style", style,
      ParamInfo{"hairstyle grown on the hull when neither `groom` nor `styler` is given: preset "
                "name or full style (Anjyo 1992 §2)"});
    v("density_scale", density_scale,
      ParamInfo{"multiplies every pore density of the style (previews, tests)", "", 1e-4, 100.0});
    v("max_strands", max_strands,
      ParamInfo{"budget of strands: a style or groom with more is refused before it grows (or, "
                "imported, before it is simulated), naming the count",
                "", 1.0, 1e8});
    v("dynamics", dynamics, ParamInfo{"projective dynamics of model anjyo1992 (Anjyo 1992 §3)"});
    v("daldegan", daldegan,
      ParamInfo{"hinge dynamics, body collision and wisps of model daldegan1993 (Daldegan 1993 "
                "§3)"});
    v("bando", bando,
      ParamInfo{"loosely connected particles of model bando2003 on the groom (Bando 2003; thesis "
                "ch. 3): particle sampling, dynamics, body collision, wisps"});
    v("shading", shading,
      ParamInfo{"anisotropic shading of anjyo1992 and bando2003 hair (Anjyo 1992 §4, eqs. 8-9); "
                "daldegan1993 "
                "hair uses its styler materials and eq. (7)"});
    v("render", render, ParamInfo{"how the strands are drawn"});
    v("seed", seed,
      ParamInfo{"random seed of pores, lengths, k_a and fluctuation, of the HairStyler (unless "
                "styler.seed is given) and of the bando2003 strand choice"});
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

/// A gust of air: 0 before t0, rising smoothly to `peak` at t0 + rise, held until t1, falling
/// smoothly to 0 at t1 + rise.
struct AirGustSpec {
  Vec3 peak{0.0, 0.0, -3.0};
  double t0 = 0.5;
  double t1 = 1.5;
  double rise = 0.25;

  template <class V>
  void visit(V&& v) {
    v("peak", peak, ParamInfo{"air velocity at the height of the gust", "m/s", -1e3, 1e3});
    v("t0", t0, ParamInfo{"start of the gust", "s", 0.0, 1e6});
    v("t1", t1, ParamInfo{"start of its decay", "s", 0.0, 1e6});
    v("rise", rise, ParamInfo{"rise and decay time", "s", 1e-3, 1e3});
  }
  Vec3 at(double t) const;
};

struct WindSpec {
  Vec3 uniform{0.0, 0.0, 0.0};
  std::optional<hair::GustParams> gust;
  Vec3 velocity{0.0, 0.0, 0.0};
  std::optional<AirGustSpec> velocity_gust;

  template <class V>
  void visit(V&& v) {
    v("uniform", uniform, ParamInfo{"constant wind force per unit mass", "m/s^2", -1e4, 1e4});
    v("gust", gust, ParamInfo{"time-varying gust of Anjyo 1992 Fig. 10, added to uniform"});
    v("velocity", velocity,
      ParamInfo{"uniform air velocity, for models with air drag (daldegan1993)", "m/s", -1e3, 1e3});
    v("velocity_gust", velocity_gust, ParamInfo{"a gust of air velocity added to velocity"});
  }
  Vec3 air_at(double t) const {
    return velocity + (velocity_gust ? velocity_gust->at(t) : Vec3::Zero());
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
