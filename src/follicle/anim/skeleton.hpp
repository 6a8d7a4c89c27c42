#pragma once
// Skeleton + linear blend skinning.
//
// A bone has a rest head/tail [m] and a rest frame (columns x, y, z; y along head->tail). A Pose
// holds one rotation per bone about its head, expressed in the bone's rest frame. Skinning
// transforms are built root-first: S_b(x) = S_parent(h_b + Q_b (x - h_b)), Q_b = F_b q_b F_b^T.
// They are stored as x -> x + A_b x + T_b with A_b = R_b - I, so LBS
//     x' = x + sum_i w_i (A_i x + T_i)
// reproduces the rest mesh bit-exactly in the rest pose (A = 0, T = 0 exactly) whatever the
// weights are.
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"

namespace follicle::anim {

struct Bone {
  std::string name;
  int parent = -1;  // index into Skeleton::bones, always smaller than this bone's index
  Vec3 head = Vec3::Zero();
  Vec3 tail = Vec3::Zero();
  Mat3 frame = Mat3::Identity();  // rest orientation: columns x, y (along the bone), z
};

class Skeleton {
 public:
  /// Appends a bone; parent must already exist ("" = root). Throws on duplicate names.
  int add_bone(const std::string& name, const std::string& parent, const Vec3& head,
               const Vec3& tail, const Mat3& frame);
  const std::vector<Bone>& bones() const { return m_bones; }
  std::size_t size() const { return m_bones.size(); }
  int find(const std::string& name) const;   // -1 when absent
  int index(const std::string& name) const;  // throws follicle::Error with did-you-mean
  /// Bone frame with y along head->tail and x the component of `x_hint` orthogonal to y.
  static Mat3 frame_from(const Vec3& head, const Vec3& tail, const Vec3& x_hint);

 private:
  std::vector<Bone> m_bones;
};

struct Pose {
  std::vector<Quat> local;  // per bone, rotation about the head in the bone's rest frame
  static Pose rest(const Skeleton& s) {
    return Pose{std::vector<Quat>(s.size(), Quat::Identity())};
  }
  /// Rotates bone b about its rest-frame axis (0 = x, 1 = y, 2 = z) by `angle` [rad]
  /// (composed after any rotation it already has).
  void rotate(int bone, int axis, double angle);
};

/// Per-bone skinning transform x -> x + A x + T (A = R - I).
struct SkinningTransforms {
  std::vector<Mat3> A;
  std::vector<Vec3> T;
  Vec3 apply(int bone, const Vec3& x) const { return x + A[bone] * x + T[bone]; }
};

SkinningTransforms skinning_transforms(const Skeleton& skel, const Pose& pose);

/// Sparse per-vertex bone weights (CSR): influences of vertex v are [offsets[v], offsets[v+1]).
struct SkinWeights {
  std::vector<uint32_t> offsets{0};
  std::vector<int32_t> bone;
  std::vector<float> weight;

  std::size_t num_vertices() const { return offsets.size() - 1; }
  /// Builds from per-vertex lists of (bone, weight); zero weights dropped.
  static SkinWeights from_lists(const std::vector<std::vector<std::pair<int, float>>>& lists);
  /// Scales each vertex's weights to sum 1 (vertices without weights are left empty).
  void normalize();
  /// Weights of a subset of vertices: vertex i of the result is vertex `map[i]` here.
  SkinWeights remap(const std::vector<int>& map) const;
  /// Sum of weights of vertex v on the bones flagged in `mask`.
  double weight_on(std::size_t v, const std::vector<char>& mask) const;
};

/// Linear blend skinning, parallel over vertices. out is resized to rest.size().
void skin_lbs(const Context& ctx, const std::vector<Vec3>& rest, const SkinWeights& w,
              const SkinningTransforms& xf, std::vector<Vec3>& out);

}  // namespace follicle::anim
