// Implicit integration of the loosely connected particles (ADR 0014): the thesis's forces
// (Bando 2003, (3.7)-(3.24)) advanced by linearised backward Euler (Baraff & Witkin 1998,
// "Large steps in cloth simulation", eq. (15)-(18)):
//
//   (M + dt C + dt^2 S) dv = dt f(x0, v0) - dt^2 S v0,   v1 = v0 + dv,   x1 = x0 + dt v1,
//
// S = -df/dx and C = -df/dv. In the matrix: the loose springs (3.7)-(3.14) (stiffness alpha k
// along the connection, the tension T / r across it when stretched, the spring damping along
// it), the SPH pressure (3.16) through the stiffness of each interacting pair (see pair_blocks),
// the hair-hair collision damping (3.17) and friction (3.18) (exact: linear in the velocities),
// and the air drag. Explicit: gravity, the inertial forces of the head frame (§3.6, Coriolis
// included), the wind. The body contact (3.19)-(3.24) acts on the solved velocity exactly as in
// the explicit step (it is a velocity-level rule for a given dt). The system is symmetric
// positive definite (every block is clamped to its positive part) and solved by conjugate
// gradients with a block-Jacobi preconditioner; the root particles are held (their rows are the
// identity with a zero right-hand side). The sub-step length is set by how far the fastest
// particle may move, LcpImplicitParams::cfl h, not by the spring stiffness.
//
// Everything is summed in a fixed order (per connection / pair slot, then gathered per particle
// as the explicit step does; dot products by deterministic_reduce), so the result is the same
// for any thread count.
#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/hair/lcp_bando2003.hpp"

