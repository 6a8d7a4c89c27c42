#pragma once
// HairStyler, Daldegan, Magnenat Thalmann, Kurihara, Thalmann 1993 §2: hair grown on the
// triangles of any mesh (scalp, face, body, an object: the same tool makes hair styles, beards,
// moustaches, eyebrows and fur). Every triangle carries the paper's nine parameters
// (TriangleHairParams): a 3-D curve, a material, jitter of the base location, a tangent vector,
// random angle variation, a scale (length) and its random variation, a density and a seed.
//
// Parameters are given to regions of triangles (HairRegion: selectors "all", "mask",
// "triangles", "vertices", "sphere", "box", "half_space"; later regions override earlier ones,
// only the keys they give). With `smooth` (default), the continuous parameters are averaged to
// the vertices and every hair takes the barycentric interpolation at its root, so they vary
// smoothly across triangles ("parameters are assigned to triangle regions and vary smoothly").
//
// Growing is deterministic and independent per triangle: triangle f draws from its own random
// streams keyed by (style seed, triangle seed, f), so editing one triangle never changes the
// hairs of a triangle that does not share a vertex with it (none at all without smoothing), and
// the result is bit-identical for any thread count. The paper's drawing-order problem on a
// deformed mesh is avoided by taking counts and random values from the rest mesh; the tangent is
// then corrected on the deformed triangle (correct_tangent).
//
// Docs: docs/equations/daldegan_styler.md.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/hair/groom.hpp"
#include "follicle/image/image.hpp"

namespace follicle::hair {

// ---------------------------------------------------------------------------------------------
// Curves and materials

/// A hair's 3-D curve (§2: "the three-dimensional curved cylinder is composed of straight
/// cylindrical segments connected by points") in the hair's local frame: x along the hair's
/// tangent on the surface, y along the surface normal, z along the binormal x × y. Any scale:
/// it is sampled to unit arc length and `TriangleHairParams::scale` gives the length.
struct HairCurve {
  std::string name;
  std::vector<Vec3> points;  // control points (a centripetal Catmull-Rom spline runs through them)

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"curve name (triangles refer to it)"});
    v("points", points,
      ParamInfo{"control points, local frame: x = tangent, y = normal, z = binormal (any scale)"});
  }
};

/// Names of the built-in curves: "straight" (along the normal), "swept" (leaves the surface and
/// bends along the tangent, like combed scalp hair), "wavy", "curl", "fur" (short, slightly
/// bent), "eyebrow" (lies almost flat along the tangent), "beard" (out, then down the tangent).
std::vector<std::string> builtin_curve_names();
/// A built-in curve's control points; throws naming the known curves for an unknown name.
HairCurve builtin_curve(std::string_view name);

/// `n` >= 2 points at equal arc length along the centripetal Catmull-Rom spline through the
/// curve's points, scaled to unit arc length, first point at the origin. Throws naming `where`
/// for fewer than 2 points, non-finite or coincident points, or a curve that does not leave the
/// surface (the second sample must have y > 0: hairs never start inside the surface).
std::vector<Vec3> sample_curve(const HairCurve& curve, std::size_t n, const std::string& where);

/// Hair material (§4: the hair material file). The renderer's eq. (7) coefficients are carried,
/// not used here: H = L_A K_A + S_i L_i (K_D sin θ + K_S cos^n(θ + φ)).
struct HairMaterial {
  std::string name = "brown";
  Vec3 color{0.25, 0.15, 0.08};  // linear RGB
  double ambient = 0.2;          // K_A
  double diffuse = 0.6;          // K_D
  double specular = 0.3;         // K_S
  double shininess = 40.0;       // n
  double radius = 40e-6;         // [m] hair radius

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"material name (triangles refer to it)"});
    v("color", color, ParamInfo{"hair colour (linear RGB)", "", 0.0, 1.0});
    v("ambient", ambient, ParamInfo{"ambient reflectance K_A of eq. (7)", "", 0.0, 10.0});
    v("diffuse", diffuse, ParamInfo{"diffuse coefficient K_D of eq. (7)", "", 0.0, 10.0});
    v("specular", specular, ParamInfo{"specular coefficient K_S of eq. (7)", "", 0.0, 10.0});
    v("shininess", shininess, ParamInfo{"specular exponent n of eq. (7)", "", 0.0, 1e4});
    v("radius", radius, ParamInfo{"hair radius", "m", 1e-7, 1e-2});
  }
  void validate(const std::string& where = "material") const { validate_params(*this, where); }
};

