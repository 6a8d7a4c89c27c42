#pragma once
// Wind as SPH air particles, two-way coupled with the LCP hair particles (Bando 2003 §3.6,
// Fig. 3.9: "the wind is also represented by a set of particles, and is simulated using SPH [27].
// The interactions between the hair particles and the air particles are modeled in the same way
// as Hadap and Magnenat-Thalmann [16]", so the wind is slowed by the hair it pushes).
//
// Air particles fill an axis-aligned box (world frame) and enter through the box face the wind
// blows from, as lattice layers moving at the wind velocity; particles leaving the box are
// removed. Air-air: SPH density (3.1) and pressure force (3.16) with P = k_p max(rho - rho0, 0)
// (no tension, so the free edges of the stream do not clump). Air-hair: a kernel-weighted drag
// on the velocity difference, f = d mu W(h_c, r)/W(h_c, 0) (v_air - v_hair) on the hair particle
// and -f on the air particle (mu = reduced mass), i.e. equal and opposite: momentum the hair
// gains is lost by the air. The hair is held fixed during one air step (explicit coupling); the
// impulse on each hair particle is returned as a mean force over the step.
#include <cstdint>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/hair/lcp_kernels_bando2003.hpp"
#include "follicle/hair/particle_grid.hpp"
#include "follicle/sim/step_report.hpp"

namespace follicle::hair {

struct SphAirParams {
  Vec3 wind_velocity{2.0, 0.0, 0.0};  // [m/s] inflow velocity (world)
  Vec3 box_min{-0.3, -0.45, -0.3};    // [m] air domain (world)
  Vec3 box_max{0.3, 0.2, 0.3};
  double spacing = 0.02;          // [m] lattice spacing of the air particles
  double air_density = 1.2;       // [kg/m^3] particle mass = air_density spacing^3
  double h_factor = 1.0;          // h_air = h_factor spacing
  double k_p = 4.0;               // [m^2/s^2] pressure constant of P = k_p (rho - rho0)
  double drag = 150.0;            // d [1/s] of the air-hair drag, per reduced mass
  double coupling_radius = 0.02;  // [m] 2 h_c: air and hair interact within this distance
  double cfl = 0.4;               // dt_sub <= cfl h / (sqrt(k_p) + |v|max), and d dt_sub <= cfl
  int max_particles = 200000;     // cap (inflow stops spawning beyond it)
  double max_speed = 100.0;       // [m/s] blow-up limit
  template <class V>
  void visit(V&& v) {
    v("wind_velocity", wind_velocity, ParamInfo{"inflow velocity", "m/s", -1000, 1000});
    v("box_min", box_min, ParamInfo{"air domain min corner", "m", -1e3, 1e3});
    v("box_max", box_max, ParamInfo{"air domain max corner", "m", -1e3, 1e3});
    v("spacing", spacing, ParamInfo{"air particle spacing", "m", 1e-4, 10});
    v("air_density", air_density, ParamInfo{"air density", "kg/m^3", 1e-6, 1e4});
    v("h_factor", h_factor, ParamInfo{"h_air / spacing", "", 0.5, 3});
    v("k_p", k_p, ParamInfo{"air pressure constant", "m^2/s^2", 0, 1e6});
    v("drag", drag, ParamInfo{"air-hair drag per reduced mass", "1/s", 0, 1e6});
    v("coupling_radius", coupling_radius, ParamInfo{"air-hair interaction radius", "m", 1e-5, 10});
    v("cfl", cfl, ParamInfo{"sub-step factor", "", 1e-3, 1});
    v("max_particles", max_particles, ParamInfo{"air particle cap", "", 1, 1e8});
    v("max_speed", max_speed,
      ParamInfo{"blow-up speed (the lcp section raises it to twice the wind speed)", "m/s", 1e-3,
                1e9});
  }
  void validate() const;
};

class SphAir {
 public:
  /// Fills the box with a lattice of air particles moving at the wind velocity. Throws
  /// follicle::Error on bad parameters (empty box, zero wind, too many particles).
  SphAir(const Context& ctx, const SphAirParams& params);

  /// Advances the air by dt (sub-stepped), coupled to hair particles at world positions/velocities
  /// hair_x/hair_v with masses hair_mass (all may be empty: air alone). `force_on_hair` (may be
  /// null) receives the mean drag force [N, world] on each hair particle over the step; pass it
  /// as LcpStepInput::external_force (after mapping nothing: it is in the world frame).
  sim::StepReport step(const Context& ctx, double dt, const std::vector<Vec3>& hair_x,
                       const std::vector<Vec3>& hair_v, const std::vector<double>& hair_mass,
                       std::vector<Vec3>* force_on_hair);

  /// The longest stable air sub-step at the current velocities, the rule step() sub-steps by:
  /// cfl h / (sqrt(k_p) + |v|max), and with hair (coupled) also cfl / drag.
  double stable_step(const Context& ctx, bool coupled) const;

  const std::vector<Vec3>& positions() const { return m_x; }
  const std::vector<Vec3>& velocities() const { return m_v; }
  std::size_t size() const { return m_x.size(); }
  double particle_mass() const { return m_mass; }
  double rest_density() const { return m_rho0; }
  const SphAirParams& params() const { return m_p; }
  /// Mean velocity of the air particles inside a box (zero when none; count written if given).
  Vec3 mean_velocity_in(const Vec3& lo, const Vec3& hi, std::size_t* count = nullptr) const;
  /// Total momentum of the air [kg m/s].
  Vec3 momentum() const;

 private:
  void spawn_layer(double offset);
  SphAirParams m_p;
  int m_axis = 0;     // wind axis
  double m_sign = 1;  // +1: wind towards +axis
  double m_mass = 0, m_h = 0, m_rho0 = 0;
  double m_phase = 0;  // distance the last inflow layer has travelled
  std::vector<Vec3> m_x, m_v;
  detail::LcpKernels m_kernels = detail::lcp_kernels();  // density/pressure loops (AVX2 or not)
  // scratch
  ParticleGrid m_grid, m_hair_grid;
  std::vector<uint32_t> m_off, m_nb, m_aoff, m_anb;
  std::vector<double> m_rho, m_pr, m_pr_rho2;  // density, pressure, P/rho^2 per air particle
  std::vector<double> m_mu;                    // reduced mass per hair particle
  std::vector<Vec3> m_acc, m_drag;  // m_drag: air-hair drag on the hair per air-list entry
  std::vector<Vec3> m_impulse;      // drag impulse on each hair particle over a step
  std::vector<Vec3> m_hair_sum;     // drag on each hair particle in one sub-step
};

}  // namespace follicle::hair
