#pragma once
// Hair dynamics, Daldegan, Magnenat Thalmann, Kurihara, Thalmann 1993 §3.1, §3.2, §3.4: a strand
// is a chain of k rigid segments s_i between nodes P_0 (root, fixed to the head) .. P_k; every
// segment turns about its start node P_{i-1} by two polar angles θ_i, φ_i obeying
//   (1)  I_i θ_i'' + γ_i θ_i' = M_θ,   I_i φ_i'' + γ_i φ_i' = M_φ
//   (2)  M = M_spring + M_external          (3)  M_spring = -k (angle - initial angle)
// ("hinge effect": each angle is pulled back to its styled value). External moments come from
// gravity, the inertial forces of the rigid head motion, wind drag, and the reaction constraint
// of the cylindrical body tables (4)-(6). Node positions are rebuilt root to tip from the
// angles. Everything is solved in the head frame (y up, z to the face, as ProjectiveSolver).
//
// Polar frame (Fig. 2; its drawing is not legible in our copy): a segment's direction is
// F_i · segment_direction(θ, φ) = F_i (sinθ sinφ, cosθ, sinθ cosφ) with a fixed rotation F_i per
// segment. polar_frame "head": F_i = identity, θ the zenith from the head's y axis and φ the
// azimuth from z, the frame of Anjyo 1992 (ProjectiveSolver) read literally. Its poles are where
// hanging hair rests: a segment pointing straight down has ∂d/∂φ = 0, so sideways forces (a head
// shake, side wind) give it no torque at all. polar_frame "rest" (default, ours): F_i puts the
// styled direction on the equator (θ_0 = π/2, φ_0 = 0) with the pole horizontal and across it, so
// the styled pose is far from both poles; φ then turns the segment in the vertical plane of its
// styled direction (sagging), θ turns it sideways. Near the styled pose both charts agree to first
// order for horizontal segments.
//
// Moment of inertia (docs/equations/daldegan_dynamics.md): the paper leaves I_i to the user
// ("we specify parameters ... such as moment of inertia"). inertia "segment": I_i = m_i l_i²/3, a
// uniform rod about its start node, loaded only by the forces on itself (lever l_i/2). inertia
// "outboard" (default): the hinge at P_{i-1} carries the rest of the strand as a straight rod of
// length a_i = l_i + ... + l_k along s_i, I_i = μ a_i³/3 with its load at a_i/2 (the idea of Anjyo
// 1992 §3.2.1): root segments then swing like the whole strand, the tip like itself.
//
// Time integration, per angle, each sub-step h (comments in the .cpp): a kick by the explicit
// external moments, then the damped hinge oscillator I q'' + γ q' + k (q - q_0) = 0 advanced by
// the implicit midpoint rule (exact energy for the undamped linear part, unconditionally stable,
// monotone decay with damping); gravity and the head's linear acceleration (a uniform field) are
// split symmetrically (half kick before, half after), so without damping the energy
//   E = Σ_i ½ I_i (θ_i'² + φ_i'²) + ½ k_θ,i Δθ_i² + ½ k_φ,i Δφ_i² − μ a_i (a_i/2) g·d_i
// (kinetic_energy + potential_energy) is conserved to O(h²) with no drift. The collision
// penalty (5), linearised in the segment's own angles, joins the implicit solve.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/hair/projective_anjyo1992.hpp"  // HeadMotion, segment_direction, direction_angles
#include "follicle/sim/cylinder_table_daldegan1993.hpp"
#include "follicle/sim/step_report.hpp"