// ---------------------------------------------------------------------------------------------
// Per-triangle parameters and regions

/// The paper's nine per-polygon parameters (§2), SI.
struct TriangleHairParams {
  std::string curve = "swept";  // identifier of a 3-D curve (built-in or HairStylerParams::curves)
  std::string material;         // material name; "" = the first of HairStylerParams::materials
  /// Jitter of the base location, a fraction of the triangle's size in [0, 1]: hair i's root is
  /// lattice site i of the triangle (the paper's initial "symmetrical position") moved by
  /// jitter * U(-1/2, 1/2) in each parametric direction (wrapping inside the triangle); 1 gives
  /// area-uniform random roots.
  double jitter = 1.0;
  /// Orientation of the hairs: a world-space direction projected onto the triangle; the zero
  /// vector means the style's comb direction (HairStylerParams::comb) projected onto it.
  Vec3 tangent = Vec3::Zero();
  double angle_deg = 0.0;            // rotation of the tangent about the normal (counter-clockwise
                                     // seen from outside) [deg]
  double angle_variation_deg = 0.0;  // random rotation: angle += U(-1, 1) * this [deg]
  double scale = 0.1;                // [m] hair length (the curve has unit length)
  double scale_variation = 0.0;      // length *= 1 + U(-1, 1) * this
  double density = 2.0e6;            // [hairs/m²] (human scalp ~ 2e6 = 200 per cm²)
  uint64_t seed = 0;                 // seed of this triangle's random streams

  template <class V>
  void visit(V&& v) {
    v("curve", curve, ParamInfo{"name of the hair curve"});
    v("material", material, ParamInfo{"name of the material (\"\" = the first material)"});
    v("jitter", jitter,
      ParamInfo{"root jitter: 0 = regular lattice, 1 = uniform random (fraction of the triangle)",
                "", 0.0, 1.0});
    v("tangent", tangent,
      ParamInfo{"hair direction on the surface (world); [0,0,0] = the style's comb direction", "",
                -1e3, 1e3});
    v("angle_deg", angle_deg,
      ParamInfo{"rotation of the tangent about the normal", "deg", -360.0, 360.0});
    v("angle_variation_deg", angle_variation_deg,
      ParamInfo{"random rotation amplitude about the normal", "deg", 0.0, 180.0});
    v("scale", scale, ParamInfo{"hair length", "m", 1e-5, 10.0});
    v("scale_variation", scale_variation,
      ParamInfo{"relative random length variation", "", 0.0, 0.99});
    v("density", density, ParamInfo{"hairs per square metre", "1/m^2", 0.0, 1e9});
    v("seed", seed, ParamInfo{"seed of the triangle's random streams"});
  }
  void validate(const std::string& where = "defaults") const { validate_params(*this, where); }
};

enum class RegionSelect { All, Mask, Triangles, Vertices, Sphere, Box, HalfSpace };
constexpr std::array<std::pair<RegionSelect, const char*>, 7> follicle_enum_names(RegionSelect) {
  return {{{RegionSelect::All, "all"},
           {RegionSelect::Mask, "mask"},
           {RegionSelect::Triangles, "triangles"},
           {RegionSelect::Vertices, "vertices"},
           {RegionSelect::Sphere, "sphere"},
           {RegionSelect::Box, "box"},
           {RegionSelect::HalfSpace, "half_space"}}};
}
const char* to_string(RegionSelect s);

