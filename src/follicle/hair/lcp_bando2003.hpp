#pragma once
// Loosely connected particles (Bando, Chen & Nishita 2003; thesis ch. 3): hair as unordered
// particles sampling the hair volume, loose springs between initially aligned neighbours with a
// constant tensile modulus, SPH-style hair-hair interaction and voxel-plane hair-body collision.
//
// Frames: particles are simulated in the HEAD (rest) frame; the head moves rigidly by an
// anim::RigidSample given per step, which adds the inertial forces of §3.6 (the paper simulates
// in the head frame too: "inertia force due to head movement"). Root particles (s < 0) and the
// body's voxel planes stay fixed in that frame. world_positions() maps the state to the world.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/anim/rigid_motion.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/hair/lcp_kernels_bando2003.hpp"
#include "follicle/hair/particle_grid.hpp"
#include "follicle/hair/scalp_bando2003.hpp"
#include "follicle/hair/sph_kernel.hpp"
#include "follicle/sim/step_report.hpp"
#include "follicle/sim/voxel_planes.hpp"

namespace follicle::hair {

/// Particle initialisation and connections (§3.3.1).
struct LcpInitParams {
  double spacing = 0.012;          // r [m]: Poisson-disc radius under the distance (3.2)
  int max_particles = 200000;      // hard cap on the number of particles
  int attempts_per_particle = 40;  // dart throwing stops after this many misses per particle
  Vec3 whirl_point{0, 1, 0};       // [m] head frame; the nearest scalp vertex is the whirl
  double w_t = 1.0;                // (3.4) weight of the tangential root direction
  double w_n = 0.6;                // (3.4) weight of the normal root direction
  double hs_factor = 1.25;         // h_s = hs_factor * mean nearest-neighbour distance
  double h_factor = 0.8;           // h = h_factor * mean nearest-neighbour distance
  double a0 = 0.5;                 // minimum alignment a_ij (3.6) of a connection
  int n_n = 12;                    // N_n: about this many connections per particle
  double total_mass = 0.05;        // [kg] hair mass shared equally by the particles
  Vec3 gravity_dir{0, -1, 0};      // head-frame direction of gravity for the cantilever shape
  double cantilever_sag = 800;     // w/(EI) [1/m^3]: load over bending stiffness of the beam
  int cantilever_segments = 24;    // segments of the cantilever chain per strand
  double body_clearance = 0.004;   // [m] the initial chain keeps this far from the body planes
  template <class V>
  void visit(V&& v) {
    v("spacing", spacing, ParamInfo{"Poisson-disc radius of (3.2)", "m", 1e-4, 1.0});
    v("max_particles", max_particles, ParamInfo{"particle cap", "", 1, 1e8});
    v("attempts_per_particle", attempts_per_particle, ParamInfo{"dart misses", "", 1, 1e5});
    v("whirl_point", whirl_point, ParamInfo{"whirl of hair (head frame)", "m", -100, 100});
    v("w_t", w_t, ParamInfo{"tangent weight of (3.4)", "", -100, 100});
    v("w_n", w_n, ParamInfo{"normal weight of (3.4)", "", -100, 100});
    v("hs_factor", hs_factor, ParamInfo{"h_s / mean spacing", "", 0.1, 10});
    v("h_factor", h_factor, ParamInfo{"h / mean spacing", "", 0.1, 10});
    v("a0", a0, ParamInfo{"alignment threshold a_0", "", 0.0, 1.0});
    v("n_n", n_n, ParamInfo{"connections per particle N_n", "", 1, 1000});
    v("total_mass", total_mass, ParamInfo{"hair mass", "kg", 1e-9, 100});
    v("gravity_dir", gravity_dir, ParamInfo{"gravity direction for the initial shape", "", -1, 1});
    v("cantilever_sag", cantilever_sag, ParamInfo{"w/(EI) of the cantilever", "1/m^3", 0, 1e9});
    v("cantilever_segments", cantilever_segments, ParamInfo{"chain segments", "", 1, 10000});
    v("body_clearance", body_clearance, ParamInfo{"initial distance from the body", "m", 0, 1});
  }
  void validate() const;
};

/// The implicit integrator (ADR 0014): each sub-step is one linearised backward-Euler step of the
/// thesis's forces (Baraff & Witkin 1998): the loose springs (3.7)-(3.14) with their damping, the
/// SPH pressure (3.16) through its pair stiffness, the hair-hair damping (3.17)/(3.18) and the air
/// drag enter the matrix, solved by conjugate gradients; gravity, inertial forces and wind are
/// explicit, the body contact (3.19)-(3.24) acts on the solved velocity. The sub-step is set by
/// how far particles move (cfl: the fastest particle moves at most cfl h per sub-step, h the
/// hair-hair smoothing length), not by the spring stiffness.
struct LcpImplicitParams {
  int min_substeps = 1;      // sub-steps per step() at least
  double cfl = 1.0;          // largest displacement per sub-step / h
  double tolerance = 1e-2;   // conjugate gradients stop at |r| <= tolerance |b|
  int max_iterations = 200;  // conjugate-gradient iteration cap per sub-step
  // Body contact on the velocity predicted at the sub-step's end, against the planes where the
  // particle is and where it would go (sim::body_contact_accel_speculative, ADR 0016): sub-steps
  // need not keep particles within the contact band. false: the band bounds the sub-step while
  // any particle touches the body (the rule of ADR 0014).
  bool speculative_contact = true;
  template <class V>
  void visit(V&& v) {
    v("min_substeps", min_substeps, ParamInfo{"minimum implicit sub-steps per step", "", 1, 10000});
    v("cfl", cfl, ParamInfo{"largest displacement per sub-step / h", "", 0.01, 4});
    v("tolerance", tolerance, ParamInfo{"relative residual of the linear solve", "", 1e-12, 0.5});
    v("max_iterations", max_iterations, ParamInfo{"linear-solve iteration cap", "", 1, 100000});
    v("speculative_contact", speculative_contact,
      ParamInfo{"body contact on the predicted end-of-sub-step motion"});
  }
};

/// Dynamics (§3.3.2, §3.3.3, §3.5, §3.6).
struct LcpParams {
  // "leapfrog": the explicit reference integration (adaptive sub-steps by `cfl`); "implicit":
  // LcpImplicitParams (ADR 0014).
  std::string integrator = "leapfrog";
  LcpImplicitParams implicit;
  int substeps = 4;                 // minimum sub-steps per step()
  double cfl = 0.5;                 // adaptive sub-steps: omega_max dt_sub <= cfl (0 = fixed)
  int max_substeps = 2000;          // cap of the adaptive sub-step count
  Vec3 gravity{0, -9.81, 0};        // [m/s^2] world frame
  double air_drag = 0.6;            // [1/s] drag per unit mass against still air
  double elastic_modulus = 40000;   // E [Pa] of (3.10)/(3.11), kept constant per particle
  double material_density = 1300;   // delta [kg/m^3] of (3.9)
  double spring_damping = 0.5;      // damping ratio of each loose spring
  double compression_scale = 0.25;  // scales compressed springs: bending vs tensile stiffness
  int alpha_sweeps = 0;             // balancing sweeps after (3.14) (0 = the paper: average only)
  bool hair_hair = true;            // §3.3.3 on/off (Fig. 3.7 c vs d)
  double k_a = 5.0;                // [m^2/s^2] (3.16) P = k_a (rho - rho0); sqrt(k_a) = sound speed
  double rho0_scale = 1.0;         // rho0 = rho0_scale * mean rest density (< 1 repulsive)
  double collision_damping = 400;  // d_c of (3.17), per reduced mass [1/s] (see .cpp)
  double friction_damping = 4;     // d_f of (3.18), per reduced mass [1/s]
  double colinear_eps = 0.2;       // |t_i x t_j| below this: near-colinear collision direction
  bool body_collision = true;      // §3.5 on/off (needs voxel planes)
  sim::BodyContactParams contact;  // (3.19)-(3.24)
  double max_speed = 30;           // [m/s] a faster particle is reported as a blow-up
  // Verlet skin of the hair-hair neighbour lists, as a fraction of the interaction radius 2h:
  // lists hold all pairs within 2h (1 + skin) and are rebuilt only when some particle has moved
  // more than half the skin since the last build (0 = rebuild every sub-step). Does not change
  // which pairs interact (the kernel is zero beyond 2h), only how often the grid is searched.
  double neighbour_skin = 0.15;
  template <class V>
  void visit(V&& v) {
    v("integrator", integrator,
      ParamInfo{"leapfrog (explicit reference) | implicit (linearised backward Euler, ADR 0014)"});
    v("implicit", implicit,
      ParamInfo{"the implicit integrator's step control and linear solve (integrator implicit)"});
    v("substeps", substeps, ParamInfo{"minimum leapfrog sub-steps per step", "", 1, 10000});
    v("cfl", cfl,
      ParamInfo{"stability factor of the adaptive sub-step (0: exactly `substeps`, refused when "
                "beyond the leapfrog's stability limit)",
                "", 0, 1});
    v("max_substeps", max_substeps, ParamInfo{"sub-step cap", "", 1, 1000000});
    v("gravity", gravity, ParamInfo{"gravity", "m/s^2", -1000, 1000});
    v("air_drag", air_drag, ParamInfo{"air drag per unit mass", "1/s", 0, 1000});
    v("elastic_modulus", elastic_modulus, ParamInfo{"tensile modulus E", "Pa", 1e-6, 1e12});
    v("material_density", material_density, ParamInfo{"hair material density", "kg/m^3", 1, 1e5});
    v("spring_damping", spring_damping, ParamInfo{"spring damping ratio", "", 0, 10});
    v("compression_scale", compression_scale, ParamInfo{"compressed spring scale", "", 0, 10});
    v("alpha_sweeps", alpha_sweeps, ParamInfo{"alpha balancing sweeps", "", 0, 100});
    v("hair_hair", hair_hair, ParamInfo{"hair-hair interaction"});
    v("k_a", k_a, ParamInfo{"pressure constant k_a (sqrt(k_a): sound speed)", "m^2/s^2", 0, 1000});
    v("rho0_scale", rho0_scale,
      ParamInfo{"rest density rho0 / mean rest density (< 1 repulsive, > 1 clumping)", "", 0, 1.5});
    v("collision_damping", collision_damping, ParamInfo{"collision damping d_c", "1/s", 0, 1e4});
    v("friction_damping", friction_damping, ParamInfo{"friction damping d_f", "1/s", 0, 1e4});
    v("colinear_eps", colinear_eps, ParamInfo{"near-colinear threshold", "", 0, 1});
    v("body_collision", body_collision, ParamInfo{"hair-body collision"});
    v("contact", contact, ParamInfo{"hair-body contact (3.19)-(3.24)"});
    v("max_speed", max_speed,
      ParamInfo{"blow-up speed (the lcp section raises it to twice wind + shake swing + free fall)",
                "m/s", 1e-3, 1e9});
    v("neighbour_skin", neighbour_skin,
      ParamInfo{"Verlet skin / 2h of the neighbour lists", "", 0, 2});
  }
  void validate() const;
};

/// Constant per-particle data and the fixed connections.
struct LcpModel {
  std::vector<Vec3> uvs;      // (u_i, v_i, s_i)
  std::vector<double> mass;   // m_i [kg]
  std::vector<uint8_t> root;  // 1 = root particle (s < 0): fixed to the head
  std::vector<Vec3> rest_x;   // initial positions (head frame) [m]
  std::vector<Vec3> rest_t;   // initial hair directions, unit
  // Connections, each oriented from its root-side particle a to its tip-side particle b, so
  // b is in N_t(a) and a in N_r(b) (Fig. 3.3 a).
  std::vector<uint32_t> pair_a, pair_b;
  std::vector<double> l0;            // l0_ij [m]
  std::vector<double> c;             // c_ij = a_ij l0_ij (3.5)
  std::vector<double> cos_a, cos_b;  // cos(theta0) of t_a and t_b against x_ab (both > 0)
  std::vector<uint32_t> adj_offsets, adj_pairs;  // particle -> its connections (CSR)
  double spacing = 0;                            // mean nearest-neighbour distance [m]
  double h_s = 0;                                // smoothing length of the connections [m]
  double h = 0;                                  // smoothing length of hair-hair interaction [m]
  double rest_density = 0;  // mean SPH density (3.1) of non-root particles at rest