namespace follicle::hair {

struct HingeParams {
  double dt = 1.0 / 240.0;           // [s] step() advances by dt
  int substeps = 1;                  // integration sub-steps per step (h = dt / substeps)
  std::string polar_frame = "rest";  // "rest" (styled direction on the equator) | "head"
  std::string inertia =
      "outboard";              // "outboard" (hinge carries the rest of the strand) | "segment"
  double inertia_scale = 1.0;  // multiplies every I_i (the paper's user parameter)
  double density = 1300.0;     // [kg/m³] hair (keratin)
  double radius = 40e-6;       // [m] hair radius: μ = ρ π r² per unit length
  // Springs (3) and damping (1) for a lever arm of reference_length; an arm a (l_i or a_i, see
  // inertia) gets k (a / reference_length)² and γ (a / reference_length)^2.5, which keeps the
  // sag under gravity and the damping ratio independent of the segmentation (0 = no scaling).
  // Defaults: a horizontal styled segment sags about 26° under gravity (k ≈ 1.9 m g a/2 for the
  // reference arm), damping ratio about 0.2 (γ = 0.4 sqrt(k I)), for hair of the default density
  // and radius. Springs, damping and the penalty of (5) are implicit; the explicit kick of the
  // external field needs dt < 2 sqrt(2 a / 3 g) (16 ms for an arm of 1 mm).
  double k_theta = 1.5e-9;          // [N·m/rad] k_θ at the root
  double k_phi = 1.5e-9;            // [N·m/rad] k_φ at the root
  double tip_stiffness = 1.0;       // k at the tip / k at the root (linear in arc length)
  double damping = 8e-12;           // [N·m·s/rad] γ
  double reference_length = 0.005;  // [m]
  double drag = 5e-5;               // [N·s/m²] wind drag per unit length and unit relative speed
  // Reaction constraint (4)-(6), per unit mass of the segment's arm: F_constrained =
  // -(k PT + c V·N) N with PT = (P - T)·N (negative inside).
  double collision_k = 1e4;         // [1/s²] strength k of (5)
  double collision_c = 100.0;       // [1/s] damping c of (5)
  double contact_distance = 0.001;  // [m] (4)-(6) act on nodes this close to the surface
  bool projection = true;           // ours: put nodes still inside back onto the surface
  double max_speed = 50.0;          // [m/s] blow-up limit (node speed in the head frame)

  template <class V>
  void visit(V&& v) {
    v("dt", dt, {"time step advanced by one step()", "s", 1e-6, 0.1});
    v("substeps", substeps, {"integration sub-steps per step", "", 1, 1000});
    v("polar_frame", polar_frame,
      {"rest (styled direction on the equator of each segment's polar frame) | head (the head's "
       "y axis as pole for every segment)"});
    v("inertia", inertia,
      {"outboard (each hinge carries the rest of the strand as a rod) | segment (I = m l^2/3 of "
       "the segment alone)"});
    v("inertia_scale", inertia_scale, {"multiplier of every moment of inertia", "", 1e-3, 1e6});
    v("density", density, {"hair density", "kg/m^3", 1.0, 1e5});
    v("radius", radius, {"hair radius", "m", 1e-7, 0.01});
    v("k_theta", k_theta,
      {"spring constant k_theta at the root (reference arm)", "N*m/rad", 0.0, 1.0});
    v("k_phi", k_phi, {"spring constant k_phi at the root (reference arm)", "N*m/rad", 0.0, 1.0});
    v("tip_stiffness", tip_stiffness, {"spring constant at the tip / at the root", "", 0.0, 1e3});
    v("damping", damping, {"damping gamma (reference arm)", "N*m*s/rad", 0.0, 1.0});
    v("reference_length", reference_length,
      {"arm length the spring and damping constants are given for (0: no scaling)", "m", 0.0,
       10.0});
    v("drag", drag, {"wind drag per unit length and relative speed", "N*s/m^2", 0.0, 1.0});
    v("collision_k", collision_k,
      {"strength k of the reaction constraint (5), per unit mass", "1/s^2", 0.0, 1e9});
    v("collision_c", collision_c,
      {"damping c of the reaction constraint (5), per unit mass", "1/s", 0.0, 1e6});
    v("contact_distance", contact_distance,
      {"distance above the surface where (4)-(6) act", "m", 0.0, 0.1});
    v("projection", projection,
      {"put nodes still inside the body back onto its surface after each sub-step (ours)"});
    v("max_speed", max_speed, {"blow-up speed", "m/s", 1e-3, 1e6});
  }
  void validate() const;
};

struct HingeInput {
  Vec3 gravity{0.0, -9.81, 0.0};      // [m/s²] world
  Vec3 wind_velocity = Vec3::Zero();  // [m/s] world: uniform air velocity
  HeadMotion head;                    // rigid head motion (world), see projective_anjyo1992.hpp
};

/// State, structure of arrays: angles and angular velocities per [segment][strand] (segment
/// i = 1..k at row i-1; rows beyond a short strand's k stay 0), node positions in the head frame
/// per [node][strand] (row 0 = roots).
struct HingeState {
  std::vector<double> theta, phi, dtheta, dphi;  // K * N [rad], [rad/s]
  std::vector<Vec3> nodes;                       // (K + 1) * N, head frame [m]
  double time = 0.0;
  uint64_t step = 0;
  std::size_t unresolved = 0;  // nodes the last step could not move out of the body (0 normally)
  // Contacts found at the end of the last step, [segment][strand] for the segment's end node:
  // (P - T)·N of (5) where the node is within contact_distance of the body, +inf elsewhere, and
  // the normal N there. The next step applies the reaction constraint (4)-(6) from these (its
  // nodes start where the last step left them). initial_state: NaN = "not known, test every
  // node"; a state edited by hand should be reset to NaN.
  std::vector<float> contact_distance;
  std::vector<Vec3f> contact_normal;
};

class HingeSolver {
 public:
  /// `rest_head_frame`: the styled strands in the head frame (root first, >= 2 points each).
  /// `collider`: the body's cylinder tables in the head frame, or null. Throws follicle::Error on
  /// bad parameters or strands.
  HingeSolver(const HingeParams& params, const geom::StrandSet& rest_head_frame,
              std::shared_ptr<const sim::CylinderBody> collider);

