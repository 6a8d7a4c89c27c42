#pragma once
// Internal to the scene module: the face-rig state a Session keeps for the "skin" section (the
// resolved face setup, the FaceRig, contraction tracks and the last deformed mesh). Included by
// session_skin.cpp only.
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include "follicle/anim/keyframe_track.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/fine_wrinkles_bando2002.hpp"
#include "follicle/skin/skin_json.hpp"

namespace follicle::scene {

class SkinRuntime {
 public:
  struct Rig {
    bool resolved = false;
    skin::FaceSetup setup;         // the face-setup file with the scene's wrinkle edits applied
    skin::MusclePose static_pose;  // expression * weight with the explicit contractions
    bool tracked = false;          // skin[].track given
    std::vector<anim::ScalarTrack> muscle_tracks;  // one per muscle
    std::vector<anim::ScalarTrack> shape_tracks;   // one per blendshape target
    anim::ScalarTrack jaw_track;
    std::optional<skin::MusclePose> pose_override;  // Session::set_skin_pose
    // The rig's base mesh: the mesh asset, or the asset with a texture space of its own
    // (skin[].mapping, Bando 2002 §2.4), and the large wrinkles in that texture space.
    std::shared_ptr<const geom::TriMesh> base;
    std::vector<skin::LargeWrinkle> wrinkles;
    std::unique_ptr<skin::FaceRig> rig;
    skin::FaceState state;
    int last_frame = -1;  // frame of `last` (-2: a still face, valid for every frame)
    std::shared_ptr<const geom::TriMesh> last;
    std::vector<Vec3f> colors;  // per vertex of the rig mesh (albedo skin_color)
    // Fine-scale wrinkles ("fine"): both height fields generated once on the base mesh (the mesh
    // asset the FaceRig refines; its vertices are the first ones of the refined mesh), the relief
    // [m] of the frame of `last` (fine_for) and the per-field shrinkage scratch.
    std::unique_ptr<skin::FineWrinkleAnimator> fine;
    double fine_depth_m = 0.0;
    std::weak_ptr<const geom::TriMesh> fine_for;
    std::shared_ptr<const image::ImageF> fine_height;
    std::array<std::vector<float>, 2> fine_s;
  };
  std::vector<Rig> rigs;
};

}  // namespace follicle::scene
