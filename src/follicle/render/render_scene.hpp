#pragma once
// RenderScene: everything the renderer draws, as plain data. The renderer never sees a solver;
// scene::Session fills this from simulation state. Units: metres, radians; colours linear RGB.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"

namespace follicle::render {

struct Camera {
  Vec3 eye{0, 0, 1};
  Vec3 target{0, 0, 0};
  Vec3 up{0, 1, 0};
  double fov_y = 0.6;    // [rad] vertical field of view
  double z_near = 0.01;  // [m]
  double z_far = 100.0;  // [m]

  template <class V>
  void visit(V&& v) {
    v("eye", eye, ParamInfo{"camera position", "m"});
    v("target", target, ParamInfo{"point looked at", "m"});
    v("up", up, ParamInfo{"up direction", ""});
    v("fov_y", fov_y, ParamInfo{"vertical field of view", "rad", 1e-3, 3.1});
    v("z_near", z_near, ParamInfo{"near clip distance", "m", 1e-6, 1e6});
    v("z_far", z_far, ParamInfo{"far clip distance", "m", 1e-5, 1e9});
  }
  /// Also checks eye != target, up not parallel to the view direction and z_near < z_far.
  void validate() const;
};

struct DirectionalLight {
  Vec3 direction{-0.3, -0.5, -1.0};  // direction the light travels (from light towards scene)
  Vec3 color{1, 1, 1};
  double intensity = 1.0;
  bool cast_shadow = true;
};

enum class MeshShading {
  BlinnPhong,     // Lambert diffuse + Blinn-Phong specular
  LafortuneSkin,  // Lafortune multi-lobe skin BRDF (Bando 2003 §2.7); lobes in `lafortune`
  Unlit,          // per-vertex colour or texture as is (error maps, debugging)
};

/// One generalized cosine lobe: max(0, Cxy (wo.x wi.x + wo.y wi.y) + Cz wo.z wi.z)^n, per
/// channel (see docs/skin-constants.md §4.1).
struct LafortuneLobe {
  Vec3 cxy{0, 0, 0};
  Vec3 cz{0, 0, 0};
  Vec3 n{1, 1, 1};
};

struct LafortuneBrdf {
  Vec3 rho_d{0, 0, 0};  // diffuse albedo
  std::vector<LafortuneLobe> lobes;
};

struct MeshMaterial {
  MeshShading shading = MeshShading::BlinnPhong;
  Vec3 base_color{0.8, 0.65, 0.55};  // used when there is no texture or per-vertex colour
  double specular = 0.15;
  double shininess = 32.0;
  double ambient = 0.15;
  LafortuneBrdf lafortune;                              // for LafortuneSkin
  std::shared_ptr<const image::ImageRGBA8> albedo_map;  // sRGB texture over the mesh UVs
  std::shared_ptr<const image::ImageF> height_map;      // bump map over the mesh UVs [m]
  double bump_strength = 1.0;
  std::shared_ptr<const image::ImageRGBF> normal_map;  // tangent space, [-1,1]^3
};

struct MeshItem {
  std::shared_ptr<const geom::TriMesh> mesh;
  Affine3 transform = Affine3::Identity();
  MeshMaterial material;
  std::vector<Vec3f> vertex_colors;  // linear RGB per position vertex, optional
  bool cast_shadow = true;
};

enum class StrandShading {
  VertexColor,   // colours computed on the CPU (e.g. Anjyo 1992 eq. 8-9) drawn as they are
  KajiyaKay,     // Kajiya-Kay diffuse + specular from the strand tangent
  Daldegan1993,  // Daldegan et al. 1993 §4: eq. (7) at every segment endpoint, shadowed by the
                 // composite shadow buffers, blended on the CPU (hair_blend_daldegan1993.hpp)
};

struct StrandMaterial {
  StrandShading shading = StrandShading::KajiyaKay;
  Vec3 color{0.25, 0.15, 0.08};  // when the StrandSet has no colours
  double diffuse = 0.8;
  double specular = 0.35;
  double shininess = 40.0;
  double ambient = 0.15;
  double width_px = 1.0;  // line width in output pixels (before supersampling)
  double opacity = 1.0;
  // The CPU shadow-buffer hair pass (Daldegan1993 shading or StrandItem::hair_shadow): the
  // lookup of a hair point in a light's composite shadow buffer (Reeves et al. 1987 PCF).
  double shadow_bias = 1.5;        // [shadow texels] constant depth bias
  double shadow_slope_bias = 2.0;  // [shadow texels] times cot(angle of the hair to the light)
  int shadow_filter_radius = 1;    // PCF box of (2 r + 1)^2 texels
};

/// Strands go through the CPU shadow-buffer hair pass of Daldegan et al. 1993 §4
/// (hair_blend_daldegan1993.hpp; docs/equations/daldegan_render.md) when
/// RenderSettings::strand_pass is "cpu" (the default) or the item has StrandShading::Daldegan1993
/// or hair_shadow; otherwise ("gpu") they are GL lines/ribbons. In the CPU pass every light with
/// cast_shadow gets a hair shadow buffer of the casting items (hair_shadow or cast_shadow),
/// composed with the scene's (so that hair shadows the meshes, in the GL mesh pass for the
/// first shadow light), and the hair is blended into the rendered scene as antialiased lines in
/// depth order. Items with hair_shadow or Daldegan1993 shading are shadowed by those buffers
/// (hair shadows itself); the others are lit without shadows, as the GL strand pass lights
/// them. Colours of that pass: Daldegan1993 and KajiyaKay shade with eq. (7) (K_A = ambient x
/// colour, K_D = diffuse x colour, K_S = specular, n = shininess, S_i from each light's
/// composite buffer, 1 when unshadowed: the Kajiya-Kay terms of the GL pass); VertexColor keeps
/// its colours c (e.g. Anjyo 1992 eq. 8-9), shadowed: times (ambient + (1 - ambient) S) of the
/// first shadow-casting light. In the GL pass cast_shadow draws the item into the GL shadow
/// map.
struct StrandItem {
  std::shared_ptr<const geom::StrandSet> strands;
  Affine3 transform = Affine3::Identity();
  StrandMaterial material;
  bool cast_shadow = true;
  bool hair_shadow = false;  // CPU pass, shadowed by and casting into the hair shadow buffers
};

enum class ParticleShading {
  Flat,       // colour (and opacity) of each particle as given
  HairSplat,  // textured billboards aligned with the particle direction (Bando 2003 §3.4)
};

/// Hair splatting parameters (Bando 2003 §3.4; formulas in docs/equations/splat.md). Used by
/// ParticleShading::HairSplat: every particle is a billboard 2*width_scale*r wide across and
/// 2*length_scale*r long along its direction t_i (r = its radius), textured with a hair texture
/// whose vertical axis follows t_i, of opacity min(1, alpha / max(sin(theta), min_sin_theta))
/// where cos(theta) = t_i . d_p, and shaded by the Kajiya-Kay phase function times Goldman's
/// directionality factor f_dir = (1+kappa)/2 reflect + (1-kappa)/2 transmit.
struct SplatMaterial {
  double diffuse = 0.8;               // Kajiya-Kay K_d
  double specular = 0.25;             // Kajiya-Kay K_s
  double shininess = 30.0;            // Kajiya-Kay exponent p
  double ambient = 0.12;              // ambient factor (times RenderScene::ambient_color)
  double reflect = 1.0;               // Goldman rho_reflect (eye on the lit side, kappa = +1)
  double transmit = 0.35;             // Goldman rho_transmit (back-lit, kappa = -1)
  double length_scale = 3.0;          // billboard half-length along t_i, in particle radii
  double width_scale = 1.0;           // billboard half-width across t_i, in particle radii
  double min_sin_theta = 0.25;        // clamp of sin(theta) in the 1/sin(theta) opacity rule
  double shadow_opacity_scale = 1.0;  // opacity multiplier in the light-view pass
  bool self_shadow = true;  // particles read the light attenuated by the hair nearer the light
  bool cast_shadow = true;  // particles attenuate light for other particles and for the meshes