/// A set of triangles and the parameters it overrides (only the keys given). Selectors, in mesh
/// coordinates [m] (after any transform the caller applied to the mesh):
///   "all"         every triangle
///   "mask"        `mask`: a greyscale/RGB image in texture space, looked up (bilinear, clamped,
///                 v up) at the triangle's UV centroid; selects value > `threshold` (0.5); with
///                 `mask_scales_density` the selected triangles' density is also multiplied by
///                 the value. Needs a mesh with texture coordinates.
///   "triangles"   `triangles`: a text file of triangle indices, or inline `indices`
///   "vertices"    `vertices`: a text file of vertex indices, or inline `indices`; selects the
///                 triangles whose three vertices are all listed
///   "sphere"      `centre`, `radius`: triangles whose centroid is inside
///   "box"         `min`, `max`: axis-aligned box containing the centroid
///   "half_space"  `point`, `normal`: centroids with (c - point) · normal >= 0
/// Index files: integers separated by spaces, commas or newlines; '#' starts a comment.
/// `invert` selects the complement. `exclude: true` removes the selection from growth (no hairs,
/// no influence on smoothing); `exclude: false` puts it back. A density of 0 also grows no hairs
/// there but lets the neighbours' smoothed density fade towards 0.
struct HairRegion {
  std::string name;
  RegionSelect select = RegionSelect::All;
  bool invert = false;
  std::optional<bool> exclude;
  // selector arguments (only those of `select` may be given)
  std::optional<std::string> mask;
  std::optional<double> threshold;
  std::optional<bool> mask_scales_density;
  std::optional<std::string> triangles;
  std::optional<std::string> vertices;
  std::optional<std::vector<int64_t>> indices;
  std::optional<Vec3> centre;
  std::optional<double> radius;
  std::optional<Vec3> min, max;
  std::optional<Vec3> point, normal;
  // partial TriangleHairParams: only the keys given override
  std::optional<std::string> curve;
  std::optional<std::string> material;
  std::optional<double> jitter;
  std::optional<Vec3> tangent;
  std::optional<double> angle_deg;
  std::optional<double> angle_variation_deg;
  std::optional<double> scale;
  std::optional<double> scale_variation;
  std::optional<double> density;
  std::optional<uint64_t> seed;

  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"label (for messages)"});
    v("select", select, ParamInfo{"selector kind"});
    v("invert", invert, ParamInfo{"select the complement"});
    v("exclude", exclude, ParamInfo{"true: no hairs on the selection; false: grow there again"});
    v("mask", mask, ParamInfo{"mask: image path (texture space, v up)"});
    v("threshold", threshold,
      ParamInfo{"mask: selects mask value > threshold (default 0.5)", "", -1.0, 2.0});
    v("mask_scales_density", mask_scales_density,
      ParamInfo{"mask: also multiply the density by the mask value (default false)"});
    v("triangles", triangles, ParamInfo{"triangles: path of a triangle index file"});
    v("vertices", vertices, ParamInfo{"vertices: path of a vertex index file"});
    v("indices", indices, ParamInfo{"triangles/vertices: inline indices instead of a file"});
    v("centre", centre, ParamInfo{"sphere: centre", "m", -1e3, 1e3});
    v("radius", radius, ParamInfo{"sphere: radius", "m", 0.0, 1e3});
    v("min", min, ParamInfo{"box: minimum corner", "m", -1e3, 1e3});
    v("max", max, ParamInfo{"box: maximum corner", "m", -1e3, 1e3});
    v("point", point, ParamInfo{"half_space: a point on the plane", "m", -1e3, 1e3});
    v("normal", normal, ParamInfo{"half_space: normal towards the selected side", "", -1e3, 1e3});
    v("curve", curve, ParamInfo{"overrides: hair curve name"});
    v("material", material, ParamInfo{"overrides: material name"});
    v("jitter", jitter, ParamInfo{"overrides: root jitter", "", 0.0, 1.0});
    v("tangent", tangent, ParamInfo{"overrides: hair direction (world, 0 = comb)", "", -1e3, 1e3});
    v("angle_deg", angle_deg, ParamInfo{"overrides: rotation about the normal", "deg", -360, 360});
    v("angle_variation_deg", angle_variation_deg,
      ParamInfo{"overrides: random rotation amplitude", "deg", 0.0, 180.0});
    v("scale", scale, ParamInfo{"overrides: hair length", "m", 1e-5, 10.0});
    v("scale_variation", scale_variation,
      ParamInfo{"overrides: relative random length variation", "", 0.0, 0.99});
    v("density", density, ParamInfo{"overrides: hairs per square metre", "1/m^2", 0.0, 1e9});
    v("seed", seed, ParamInfo{"overrides: triangle seed"});
  }
  /// Checks ranges and that exactly the arguments of `select` are given; `where` is the JSON path
  /// of this region ("regions[2]").
  void validate(const std::string& where) const;
  /// Applies the region's overrides to `p` (the keys given only).
  void apply(TriangleHairParams& p) const;
};

