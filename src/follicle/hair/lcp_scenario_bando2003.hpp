#pragma once
// Ready-made LCP scenes (Bando 2003 §3.6, Figs. 3.7-3.9) for tests, benchmarks and the scene
// layer: back hair on a head under gravity, optionally a head-shake track and SPH wind. The head
// is a sphere (tests, benchmarks) unless a head mesh is given; then the scalp is trimmed from the
// mesh by the four Catmull-Rom curves of LcpMeshHeadParams (§3.3.1) and the body's voxel planes
// (§3.5) are built from area-uniform samples of the mesh and an optional torso box.
#include <memory>
#include <optional>

#include "follicle/anim/rigid_motion.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/scalp_bando2003.hpp"
#include "follicle/hair/sph_air_bando2003.hpp"
#include "follicle/image/image.hpp"
#include "follicle/sim/voxel_planes.hpp"

namespace follicle::hair {

/// The scalp and body of a mesh head, in the head mesh's frame [m]. The defaults fit the
/// Lee Perry-Smith head of data/meshes/lee_perry_smith (face towards +z, crown at y ~ 0.185 m,
/// nape at y ~ 0.01 m): a scalp over the back and top of the head behind the ears, the whirl at
/// the front of the crown (so the hair is combed back and down) and the shake pivot in the neck.
struct LcpMeshHeadParams {
  // Four Catmull-Rom control polygons forming a closed loop (curve k ends where curve k+1 starts):
  // curve0 -> v = 0 (nape, left to right), curve1 -> u = 1 (right side, up behind and over the
  // ear to the temple), curve2 -> v = 1 (front hairline, right to left), curve3 -> u = 0 (left
  // side, down). Points near the mesh surface; the default is the whole scalp of the default
  // head, nape to hairline.
  std::vector<Vec3> curve0{{0.055, 0.03, -0.062},
                           {0.03, 0.012, -0.068},
                           {0.0, 0.008, -0.068},
                           {-0.03, 0.012, -0.068},
                           {-0.055, 0.03, -0.062}};
  std::vector<Vec3> curve1{
      {-0.055, 0.03, -0.062}, {-0.066, 0.08, -0.05}, {-0.068, 0.125, -0.01}, {-0.055, 0.145, 0.05}};
  std::vector<Vec3> curve2{{-0.055, 0.145, 0.05},
                           {-0.03, 0.157, 0.07},
                           {0.0, 0.16, 0.076},
                           {0.03, 0.157, 0.07},
                           {0.055, 0.145, 0.05}};
  std::vector<Vec3> curve3{
      {0.055, 0.145, 0.05}, {0.068, 0.125, -0.01}, {0.066, 0.08, -0.05}, {0.055, 0.03, -0.062}};
  Vec3 whirl_point{0.0, 0.185, 0.06};  // [m] the nearest scalp vertex is the whirl of (3.4)
  Vec3 pivot{0.0, 0.0, -0.01};         // [m] centre of the head shake (about +y)
  // A box for the torso below the mesh (collision only, not drawn); the default head mesh already
  // includes the neck and shoulders down to y = -0.2 m, so the default box is the chest below.
  bool torso = true;
  Vec3 torso_centre{0.0, -0.3, -0.01};
  Vec3 torso_half_extents{0.17, 0.11, 0.1};
  template <class V>
  void visit(V&& v) {
    v("curve0", curve0, ParamInfo{"scalp boundary v = 0 (Catmull-Rom control points)", "m"});
    v("curve1", curve1, ParamInfo{"scalp boundary u = 1, starts where curve0 ends", "m"});
    v("curve2", curve2, ParamInfo{"scalp boundary v = 1, starts where curve1 ends", "m"});
    v("curve3", curve3,
      ParamInfo{"scalp boundary u = 0, from curve2's end to curve0's start", "m"});
    v("whirl_point", whirl_point, ParamInfo{"whirl of hair (nearest scalp vertex)", "m", -10, 10});
    v("pivot", pivot, ParamInfo{"pivot of the head shake", "m", -10, 10});
    v("torso", torso, ParamInfo{"add a torso box to the collision body"});
    v("torso_centre", torso_centre, ParamInfo{"torso box centre", "m", -10, 10});
    v("torso_half_extents", torso_half_extents, ParamInfo{"torso box half extents", "m", 1e-3, 10});
  }
};

struct LcpScenarioParams {
  double head_radius = 0.1;         // [m] sphere head centred at the origin (when no mesh is given)
  double hair_length = 0.2;         // [m] max hair length
  double spacing = 0.012;           // [m] Poisson-disc radius (about 2,000 particles at 0.009)
  double total_mass = 0.05;         // [kg]
  bool shake = false;               // head shake about +y (Fig. 3.8)
  double shake_angle = 0.7;         // [rad]
  double shake_period = 0.5;        // [s] per cycle
  bool wind = false;                // SPH air (Fig. 3.9)
  double wind_speed = 3.0;          // [m/s] along -z (blowing from the face towards the back hair)
  double air_spacing = 0.02;        // [m]
  double shake_start = 0.0;         // [s] the shake starts here (the head is still before)
  double root_normal_weight = 0.6;  // w_n of (3.4) (w_t = 1): how much the roots stand up
  double cantilever_sag = 800;      // [1/m^3] w/(EI) of the initial cantilever shape
  // Settling before frame 0: the hair is stepped this long under gravity with the head still,
  // no wind and air drag settle_drag, then its velocity is zeroed and time restarts at 0.
  double settle_time = 0.0;     // [s]
  double settle_drag = 12.0;    // [1/s]
  LcpMeshHeadParams mesh_head;  // used with a head mesh
  template <class V>
  void visit(V&& v) {
    v("head_radius", head_radius,
      ParamInfo{"sphere head radius (a head: 3 cm to 1 m)", "m", 0.03, 1.0});
    v("hair_length", hair_length, ParamInfo{"hair length", "m", 1e-3, 10});
    v("spacing", spacing, ParamInfo{"particle spacing", "m", 1e-4, 1});
    v("total_mass", total_mass, ParamInfo{"hair mass", "kg", 1e-9, 100});
    v("shake", shake, ParamInfo{"head shake"});
    v("shake_angle", shake_angle, ParamInfo{"shake amplitude", "rad", 0, 3.2});
    v("shake_period", shake_period, ParamInfo{"shake period", "s", 0.01, 100});
    v("wind", wind, ParamInfo{"SPH wind"});
    v("wind_speed", wind_speed, ParamInfo{"wind speed", "m/s", 0.01, 100});
    v("air_spacing", air_spacing, ParamInfo{"air particle spacing", "m", 1e-3, 1});
    v("shake_start", shake_start, ParamInfo{"time the head shake starts", "s", 0, 1e5});
    v("root_normal_weight", root_normal_weight,
      ParamInfo{"w_n of (3.4): weight of the scalp normal in the root direction (w_t = 1)", "", 0,
                100});
    v("cantilever_sag", cantilever_sag,
      ParamInfo{"w/(EI) of the initial cantilever hair shape", "1/m^3", 0, 1e9});
    v("settle_time", settle_time,
      ParamInfo{"simulated settling under gravity before frame 0 (head still, no wind)", "s", 0,
                100});
    v("settle_drag", settle_drag, ParamInfo{"air drag while settling", "1/s", 0, 1e6});
    v("mesh_head", mesh_head,
      ParamInfo{"scalp curves, whirl, shake pivot and torso of a mesh head (lcp.mesh)"});
  }
  void validate() const { validate_params(*this, "lcp_scenario"); }
};

class LcpScenario {
 public:
  /// Back hair on a sphere head: scalp over the back (polar 0.3..1.9 rad, azimuth 0.35..0.65 pi
  /// about the -z side), whirl at the crown. `lcp` sets the dynamics.
  /// With `head_mesh` (metres, the head frame): the scalp is trimmed from it by
  /// params.mesh_head's curves and the body is the mesh plus the torso box. `length_map`
  /// (optional, values in [0, 1], row 0 = v = 1) scales the hair length (§3.3.1).
  /// Throws follicle::Error (naming the key) on bad curves or parameters.
  LcpScenario(const Context& ctx, const LcpScenarioParams& params, const LcpParams& lcp = {},
              const geom::TriMesh* head_mesh = nullptr, const image::ImageF* length_map = nullptr);

