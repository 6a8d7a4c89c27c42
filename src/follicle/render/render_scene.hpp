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
  VertexColor,  // colours computed on the CPU (e.g. Anjyo 1992 eq. 8-9) drawn as they are
  KajiyaKay,    // Kajiya-Kay diffuse + specular from the strand tangent
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
};

struct StrandItem {
  std::shared_ptr<const geom::StrandSet> strands;
  Affine3 transform = Affine3::Identity();
  StrandMaterial material;
  bool cast_shadow = true;
};

enum class ParticleShading {
  Flat,       // colour (and opacity) of each particle as given
  HairSplat,  // textured billboards aligned with the particle direction (Bando 2003 §3.4)
};

struct ParticleItem {
  std::shared_ptr<const geom::ParticleSet> particles;
  Affine3 transform = Affine3::Identity();
  ParticleShading shading = ParticleShading::Flat;
  Vec3 color{0.3, 0.2, 0.1};
  double radius = 0.002;  // [m] when the set has no radii
  double opacity = 1.0;
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

  template <class V>
  void visit(V&& v) {
    v("width", width, ParamInfo{"output width", "px", 1, 16384});
    v("height", height, ParamInfo{"output height", "px", 1, 16384});
    v("supersample", supersample, ParamInfo{"supersampling factor per axis", "", 1, 8});
    v("shadow_map_size", shadow_map_size, ParamInfo{"shadow map resolution", "px", 16, 16384});
    v("transparent_background", transparent_background, ParamInfo{"background alpha 0", ""});
  }
  void validate() const { validate_params(*this, "render"); }
};

}  // namespace follicle::render
