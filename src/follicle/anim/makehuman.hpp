#pragma once
// MakeHuman (CC0) base mesh hm08, default skeleton (.mhskel, JSON) and default skinning weights
// (.mhw, JSON), and extraction of a hand as a sub-mesh with remapped weights.
//
// Units: base.obj is in decimetres, y up, facing +z (see ../shared/data/makehuman-base/SOURCE.md);
// everything returned here is in metres. The character's left side is +x.
#include <filesystem>
#include <string>
#include <vector>

#include "follicle/anim/keyframe_track.hpp"
#include "follicle/anim/skeleton.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::anim {

/// The base mesh as MakeHuman indexes it: all vertices (weights and joints refer to these
/// indices), all texture coordinates, and the quads of group "body" split into triangles.
struct MakeHumanBase {
  std::vector<Vec3> positions;  // [m], every `v` of the file
  std::vector<Vec2> uvs;        // every `vt`
  std::vector<Vec3i> faces;     // body triangles (position indices)
  std::vector<Vec3i> uv_faces;  // body triangles (uv indices)
};

/// Reads base.obj (v, vt, g, f only; other lines ignored). Throws follicle::Error with file:line
/// on malformed input.
MakeHumanBase load_makehuman_obj(const std::filesystem::path& path);

/// Reads a .mhskel: bone heads/tails are the means of the joint vertex groups of `base`, the bone
/// frame's x axis is the normal of the bone's rotation plane (the flexion axis of fingers).
Skeleton load_mhskel(const std::filesystem::path& path, const std::vector<Vec3>& base_positions);

/// Reads a .mhw for `num_vertices` vertices; bones not in `skel` are an error, weights are
/// normalized per vertex.
SkinWeights load_mhw(const std::filesystem::path& path, const Skeleton& skel,
                     std::size_t num_vertices);

enum class Side { left, right };  // the character's left (+x) / right (-x)

struct SubMesh {
  geom::TriMesh mesh;           // [m]; uvs rescaled so the part fills [0,1]^2 (aspect kept)
  std::vector<int> vertex_map;  // sub-mesh vertex -> base vertex
  SkinWeights weights;          // remapped, normalized
};

/// The hand: body vertices whose weight on the wrist, metacarpal and finger bones of `side` is at
/// least `threshold`, and the body triangles with all three corners among them.
SubMesh extract_hand(const MakeHumanBase& base, const Skeleton& skel, const SkinWeights& w,
                     Side side, double threshold = 0.5);

/// Finger flexion pose: every finger bone of `side` rotated about its rest-frame x axis by
/// flexion * max_angle (thumb by half), flexion in [0, 1]; fingers curl toward the palm.
Pose finger_flexion_pose(const Skeleton& skel, Side side, double flexion, double max_angle = 1.3);
/// A finger-flexion animation: 0 -> 1 -> 0 over `duration` seconds (smooth).
ScalarTrack finger_flexion_track(double duration = 2.0);

}  // namespace follicle::anim