namespace follicle::hair {

namespace {
constexpr std::size_t kChunk = 64;         // as lcp_bando2003.cpp: the active-pair lists are per 64
constexpr std::size_t kSolveChunk = 1024;  // particles or connections per task of the solver loops

double dot_range(const std::vector<Vec3>& a, const std::vector<Vec3>& b, std::size_t i0,
                 std::size_t i1) {
  double s = 0;
  for (std::size_t i = i0; i < i1; ++i) s += a[i].dot(b[i]);
  return s;
}

double dot(const Context& ctx, const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return deterministic_reduce(
      ctx, a.size(), kSolveChunk, 0.0,
      [&](std::size_t i0, std::size_t i1) { return dot_range(a, b, i0, i1); },
      [](double x, double y) { return x + y; });
}

using Sym = LcpWorkspace::Sym;  // a symmetric 3x3 block: xx yy zz xy xz yz

// B += a x x^T.
inline void add_rank1(Sym& B, const Vec3& x, double a) {
  B[0] += a * x.x() * x.x();
  B[1] += a * x.y() * x.y();
  B[2] += a * x.z() * x.z();
  B[3] += a * x.x() * x.y();
  B[4] += a * x.x() * x.z();
  B[5] += a * x.y() * x.z();
}

template <class B6>
inline Vec3 sym_mul(const B6& B, const Vec3& u) {
  return Vec3(B[0] * u.x() + B[3] * u.y() + B[4] * u.z(),
              B[3] * u.x() + B[1] * u.y() + B[5] * u.z(),
              B[4] * u.x() + B[5] * u.y() + B[2] * u.z());
}

Mat3 sym_matrix(const Sym& B) {
  Mat3 M;
  M << B[0], B[3], B[4], B[3], B[1], B[5], B[4], B[5], B[2];
  return M;
}
}  // namespace

void LcpSolver::implicit_blocks(const Context& ctx, const LcpState& s, LcpWorkspace& ws, double dt,
                                double drag) const {
  const auto& m = m_model;
  const auto& P = m_params;
  const std::size_t n = m.size(), np = m.num_pairs();
  ws.imp_spar.resize(np);
  ws.imp_sperp.resize(np);
  ws.imp_cpar.resize(np);
  // Springs: f_a = K (x_b - x_a) + c ((v_b - v_a) . x^) x^ with K = kk x^ x^T + (T / r)(I - x^
  // x^T), T = alpha k (r - l0) the tension (dropped when compressed: it would make S indefinite).
  parallel_chunks(ctx, np, kSolveChunk, [&](std::size_t q0, std::size_t q1) {
    for (std::size_t q = q0; q < q1; ++q) {
      const double r = ws.conn_r[q];
      if (!(r > 0)) {
        ws.imp_spar[q] = ws.imp_sperp[q] = ws.imp_cpar[q] = 0;
        continue;
      }
      const double ak = ws.alpha[q] * ws.k[q];
      const double ext = r - m.l0[q];
      const double kk = ext < 0 ? ak * P.compression_scale : ak;
      ws.imp_spar[q] = kk;
      ws.imp_sperp[q] = ext > 0 ? ak * ext / r : 0.0;
      ws.imp_cpar[q] = m_damp[q] * std::sqrt(kk);
    }
  });
  // Hair-hair pairs.
  const bool hh = P.hair_hair && ws.pair_off.size() == n + 1;
  const std::size_t nslots = hh ? ws.pair_off.back() : 0;
  ws.imp_pxh.resize(nslots);
  ws.imp_pdh.resize(nslots);
  ws.imp_pk.resize(nslots);
  ws.imp_pc.resize(nslots);
  ws.imp_pf.resize(nslots);
  if (hh) {
    const SphKernel K(m.h);
    const double inv_w0 = 1.0 / K.w(0.0);
    const double eps2 = P.colinear_eps * P.colinear_eps;
    parallel_for(
        ctx, 0, ws.act_count.size(),
        [&](std::size_t c) {
          const std::size_t s0 = ws.pair_off[c * kChunk],
                            s1 = ws.pair_off[std::min(n, (c + 1) * kChunk)];
          for (std::size_t sl = s0; sl < s1; ++sl)
            ws.imp_pk[sl] = ws.imp_pc[sl] = ws.imp_pf[sl] = 0;
          for (std::size_t k = s0; k < s0 + ws.act_count[c]; ++k) {
            const uint32_t i = ws.act_i[k], j = ws.act_j[k], sl = ws.act_slot[k];
            const Vec3 xab = s.x[j] - s.x[i];
            const double r = xab.norm();
            const Vec3 xh = xab / r;
            double w, dw;
            K.w_dw(r, w, dw);
            const double d2w = K.d2w(r);
            const double mi = m.mass[i], mj = m.mass[j];
            const double ri = ws.density[i], rj = ws.density[j];
            // (3.16): the repulsion g(r) = -m_i m_j (P_i/rho_i^2 + P_j/rho_j^2) W'(r); its
            // stiffness -dg/dr with W'' and with the pair's own share of the densities
            // (d rho_i / dr = m_j W'), the rest of each density held: a positive part along x^.
            const double kp = mi * mj * (ws.p_rho2[i] + ws.p_rho2[j]) * d2w +
                              mi * mj * P.k_a * (mj / (ri * ri) + mi / (rj * rj)) * dw * dw;
            ws.imp_pk[sl] = std::max(kp, 0.0);
            ws.imp_pxh[sl] = xh;
            // (3.17)/(3.18): the same collision direction as hair_pair_force.
            const Vec3 dc = s.t[i].cross(s.t[j]);
            const Vec3 dp = xh - xh.dot(s.t[i]) * s.t[i];
            const bool colinear = dc.squaredNorm() < eps2;
            const Vec3 dn = colinear ? dp : dc;
            const double dn2 = dn.squaredNorm();
            if (dn2 < 1e-18) {
              ws.imp_pdh[sl] = Vec3::Zero();
              continue;
            }
            const Vec3 dh = dn / std::sqrt(dn2);
            const double muw = mi * mj / (mi + mj) * (w * inv_w0);
            const double vn = (s.v[j] - s.v[i]).dot(dh);
            ws.imp_pdh[sl] = dh;
            ws.imp_pc[sl] = vn * xab.dot(dh) < 0 ? P.collision_damping * muw : 0.0;
            ws.imp_pf[sl] = P.friction_damping * muw;
          }
        },
        1);
  }
  // The rows of A = M (1 + dt drag) + dt C + dt^2 S, assembled once per sub-step so that every
  // conjugate-gradient product is one pass over the particles (no per-connection / per-pair
  // scatter and gather): A_ii = M_i (1 + dt drag) + sum_e B_e, A_ij = -B_e, with the symmetric
  // block B_e = dt C_e + dt^2 S_e of each connection and interacting pair at i (each stored at
  // both ends, computed from the same coefficients: the matrix is exactly symmetric). Row i's
  // entries, in a fixed order: connections where i is the root-side end, where it is the
  // tip-side end, then its listed neighbours in list order (those that interact). The same pass
  // gives S v0 (for b) and the block-Jacobi preconditioner, the inverse of A_ii.
  ws.imp_dinv.resize(n);
  ws.imp_diag.resize(n);
  ws.imp_len.resize(n);
  ws.imp_sv.resize(n);
  const std::size_t cap =
      m_ts_offsets[n] + m_rs_offsets[n] + (hh ? std::size_t(ws.nbr_offsets[n]) : 0);
  ws.imp_col.resize(cap);
  ws.imp_blk.resize(cap);
  const double h2 = dt * dt;
  parallel_chunks(ctx, n, kSolveChunk, [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) {
      if (m.root[i]) {
        ws.imp_sv[i] = Vec3::Zero();
        ws.imp_len[i] = 0;
        ws.imp_dinv[i] = Mat3::Identity();
        ws.imp_diag[i] = Sym{1, 1, 1, 0, 0, 0};
        continue;
      }
      const std::size_t base = row_start(i, ws, hh);
      uint32_t len = 0;
      Sym D{};
      D[0] = D[1] = D[2] = m.mass[i] * (1 + dt * drag);
      Vec3 sv = Vec3::Zero();
      const Vec3& vi = s.v[i];
      // One entry: B = bx x x^T + bd d d^T + bi I, S = sx x x^T + si I (S v0 for b).
      auto put = [&](uint32_t col, const Vec3& x, double bx, const Vec3& dd, double bd, double bi,
                     double sx, double si) {
        Sym B{};
        add_rank1(B, x, bx);
        if (bd != 0) add_rank1(B, dd, bd);
        B[0] += bi;
        B[1] += bi;
        B[2] += bi;
        // The off-diagonal block is kept in single precision (half the memory traffic of the
        // products; the solve stops at a relative residual of 1e-2): the diagonal sums the
        // same rounded blocks, so A times a uniform velocity stays exactly M (1 + dt drag) u.
        auto& Bf = ws.imp_blk[base + len];
        for (int k = 0; k < 6; ++k) {
          Bf[k] = float(B[k]);
          D[k] += double(Bf[k]);
        }
        ws.imp_col[base + len] = col;
        ++len;
        const Vec3 d = vi - s.v[col];
        sv += (sx * x.dot(d)) * x + si * d;
      };
      auto put_conn = [&](uint32_t q, uint32_t partner) {
        if (ws.imp_spar[q] == 0 && ws.imp_sperp[q] == 0 && ws.imp_cpar[q] == 0) return;
        const double sx = ws.imp_spar[q] - ws.imp_sperp[q];
        put(partner, ws.conn_xh[q], dt * ws.imp_cpar[q] + h2 * sx, ws.conn_xh[q], 0,
            h2 * ws.imp_sperp[q], sx, ws.imp_sperp[q]);
      };
      for (uint32_t e = m_ts_offsets[i]; e < m_ts_offsets[i + 1]; ++e)
        put_conn(m_ts_pairs[e], m.pair_b[m_ts_pairs[e]]);
      for (uint32_t e = m_rs_offsets[i]; e < m_rs_offsets[i + 1]; ++e)
        put_conn(m_rs_pairs[e], m.pair_a[m_rs_pairs[e]]);
      if (hh) {
        const uint32_t e0 = ws.nbr_offsets[i], eu = ws.nbr_upper[i], e1 = ws.nbr_offsets[i + 1];
        const uint32_t p0 = ws.pair_off[i];  // pair slot of entry e >= eu: p0 + (e - eu)
        for (uint32_t e = e0; e < e1; ++e) {
          const uint32_t sl = e < eu ? ws.nbr_pair[e] : p0 + (e - eu);
          if (ws.imp_pk[sl] == 0 && ws.imp_pc[sl] == 0 && ws.imp_pf[sl] == 0) continue;
          put(ws.nbrs[e], ws.imp_pxh[sl], h2 * ws.imp_pk[sl], ws.imp_pdh[sl],
              dt * (ws.imp_pc[sl] - ws.imp_pf[sl]), dt * ws.imp_pf[sl], ws.imp_pk[sl], 0.0);
        }
      }
      ws.imp_len[i] = len;
      ws.imp_diag[i] = D;
      ws.imp_sv[i] = sv;
      ws.imp_dinv[i] = sym_matrix(D).inverse();
    }
  });
}

