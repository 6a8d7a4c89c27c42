#pragma once
// Hair dynamics, Anjyo, Usami, Kurihara 1992 §3: every segment s_i of a strand is a rigid stick
// whose zenith θ_i and azimuth φ_i obey the one-dimensional projective equations
//   (4)'  θ^{n+1} - 2θ^n + θ^{n-1} = Δt² c_i u_i F_θ
//   (5)'  φ^{n+1} - 2φ^n + φ^{n-1} = Δt² c_i v_i F_φ
// solved segment by segment from the root (outer loop i, inner loop over strands: the state is
// structure-of-arrays [segment][strand], vectorised across strands). Pseudo-force field
// (§3.2.2), joint-angle stiffness σ_i with an optional random fluctuation every ten steps
// (§3.2.3), inertia arrangement of c_i (§3.2.1), gravity, wind and the inertial forces of a
// rigid head motion. Everything is solved in the head frame (the frame of the hull: y up, z to
// the face), as in Fig. 5a; the y axis of the θ plane is the head's.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/mesh_sdf.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/sim/ellipsoid.hpp"
#include "follicle/sim/step_report.hpp"

namespace follicle::hair {

struct ProjectiveParams {
  double dt = 1.0 / 60.0;          // Δt [s]
  std::string inertia = "paper";   // "paper": c_i ∝ i, I_k = I_S (§3.2.1); "uniform": c_i equal
  double inertia_scale = 1.0;      // multiplies every c_i
  double top_inertia_scale = 1.0;  // c_i factor for segments starting above top_height (friction
  double top_height = 0.6;         // near the top of the head, §3.2.1); normalized hull q_y
  bool pseudo_force = true;        // §3.2.2
  double alpha = -0.75;            // α: (D_i, F) < α |D_i| |F| means "against the head"
  double epsilon = 0.1;            // ε_i of the segments near the head
  double epsilon_extent = 1.0;     // ε applies to segments i <= extent * k (root side)
  double near_head = 0.25;         // "near the head": |q| - 1 < near_head (normalized hull)
  double stiffness_root_deg = 180.0;  // σ_i of the first stiffness_root_segments joints [deg]
  double stiffness_deg = 180.0;       // σ_i of the other joints [deg] (180 = no adjustment)
  int stiffness_root_segments = 3;
  double fluctuation = 0.0;           // [rad] amplitude of the uniform random angle fluctuation
  int fluctuation_interval = 10;      // steps between fluctuations ("one per ten frames")
  double damping = 0.0;               // [1/s] velocity damping (not in the paper; 0 = off)
  double rest_spring = 0.0;           // [1/s²] pull towards the styled angles (not in the paper)
  double parallel_threshold = 0.05;   // |sin θ| below which the θ plane is spanned by y and F
  bool ellipsoid_constraint = false;  // hard push-out of nodes from the hull (not in the paper)
  // Collision with the real head surface (not in the paper, which knows only the hull): "mesh"
  // pushes every node whose signed distance to the head mesh (grid, set_collision_grid) is below
  // collision_margin back out by turning its segment about p_{i-1} (the stick keeps its length);
  // "hull": the hull alone, as in the paper (pseudo-force field, ellipsoid_constraint).
  std::string collision = "mesh";
  double collision_margin = 0.002;  // [m] clearance kept above the skin
  double collision_cell = 0.0025;   // [m] spacing of the signed-distance grid
  double max_speed = 100.0;         // [m/s] blow-up limit reported in StepReport