/// A whole style: defaults for every triangle, regions applied in order, curves, materials.
struct HairStylerParams {
  TriangleHairParams defaults;      // every triangle starts from these
  std::vector<HairRegion> regions;  // applied in order; later entries override earlier ones
  std::vector<HairCurve> curves;    // user curves (a built-in name is replaced)
  std::vector<HairMaterial> materials{HairMaterial{}};
  Vec3 comb{0.0, -1.0, 0.0};           // default hair direction (projected onto the surface)
  Vec3 comb_fallback{0.0, 0.0, -1.0};  // used where the comb is along the normal
  bool smooth = true;                  // vertex-averaged parameters (false: per triangle)
  bool blend_curves = true;            // blend the vertices' curves (with smooth)
  bool transport_tangent = true;       // deformed growth: carry the tangent with the triangle
  int points_per_hair = 20;
  double density_scale = 1.0;    // multiplies every density (previews, guides)
  double length_scale = 1.0;     // multiplies every scale (§2: "grow or shrink" a style)
  uint64_t max_hairs = 2000000;  // budget: growing more fails before allocating
  uint64_t seed = 1;

  template <class V>
  void visit(V&& v) {
    v("defaults", defaults, ParamInfo{"parameters of every triangle before the regions"});
    v("regions", regions, ParamInfo{"regions, applied in order (later ones override)"});
    v("curves", curves, ParamInfo{"user hair curves (local frame: x tangent, y normal)"});
    v("materials", materials, ParamInfo{"hair materials (at least one)"});
    v("comb", comb,
      ParamInfo{"default hair direction, projected onto each triangle", "", -1e3, 1e3});
    v("comb_fallback", comb_fallback,
      ParamInfo{"direction used where the comb is along the surface normal", "", -1e3, 1e3});
    v("smooth", smooth, ParamInfo{"interpolate parameters smoothly across triangles"});
    v("blend_curves", blend_curves,
      ParamInfo{"blend curve shapes between neighbouring triangles (with smooth)"});
    v("transport_tangent", transport_tangent,
      ParamInfo{"on a deformed mesh carry the tangent with the triangle before correcting it "
                "(false: the paper's world-space tangent)"});
    v("points_per_hair", points_per_hair, ParamInfo{"points per hair", "", 2, 1024});
    v("density_scale", density_scale, ParamInfo{"multiplies every density", "", 0.0, 1e3});
    v("length_scale", length_scale, ParamInfo{"multiplies every hair length", "", 1e-3, 1e3});
    v("max_hairs", max_hairs, ParamInfo{"largest number of hairs allowed", "", 1.0, 1e10});
    v("seed", seed, ParamInfo{"style random seed"});
  }
  /// Ranges, regions, unique names, known curve/material names, sampleable curves.
  void validate(const std::string& where = "") const;
};

