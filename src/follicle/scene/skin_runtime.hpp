#pragma once
// Internal to the scene module: the face-rig state a Session keeps for the "skin" section (the
// resolved face setup, the FaceRig, contraction tracks and the last deformed mesh). Included by
// session_skin.cpp only.
#include <memory>
#include <optional>
#include <vector>

#include "follicle/anim/keyframe_track.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/skin_json.hpp"

namespace follicle::scene {

class SkinRuntime {
 public:
  struct Rig {
    bool resolved = false;
    skin::FaceSetup setup;         // the face-setup file with the scene's wrinkle edits applied
    skin::MusclePose static_pose;  // expression * weight with the explicit contractions
    std::vector<anim::ScalarTrack> muscle_tracks;  // one per muscle (empty: no track)
    anim::ScalarTrack jaw_track;
    std::unique_ptr<skin::FaceRig> rig;
    skin::FaceState state;
    int last_frame = -1;  // frame of `last` (-2: a still face, valid for every frame)
    std::shared_ptr<const geom::TriMesh> last;
    std::vector<Vec3f> colors;  // per vertex of the rig mesh (albedo skin_color)
  };
  std::vector<Rig> rigs;
};

}  // namespace follicle::scene
