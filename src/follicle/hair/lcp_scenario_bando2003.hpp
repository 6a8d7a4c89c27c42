#pragma once
// Ready-made LCP scenes (Bando 2003 §3.6, Figs. 3.7-3.9) for tests, benchmarks and the scene
// layer: back hair on a head under gravity, optionally a head-shake track and SPH wind. The head
// is a sphere unless a mesh and scalp curves are given.
#include <memory>
#include <optional>

#include "follicle/anim/rigid_motion.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/scalp_bando2003.hpp"
#include "follicle/hair/sph_air_bando2003.hpp"
#include "follicle/sim/voxel_planes.hpp"

namespace follicle::hair {

struct LcpScenarioParams {
  double head_radius = 0.1;   // [m] sphere head centred at the origin (when no mesh is given)
  double hair_length = 0.2;   // [m] max hair length
  double spacing = 0.012;     // [m] Poisson-disc radius (about 2,000 particles at 0.009)
  double total_mass = 0.05;   // [kg]
  bool shake = false;         // head shake about +y (Fig. 3.8)
  double shake_angle = 0.7;   // [rad]
  double shake_period = 0.5;  // [s] per cycle
  bool wind = false;          // SPH air (Fig. 3.9)
  double wind_speed = 3.0;    // [m/s] along -z (blowing from the face towards the back hair)
  double air_spacing = 0.02;  // [m]
  template <class V>
  void visit(V&& v) {
    v("head_radius", head_radius, ParamInfo{"sphere head radius", "m", 1e-3, 10});
    v("hair_length", hair_length, ParamInfo{"hair length", "m", 1e-3, 10});
    v("spacing", spacing, ParamInfo{"particle spacing", "m", 1e-4, 1});
    v("total_mass", total_mass, ParamInfo{"hair mass", "kg", 1e-9, 100});
    v("shake", shake, ParamInfo{"head shake"});
    v("shake_angle", shake_angle, ParamInfo{"shake amplitude", "rad", 0, 3.2});
    v("shake_period", shake_period, ParamInfo{"shake period", "s", 0.01, 100});
    v("wind", wind, ParamInfo{"SPH wind"});
    v("wind_speed", wind_speed, ParamInfo{"wind speed", "m/s", 0.01, 100});
    v("air_spacing", air_spacing, ParamInfo{"air particle spacing", "m", 1e-3, 1});
  }
  void validate() const { validate_params(*this, "lcp_scenario"); }
};

class LcpScenario {
 public:
  /// Back hair on a sphere head: scalp over the back (polar 0.3..1.9 rad, azimuth 0.35..0.65 pi
  /// about the -z side), whirl at the crown. `lcp` sets the dynamics.
  LcpScenario(const Context& ctx, const LcpScenarioParams& params, const LcpParams& lcp = {});

  /// One frame of dt: wind (if any) first, then the hair with the wind's drag as external force.
  LcpStepReport step(const Context& ctx, double dt);

  double time() const { return m_state.time; }
  const LcpSolver& solver() const { return *m_solver; }
  const LcpState& state() const { return m_state; }  // head frame
  const geom::TriMesh& head() const { return m_head; }
  const Scalp& scalp() const { return m_scalp; }
  const SphAir* air() const { return m_air ? &*m_air : nullptr; }
  anim::RigidSample head_pose() const;
  /// Particle positions and directions in the world frame.
  void world(std::vector<Vec3>& x, std::vector<Vec3>* t = nullptr) const;

 private:
  LcpScenarioParams m_p;
  geom::TriMesh m_head;
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

}  // namespace follicle::hair