// ---------------------------------------------------------------------------------------------
// Inputs from files

/// What a region needs from disk, loaded by load_styler_inputs.
struct RegionInput {
  image::ImageF mask;            // "mask" regions
  std::vector<int64_t> indices;  // "triangles" / "vertices" regions with a file
  std::vector<uint32_t> lines;   // line of each index in the file
  std::string source;            // the file (for messages)
  bool loaded = false;
};
struct StylerInputs {
  std::vector<RegionInput> regions;  // empty, or one per HairStylerParams::regions
};

/// Loads every region's mask image (image::read_gray_map: PNG grey/RGB, JPEG, EXR) and index
/// file; `resolve` turns a path as written in the style into a file path. Errors name the JSON
/// path (`regions[2].mask`), the file, and for a bad token its line (`file:line`).
StylerInputs load_styler_inputs(
    const HairStylerParams& params,
    const std::function<std::filesystem::path(const std::string&)>& resolve);

// ---------------------------------------------------------------------------------------------
// The styler

/// The binormal/tangent correction of §2 for a deformed triangle: b = N_new × t_old,
/// t_new = b × N_new (= t_old minus its N_new component), normalized. When t_old is along
/// N_new the result is an arbitrary unit vector perpendicular to N_new. N_new must be unit.
Vec3 correct_tangent(const Vec3& tangent_old, const Vec3& normal_new);

/// Per-triangle and per-vertex parameters of a style on one mesh, ready to grow hairs. Holds
/// copies of what it needs (not a reference to the mesh).
class HairStyler {
 public:
  /// Validates `params`, resolves the regions on `mesh` (which must have faces; vertex normals
  /// are computed when absent). `inputs` must come from load_styler_inputs when a region uses a
  /// mask or an index file. Throws follicle::Error naming the region on bad input.
  HairStyler(const geom::TriMesh& mesh, const HairStylerParams& params,
             const StylerInputs& inputs = {});

  std::size_t num_faces() const { return m_faces.size(); }
  const HairStylerParams& params() const { return m_params; }
  /// The face's parameters after the regions (before smoothing). Tangent as given (zero = comb).
  TriangleHairParams triangle_params(std::size_t face) const;
  /// Whether hairs grow on the face (not excluded, density > 0, non-degenerate).
  bool grows(std::size_t face) const { return m_grow[face] != 0; }
  bool excluded(std::size_t face) const { return m_excluded[face] != 0; }
  /// Parameters at a point of a face: the continuous ones interpolated from the vertices (with
  /// `smooth`), curve/material/seed of the face. `tangent` is the unit tangent on the surface
  /// (before the angle rotation), perpendicular to the interpolated normal. A face that does not
  /// grow reports density 0; an excluded face reports its own (unsmoothed) parameters.
  TriangleHairParams params_at(std::size_t face, const Vec3& bary) const;
  /// Unit surface normal used for the hair frame at a point (interpolated vertex normal with
  /// `smooth`, else the face normal).
  Vec3 normal_at(std::size_t face, const Vec3& bary) const;
  /// Expected number of hairs on a face: density integrated over it × density_scale.
  double expected_hairs(std::size_t face) const;
  double expected_total() const;
  /// Hairs per face (stochastic rounding of expected_hairs with the face's own stream).
  std::vector<uint32_t> hair_counts(const Context& ctx) const;
  /// The unit-length sampled shape of a curve by name (points_per_hair points).
  const std::vector<Vec3>& curve_shape(const std::string& name) const;