  template <class V>
  void visit(V&& v) {
    v("dt", dt, {"time step", "s", 1e-6, 1.0});
    v("inertia", inertia, {"paper | uniform"});
    v("inertia_scale", inertia_scale, {"multiplier of c_i", "", 0.0, 1e6});
    v("top_inertia_scale", top_inertia_scale,
      {"c_i factor near the top of the head", "", 0.0, 1e3});
    v("top_height", top_height, {"q_y above which top_inertia_scale applies", "", -10.0, 10.0});
    v("pseudo_force", pseudo_force, {"use the pseudo-force field"});
    v("alpha", alpha, {"pseudo-force angle test", "", -1.0, 1.0});
    v("epsilon", epsilon, {"pseudo-force factor", "", 0.0, 1.0});
    v("epsilon_extent", epsilon_extent,
      {"fraction of segments (root side) with epsilon", "", 0.0, 1.0});
    v("near_head", near_head, {"near-head band in normalized hull units", "", 0.0, 10.0});
    v("stiffness_root_deg", stiffness_root_deg, {"sigma near the pore", "deg", 0.0, 180.0});
    v("stiffness_deg", stiffness_deg, {"sigma elsewhere", "deg", 0.0, 180.0});
    v("stiffness_root_segments", stiffness_root_segments,
      {"joints counted as near the pore", "", 0, 64});
    v("fluctuation", fluctuation, {"random angle fluctuation", "rad", 0.0, 1.0});
    v("fluctuation_interval", fluctuation_interval, {"steps between fluctuations", "", 1, 100000});
    v("damping", damping, {"angular velocity damping", "1/s", 0.0, 1e4});
    v("rest_spring", rest_spring, {"pull towards the styled shape", "1/s^2", 0.0, 1e6});
    v("parallel_threshold", parallel_threshold,
      {"|sin theta| of a segment parallel to y", "", 0.0, 0.5});
    v("ellipsoid_constraint", ellipsoid_constraint, {"push nodes out of the hull"});
    v("collision", collision,
      {"mesh (push nodes out of the head mesh, not in the paper) | hull (the hull only, as in "
       "the paper)"});
    v("collision_margin", collision_margin,
      {"clearance of the mesh collision above the skin", "m", 0.0, 0.01});
    v("collision_cell", collision_cell,
      {"cell of the head's signed-distance grid (mesh collision)", "m", 5e-4, 0.02});
    v("max_speed", max_speed, {"blow-up speed", "m/s", 1e-3, 1e6});
  }
  void validate() const;
};

/// Rigid head motion for one step (world): the head frame's origin and orientation with their
/// derivatives. The caller (scene / anim track) supplies it.
struct HeadMotion {
  Vec3 position = Vec3::Zero();
  Quat rotation = Quat::Identity();
  Vec3 velocity = Vec3::Zero();
  Vec3 acceleration = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();      // [rad/s] world
  Vec3 angular_acceleration = Vec3::Zero();  // [rad/s²] world
};

struct ProjectiveInput {
  Vec3 gravity{0.0, -9.81, 0.0};  // [m/s²] world
  Vec3 wind = Vec3::Zero();       // [m/s²] world: force per unit mass of the wind (uniform field)
  HeadMotion head;
};

/// The wind gust of Fig. 10: `before` until `switch_time`, then `after` (paper: (-200,0,0) then
/// (-20,-250,0) from the 16th frame, in its x-to-the-face frame; see docs/equations/anjyo.md).
struct GustParams {
  Vec3 before{0.0, 0.0, -6.0};
  Vec3 after{0.0, -7.5, -0.6};
  double switch_time = 0.5;  // [s]
  template <class V>
  void visit(V&& v) {
    v("before", before, {"wind before the gust", "m/s^2", -1e4, 1e4});
    v("after", after, {"wind after the gust", "m/s^2", -1e4, 1e4});
    v("switch_time", switch_time, {"time of the change", "s", 0.0, 1e6});
  }
  Vec3 at(double t) const { return t < switch_time ? before : after; }
};

/// State: angles per [segment][strand] (segment i = 1..k stored at row i-1), node positions in
/// the head frame per [node][strand], and the step count.
struct ProjectiveState {
  std::vector<double> theta, theta_prev, phi, phi_prev;  // K * N
  std::vector<Vec3> nodes;                               // (K+1) * N, head frame
  uint64_t step = 0;
};

class ProjectiveSolver {
 public:
  /// `rest`: styled strands in the head frame (root first); `hull` in the head frame.
  ProjectiveSolver(const ProjectiveParams& params, const sim::Ellipsoid& hull,
                   const geom::StrandSet& rest, uint64_t seed);

  /// Mesh collision (params().collision == "mesh"): the signed distance of the head surface in
  /// the head frame. Without a grid (or with collision "hull") only the hull is known.
  void set_collision_grid(std::shared_ptr<const geom::SignedDistanceGrid> grid) {
    m_grid = std::move(grid);
  }
  const geom::SignedDistanceGrid* collision_grid() const {
    return m_p.collision == "mesh" ? m_grid.get() : nullptr;
  }

  /// Still hair in the styled shape: θ^0 = θ^{-1} = θ^init, φ^0 = φ^{-1} = φ^init.
  ProjectiveState initial_state() const;
  /// One step of (4)' and (5)'; parallel over strand chunks, identical for any thread count.
  sim::StepReport step(const Context& ctx, const ProjectiveInput& in, ProjectiveState& s) const;
  /// World positions of the current state (head transform applied), same layout as `rest`.
  void positions(const ProjectiveState& s, const HeadMotion& head, geom::StrandSet& out) const;

  std::size_t num_strands() const { return m_n; }
  int max_segments() const { return m_k; }
  const ProjectiveParams& params() const { return m_p; }
  /// c_i u_i (the gain of (4)' per unit F_θ before Δt²) for segment i of strand s (tests).
  double gain(std::size_t s, int i) const;

 private:
  ProjectiveParams m_p;
  sim::Ellipsoid m_hull;
  std::shared_ptr<const geom::SignedDistanceGrid> m_grid;
  geom::StrandSet m_rest;
  uint64_t m_seed;
  std::size_t m_n = 0;
  int m_k = 0;
  std::vector<int> m_nseg;               // segments per strand
  std::vector<double> m_len;             // [K*N] segment lengths
  std::vector<double> m_gain;            // [K*N] c_i u_i / |s_i| ... see gain()
  std::vector<double> m_theta0, m_phi0;  // [K*N] styled angles
  std::vector<Vec3> m_root;              // [N] roots, head frame
  // Single-precision copies for the vectorised step (structure of arrays, [segment][strand]).
  std::vector<float> m_lenf, m_gainf;            // [K*N]
  std::vector<float> m_dir0x, m_dir0y, m_dir0z;  // [K*N] styled directions (rest_spring only)
  std::vector<float> m_rootx, m_rooty, m_rootz;  // [N]
};

/// The mesh collision's signed-distance grid of `head` (head frame, as the solver's hull): over
/// the box of the hull grown by 4 cm, cell params.collision_cell, band max(1 cm, 4 cells).
std::shared_ptr<const geom::SignedDistanceGrid> head_collision_grid(const Context& ctx,
                                                                    const geom::TriMesh& head,
                                                                    const sim::Ellipsoid& hull,
                                                                    const ProjectiveParams& params);

/// Direction of a segment from its angles: (sinθ sinφ, cosθ, sinθ cosφ).
inline Vec3 segment_direction(double theta, double phi) {
  const double st = std::sin(theta);
  return Vec3(st * std::sin(phi), std::cos(theta), st * std::cos(phi));
}
/// Angles of a unit direction, choosing among (θ, φ) and (-θ, φ + π) the one whose φ is nearest
/// to phi_hint (keeps φ continuous through the poles).
void direction_angles(const Vec3& dir, double phi_hint, double& theta, double& phi);

}  // namespace follicle::hair