  std::size_t size() const { return mass.size(); }
  std::size_t num_pairs() const { return l0.size(); }
};

struct LcpState {
  std::vector<Vec3> x;  // head frame [m]
  std::vector<Vec3> v;  // head frame [m/s] (leapfrog: half a sub-step behind x)
  std::vector<Vec3> t;  // unit hair directions
  double time = 0;
};

/// What step() reports (the simulation never throws on divergence): the shared sim::StepReport
/// (ok, non_finite, blow_up, max_speed [m/s, head frame], first_bad particle, message) plus the
/// LCP specifics.
struct LcpStepReport : sim::StepReport {
  int substeps = 0;              // sub-steps taken
  int solver_iterations = 0;     // implicit: conjugate-gradient iterations over all sub-steps
  double solver_residual = 0;    // implicit: largest relative residual a sub-step ended with
  double max_penetration = 0;    // [m] deepest particle below a body plane (>= 0)
  std::size_t num_contacts = 0;  // particles in contact at the last sub-step
};

struct LcpStepInput {
  double dt = 1.0 / 60.0;                             // [s] split into params.substeps
  anim::RigidSample head;                             // head/body pose and motion (world)
  const std::vector<Vec3>* external_force = nullptr;  // [N] world frame per particle (wind)
};

/// Scratch buffers of a solver (reused between steps; not part of the physical state).
struct LcpWorkspace {
  ParticleGrid grid;
  // Neighbours within 2h (1 + skin) at the last build, each list sorted by index (a superset of
  // the current neighbours within 2h; farther pairs contribute nothing). step() keeps them
  // between sub-steps (Verlet lists); pair_forces() also accepts lists built by the caller.
  std::vector<uint32_t> nbr_offsets, nbrs;
  std::vector<double> density, pressure;  // (3.1), P = k_a (rho - rho0)
  std::vector<double> k;                  // k_ij (3.7) per connection
  std::vector<double> alpha;              // alpha_ij (3.14) per connection
  std::vector<double> alpha_r, alpha_t;   // (3.13) per particle
  std::vector<Vec3> force;                // [N] head frame
  std::vector<Vec3> accel;
  // Verlet-list bookkeeping and per-pair scratch (pairs evaluated once, gathered per particle).
  std::vector<uint32_t> nbr_mirror;  // entry (i -> j) -> entry (j -> i)
  std::vector<Vec3> nbr_built_x;     // positions at the last list build
  double nbr_radius = 0;             // radius of the last build [m]
  std::size_t nbr_builds = 0;        // number of list builds (statistics)
  // Pairs i < j (the entries of each list from nbr_upper[i] on) are numbered in list order:
  // particle i's pairs are the slots pair_off[i] .. pair_off[i + 1] - 1, and nbr_pair[e] is the
  // slot of the pair of entry e (of either end), so the per-pair arrays hold each pair once.
  std::vector<uint32_t> pair_off, nbr_pair;
  std::vector<double> pair_w;            // W(h, r) per pair slot
  std::vector<Vec3> pair_f;              // hair-hair force on the lower-index end per pair slot [N]
  std::vector<uint32_t> pair_i, pair_j;  // the ends i < j of each pair slot
  // The interacting pairs (0 < r < 2h) of each chunk c of 64 particles, from index
  // pair_off[64 c] on (act_count[c] of them): ends and pair slot.
  std::vector<uint32_t> act_i, act_j, act_slot, act_count;
  std::vector<Vec3> spring_f;       // spring force on the root-side end per connection [N]
  std::vector<double> p_rho2;       // P_i / rho_i^2 per particle
  std::vector<uint8_t> contact;     // per particle, last sub-step
  std::vector<double> penetration;  // per particle, last sub-step [m]
  // First entry of each neighbour list with a higher index (the lists are sorted): the pairs a
  // particle evaluates itself.
  std::vector<uint32_t> nbr_upper;
  // Connection geometry at the positions geom_x: |x_ab| and x^_ab = x_ab / |x_ab| per connection
  // (x_ab = x_b - x_a). Shared by k_ij (3.7), the spring forces and the direction update (3.15)
  // of both ends; reused by the next step() when the positions are bit-identical.
  std::vector<double> conn_r;
  std::vector<Vec3> conn_xh;
  std::vector<Vec3> geom_x;
  // The terms of the direction update (3.15) of both ends of each connection, 8 per connection
  // (detail::lcp_geometry_terms), computed with the geometry.
  std::vector<double> dir_term;
  const void* geom_owner = nullptr;  // the solver that computed conn_r / conn_xh
  // max |d - nbr_shift|^2 per chunk, d the displacement since the list build
  // (LcpSolver::lists_hold).
  std::vector<double> chunk_shift;
  Vec3 nbr_shift = Vec3::Zero();     // common shift u of the last successful list check [m]
  bool shift_ready = false;          // chunk_shift holds the displacements of the current positions
  std::size_t nbr_early_builds = 0;  // builds decided before a sub-step's first pass (statistics)
  struct ChunkCheck {
    double vmax = 0;
    std::size_t bad = SIZE_MAX;
    std::size_t contacts = 0;  // particles in contact (last sub-step)
    double max_pen = 0;        // deepest penetration [m] (last sub-step)
  };
  std::vector<ChunkCheck> chunk_check;
  // Implicit sub-step (LcpSolver::step_implicit, ADR 0014). Per connection: the stiffness along
  // x^_ab (alpha k, scaled when compressed), across it (the tension alpha k (1 - l0/r) >= 0) and
  // the damping along it; per pair slot: x^_ij, d^_n (3.17) and the pair's stiffness (3.16),
  // collision (3.17) and friction (3.18) damping coefficients.
  std::vector<double> imp_spar, imp_sperp, imp_cpar;
  std::vector<Vec3> imp_pxh, imp_pdh;
  std::vector<double> imp_pk, imp_pc, imp_pf;
  std::vector<Vec3> imp_dv, imp_r, imp_z, imp_p, imp_q, imp_b;
  std::vector<Mat3> imp_dinv;  // inverse diagonal blocks (block-Jacobi preconditioner)
  // The assembled rows of the system matrix (symmetric blocks xx yy zz xy xz yz): the diagonal
  // block, the row's entries (column and block B, A_ij = -B) from LcpSolver::row_start on, their
  // count, and S v0 of the sub-step's start velocities.
  using Sym = std::array<double, 6>;
  std::vector<Sym> imp_diag;
  std::vector<std::array<float, 6>> imp_blk;
  std::vector<uint32_t> imp_col, imp_len;
  std::vector<Vec3> imp_sv;
  std::vector<double> imp_part;  // per-chunk partial sums of the dot products
};

/// Builds the connections (§3.3.1, (3.5)-(3.6), pruning by a0 and N_n) for given particles.
/// Also used by tests on lattices. Throws follicle::Error on size mismatches or bad values.
LcpModel connect_particles(const Context& ctx, const std::vector<Vec3>& x,
                           const std::vector<Vec3>& t, const std::vector<Vec3>& uvs,
                           const std::vector<double>& mass, const LcpInitParams& p);

struct LcpInit {
  LcpModel model;
  LcpState state;
};

/// Poisson-disc sampling of the (u, v, s) pillar with (3.2), root directions (3.4), mapping
/// back (3.3) along a cantilever-beam shape, and connections. `body` (optional, head frame)
/// keeps the initial chains outside the body. Particles are numbered along a Z-order curve of
/// their initial positions (neighbours near in memory). Deterministic for ctx.seed().
LcpInit initialize_lcp(const Context& ctx, const Scalp& scalp, const LcpInitParams& p,
                       const sim::VoxelPlanes* body = nullptr);

/// The order of the points along a Morton (Z-order) curve over their bounding box (21 bits per
/// axis; ties keep the input order): numbering particles in this order puts neighbours near in
/// memory. x must not be empty.
std::vector<uint32_t> lcp_zorder(const std::vector<Vec3>& x);

/// 1 for root particles and for every particle reachable from one through root-side -> tip-side
/// connections (i.e. held by the head), 0 otherwise.
std::vector<char> lcp_attached(const LcpModel& model);

/// (3.4) root direction t_r(u, v) (not normalised) for the whirl normal n_w.
Vec3 root_direction(const Vec3& n_w, const Vec3& n, double w_t, double w_n);

/// (3.1) SPH density of every point with Monaghan's kernel, smoothing length h.
std::vector<double> sph_density(const Context& ctx, const std::vector<Vec3>& x,
                                const std::vector<double>& mass, double h);

class LcpSolver {
 public:
  /// Validates params and the model. `body` (head frame) may be null; it must outlive the solver.
  LcpSolver(const LcpParams& params, LcpModel model, const sim::VoxelPlanes* body = nullptr);

