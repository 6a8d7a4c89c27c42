#pragma once
// HandRig: the skeleton-animated hand of Bando 2002 §2.7 / paper §8 (Figs. 2.16, 2.17) on the
// MakeHuman (CC0) hand: linear blend skinning -> large-scale finger-joint wrinkles (cubic Bezier
// furrows across the back of each finger joint, d and w 0.5-1 mm, r = 1, adaptive refinement
// around them) displaced along the normals with M(s) S(l) -> fine-scale wrinkles (two direction
// fields over the whole hand) modulated per frame by the shrinkage perpendicular to each field
// (2.3, 2.4) and bump-mapped.
//
// Per frame (update): skin_lbs -> skinned rest normals -> WrinkleLayer::heights (shrinkage +
// M(s) S(l)) -> displaced surface + its normals -> FineWrinkleAnimator::shrinkage (per uv vertex,
// on the skinned surface) -> optionally the modulated relief map (per texel). Everything is
// parallel and deterministic for any thread count.
//
// Note on r = 1 (the paper's value for the joint wrinkles): M(s) = 1 for every s when r = 1, so
// the joint wrinkles keep their full height in every pose; the response to the motion then comes
// from the fine wrinkles (r = 0.5), as in Fig. 2.17. With joint_r < 1 the joint wrinkles also
// deepen where the skin shrinks across them and fade where it stretches.
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "follicle/anim/makehuman.hpp"
#include "follicle/anim/skeleton.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"
#include "follicle/skin/adaptive_refine_volino1999.hpp"
#include "follicle/skin/fine_wrinkles_bando2002.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

namespace follicle::skin {

struct HandRigParams {
  bool left = true;               // the character's left hand (+x), else the right one
  double weight_threshold = 0.5;  // hand vertices: weight on hand bones >= this
  double max_flexion = 1.3;       // finger bone rotation at flexion 1 [rad] (thumb: half)
  // Large-scale joint wrinkles (paper §8: d, w in 0.5-1 mm, r = 1).
  bool joint_wrinkles = true;
  double joint_depth = 0.8e-3;     // d [m]
  double joint_width = 0.7e-3;     // w [m]
  double joint_r = 1.0;            // (2.4) r of every joint wrinkle
  int creases_per_joint = 3;       // parallel furrows at each joint
  double crease_spacing = 2.2e-3;  // between them, along the finger [m]
  double crease_half_arc = 0.9;    // half the angle the furrow spans around the finger [rad]
  double joint_end_taper = 0.3;    // LargeWrinkle::end_taper
  bool palmar_creases = false;     // also furrows on the palm side of each joint
  RefineParams refine{3, 0.75, 4.0};
  // Fine-scale wrinkles: field 0 runs around the fingers / across the back of the hand, field 1
  // at fine_angle from it toward the bone direction; magnitudes m (2.5).
  FineWrinkleParams fine{1024, 1.0, 0.3, 200, true, 200e-6, 0.5};
  double fine_m0 = 0.5;
  double fine_m1 = 0.4;
  double fine_angle = 1.0;  // [rad]
  int fine_key_stride = 8;  // a direction key on every k-th uv vertex
  // Bump strength for rendering / normal-map export of the fine relief (the paper enhances the
  // bump mapping "excessively" in Fig. 2.17 so the fine wrinkles are clearly visible).
  double bump_strength = 3.0;