  /// Still hair in the styled shape (§3.4: the styled angles are the initial angles of (3)).
  HingeState initial_state() const;
  /// Advances by params().dt; parallel over strand chunks, bit-identical for any thread count.
  /// NaN/Inf or a node faster than max_speed is reported (smallest strand index), not thrown.
  sim::StepReport step(const Context& ctx, const HingeInput& in, HingeState& s) const;
  /// World positions (head transform applied), same layout as the rest strands.
  void positions(const HingeState& s, const HeadMotion& head, geom::StrandSet& out_world) const;

  /// Σ ½ I_i (θ_i'² + φ_i'²) [J].
  double kinetic_energy(const HingeState& s) const;
  /// Σ ½ k_θ Δθ² + ½ k_φ Δφ² − μ a_i (a_i/2) g·d_i with g = in.gravity in the head frame
  /// (in.head.rotation): the potential of the moments the solver integrates [J].
  double potential_energy(const HingeState& s, const HingeInput& in) const;

  std::size_t num_strands() const { return m_n; }
  int max_segments() const { return m_k; }
  int num_segments(std::size_t s) const { return m_nseg[s]; }
  const HingeParams& params() const { return m_p; }
  const sim::CylinderBody* collider() const { return m_body.get(); }
  /// Moment of inertia I_i [kg·m²], spring constants [N·m/rad], damping [N·m·s/rad], lever arm
  /// a_i [m] and styled angles of segment i (1..k) of strand s (tests, tools).
  double inertia(std::size_t s, int i) const;
  double k_theta(std::size_t s, int i) const;
  double k_phi(std::size_t s, int i) const;
  double damping(std::size_t s, int i) const;
  double arm(std::size_t s, int i) const;
  double theta0(std::size_t s, int i) const { return m_theta0[row(s, i)]; }
  double phi0(std::size_t s, int i) const { return m_phi0[row(s, i)]; }
  /// Head-frame direction of segment i of strand s for angles (θ, φ) (its polar frame applied).
  Vec3 direction(std::size_t s, int i, double theta, double phi) const;
  /// Angles of a head-frame unit direction for segment i of strand s (φ nearest phi_hint).
  void angles(std::size_t s, int i, const Vec3& dir, double phi_hint, double& theta,
              double& phi) const;

 private:
  std::size_t row(std::size_t s, int i) const { return std::size_t(i - 1) * m_n + s; }

  HingeParams m_p;
  std::shared_ptr<const sim::CylinderBody> m_body;
  geom::StrandSet m_rest;
  std::size_t m_n = 0;
  int m_k = 0;
  double m_mu = 0;  // [kg/m] mass per unit length
  std::vector<int> m_nseg;
  // Per segment, [segment][strand] (padding rows: zero length, inert).
  std::vector<double> m_len_d, m_arm_d, m_inertia_d, m_kt_d, m_kp_d, m_gamma_d;  // SI, double
  std::vector<float> m_theta0, m_phi0;  // styled angles (the state starts at exactly these)
  std::vector<float> m_len;             // l_i
  std::vector<float> m_gain;            // 3 / (2 a_i s): angular acceleration per unit field
  std::vector<float> m_pen;  // 3 l_i / (a_i² s): same for a force per unit arm mass at P_i
  std::vector<float> m_kt, m_kp, m_gd;  // k_θ / I, k_φ / I, (γ + drag of the arm's own turn) / I
  std::vector<float> m_fy[3], m_fz[3];  // polar frame: pole (local y) and equator zero (local z)
  std::vector<float> m_root[3];         // [N] roots, head frame
};

}  // namespace follicle::hair
