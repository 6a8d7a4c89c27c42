#pragma once
// Bando, Chen & Nishita 2003 (thesis ch. 3) as a HairSimulation (ADR 0010): loosely connected
// particles on any groom. The thesis samples the hair volume by Poisson-disc darts in the
// (u, v, s) pillar of a trimmed scalp (§3.3.1, (3.2)-(3.4)); on a groom the volume is already
// given, so the particles sample the groom instead:
//   1. simulated strands: the groom's strands whose roots are at least `strand_spacing` apart
//      (Poisson-disc over the roots in a seeded random order), so particles of neighbouring
//      strands are about as far apart as particles along a strand;
//   2. every simulated strand is resampled by arc length to `spacing` (the r of (3.2)); its
//      first `root_particles` particles get s < 0 (held by the head, §3.3.1), the others s = arc
//      length past them; directions t_i are the strand's tangents;
//   3. the connections of §3.3.1 ((3.5)-(3.6), a_0, N_n) are made from those particles by
//      connect_particles; a particle that cannot reach a root through root-side connections ends
//      its strand's chain (it and the rest of that strand are dropped, as in initialize_lcp);
//   4. the dynamics (3.7)-(3.24) run unchanged (LcpSolver) with the body's voxel planes from the
//      head mesh (§3.5); gravity, the uniform wind field and the air velocity of the environment
//      enter as an external force per particle, the head motion as the inertial forces of §3.6;
//   5. the groom's strands follow the particle chains of the simulated strands by the wisp
//      binding (wisp_daldegan1993.hpp, "offset" mode by default); when every strand is simulated
//      and none was cut, the chains themselves are the output.
#include <memory>

#include "follicle/core/params.hpp"
#include "follicle/hair/hair_model.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/wisp_daldegan1993.hpp"
#include "follicle/sim/voxel_planes.hpp"

namespace follicle::hair {

struct BandoParams {
  LcpParams dynamics;           // (3.7)-(3.24); gravity comes from animation.gravity
  sim::VoxelPlanesParams body;  // voxel planes of the head mesh (§3.5)
  WispParams wisps;             // how the groom follows the particle chains
  double spacing = 0.01;        // [m] particle spacing along a strand (r of (3.2))
  double strand_spacing = 0.0;  // [m] least root distance of simulated strands (0: spacing)
  int root_particles = 2;       // particles per strand held by the head (s < 0)
  int max_particles = 200000;   // refuse grooms that would need more
  double total_mass = 0.05;     // [kg] shared equally by the particles
  double hs_factor = 1.25;      // h_s = hs_factor * spacing (connections)
  double h_factor = 0.8;        // h = h_factor * spacing (hair-hair interaction)
  double a0 = 0.5;              // least alignment a_ij (3.6) of a connection
  int n_n = 12;                 // N_n: about this many connections per particle
  double dt = 1.0 / 120.0;      // [s] step; adaptive leapfrog sub-steps inside (cfl)
  double settle_time = 0.0;     // [s] settling under gravity before t = 0 (head still)
  double settle_drag = 12.0;    // [1/s] air drag while settling
  Vec3 settle_gravity{0.0, -9.81, 0.0};  // [m/s²] head frame, while settling

  template <class V>
  void visit(V&& v) {
    v("dynamics", dynamics,
      ParamInfo{"loosely connected particle dynamics (thesis §3.3.2-3.6); `gravity` must stay "
                "at its default: hair[] models take gravity from animation.gravity"});
    v("body", body, ParamInfo{"voxel planes of the head mesh for hair-body collision (§3.5)"});
    v("wisps", wisps, ParamInfo{"how the groom's strands follow the simulated particle chains"});
    v("spacing", spacing,
      ParamInfo{"particle spacing along a simulated strand (r of (3.2))", "m", 1e-4, 1.0});
    v("strand_spacing", strand_spacing,
      ParamInfo{"least distance between the roots of simulated strands (0: spacing)", "m", 0.0,
                1.0});
    v("root_particles", root_particles,
      ParamInfo{"particles at the start of each strand held by the head (s < 0)", "", 1, 100});
    v("max_particles", max_particles,
      ParamInfo{"refuse a groom that would need more particles", "", 2, 100000000});
    v("total_mass", total_mass, ParamInfo{"hair mass shared by the particles", "kg", 1e-9, 100.0});
    v("hs_factor", hs_factor, ParamInfo{"h_s / spacing (connection smoothing)", "", 0.1, 10.0});
    v("h_factor", h_factor, ParamInfo{"h / spacing (hair-hair smoothing)", "", 0.1, 10.0});
    v("a0", a0, ParamInfo{"alignment threshold a_0 of a connection (3.6)", "", 0.0, 1.0});
    v("n_n", n_n, ParamInfo{"connections per particle N_n", "", 1, 1000});
    v("dt", dt, ParamInfo{"time step (split into adaptive leapfrog sub-steps)", "s", 1e-5, 0.1});
    v("settle_time", settle_time,
      ParamInfo{"let the groom fall under gravity for this long before frame 0 (0: start from "
                "the groom's shape)",
                "s", 0.0, 60.0});
    v("settle_drag", settle_drag, ParamInfo{"air drag while settling", "1/s", 0.0, 1e6});
    v("settle_gravity", settle_gravity,
      ParamInfo{"gravity while settling, head frame (y up)", "m/s^2", -100.0, 100.0});
  }
  void validate() const;
};

/// What the particles of a groom are (steps 1-3 above), for tests and tools.
struct BandoParticles {
  LcpModel model;
  std::vector<std::vector<uint32_t>> chains;  // per simulated strand: particles root to tip
  std::vector<uint32_t> chain_strand;         // per chain: the groom strand it samples
  std::size_t dropped = 0;                    // particles dropped as not held by the head
};
/// Samples `groom` (head frame) into connected particles. Throws follicle::Error naming the key
/// when the groom needs more than max_particles or nothing can be held by the head.
BandoParticles bando_particles(const Context& ctx, const Groom& groom, const BandoParams& params,
                               uint64_t seed);

std::unique_ptr<HairSimulation> make_bando2003(const Context& ctx, const BandoParams& params,
                                               const HairModelSetup& setup);

}  // namespace follicle::hair
