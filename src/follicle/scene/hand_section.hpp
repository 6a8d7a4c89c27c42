#pragma once
// Scene sections for the skeleton-animated MakeHuman hand (Bando 2002 §2.7, Figs. 2.16/2.17:
// `"hand": {...}`) and for loosely connected particle hair (Bando 2003 ch. 3, Figs. 3.7-3.9:
// `"lcp": {...}`). Same pattern as scene.hpp: every struct lists its keys once in visit().
#include <optional>
#include <string>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/lcp_scenario_bando2003.hpp"
#include "follicle/render/render_scene.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/skin/hand_rig.hpp"

namespace follicle::scene {

struct HandMaterialSpec {
  Vec3 base_color{0.78, 0.56, 0.46};
  double specular = 0.12;
  double shininess = 24.0;
  double ambient = 0.2;

  template <class V>
  void visit(V&& v) {
    v("base_color", base_color, ParamInfo{"linear RGB skin colour", "", 0.0, 1.0});
    v("specular", specular, ParamInfo{"Blinn-Phong specular weight", "", 0.0, 1.0});
    v("shininess", shininess, ParamInfo{"Blinn-Phong exponent", "", 1.0, 10000.0});
    v("ambient", ambient, ParamInfo{"ambient weight", "", 0.0, 1.0});
  }
};

/// The MakeHuman hand rig (linear blend skinning, finger-joint wrinkles, fine wrinkles modulated
/// per frame and bump-mapped). Scene coordinates are those of the MakeHuman base mesh [m].
struct HandSpec {
  std::string makehuman = "../makehuman";
  skin::HandRigParams rig;
  bool wrinkles = true;
  std::optional<double> flexion;
  double track_speed = 1.0;
  HandMaterialSpec material;
  bool cast_shadow = true;

  template <class V>
  void visit(V&& v) {
    v("makehuman", makehuman,
      ParamInfo{"folder with base.obj, default.mhskel and default_weights.mhw, relative to the "
                "scene file"});
    v("rig", rig, ParamInfo{"hand rig: joint wrinkles, fine wrinkles, bump strength"});
    v("wrinkles", wrinkles,
      ParamInfo{"draw joint and fine wrinkles (false: the plain skinned hand, Figs. 2.16a/2.17a)"});
    v("flexion", flexion,
      ParamInfo{"constant finger flexion, 0 = rest (absent: follow the rig's flexion track, "
                "0 -> 1 -> 0 over 2 s, at the frame time)",
                "", 0.0, 1.0});
    v("track_speed", track_speed,
      ParamInfo{"time scale of the flexion track (2: twice as fast)", "", 1e-3, 1e3});
    v("material", material, ParamInfo{"skin appearance"});
    v("cast_shadow", cast_shadow, ParamInfo{"whether the hand casts shadows"});
  }
  void validate() const { rig.validate(); }
};

struct LcpRenderSpec {
  Vec3 color{0.20, 0.105, 0.05};
  double radius = 0.006;
  double opacity = 0.7;
  render::SplatMaterial splat;
  bool show_head = true;
  Vec3 head_color{0.75, 0.55, 0.45};
  bool show_air = false;
  double air_radius = 0.0015;

  template <class V>
  void visit(V&& v) {
    v("color", color, ParamInfo{"linear RGB hair colour", "", 0.0, 1.0});
    v("radius", radius, ParamInfo{"splat radius of a hair particle", "m", 1e-5, 1.0});
    v("opacity", opacity, ParamInfo{"splat opacity alpha (scaled by 1/sin theta)", "", 0.0, 1.0});
    v("splat", splat,
      ParamInfo{"splat shading: Kajiya-Kay + Goldman, billboard shape, self-shadowing"});
    v("show_head", show_head,
      ParamInfo{"draw the sphere head (a mesh head, lcp.mesh, is drawn as its asset)"});
    v("head_color", head_color, ParamInfo{"linear RGB colour of the sphere head", "", 0.0, 1.0});
    v("show_air", show_air, ParamInfo{"draw the SPH air particles as small dots (wind)"});
    v("air_radius", air_radius, ParamInfo{"dot radius of an air particle", "m", 1e-5, 1.0});
  }
};

/// A parting force (Fig. 3.7): between t0 and t1 every free particle is pushed away from the
/// plane x = centre_x with `accel` (sin^2 ramp in and out), so the back hair splits in two; after
/// t1 gravity swings the halves back together, where they merge (hair-hair interaction on) or
/// pass through each other (off).
struct LcpPartSpec {
  double t0 = 0.1;
  double t1 = 0.7;
  double accel = 8.0;
  double centre_x = 0.0;

  template <class V>
  void visit(V&& v) {
    v("t0", t0, ParamInfo{"start of the parting force", "s", 0.0, 1e5});
    v("t1", t1, ParamInfo{"end of the parting force", "s", 0.0, 1e5});
    v("accel", accel, ParamInfo{"peak acceleration away from the parting plane", "m/s^2", 0, 1e3});
    v("centre_x", centre_x, ParamInfo{"x of the parting plane (head frame)", "m", -10, 10});
  }
  /// Acceleration magnitude at time t (0 outside [t0, t1]).
  double at(double t) const;
};

/// Loosely connected particle hair on a head (hair::LcpScenario): back hair under gravity,
/// optionally a head shake and SPH wind. Without `mesh` the head is a sphere centred at the
/// origin; with `mesh` the hair grows on that mesh asset (its transform applied; the scalp,
/// whirl, shake pivot and torso are scenario.mesh_head, in those scene coordinates) and the mesh
/// moves with the head shake.
struct LcpSpec {
  std::string mesh;        // mesh asset name ("" = sphere head of scenario.head_radius)
  std::string length_map;  // grayscale image of the hair length over the scalp ("" = uniform)
  hair::LcpScenarioParams scenario;
  hair::LcpParams dynamics;
  int steps_per_frame = 2;
  uint64_t seed = 1;
  std::optional<LcpPartSpec> part;
  LcpRenderSpec render;

  template <class V>
  void visit(V&& v) {
    v("mesh", mesh,
      ParamInfo{"mesh asset the hair grows on (\"\" = a sphere of scenario.head_radius)"});
    v("length_map", length_map,
      ParamInfo{"grayscale PNG/JPEG of the hair length L(u, v) / hair_length over the scalp "
                "(row 0 = v = 1, the crown; \"\" = uniform), relative to the scene file"});
    v("scenario", scenario,
      ParamInfo{"head, hair length, particle spacing, mass, head shake and wind"});
    v("dynamics", dynamics,
      ParamInfo{"LCP dynamics (sub-steps, stiffness, hair-hair interaction, body collision)"});
    v("steps_per_frame", steps_per_frame,
      ParamInfo{"simulation steps per animation frame (each sub-stepped by dynamics.substeps "
                "or more)",
                "", 1, 10000});
    v("seed", seed, ParamInfo{"random seed of the particle sampling"});
    v("part", part,
      ParamInfo{"parting force that splits the back hair in two (Fig. 3.7; not with shake or "
                "wind)"});
    v("render", render, ParamInfo{"how the particles are drawn"});
  }
  void validate() const;
};

}  // namespace follicle::scene