  /// One frame of dt: wind (if any) first, then the hair with the wind's drag as external force,
  /// plus `extra_force` [N, world frame, one per particle] when given (e.g. a parting force).
  LcpStepReport step(const Context& ctx, double dt, const std::vector<Vec3>* extra_force = nullptr);

  double time() const { return m_state.time; }
  const LcpSolver& solver() const { return *m_solver; }
  /// The hair's blow-up speed [m/s]: twice the fastest legitimate motion (wind + the shake's
  /// swing at the hair tips + a free fall over the hair length), at least LcpParams::max_speed.
  double max_speed() const { return m_max_speed; }
  /// LcpSolver::use_simd (same results either way; for A/B benchmarks).
  void use_simd(bool on) { m_solver->use_simd(on); }
  const LcpState& state() const { return m_state; }  // head frame
  /// Puts the hair back into an earlier state() of this scenario (its time included), e.g. to
  /// replay the same frames (the air, if any, is not restored). Throws follicle::Error when the
  /// particle count differs.
  void restore(const LcpState& s);
  const geom::TriMesh& head() const { return m_head; }
  bool mesh_head() const { return m_mesh_head; }
  /// The collision body (head frame): voxel planes of the head (and torso).
  const sim::VoxelPlanes& body() const { return *m_body; }
  /// The torso box mesh (empty without one).
  const geom::TriMesh& torso() const { return m_torso; }
  const Scalp& scalp() const { return m_scalp; }
  const SphAir* air() const { return m_air ? &*m_air : nullptr; }
  anim::RigidSample head_pose() const;
  /// Particle positions and directions in the world frame.
  void world(std::vector<Vec3>& x, std::vector<Vec3>* t = nullptr) const;