  template <class V>
  void visit(V&& v) {
    v("diffuse", diffuse, ParamInfo{"Kajiya-Kay diffuse coefficient K_d", "", 0, 10});
    v("specular", specular, ParamInfo{"Kajiya-Kay specular coefficient K_s", "", 0, 10});
    v("shininess", shininess, ParamInfo{"Kajiya-Kay specular exponent", "", 0, 10000});
    v("ambient", ambient, ParamInfo{"ambient factor", "", 0, 10});
    v("reflect", reflect, ParamInfo{"Goldman directionality: reflection factor", "", 0, 10});
    v("transmit", transmit, ParamInfo{"Goldman directionality: transmission factor", "", 0, 10});
    v("length_scale", length_scale,
      ParamInfo{"billboard half-length along the hair direction", "radii", 1e-3, 1e3});
    v("width_scale", width_scale,
      ParamInfo{"billboard half-width across the hair direction", "radii", 1e-3, 1e3});
    v("min_sin_theta", min_sin_theta,
      ParamInfo{"lower clamp of sin(theta) in the 1/sin(theta) opacity rule", "", 1e-3, 1});
    v("shadow_opacity_scale", shadow_opacity_scale,
      ParamInfo{"opacity multiplier in the light-view (shadow) pass", "", 0, 100});
    v("self_shadow", self_shadow, ParamInfo{"hair shadows itself", ""});
    v("cast_shadow", cast_shadow, ParamInfo{"hair casts shadows on hair and meshes", ""});
  }
  void validate() const { validate_params(*this, "splat"); }
};

struct ParticleItem {
  std::shared_ptr<const geom::ParticleSet> particles;
  Affine3 transform = Affine3::Identity();
  ParticleShading shading = ParticleShading::Flat;
  Vec3 color{0.3, 0.2, 0.1};  // linear RGB when the set has no colours (the hair colour)
  double radius = 0.002;      // [m] when the set has no radii
  double opacity = 1.0;       // times the per-particle opacity of the set
  SplatMaterial splat;        // for HairSplat
  /// For HairSplat: RGB = brightness factor (linear), A = coverage; the hair runs along the
  /// image's vertical axis. Null: the procedural make_hair_texture(). HairSplat items drawn
  /// together must use the same texture (or null).
  std::shared_ptr<const image::ImageRGBA8> hair_texture;