  /// Grows the hairs: strands in mesh coordinates [m] (points_per_hair points each, root first),
  /// roots bound to (face, barycentric), one material index per strand, per-point radius and
  /// colour from the material. Strands are ordered by face, then by index within the face.
  /// Fails before allocating when the expected count exceeds max_hairs.
  Groom grow(const Context& ctx) const;
  /// Grows on `deformed` (same topology as the construction mesh, other positions): counts,
  /// parameters and random values come from the rest mesh (so nothing is redrawn), roots sit at
  /// the same barycentric points of the deformed triangles, frames use the deformed normals and
  /// the tangent corrected by correct_tangent (after carrying it with the triangle when
  /// `transport_tangent`).
  Groom grow(const Context& ctx, const geom::TriMesh& deformed) const;

 private:
  struct Corner {
    double jitter, angle_deg, angle_var_deg, scale, scale_var, density;
    Vec3 tangent, normal;
    uint32_t shape;
  };
  void corners(std::size_t face, std::array<Corner, 3>& c) const;
  Groom grow_impl(const Context& ctx, const geom::TriMesh* deformed) const;
  uint64_t face_key(std::size_t face) const;
  Vec3 surface_tangent(const Vec3& t, const Vec3& n) const;

  HairStylerParams m_params;
  std::vector<Vec3> m_positions;
  std::vector<Vec3i> m_faces;
  std::vector<Vec3> m_vertex_normals;
  std::vector<Vec3> m_face_normals;
  std::vector<double> m_face_area;
  // per face, after regions
  std::vector<TriangleHairParams> m_tri;
  std::vector<uint16_t> m_curve, m_material;
  std::vector<Vec3> m_face_tangent;  // resolved unit tangent in the face plane (before rotation)
  std::vector<uint8_t> m_excluded, m_grow;
  // per vertex (smooth)
  std::vector<Corner> m_vertex;
  // shapes: [0, curves) the named curves, then blended vertex shapes; each points_per_hair points
  std::vector<std::string> m_curve_names;
  std::vector<std::vector<Vec3>> m_shapes;
};

/// Convenience: HairStyler(mesh, params, inputs).grow(ctx).
Groom grow_hairstyler(const Context& ctx, const geom::TriMesh& mesh, const HairStylerParams& params,
                      const StylerInputs& inputs = {});

// ---------------------------------------------------------------------------------------------
// Presets

/// Landmarks of a head mesh facing `front` with `up` up (both need not be unit; they are
/// orthonormalized, front first made perpendicular to up), measured on the mesh: the top (largest
/// up), the nose tip (most frontal vertex in the upper three quarters, moved onto the lateral
/// midline of the bounding box), the back of the head and the ears (most lateral vertices at ear
/// height). `unit` is the top-to-nose-tip height; presets place regions in that unit.
struct HeadLandmarks {
  Vec3 up, front, left;  // orthonormal, left = up × front (the head's left)
  Vec3 top, nose_tip, left_ear, right_ear;
  double back = 0.0;  // smallest front coordinate above the nose tip (back of the head)
  double unit = 0.0;  // [m] top·up - nose_tip·up
  /// nose_tip + unit * (lateral * left + height * up + depth * front)
  Vec3 at(double lateral, double height, double depth) const {
    return nose_tip + unit * (lateral * left + height * up + depth * front);
  }
};
HeadLandmarks head_landmarks(const geom::TriMesh& mesh, const Vec3& up = Vec3::UnitY(),
                             const Vec3& front = Vec3::UnitZ());

/// Styles for a head facing `front`: "long" (scalp), "beard" (chin and jaw below the mouth),
/// "moustache" (upper lip), "eyebrows", "fur" (the whole mesh). Regions are geometric
/// selectors placed from head_landmarks, so they fit any head mesh of human proportions.
HairStylerParams styler_preset(std::string_view name, const geom::TriMesh& mesh,
                               const Vec3& up = Vec3::UnitY(), const Vec3& front = Vec3::UnitZ());
std::vector<std::string> styler_preset_names();

}  // namespace follicle::hair