std::size_t LcpSolver::row_start(std::size_t i, const LcpWorkspace& ws, bool hh) const {
  return m_ts_offsets[i] + m_rs_offsets[i] + (hh ? std::size_t(ws.nbr_offsets[i]) : 0);
}

double LcpSolver::implicit_product(const Context& ctx, const LcpWorkspace& ws,
                                   const std::vector<Vec3>& u, std::vector<Vec3>& out) const {
  // out = A u over the rows assembled by implicit_blocks (root rows the identity); returns u . out.
  const bool hh = m_params.hair_hair && ws.pair_off.size() == m_model.size() + 1;
  return deterministic_reduce(
      ctx, m_model.size(), kSolveChunk, 0.0,
      [&](std::size_t i0, std::size_t i1) {
        double uq = 0;
        for (std::size_t i = i0; i < i1; ++i) {
          Vec3 y = sym_mul(ws.imp_diag[i], u[i]);
          const std::size_t base = row_start(i, ws, hh);
          for (std::size_t e = base; e < base + ws.imp_len[i]; ++e)
            y -= sym_mul(ws.imp_blk[e], u[ws.imp_col[e]]);
          out[i] = y;
          uq += u[i].dot(y);
        }
        return uq;
      },
      [](double x, double y) { return x + y; });
}

