#pragma once
// Inner kernels of the loosely connected particles' sub-step (Bando 2003), over flat ranges of
// particles, connections or pair slots. For the hair-hair pairs (§3.3.3), the kernel W(h, r) of
// every listed pair with the selection of the interacting ones (0 < r < 2h) and the pair force
// (3.16)-(3.18) each have a scalar reference and a batch version that uses AVX2 (4 pairs per
// instruction, double precision) when the CPU has it. The AVX2 versions perform the same IEEE
// operations in the same order as the scalar code, lane by lane (no FMA, no reduction across
// lanes), so both give the same bits; the solver's results do not depend on which runs
// (ADR 0008). The connection geometry with the terms of the direction update (3.15) and the
// springs (one connection per lane) have AVX2 versions too; the per-particle sums (force gather,
// (3.15)) are scalar: AVX2 versions with one particle per lane measured nothing (ADR 0008).
// The SPH air's density and pressure loops evaluate four list entries per instruction and add
// them to the particle's sum one by one in list order (same bits as the scalar loops).
#include <cstddef>
#include <cstdint>

#include "follicle/core/types.hpp"
#include "follicle/hair/sph_kernel.hpp"

namespace follicle::hair::detail {

/// Per-particle inputs of the pair force (arrays indexed by particle).
struct HairPairInputs {
  const Vec3* x = nullptr;         // positions [m]
  const Vec3* v = nullptr;         // velocities [m/s]
  const Vec3* t = nullptr;         // unit hair directions
  const double* mass = nullptr;    // [kg]
  const double* p_rho2 = nullptr;  // P_i / rho_i^2
};

/// Constants of the pair force.
struct HairPairConsts {
  SphKernel kernel{1.0};         // Monaghan's kernel for h
  double inv_w0 = 0;             // 1 / W(h, 0)
  double r2max = 0;              // (2h)^2
  double eps2 = 0;               // colinear_eps^2
  double collision_damping = 0;  // d_c of (3.17) per reduced mass [1/s]
  double friction_damping = 0;   // d_f of (3.18) per reduced mass [1/s]
};

/// Force on particle i from particle j (0 < |x_j - x_i| < 2h), the reference for the batch
/// kernel: (3.16) pressure, (3.17) inelastic collision along the collision direction, (3.18)
/// friction.
Vec3 hair_pair_force(const HairPairInputs& in, const HairPairConsts& c, uint32_t i, uint32_t j);

/// Evaluates hair_pair_force for pairs (i[k], j[k]), k < count, into out[slot[k]].
using HairPairBatchFn = void (*)(const HairPairInputs& in, const HairPairConsts& c,
                                 const uint32_t* i, const uint32_t* j, const uint32_t* slot,
                                 std::size_t count, Vec3* out);

/// For the pair slots s0 .. s1 - 1 (slot s joins pair_i[s] < pair_j[s]): w[s] = W(h, r), 0 for
/// r >= 2h, and the interacting slots (0 < r < 2h), in slot order, with their ends into
/// act_i/act_j/act_slot from index s0 on. Returns how many there are.
using ActivePairsFn = std::size_t (*)(const Vec3* x, const uint32_t* pair_i, const uint32_t* pair_j,
                                      const HairPairConsts& c, std::size_t s0, std::size_t s1,
                                      double* w, uint32_t* act_i, uint32_t* act_j,
                                      uint32_t* act_slot);

/// Per-connection inputs of the direction update (3.15): positions and the current directions
/// by particle; per connection a -> b its ends, alpha_ij, k_ij and cos/sin theta0 at each end,
/// cos against x_ij seen from that end (x_ij = x_ab at a, -x_ab at b).
struct DirectionTermInputs {
  const Vec3* x = nullptr;
  const Vec3* t = nullptr;
  const uint32_t *pair_a = nullptr, *pair_b = nullptr;
  const double *alpha = nullptr, *k = nullptr;
  const double *cos_a = nullptr, *sin_a = nullptr, *cos_b = nullptr, *sin_b = nullptr;
};

/// lcp_geometry for q0 <= q < q1 and, from that geometry and the directions t, the two terms of
/// (3.15) of each connection, 8 doubles per connection: term[8q .. 8q + 3] for end a and
/// term[8q + 4 .. 8q + 7] for end b, each (A x^_ij, B) with A = ak (cos0 - sin0 (t_i . x^_ij) / p)
/// and B = ak sin0 / p, ak = alpha_ij k_ij, p = |t_i - (t_i . x^_ij) x^_ij| (B = 0 when p
/// vanishes); all zero when |x_ab| is not > 0. See lcp_direction_sum.
void lcp_geometry_terms(const DirectionTermInputs& in, std::size_t q0, std::size_t q1, double* r,
                        Vec3* xh, double* term);

using GeometryTermsFn = void (*)(const DirectionTermInputs& in, std::size_t q0, std::size_t q1,
                                 double* r, Vec3* xh, double* term);

/// Inputs of the per-particle sum of (3.15): each particle's connections by role (CSR; ts = it
/// is the root-side end a, rs = the tip-side end b), the terms of lcp_geometry_terms and the
/// root flags.
struct DirectionSumInputs {
  const uint32_t *ts_off = nullptr, *ts_pairs = nullptr, *rs_off = nullptr, *rs_pairs = nullptr;
  const double* term = nullptr;
  const uint8_t* root = nullptr;
};

/// (3.15) new direction t_i of every non-root particle i0 <= i < i1: t_i = sum_j alpha_ij k_ij
/// t_i^j / |.|, t_i^j the unit vector at angle theta0_ij from x^_ij in the plane of t_i and x_ij
/// (Fig. 3.3 c), summed as sum_j A_j x^_j + (sum_j B_j) t_i over the ends' terms in a fixed
/// order (root-side ends, then tip-side ends). t is read and written (its own entry only).
void lcp_direction_sum(const DirectionSumInputs& in, std::size_t i0, std::size_t i1, Vec3* t);

/// Inputs of the force gather: each particle's connections by role (as DirectionSumInputs) with
/// the spring force on the root-side end per connection, and with hair-hair interaction (hh)
/// the sorted neighbour lists (nbr_off, nbr_upper: first entry above the particle's own index,
/// nbr_pair: pair slot of each entry, pair_off: first pair slot of each particle) with the
/// force on the lower-index end per pair slot.
struct GatherInputs {
  const uint32_t *ts_off = nullptr, *ts_pairs = nullptr, *rs_off = nullptr, *rs_pairs = nullptr;
  const Vec3* spring_f = nullptr;
  bool hh = false;
  const uint32_t *nbr_off = nullptr, *nbr_upper = nullptr, *nbr_pair = nullptr, *pair_off = nullptr;
  const Vec3* pair_f = nullptr;
};

/// Total internal force on every particle i0 <= i < i1 into force[i], summed in a fixed order:
/// + springs where i is the root-side end, - where it is the tip-side end, - pairs with a
/// lower-index partner, + pairs with a higher-index one.
void lcp_gather(const GatherInputs& in, std::size_t i0, std::size_t i1, Vec3* force);

/// Inputs of the loose springs (§3.3.2), one per connection a -> b: the cached geometry |x_ab|,
/// x^_ab, rest length l0, damping factor 2 zeta sqrt(mu_ab), k_ij (3.7) and alpha_ij; with
/// alpha_r/alpha_t set, alpha_ij is first computed by (3.14) from the per-particle (3.13) sums.
struct SpringInputs {
  const uint32_t *pair_a = nullptr, *pair_b = nullptr;
  const double *l0 = nullptr, *damp = nullptr, *conn_r = nullptr, *k = nullptr;
  const Vec3* conn_xh = nullptr;
  double* alpha = nullptr;
  const double *alpha_r = nullptr, *alpha_t = nullptr;  // null: alpha is already set
  const Vec3* v = nullptr;
  double compression_scale = 1;
};

/// Spring force on the root-side end a of connection q (b gets the negation); zero for r <= 0.
Vec3 spring_force(const SpringInputs& in, std::size_t q);

/// alpha_ij (3.14) when requested and spring_f[q] = spring_force(q) for q0 <= q < q1.
void lcp_springs(const SpringInputs& in, std::size_t q0, std::size_t q1, Vec3* spring_f);

using SpringsFn = void (*)(const SpringInputs& in, std::size_t q0, std::size_t q1, Vec3* spring_f);

/// Connection geometry for q0 <= q < q1: x_ab = x[pair_b[q]] - x[pair_a[q]], r[q] = |x_ab| and
/// xh[q] = x_ab (1 / r[q]). Shared by k_ij (3.7), the springs and the direction update (3.15)
/// of both ends.
void lcp_geometry(const Vec3* x, const uint32_t* pair_a, const uint32_t* pair_b, std::size_t q0,
                  std::size_t q1, double* r, Vec3* xh);

using GeometryFn = void (*)(const Vec3* x, const uint32_t* pair_a, const uint32_t* pair_b,
                            std::size_t q0, std::size_t q1, double* r, Vec3* xh);

/// SPH air (§3.6, hair/sph_air_bando2003): particles of one mass with CSR neighbour lists
/// (particle i: entries off[i] .. off[i + 1] - 1 of nb).
struct AirInputs {
  const Vec3* x = nullptr;
  const uint32_t* off = nullptr;
  const uint32_t* nb = nullptr;
  double mass = 0;
  SphKernel kernel{1.0};
  const double* p_rho2 = nullptr;  // P_i / rho_i^2 (air_pressure only)
};

/// Density (3.1) rho_i = m W(0) + sum_e m W(|x_nb[e] - x_i|), in list order, for i0 <= i < i1.
void air_density(const AirInputs& in, std::size_t i0, std::size_t i1, double* rho);
/// Pressure force (3.16) on i, f_i = sum_e m^2 (P_i/rho_i^2 + P_j/rho_j^2) W'(r) / r (x_j -
/// x_i) over the entries with r = |x_j - x_i| > 0, in list order, for i0 <= i < i1.
void air_pressure(const AirInputs& in, std::size_t i0, std::size_t i1, Vec3* f);

using AirDensityFn = void (*)(const AirInputs& in, std::size_t i0, std::size_t i1, double* rho);
using AirPressureFn = void (*)(const AirInputs& in, std::size_t i0, std::size_t i1, Vec3* f);

/// Air-hair drag (§3.6, two-way coupling): air particle i (position x, velocity v) with the hair
/// particles listed for it (CSR: entries off[i] .. off[i + 1] - 1 of nb, hair indices).
struct AirDragInputs {
  const Vec3 *x = nullptr, *v = nullptr;            // air
  const Vec3 *hair_x = nullptr, *hair_v = nullptr;  // hair
  const double* mu = nullptr;  // reduced mass m_h m_a / (m_h + m_a) per hair particle
  const uint32_t *off = nullptr, *nb = nullptr;
  double drag = 0;        // d [1/s]
  SphKernel kernel{1.0};  // W_c, zero beyond the coupling radius
  double inv_w0 = 0;      // 1 / W_c(0)
};
/// The drag on the hair particle of each entry e, f[e] = d mu_h (W_c(r) / W_c(0)) (v_a - v_h),
/// r = |x_a - x_h|, for the entries of air particles i0 <= i < i1 (the air particle gets -f[e]).
void air_drag(const AirDragInputs& in, std::size_t i0, std::size_t i1, Vec3* f);
using AirDragFn = void (*)(const AirDragInputs& in, std::size_t i0, std::size_t i1, Vec3* f);

struct LcpKernels {
  ActivePairsFn active = nullptr;
  HairPairBatchFn forces = nullptr;
  SpringsFn springs = nullptr;
  GeometryFn geometry = nullptr;
  GeometryTermsFn geometry_terms = nullptr;
  AirDensityFn air_density = nullptr;
  AirPressureFn air_pressure = nullptr;
  AirDragFn air_drag = nullptr;
  bool simd = false;  // the AVX2 kernels
};

/// The fastest kernels this CPU runs (AVX2, else the scalar loops); `allow_simd = false` always
/// gives the scalar loops.
LcpKernels lcp_kernels(bool allow_simd = true);

}  // namespace follicle::hair::detail