  template <class V>
  void visit(V&& v) {
    v("color", color, ParamInfo{"colour when the particles have none", "", 0, 1000});
    v("radius", radius, ParamInfo{"radius when the particles have none", "m", 0, 1e6});
    v("opacity", opacity, ParamInfo{"opacity multiplier", "", 0, 1});
    v("splat", splat);
  }
  /// Checks the parameters (not the particle data; the renderer checks that, naming the item).
  void validate() const { validate_params(*this, "particles"); }
};

struct RenderScene {
  Camera camera;
  std::vector<DirectionalLight> lights;
  Vec3 ambient_color{1, 1, 1};
  Vec3 background{0.12, 0.12, 0.14};
  std::vector<MeshItem> meshes;
  std::vector<StrandItem> strands;
  std::vector<ParticleItem> particles;
};

struct RenderSettings {
  int width = 800;
  int height = 800;
  int supersample = 2;  // render at (supersample * size) and box-filter down
  int shadow_map_size = 2048;
  bool transparent_background = false;  // background alpha 0 instead of 1 (output alpha = coverage)
  int hair_light_map_size = 512;  // light-view buffer of the hair splat pass (Bando 2003 §3.4)
  /// Hair light-view pass (Bando 2003 §3.4 lines 6-12): "cpu" reads and splats exactly particle
  /// by particle on the CPU (docs/adr/0005-cpu-splat-light-pass.md); "gpu" batches the reads in
  /// `hair_light_slices` depth slices on the GPU (docs/adr/0003-splat-light-pass.md).
  std::string hair_light_pass = "cpu";
  /// "gpu" pass only: depth slices; particles are sorted by depth from the light and cut into
  /// this many equal batches; each batch reads the light reaching it, then is splatted.
  /// >= the particle count reproduces the paper's per-particle read exactly.
  int hair_light_slices = 128;
  /// Hair view pass (Bando 2003 §3.4 lines 17-21): "cpu" blends the billboards into the
  /// read-back colour buffer on the CPU (docs/adr/0007-cpu-splat-view-pass.md; several times
  /// faster than a software GL rasteriser), "gpu" draws them with GL.
  std::string hair_view_pass = "cpu";
  /// Strand items (StrandItem): "cpu" draws all of them with the CPU hair pass of Daldegan et
  /// al. 1993 §4 (antialiased lines blended in depth order, hair_blend_daldegan1993.hpp;
  /// docs/adr/0018-cpu-strand-pass.md: 4.5x faster than llvmpipe's GL lines for 100k strands),
  /// "gpu" draws those without Daldegan1993 shading or hair_shadow as GL lines / ribbons.
  std::string strand_pass = "cpu";

  template <class V>
  void visit(V&& v) {
    v("width", width, ParamInfo{"output width", "px", 1, 16384});
    v("height", height, ParamInfo{"output height", "px", 1, 16384});
    v("supersample", supersample, ParamInfo{"supersampling factor per axis", "", 1, 8});
    v("shadow_map_size", shadow_map_size, ParamInfo{"shadow map resolution", "px", 16, 16384});
    v("transparent_background", transparent_background, ParamInfo{"background alpha 0", ""});
    v("hair_light_map_size", hair_light_map_size,
      ParamInfo{"hair light-view buffer resolution", "px", 16, 16384});
    v("hair_light_pass", hair_light_pass,
      ParamInfo{"hair light-view pass: \"cpu\" (exact per particle) or \"gpu\" (depth slices)"});
    v("hair_light_slices", hair_light_slices,
      ParamInfo{"depth slices of the \"gpu\" hair light-view pass", "", 1, 1 << 24});
    v("hair_view_pass", hair_view_pass,
      ParamInfo{"hair view pass: \"cpu\" (billboards blended on the CPU) or \"gpu\" (GL)"});
    v("strand_pass", strand_pass,
      ParamInfo{"strands: \"cpu\" (antialiased lines blended on the CPU) or \"gpu\" (GL lines)"});
  }
  void validate() const {
    validate_params(*this, "render");
    if (const std::string e = hair_light_pass_error(hair_light_pass); !e.empty())
      fail_at("render.hair_light_pass", "{}", e);
    if (const std::string e = hair_light_pass_error(hair_view_pass); !e.empty())
      fail_at("render.hair_view_pass", "{}", e);
    if (const std::string e = hair_light_pass_error(strand_pass); !e.empty())
      fail_at("render.strand_pass", "{}", e);
  }
  /// Empty when `v` names a hair light-view, view or strand pass ("cpu" or "gpu"), else what is
  /// wrong with it (shared by the scene reader, which reports it at the JSON path).
  static std::string hair_light_pass_error(const std::string& v) {
    if (v == "cpu" || v == "gpu") return {};
    return "unknown value \"" + v + "\"; expected \"cpu\" or \"gpu\"";
  }
};

}  // namespace follicle::render