  /// Advances `state` by in.dt in params.substeps leapfrog sub-steps. NaN or runaway speed stops
  /// the step and is reported (state then holds the last sub-step).
  LcpStepReport step(const Context& ctx, const LcpStepInput& in, LcpState& state,
                     LcpWorkspace& ws) const;

  /// Advances `state` by in.dt with the implicit integrator (params.implicit, ADR 0014), whatever
  /// params.integrator says; step() calls it when params.integrator is "implicit".
  LcpStepReport step_implicit(const Context& ctx, const LcpStepInput& in, LcpState& state,
                              LcpWorkspace& ws) const;

  /// The initial state (rest positions and directions, zero velocity).
  LcpState rest_state() const;

  // Pieces of a sub-step, public for tests and tools.
  /// k_ij (3.7) and the alpha solve (3.12)-(3.14) into ws.k / ws.alpha.
  void solve_alpha(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const;
  /// The fastest rate [1/s] the adaptive sub-step rule limits at state s: the largest spring
  /// frequency omega_i = sqrt(sum_j alpha_ij k_ij / m_i) and, with hair-hair interaction, the
  /// explicit damping rates of (3.17)/(3.18). A sub-step dt is within the rule when
  /// rate dt <= cfl. Runs solve_alpha (fills ws.k / ws.alpha).
  double stiffness_rate(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const;
  /// E_{r,i} and E_{t,i} of (3.10)/(3.11) from ws.k/ws.alpha (0 where the group is empty).
  void tensile_moduli(const LcpWorkspace& ws, std::vector<double>& e_r,
                      std::vector<double>& e_t) const;
  /// Internal pair forces only (springs, hair-hair) into ws.force [N]; no gravity/body.
  void pair_forces(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const;
  /// (3.15) new hair directions from ws.alpha/ws.k and the current positions.
  void update_directions(const Context& ctx, LcpState& s, const LcpWorkspace& ws) const;
  /// A_i of (3.9).
  double cross_section(std::size_t i) const;

  /// Selects the kernels of the hair-hair pairs, the springs and the connection geometry: the
  /// AVX2 versions when the CPU has them (default) or the scalar loops. Both give the same bits
  /// (ADR 0008); the switch is for tests and A/B benchmarks.
  void use_simd(bool on) { m_kernels = detail::lcp_kernels(on); }

  const LcpModel& model() const { return m_model; }
  const LcpParams& params() const { return m_params; }
  double rho0() const { return m_rho0; }

 private:
  void rebuild_neighbours(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const;
  static void pair_index(const Context& ctx, LcpWorkspace& ws);
  static double max_shift2(const LcpState& s, const LcpWorkspace& ws, const Vec3& u, std::size_t i0,
                           std::size_t i1);
  // Implicit sub-step pieces (lcp_implicit_bando2003.cpp).
  void implicit_blocks(const Context& ctx, const LcpState& s, LcpWorkspace& ws, double dt,
                       double drag) const;
  // out = A u over the assembled rows; returns u . out (summed in a fixed order).
  double implicit_product(const Context& ctx, const LcpWorkspace& ws, const std::vector<Vec3>& u,
                          std::vector<Vec3>& out) const;
  // Where row i's entries start in ws.imp_col / ws.imp_blk (room for all its connections and
  // listed neighbours).
  std::size_t row_start(std::size_t i, const LcpWorkspace& ws, bool hh) const;
  /// Whether the Verlet lists still hold every pair within 2h, from ws.chunk_shift (may set
  /// ws.nbr_shift).
  bool lists_hold(const Context& ctx, const LcpState& s, LcpWorkspace& ws, double lim) const;
  void pair_forces_sorted(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const;
  // Per-particle pieces shared by the public functions and the fused sub-step of step().
  template <class R>
  void coefficients_of(std::size_t i, const LcpState& s, LcpWorkspace& ws, R&& r_of) const;
  // coefficients_of with |x_ab| from the cached geometry ws.conn_r.
  void coefficients_from_geometry(std::size_t i, const LcpState& s, LcpWorkspace& ws) const;
  void alpha_sums_of(std::size_t i, LcpWorkspace& ws) const;
  void alpha_of(std::size_t i, LcpWorkspace& ws) const;
  void alpha_sweeps(const Context& ctx, LcpWorkspace& ws) const;
  detail::SpringInputs spring_inputs(const LcpState& s, LcpWorkspace& ws, bool with_alpha) const;
  void active_pairs_of(std::size_t c, const LcpState& s, LcpWorkspace& ws,
                       const detail::HairPairConsts& pc) const;
  static void pair_scratch(LcpWorkspace& ws);
  detail::HairPairConsts pair_consts(const SphKernel& K, double inv_w0) const;
  void hair_pairs_of(std::size_t c, const LcpState& s, LcpWorkspace& ws,
                     const detail::HairPairConsts& pc) const;
  detail::GatherInputs gather_inputs(const LcpWorkspace& ws, bool hh) const;
  // |x_ab| and x^_ab of connections q0 .. q1 - 1 into ws.conn_r / ws.conn_xh.
  void geometry_of(std::size_t q0, std::size_t q1, const LcpState& s, LcpWorkspace& ws) const;
  detail::DirectionTermInputs direction_term_inputs(const LcpState& s,
                                                    const LcpWorkspace& ws) const;
  detail::DirectionSumInputs direction_sum_inputs(const double* term) const;
  void density_of(std::size_t i, LcpWorkspace& ws, double w0) const;
  // Each particle's connections split by its role, in adjacency order, so the per-particle loops
  // run without a data-dependent branch per connection: m_rs_* lists the connections of which
  // the particle is the tip-side end b (its partner is in N_r), m_ts_* those of which it is the
  // root-side end a (partner in N_t).
  std::vector<uint32_t> m_rs_offsets, m_rs_pairs, m_ts_offsets, m_ts_pairs;
  // Per connection, cos theta0 against x_ij seen from each end (x_ij = x_ab at a, -x_ab at b)
  // and sin theta0 of each end (the direction update (3.15)).
  std::vector<double> m_cos_a, m_sin_a, m_cos_b, m_sin_b;
  std::vector<double> m_damp;  // 2 zeta sqrt(mu_ab) per connection (spring damping factor)
  LcpParams m_params;
  std::vector<double> m_ea;  // E A_i per particle ((3.9) with the constant modulus)
  LcpModel m_model;
  const sim::VoxelPlanes* m_body = nullptr;
  double m_rho0 = 0;
  SphKernel m_ks{1.0};  // Monaghan's kernel with the connection smoothing length h_s
  detail::LcpKernels m_kernels = detail::lcp_kernels(true);
};

/// World positions (and optionally velocities, directions) of the particles for a head sample.
void lcp_world(const LcpState& s, const anim::RigidSample& head, std::vector<Vec3>* x,
               std::vector<Vec3>* v = nullptr, std::vector<Vec3>* t = nullptr);

}  // namespace follicle::hair
