#include "follicle/anim/skeleton.hpp"

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"

namespace follicle::anim {

int Skeleton::add_bone(const std::string& name, const std::string& parent, const Vec3& head,
                       const Vec3& tail, const Mat3& frame) {
  if (find(name) >= 0) fail("skeleton: duplicate bone '{}'", name);
  Bone b;
  b.name = name;
  b.parent = parent.empty() ? -1 : index(parent);
  b.head = head;
  b.tail = tail;
  b.frame = frame;
  if (!head.allFinite() || !tail.allFinite() || !frame.allFinite())
    fail("skeleton: bone '{}' has non-finite rest data", name);
  m_bones.push_back(std::move(b));
  return int(m_bones.size()) - 1;
}

int Skeleton::find(const std::string& name) const {
  for (std::size_t i = 0; i < m_bones.size(); ++i)
    if (m_bones[i].name == name) return int(i);
  return -1;
}

int Skeleton::index(const std::string& name) const {
  const int i = find(name);
  if (i >= 0) return i;
  std::vector<std::string> names;
  for (const auto& b : m_bones) names.push_back(b.name);
  const std::string hint = did_you_mean(name, names);
  fail("skeleton has no bone '{}'{}", name,
       hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint));
}

Mat3 Skeleton::frame_from(const Vec3& head, const Vec3& tail, const Vec3& x_hint) {
  Vec3 y = tail - head;
  if (y.norm() == 0.0) y = Vec3::UnitY();
  y.normalize();
  Vec3 x = x_hint - y * y.dot(x_hint);
  if (x.norm() < 1e-9) x = y.unitOrthogonal();
  x.normalize();
  Mat3 f;
  f.col(0) = x;
  f.col(1) = y;
  f.col(2) = x.cross(y);
  return f;
}

void Pose::rotate(int bone, int axis, double angle) {
  if (bone < 0 || std::size_t(bone) >= local.size()) fail("pose: bone index {} out of range", bone);
  if (axis < 0 || axis > 2) fail("pose: axis must be 0, 1 or 2, got {}", axis);
  local[bone] = local[bone] * Quat(Eigen::AngleAxisd(angle, Vec3::Unit(axis)));
}

SkinningTransforms skinning_transforms(const Skeleton& skel, const Pose& pose) {
  const auto& bones = skel.bones();
  if (pose.local.size() != bones.size())
    fail("pose has {} bone rotations, skeleton has {} bones", pose.local.size(), bones.size());
  const std::size_t n = bones.size();
  std::vector<Mat3> R(n);
  SkinningTransforms out;
  out.A.resize(n);
  out.T.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    const Bone& bone = bones[b];
    const Quat& q = pose.local[b];
    // Identity rotations are kept exact so the rest pose reproduces the mesh bit-exactly.
    const bool identity = q.w() == 1.0 && q.x() == 0.0 && q.y() == 0.0 && q.z() == 0.0;
    const Mat3 Q =
        identity ? Mat3::Identity()
                 : Mat3(bone.frame * q.normalized().toRotationMatrix() * bone.frame.transpose());
    const Vec3 local_t = bone.head - Q * bone.head;
    if (bone.parent < 0) {
      R[b] = Q;
      out.T[b] = local_t;
    } else {
      R[b] = R[bone.parent] * Q;
      out.T[b] = R[bone.parent] * local_t + out.T[bone.parent];
    }
    out.A[b] = R[b] - Mat3::Identity();
  }
  return out;
}

SkinWeights SkinWeights::from_lists(const std::vector<std::vector<std::pair<int, float>>>& lists) {
  SkinWeights w;
  w.offsets.assign(1, 0);
  for (const auto& l : lists) {
    for (const auto& [b, x] : l) {
      if (x == 0.0f) continue;
      w.bone.push_back(b);
      w.weight.push_back(x);
    }
    w.offsets.push_back(uint32_t(w.bone.size()));
  }
  return w;
}

void SkinWeights::normalize() {
  for (std::size_t v = 0; v < num_vertices(); ++v) {
    double s = 0;
    for (uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) s += weight[k];
    if (s <= 0) continue;
    for (uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) weight[k] = float(weight[k] / s);
  }
}

SkinWeights SkinWeights::remap(const std::vector<int>& map) const {
  SkinWeights w;
  w.offsets.assign(1, 0);
  for (int v : map) {
    if (v < 0 || std::size_t(v) >= num_vertices())
      fail("skin weights: vertex {} out of range (have {})", v, num_vertices());
    for (uint32_t k = offsets[v]; k < offsets[v + 1]; ++k) {
      w.bone.push_back(bone[k]);
      w.weight.push_back(weight[k]);
    }
    w.offsets.push_back(uint32_t(w.bone.size()));
  }
  return w;
}

double SkinWeights::weight_on(std::size_t v, const std::vector<char>& mask) const {
  double s = 0;
  for (uint32_t k = offsets[v]; k < offsets[v + 1]; ++k)
    if (std::size_t(bone[k]) < mask.size() && mask[bone[k]]) s += weight[k];
  return s;
}

void skin_lbs(const Context& ctx, const std::vector<Vec3>& rest, const SkinWeights& w,
              const SkinningTransforms& xf, std::vector<Vec3>& out) {
  if (w.num_vertices() != rest.size())
    fail("skinning: {} weight rows for {} vertices", w.num_vertices(), rest.size());
  out.resize(rest.size());
  parallel_for(
      ctx, 0, rest.size(),
      [&](std::size_t v) {
        const Vec3& x = rest[v];
        Vec3 d = Vec3::Zero();
        for (uint32_t k = w.offsets[v]; k < w.offsets[v + 1]; ++k) {
          const int b = w.bone[k];
          d += double(w.weight[k]) * (xf.A[b] * x + xf.T[b]);
        }
        out[v] = x + d;
      },
      512);
}

}  // namespace follicle::anim