  template <class V>
  void visit(V&& v) {
    v("left", left, ParamInfo{"use the character's left hand", ""});
    v("weight_threshold", weight_threshold, ParamInfo{"hand vertex weight threshold", "", 0.01, 1});
    v("max_flexion", max_flexion, ParamInfo{"finger bone angle at flexion 1", "rad", 0, 3});
    v("joint_wrinkles", joint_wrinkles, ParamInfo{"large-scale wrinkles at finger joints", ""});
    v("joint_depth", joint_depth, ParamInfo{"joint wrinkle depth d", "m", 0, 0.01});
    v("joint_width", joint_width, ParamInfo{"joint wrinkle width w", "m", 1e-5, 0.01});
    v("joint_r", joint_r, ParamInfo{"joint wrinkle rest ratio r (2.4)", "", 0, 1});
    v("creases_per_joint", creases_per_joint, ParamInfo{"furrows per joint", "", 1, 8});
    v("crease_spacing", crease_spacing, ParamInfo{"spacing of a joint's furrows", "m", 0, 0.02});
    v("crease_half_arc", crease_half_arc,
      ParamInfo{"furrow half arc around the finger", "rad", 0.1, 1.5});
    v("joint_end_taper", joint_end_taper, ParamInfo{"furrow end taper", "", 0, 0.5});
    v("palmar_creases", palmar_creases, ParamInfo{"furrows on the palm side too", ""});
    v("refine", refine, ParamInfo{"adaptive refinement around joint wrinkles", ""});
    v("fine", fine, ParamInfo{"fine-scale wrinkles", ""});
    v("fine_m0", fine_m0, ParamInfo{"field 0 direction magnitude", "", 0, 1});
    v("fine_m1", fine_m1, ParamInfo{"field 1 direction magnitude", "", 0, 1});
    v("fine_angle", fine_angle, ParamInfo{"field 1 angle from field 0", "rad", -3.2, 3.2});
    v("bump_strength", bump_strength, ParamInfo{"fine relief bump strength", "", 0, 100});
    v("fine_key_stride", fine_key_stride,
      ParamInfo{"direction key every k uv vertices", "", 1, 1000});
  }
  void validate() const { validate_params(*this, "hand_rig"); }
};

/// Per-frame state (also scratch; reuse across frames).
struct HandState {
  double flexion = 0;
  std::vector<Vec3> animated;                        // skinned surface (no wrinkles)
  std::vector<Vec3> positions;                       // final surface with joint wrinkles [m]
  std::vector<Vec3> normals;                         // of `positions`
  std::vector<double> joint_height;                  // sum of M(s) S(l) per vertex [m]
  std::array<std::vector<float>, 2> fine_shrinkage;  // (2.3) per uv vertex, per field
  image::ImageF relief;  // modulated fine relief, units of depth_m (if requested)
  // scratch
  std::vector<Vec3> face_n;
  std::vector<double> face_area;
};

struct HandUpdateOptions {
  bool joint_wrinkles = true;  // displace by the joint wrinkles
  bool fine_shrinkage = true;  // per-vertex shrinkage of both fine fields
  bool fine_relief = true;     // per-texel modulated relief (needs fine_shrinkage)
};

/// What the renderer needs for one frame (scene::Session turns it into a render::MeshItem with
/// material.height_map = height_m and bump_strength).
struct HandFrame {
  std::shared_ptr<const geom::TriMesh> mesh;      // deformed, with normals and the rig's UVs
  std::shared_ptr<const image::ImageF> height_m;  // fine-wrinkle relief [m] (null: none)
  double flexion = 0;
  double bump_strength = 1.0;  // for material.bump_strength (HandRigParams::bump_strength)
};

/// A finger-joint wrinkle with the joint it belongs to.
struct JointWrinkleInfo {
  std::string bone;     // the bone whose head is the joint
  int crease = 0;       // index among the joint's parallel furrows
  bool palmar = false;  // on the palm side (else the back of the finger)
};

class HandRig {
 public:
  /// Loads base.obj, default.mhskel and default_weights.mhw from `makehuman_dir`.
  static std::unique_ptr<HandRig> load(const Context& ctx,
                                       const std::filesystem::path& makehuman_dir,
                                       const HandRigParams& params = {});
  HandRig(const Context& ctx, const anim::MakeHumanBase& base, anim::Skeleton skel,
          const anim::SkinWeights& weights, const HandRigParams& params);
  ~HandRig();
  HandRig(const HandRig&) = delete;
  HandRig& operator=(const HandRig&) = delete;

  /// The refined rest mesh the rig deforms (positions, faces, uvs in [0,1]^2, uv_faces).
  const geom::TriMesh& rest_mesh() const { return m_rest; }
  const anim::SubMesh& hand() const { return m_hand; }  // before refinement
  const anim::Skeleton& skeleton() const { return m_skel; }
  const anim::SkinWeights& weights() const { return m_weights; }  // of rest_mesh()
  const std::vector<LargeWrinkle>& joint_wrinkles() const { return m_wrinkles; }
  const std::vector<JointWrinkleInfo>& joint_wrinkle_info() const { return m_info; }
  const WrinkleLayer& wrinkle_layer() const { return *m_layer; }
  const FineWrinkles& fine() const { return m_fine; }
  const FineWrinkleAnimator& fine_animator() const { return *m_fine_anim; }
  const anim::ScalarTrack& flexion_track() const { return m_track; }
  const HandRigParams& params() const { return m_params; }
  /// Metres per unit of the relief map (the fine wrinkles' depth_m).
  double relief_depth_m() const { return m_fine.depth_m; }

  anim::Pose pose(double flexion) const;
  /// One frame at finger flexion in [0, 1] (0 = the rest pose).
  void update(const Context& ctx, double flexion, HandState& out,
              const HandUpdateOptions& opt = {}) const;
  /// The deformed mesh of a state (rest topology and UVs, state positions and normals).
  geom::TriMesh deformed_mesh(const HandState& s) const;
  /// Render items at time t [s] of the finger-flexion track (flexion 0 -> 1 -> 0 over 2 s);
  /// `wrinkles` = false gives the plain skinned hand without any wrinkle.
  HandFrame frame(const Context& ctx, double t, bool wrinkles = true) const;
  HandFrame frame_at_flexion(const Context& ctx, double flexion, bool wrinkles = true) const;

 private:
  void build_joint_wrinkles();
  std::array<std::vector<DirectionKey>, 2> fine_keys() const;

  HandRigParams m_params;
  anim::Skeleton m_skel;
  anim::SubMesh m_hand;
  RefinedMesh m_refined;
  geom::TriMesh m_rest;
  std::vector<Vec3> m_rest_normals;
  anim::SkinWeights m_weights;
  std::vector<LargeWrinkle> m_wrinkles;
  std::vector<JointWrinkleInfo> m_info;
  std::unique_ptr<WrinkleLayer> m_layer;
  FineWrinkles m_fine;
  std::unique_ptr<FineWrinkleAnimator> m_fine_anim;
  anim::ScalarTrack m_track;
};

/// Fraction of the texels of a TexelMap covered by the mesh.
double texel_coverage(const TexelMap& t);

}  // namespace follicle::skin