 private:
  LcpScenarioParams m_p;
  double m_max_speed = 0;
  void settle(const Context& ctx, const LcpParams& lcp);
  geom::TriMesh m_head, m_torso;
  bool m_mesh_head = false;
  Scalp m_scalp;
  std::unique_ptr<sim::VoxelPlanes> m_body;
  std::unique_ptr<LcpSolver> m_solver;
  LcpState m_state;
  LcpWorkspace m_ws;
  std::optional<anim::RigidMotionTrack> m_track;
  std::optional<SphAir> m_air;
  std::vector<Vec3> m_wx, m_wv, m_wind_force;
};

/// A UV sphere mesh (for the default scenario head).
geom::TriMesh lcp_sphere_mesh(double radius, int nlat = 24, int nlon = 48);
/// An axis-aligned box mesh (outward normals), e.g. the torso of a mesh head.
geom::TriMesh lcp_box_mesh(const Vec3& centre, const Vec3& half_extents);

/// Particles of a block of nx x nz straight strands of len particles each, spacing a, hanging
/// from y = 0 along -y (the `lcp-wind` benchmark's hair): particle (i, j, k), strand (i, j),
/// k-th from the top, at index (k nz + j) nx + i, position a (i, -k, j), direction -y and pillar
/// coordinates (i / nx, j / nz, a (k - 1.5)), so the top two of each strand are root particles
/// (s < 0). Input for connect_particles.
struct LcpStrandBlock {
  std::vector<Vec3> x, t, uvs;
};
LcpStrandBlock lcp_strand_block(int nx, int nz, int len, double a);

/// Multi-rate hair-air coupling (§3.6, ADR 0009) for hair whose head frame is the world frame
/// (head at rest; LcpScenario maps the frames itself and couples once per scenario step): each
/// step() advances the hair by one step of dt and, on every `every`-th call starting with the
/// first, the air by every dt first; the air's mean drag over its step is the hair's external
/// force until the next air step.
class LcpWindCoupling {
 public:
  explicit LcpWindCoupling(int every) : m_every(std::max(1, every)) {}
  /// Hair steps of dt per air step when the air takes its own stable step
  /// (SphAir::stable_step with hair), at least 1.
  static int air_every(const Context& ctx, const SphAir& air, double dt);
  /// A failed air step is returned as the report (the hair is not stepped).
  LcpStepReport step(const Context& ctx, const LcpSolver& solver, LcpState& s, LcpWorkspace& ws,
                     SphAir& air, double dt);
  int every() const { return m_every; }

 private:
  int m_every = 1;
  long m_calls = 0;
  std::vector<Vec3> m_force;  // [N] the air's mean drag on each hair particle
};

}  // namespace follicle::hair
