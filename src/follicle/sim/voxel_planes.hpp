#pragma once
// Voxel planes for hair-body collision (Bando 2003 §3.5). The body (head, torso) is sampled at
// random points, uniformly by area; positions and normals are averaged per voxel, giving one plane
// (p, n) per non-empty voxel that locally approximates the body surface. Planes live in the body
// frame: a body in rigid motion keeps its planes, the caller maps particles into that frame.
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::sim {

struct VoxelPlanesParams {
  double voxel_size = 0.01;         // [m] edge of a voxel
  double samples_per_voxel = 24.0;  // sample density = samples_per_voxel / voxel_size^2
  double max_samples = 2e7;         // budget: a larger body fails before sampling
  template <class V>
  void visit(V&& v) {
    v("voxel_size", voxel_size, ParamInfo{"voxel edge length", "m", 1e-5, 10.0});
    v("samples_per_voxel", samples_per_voxel,
      ParamInfo{"surface samples per voxel-sized area", "", 1.0, 1e4});
    v("max_samples", max_samples,
      ParamInfo{"budget of surface samples (refused before sampling)", "", 1.0, 1e9});
  }
  void validate() const { validate_params(*this, "voxel_planes"); }
};

struct BodyPlane {
  Vec3 p = Vec3::Zero();  // average sample position [m]
  Vec3 n = Vec3::Zero();  // average sample normal, unit
};

/// Parameters of the contact response (3.19)-(3.24).
struct BodyContactParams {
  double threshold = 0.005;  // [m] contact when d < threshold (about the smoothing length h)
  double mu = 0.3;           // Coulomb friction coefficient
  double k_r = 4000.0;       // [1/s^2] repulsion per unit mass at negative distance (3.24)
  template <class V>
  void visit(V&& v) {
    v("threshold", threshold, ParamInfo{"contact distance", "m", 0.0, 1.0});
    v("mu", mu, ParamInfo{"Coulomb friction coefficient", "", 0.0, 10.0});
    v("k_r", k_r, ParamInfo{"repulsion stiffness per unit mass", "1/s^2", 0.0, 1e6});
  }
  void validate() const { validate_params(*this, "body_contact"); }
};

class VoxelPlanes {
 public:
  VoxelPlanes() = default;
  /// Samples every mesh (given in the body frame) by area and averages per voxel. Deterministic
  /// for a seed. Throws follicle::Error on an empty or malformed mesh.
  static VoxelPlanes build(const std::vector<const geom::TriMesh*>& meshes,
                           const VoxelPlanesParams& params, uint64_t seed);

  /// The plane of the voxel containing x (body frame), or nullptr when the voxel is empty.
  const BodyPlane* find(const Vec3& x) const;
  /// Signed distance (3.19) to the plane of x's voxel; +inf when the voxel is empty.
  double distance(const Vec3& x) const;

  double voxel_size() const { return m_size; }
  std::size_t num_planes() const { return m_planes.size(); }
  std::size_t num_samples() const { return m_num_samples; }
  /// All planes (unordered), e.g. for drawing Fig. 3.6.
  std::vector<BodyPlane> planes() const;

 private:
  static uint64_t key(const Eigen::Vector3i& c);
  Eigen::Vector3i cell(const Vec3& x) const;
  void build_dense_index();
  double m_size = 0.01;
  std::size_t m_num_samples = 0;
  std::unordered_map<uint64_t, BodyPlane> m_planes;
  // Dense lookup over the bounding box of the occupied voxels (when it has at most
  // kMaxDenseCells cells): find() runs per particle and sub-step, and an array index is several
  // times cheaper than hashing. m_dense holds -1 or an index into m_dense_planes.
  static constexpr std::size_t kMaxDenseCells = std::size_t(1) << 22;
  std::vector<int32_t> m_dense;
  std::vector<BodyPlane> m_dense_planes;
  Eigen::Vector3i m_lo = Eigen::Vector3i::Zero(), m_dim = Eigen::Vector3i::Zero();
};

/// Contact response of one particle against a body plane, in accelerations (force per unit mass,
/// as the paper's (3.20) v' = v + f dt reads). x: particle position, v_rel: velocity relative to
/// the body surface, a: total applied acceleration. Returns the acceleration to add:
/// (3.21) inelastic stop + (3.23) Coulomb friction + (3.24) repulsion, or zero when d >= threshold.
Vec3 body_contact_accel(const BodyPlane& plane, const Vec3& x, const Vec3& v_rel, const Vec3& a,
                        double dt, const BodyContactParams& params);

/// Speculative contact for a step of length dt (ADR 0016): body_contact_accel within the band;
/// outside it, a particle whose normal velocity after the step, v_n + a_n dt, would carry it past
/// the band's edge is slowed to reach the edge at the step's end: (3.21) applied to the part of
/// its approach beyond the edge, with (3.23)'s Coulomb friction on that impulse. With steps short
/// enough that no particle crosses the band in one (the leapfrog's), it equals
/// body_contact_accel; with longer steps a fast particle still stops at the band's edge instead
/// of inside the body.
Vec3 body_contact_accel_speculative(const BodyPlane& plane, const Vec3& x, const Vec3& v_rel,
                                    const Vec3& a, double dt, const BodyContactParams& params);

}  // namespace follicle::sim