LcpStepReport LcpSolver::step_implicit(const Context& ctx, const LcpStepInput& in, LcpState& s,
                                       LcpWorkspace& ws) const {
  LcpStepReport rep;
  const auto& m = m_model;
  const auto& P = m_params;
  const auto& IP = P.implicit;
  const std::size_t n = m.size(), np = m.num_pairs();
  if (s.x.size() != n || s.v.size() != n || s.t.size() != n) {
    rep.ok = false;
    rep.message = fmt::format("state has {} particles, model {}", s.x.size(), n);
    return rep;
  }
  if (!(in.dt > 0) || !std::isfinite(in.dt)) {
    rep.ok = false;
    rep.message = fmt::format("time step {} must be > 0", in.dt);
    return rep;
  }
  if (in.external_force && in.external_force->size() != n) {
    rep.ok = false;
    rep.message = "external force array size differs from the particle count";
    return rep;
  }
  for (auto* v : {&ws.imp_dv, &ws.imp_r, &ws.imp_z, &ws.imp_p, &ws.imp_q, &ws.imp_b}) v->resize(n);
  ws.k.resize(np);
  ws.alpha.resize(np);
  ws.alpha_r.resize(n);
  ws.alpha_t.resize(n);
  ws.spring_f.resize(np);
  ws.force.resize(n);
  ws.density.resize(n);
  ws.pressure.resize(n);
  ws.p_rho2.resize(n);
  ws.conn_r.resize(np);
  ws.conn_xh.resize(np);
  ws.dir_term.resize(8 * np);
  ws.contact.resize(n);
  ws.penetration.resize(n);
  ws.geom_x.resize(n);
  const std::size_t nchunks = (n + kChunk - 1) / kChunk;
  ws.chunk_shift.resize(nchunks);
  ws.chunk_check.resize(nchunks);
  // The connection geometry of the current positions (the explicit step's cache is not trusted:
  // one pass is cheap next to a sub-step).
  ws.geom_owner = nullptr;
  ws.shift_ready = false;
  parallel_chunks(ctx, np, kChunk,
                  [&](std::size_t q0, std::size_t q1) { geometry_of(q0, q1, s, ws); });

  const anim::RigidSample& hd = in.head;
  const Mat3 R = hd.rotation, Rt = R.transpose();
  const Vec3 g_h = Rt * P.gravity;
  const Vec3 A_h = Rt * hd.acceleration, w_h = Rt * hd.angular_velocity,
             al_h = Rt * hd.angular_acceleration, V_h = Rt * hd.velocity;
  const Vec3 piv = hd.pivot;
  const double h = m.h;
  const SphKernel K(h);
  const double w0 = K.w(0.0);
  const detail::HairPairConsts pc = pair_consts(K, 1.0 / w0);
  const double skin = P.neighbour_skin * 2 * h;
  const double Rn = 2 * h + skin;
  const bool hh = P.hair_hair;
  if (!hh) {
    ws.nbr_offsets.clear();
    ws.nbr_upper.clear();
    ws.pair_off.clear();
  }
  // Step control: the fastest particle moves at most cfl h per sub-step. Its speed is estimated
  // as the current one plus what the frame's accelerations (gravity, the head's) add in one
  // sub-step of the longest allowed length.
  double vmax = deterministic_reduce(
      ctx, n, 4096, 0.0,
      [&](std::size_t i0, std::size_t i1) {
        double v = 0;
        for (std::size_t i = i0; i < i1; ++i) v = std::max(v, s.v[i].norm());
        return v;
      },
      [](double a, double b) { return std::max(a, b); });
  const double longest = in.dt / IP.min_substeps;
  const double accel = (g_h - A_h).norm() + al_h.norm() * 0.5 + w_h.squaredNorm() * 0.5;
  double elapsed = 0, prev_dt = 0;
  int taken = 0;
  // Whether any particle touched the body in the last sub-step (before the first: whether one
  // lies within the contact band now).
  bool in_contact = false;
  if (P.body_collision && m_body)
    in_contact = deterministic_reduce(
                     ctx, n, 4096, 0,
                     [&](std::size_t i0, std::size_t i1) {
                       for (std::size_t i = i0; i < i1; ++i) {
                         if (m.root[i]) continue;
                         const sim::BodyPlane* pl = m_body->find(s.x[i]);
                         if (pl && (s.x[i] - pl->p).dot(pl->n) < P.contact.threshold) return 1;
                       }
                       return 0;
                     },
                     [](int x, int y) { return x | y; }) != 0;
  const int cap = std::max(P.max_substeps, IP.min_substeps);
  while (true) {
    const double rem = in.dt - elapsed;
    const double v_est = (std::isfinite(vmax) ? vmax : 0.0) + accel * longest;
    // Without speculative contact, particles in contact also stay within the contact band of
    // (3.19) per sub-step: the velocity-level rule (3.20)-(3.24) sees a particle once per
    // sub-step, and one that crosses the band in a sub-step is inside the body before it is seen.
    const bool band_bound = in_contact && !IP.speculative_contact;
    const double reach = band_bound ? std::min(IP.cfl * h, P.contact.threshold) : IP.cfl * h;
    double allowed = v_est > 0 ? std::min(longest, reach / v_est) : longest;
    // The body's repulsion (3.24) is applied explicitly: k_r dt^2 <= 1 while in contact.
    if (in_contact && P.contact.k_r > 0) allowed = std::min(allowed, 1 / std::sqrt(P.contact.k_r));
    int left = int(std::min<double>(std::ceil(rem / allowed * (1 - 1e-12)), 1e9));
    left = std::clamp(left, 1, std::max(1, cap - taken));
    const double dt = left == 1 ? rem : rem / left;

    // 1. Neighbour lists (Verlet, as the explicit step), the coefficients (3.7), W per pair.
    if (hh) {
      bool rebuild = skin <= 0 || ws.nbr_built_x.size() != n || ws.nbr_radius != Rn ||
                     ws.nbr_offsets.size() != n + 1 || ws.nbr_mirror.size() != ws.nbrs.size();
      if (!rebuild) {
        parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
          ws.chunk_shift[i0 / kChunk] = max_shift2(s, ws, ws.nbr_shift, i0, i1);
        });
        rebuild = !lists_hold(ctx, s, ws, 0.49 * skin);
      }
      if (rebuild) rebuild_neighbours(ctx, s, ws);
      if (rebuild || ws.nbr_upper.size() != n || ws.pair_off.size() != n + 1 ||
          ws.nbr_pair.size() != ws.nbrs.size())
        pair_index(ctx, ws);
      pair_scratch(ws);
    }
    parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) coefficients_from_geometry(i, s, ws);
      if (hh) active_pairs_of(i0 / kChunk, s, ws, pc);
    });
    // 2. (3.13) sums, density (3.1) and pressure.
    parallel_for(
        ctx, 0, n,
        [&](std::size_t i) {
          alpha_sums_of(i, ws);
          if (hh) density_of(i, ws, w0);
        },
        kChunk);
    if (P.alpha_sweeps > 0) {
      parallel_for(ctx, 0, n, [&](std::size_t i) { alpha_of(i, ws); });
      alpha_sweeps(ctx, ws);
    }
    // 3. The forces at (x0, v0): springs with (3.14), hair-hair pairs, gathered.
    const std::size_t nconn = (np + kChunk - 1) / kChunk;
    const detail::SpringInputs sin = spring_inputs(s, ws, P.alpha_sweeps == 0);
    parallel_for(
        ctx, 0, nconn + (hh ? nchunks : 0),
        [&](std::size_t c) {
          if (c >= nconn) return hair_pairs_of(c - nconn, s, ws, pc);
          m_kernels.springs(sin, c * kChunk, std::min(np, (c + 1) * kChunk), ws.spring_f.data());
        },
        1);
    const detail::GatherInputs gin = gather_inputs(ws, hh);
    parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
      detail::lcp_gather(gin, i0, i1, ws.force.data());
      for (std::size_t i = i0; i < i1; ++i) {
        if (m.root[i]) continue;
        const double mi = m.mass[i];
        const Vec3 r = s.x[i] - piv;
        Vec3 a = g_h;
        // Inertial forces due to head movement (§3.6) and air drag, as the explicit step.
        a -= A_h + al_h.cross(r) + w_h.cross(w_h.cross(r)) + 2.0 * w_h.cross(s.v[i]);
        a -= P.air_drag * (V_h + w_h.cross(r) + s.v[i]);
        if (in.external_force) a += Rt * (*in.external_force)[i] / mi;
        ws.force[i] += mi * a;
      }
    });
    // 4. The matrix blocks, then b = dt f0 - dt^2 S v0.
    implicit_blocks(ctx, s, ws, dt, P.air_drag);
    // The first guess: zero in a step's first sub-step; later ones start from the last
    // sub-step's dv scaled to this sub-step's length (the motion changes little between them),
    // which costs one product and saves more iterations than that. Only what this step() call
    // computed is used: the result does not depend on the workspace's history.
    const bool warm = taken > 0;
    if (warm) {
      const double scale = dt / prev_dt;
      parallel_chunks(ctx, n, kSolveChunk, [&](std::size_t i0, std::size_t i1) {
        for (std::size_t i = i0; i < i1; ++i)
          ws.imp_dv[i] = m.root[i] ? Vec3::Zero() : Vec3(scale * ws.imp_dv[i]);
      });
      implicit_product(ctx, ws, ws.imp_dv, ws.imp_z);
    }
    parallel_chunks(ctx, n, kSolveChunk, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        ws.imp_b[i] = m.root[i] ? Vec3::Zero() : Vec3(dt * ws.force[i] - dt * dt * ws.imp_sv[i]);
        if (warm) {
          ws.imp_r[i] = ws.imp_b[i] - ws.imp_z[i];
        } else {
          ws.imp_r[i] = ws.imp_b[i];  // dv = 0
          ws.imp_dv[i] = Vec3::Zero();
        }
        ws.imp_z[i] = ws.imp_dinv[i] * ws.imp_r[i];
        ws.imp_p[i] = ws.imp_z[i];
      }
    });
    // 5. Preconditioned conjugate gradients.
    const double bb = dot(ctx, ws.imp_b, ws.imp_b);
    double rz = dot(ctx, ws.imp_r, ws.imp_z);
    double rr = warm ? dot(ctx, ws.imp_r, ws.imp_r) : bb;
    const double tol2 = IP.tolerance * IP.tolerance * bb;
    int it = 0;
    while (it < IP.max_iterations && rr > tol2 && bb > 0) {
      const double pq = implicit_product(ctx, ws, ws.imp_p, ws.imp_q);
      if (!(pq > 0)) break;  // not positive: the blocks are clamped, so only on non-finite input
      const double al = rz / pq;
      using Pair = std::pair<double, double>;
      const Pair sums = deterministic_reduce(
          ctx, n, kSolveChunk, Pair(0.0, 0.0),
          [&](std::size_t i0, std::size_t i1) {
            Pair p(0.0, 0.0);
            for (std::size_t i = i0; i < i1; ++i) {
              ws.imp_dv[i] += al * ws.imp_p[i];
              ws.imp_r[i] -= al * ws.imp_q[i];
              ws.imp_z[i] = ws.imp_dinv[i] * ws.imp_r[i];
              p.first += ws.imp_r[i].dot(ws.imp_z[i]);
              p.second += ws.imp_r[i].squaredNorm();
            }
            return p;
          },
          [](const Pair& a, const Pair& b) {
            return Pair(a.first + b.first, a.second + b.second);
          });
      ++it;
      rr = sums.second;
      const double beta = sums.first / rz;
      rz = sums.first;
      if (rr <= tol2) break;
      parallel_chunks(ctx, n, kSolveChunk, [&](std::size_t i0, std::size_t i1) {
        for (std::size_t i = i0; i < i1; ++i) ws.imp_p[i] = ws.imp_z[i] + beta * ws.imp_p[i];
      });
    }
    rep.solver_iterations += it;
    rep.solver_residual = std::max(rep.solver_residual, bb > 0 ? std::sqrt(rr / bb) : 0.0);
    // 6. Velocities, the body contact (3.19)-(3.24) on them, positions.
    parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
      for (std::size_t i = i0; i < i1; ++i) {
        if (m.root[i]) {
          ws.contact[i] = 0;
          ws.penetration[i] = 0;
          s.x[i] = m.rest_x[i];
          s.v[i] = Vec3::Zero();
          continue;
        }
        Vec3 a = ws.imp_dv[i] / dt;  // the step's mean acceleration
        uint8_t c = 0;
        double pdepth = 0;
        if (P.body_collision && m_body) {
          const sim::BodyPlane* pl = m_body->find(s.x[i]);
          if (pl) {
            const Vec3 ac =
                IP.speculative_contact
                    ? sim::body_contact_accel_speculative(*pl, s.x[i], s.v[i], a, dt, P.contact)
                    : sim::body_contact_accel(*pl, s.x[i], s.v[i], a, dt, P.contact);
            if (ac.squaredNorm() > 0) c = 1;
            a += ac;
            pdepth = std::max(0.0, -(s.x[i] - pl->p).dot(pl->n));
          }
          // Speculative: the planes of the voxels along the predicted path, at half-voxel
          // spacing (a sub-step may carry a particle a voxel or more: along a curved or concave
          // surface, or through the one-voxel shell of planes into the empty inside).
          if (IP.speculative_contact) {
            const Vec3 path = (s.v[i] + a * dt) * dt;
            const int samples = int(std::min(
                16.0, std::ceil(path.norm() / (0.5 * m_body->voxel_size()) * (1 - 1e-12))));
            const sim::BodyPlane* last = pl;
            for (int k = 1; k <= samples; ++k) {
              const sim::BodyPlane* pe = m_body->find(s.x[i] + (double(k) / samples) * path);
              if (!pe || pe == last) continue;  // a straight path enters each voxel once
              last = pe;
              const Vec3 ac =
                  sim::body_contact_accel_speculative(*pe, s.x[i], s.v[i], a, dt, P.contact);
              if (ac.squaredNorm() > 0) c = 1;
              a += ac;
            }
          }
        }
        ws.contact[i] = c;
        ws.penetration[i] = pdepth;
        s.v[i] += a * dt;
        s.x[i] += s.v[i] * dt;
      }
    });
    // 7. Geometry and the direction update (3.15) at the new positions; the blow-up check.
    const detail::DirectionTermInputs tin = direction_term_inputs(s, ws);
    parallel_chunks(ctx, np, kChunk, [&](std::size_t q0, std::size_t q1) {
      m_kernels.geometry_terms(tin, q0, q1, ws.conn_r.data(), ws.conn_xh.data(),
                               ws.dir_term.data());
    });
    const double vlim = P.max_speed;
    const detail::DirectionSumInputs din = direction_sum_inputs(ws.dir_term.data());
    parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
      detail::lcp_direction_sum(din, i0, i1, s.t.data());  // (3.15)
      LcpWorkspace::ChunkCheck c;
      for (std::size_t i = i0; i < i1; ++i) {
        const double sp = s.v[i].norm();
        const bool bad =
            !std::isfinite(sp) || !s.x[i].allFinite() || !s.t[i].allFinite() || sp > vlim;
        if (bad && c.bad == SIZE_MAX) c.bad = i;
        if (std::isfinite(sp)) c.vmax = std::max(c.vmax, sp);
        c.contacts += ws.contact[i];
        c.max_pen = std::max(c.max_pen, ws.penetration[i]);
        ws.geom_x[i] = s.x[i];
      }
      ws.chunk_check[i0 / kChunk] = c;
    });
    ++taken;
    prev_dt = dt;
    elapsed += dt;
    s.time += dt;
    rep.substeps = taken;
    LcpWorkspace::ChunkCheck chk;
    for (const auto& part : ws.chunk_check) {
      chk.vmax = std::max(chk.vmax, part.vmax);
      if (chk.bad == SIZE_MAX) chk.bad = part.bad;
      chk.contacts += part.contacts;
      chk.max_pen = std::max(chk.max_pen, part.max_pen);
    }
    rep.max_speed = chk.vmax;
    rep.num_contacts = chk.contacts;
    rep.max_penetration = chk.max_pen;
    vmax = chk.vmax;
    in_contact = chk.contacts > 0;
    if (chk.bad != SIZE_MAX) {
      const double sp = s.v[chk.bad].norm();
      if (std::isfinite(sp) && s.x[chk.bad].allFinite() && s.t[chk.bad].allFinite())
        rep.mark_blow_up(chk.bad);
      else
        rep.mark_non_finite(chk.bad);
      rep.message = fmt::format(
          "lcp (implicit): blow-up at t = {:.5f} s: particle {} has speed {} m/s (limit {} m/s) or "
          "a non-finite value; lower lcp.implicit.cfl",
          s.time, chk.bad, sp, vlim);
      return rep;
    }
    if (left == 1) break;
  }
  ws.geom_owner = this;  // conn_r / conn_xh are of geom_x = s.x
  return rep;
}

}  // namespace follicle::hair
