// The sub-step kernels: the hair-hair pair kernel (3.16)-(3.18), the springs and the connection
// geometry, each AVX2 version against its scalar reference (same bits), and the solver with
// either set (same trajectories).
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "follicle/anim/rigid_motion.hpp"
#include "follicle/hair/lcp_kernels_bando2003.hpp"
#include "follicle/hair/sph_kernel.hpp"
#include "lcp_test_scenes.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

bool same_bits(const Vec3& a, const Vec3& b) {
  return std::memcmp(&a, &b, sizeof(Vec3)) == 0;
}

struct PairSet {
  std::vector<Vec3> x, v, t;
  std::vector<double> mass, p_rho2;
  std::vector<uint32_t> i, j, slot;
};

// Random particles within a few h of each other, with the cases the kernel selects between:
// crossing hairs, near-colinear hairs (|t_i x t_j| < eps), exactly parallel hairs beside each
// other along t (d_n = 0: only the pressure term), approaching and separating pairs, both
// pieces of the kernel.
PairSet random_pairs(std::size_t n, std::size_t npairs, double h, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  PairSet s;
  for (std::size_t k = 0; k < n; ++k) {
    s.x.push_back(Vec3(u(rng), u(rng), u(rng)) * 1.2 * h);
    s.v.push_back(Vec3(u(rng), u(rng), u(rng)) * 0.3);
    Vec3 t(u(rng), u(rng), u(rng));
    if (k % 3 == 1) t = s.t[k - 1] + 0.05 * t;  // near-colinear with the previous one
    if (k % 7 == 6) t = s.t[k - 1];             // exactly parallel
    s.t.push_back(t.normalized());
    s.mass.push_back(1e-5 * (1.5 + u(rng)));
    s.p_rho2.push_back(1e-4 * u(rng));
  }
  // Exactly parallel pair side by side along t: d_n = 0.
  s.x[6] = s.x[5] + 0.5 * h * s.t[5];
  for (std::size_t k = 0; k < npairs; ++k) {
    uint32_t a = uint32_t(rng() % n), b = uint32_t(rng() % n);
    if (a == b) b = (b + 1) % uint32_t(n);
    if (k % 5 == 0) b = (a + 1) % uint32_t(n);  // neighbouring (often near-colinear) indices
    if (k == 0) a = 5, b = 6;
    s.i.push_back(a);
    s.j.push_back(b);
    s.slot.push_back(uint32_t(npairs - 1 - k));  // scattered, reversed
  }
  return s;
}

detail::HairPairConsts consts_for(double h) {
  const SphKernel K(h);
  detail::HairPairConsts c;
  c.kernel = K;
  c.inv_w0 = 1.0 / K.w(0.0);
  c.r2max = 4 * h * h;
  c.eps2 = 0.2 * 0.2;
  c.collision_damping = 400;
  c.friction_damping = 4;
  return c;
}

}  // namespace

TEST(LcpKernels, BatchKernelGivesTheScalarBits) {
  if (!detail::lcp_kernels().simd) GTEST_SKIP() << "no AVX2 on this CPU";
  const double h = 0.004;
  const auto s = random_pairs(200, 1003, h, 11);  // 1003: a remainder of 3 after 4-wide blocks
  const auto c = consts_for(h);
  const detail::HairPairInputs in{s.x.data(), s.v.data(), s.t.data(), s.mass.data(),
                                  s.p_rho2.data()};
  std::vector<Vec3> simd(s.i.size(), Vec3::Constant(-7)), ref(s.i.size(), Vec3::Constant(-7));
  detail::lcp_kernels(true).forces(in, c, s.i.data(), s.j.data(), s.slot.data(), s.i.size(),
                                   simd.data());
  detail::lcp_kernels(false).forces(in, c, s.i.data(), s.j.data(), s.slot.data(), s.i.size(),
                                    ref.data());
  int colinear = 0, parallel = 0, approaching = 0;
  for (std::size_t k = 0; k < s.i.size(); ++k) {
    const std::size_t q = s.slot[k];
    ASSERT_TRUE(same_bits(simd[q], ref[q]))
        << "pair " << k << ": " << simd[q].transpose() << " vs " << ref[q].transpose();
    EXPECT_TRUE(same_bits(ref[q], detail::hair_pair_force(in, c, s.i[k], s.j[k])));
    const Vec3 ti = s.t[s.i[k]], tj = s.t[s.j[k]];
    const double dc2 = ti.cross(tj).squaredNorm();
    colinear += dc2 < c.eps2;
    parallel += dc2 == 0;
    approaching += (s.v[s.j[k]] - s.v[s.i[k]]).dot(s.x[s.j[k]] - s.x[s.i[k]]) < 0;
  }
  // The random set exercises every branch of the scalar code.
  EXPECT_GT(colinear, 50);
  EXPECT_GT(parallel, 0);
  EXPECT_GT(approaching, 100);
}

TEST(LcpKernels, ActivePairsGiveTheKernelAndTheInteractingSlots) {
  // Listed pairs inside and beyond 2h (and one at r = 0): W(h, r) per slot equals SphKernel's
  // (0 beyond 2h), the interacting slots are exactly those with 0 < r < 2h, in slot order, and
  // the AVX2 kernel gives the scalar bits. Ranges of every length 0..9 at odd offsets exercise
  // the 4-wide blocks and their remainders.
  const double h = 0.004;
  auto s = random_pairs(300, 1, h, 5);
  s.x[7] = s.x[3];  // a pair at r = 0: W(h, 0), not interacting
  std::vector<uint32_t> pi, pj;
  for (uint32_t a = 0; a < 300; ++a)
    for (uint32_t b = a + 1; b < 300; b += 1 + (a + b) % 5) {
      pi.push_back(a);
      pj.push_back(b);
    }
  pi.push_back(3);
  pj.push_back(7);
  const auto c = consts_for(h);
  const SphKernel K(h);
  const std::size_t np = pi.size();
  for (int simd = 0; simd < 2; ++simd) {
    const auto kern = detail::lcp_kernels(simd == 1);
    if (simd == 1 && !kern.simd) GTEST_SKIP() << "no AVX2 on this CPU";
    std::vector<double> w(np, -1.0), wref(np, -1.0);
    std::vector<uint32_t> ai(np), aj(np), as(np), ri(np), rj(np), rs(np);
    std::size_t s0 = 0, len = 0, inside = 0, zero = 0;
    while (s0 < np) {
      const std::size_t s1 = std::min(np, s0 + len);
      const std::size_t cnt = kern.active(s.x.data(), pi.data(), pj.data(), c, s0, s1, w.data(),
                                          ai.data(), aj.data(), as.data());
      const std::size_t ref =
          detail::lcp_kernels(false).active(s.x.data(), pi.data(), pj.data(), c, s0, s1,
                                            wref.data(), ri.data(), rj.data(), rs.data());
      ASSERT_EQ(cnt, ref);
      std::size_t k = s0;
      for (std::size_t q = s0; q < s1; ++q) {
        const double r = (s.x[pj[q]] - s.x[pi[q]]).norm();
        ASSERT_EQ(std::memcmp(&w[q], &wref[q], sizeof(double)), 0) << q;
        EXPECT_NEAR(w[q], r < 2 * h ? sph_w(h, r) : 0.0, 1e-9 * K.w(0.0)) << q;
        if (r > 0 && r < 2 * h) {
          ASSERT_LT(k, s0 + cnt);
          EXPECT_EQ(as[k], q);
          EXPECT_EQ(ai[k], pi[q]);
          EXPECT_EQ(aj[k], pj[q]);
          EXPECT_EQ(rs[k], q);
          ++k;
          ++inside;
        }
        zero += r == 0;
      }
      EXPECT_EQ(k, s0 + cnt);
      s0 = s1;
      len = (len + 1) % 10;
    }
    EXPECT_GT(inside, np / 10);
    EXPECT_LT(inside, np);
    EXPECT_GE(zero, 1u);  // (3, 7), also listed by the loop when its stride hits 7
  }
}

TEST(LcpKernels, ForcesAreEqualAndOppositeForCrossingHairs) {
  // (3.16)-(3.18) between crossing hairs (t_i x t_j not small): F_ji = -F_ij exactly.
  const double h = 0.004;
  auto s = random_pairs(64, 1, h, 3);
  const auto c = consts_for(h);
  const detail::HairPairInputs in{s.x.data(), s.v.data(), s.t.data(), s.mass.data(),
                                  s.p_rho2.data()};
  int tested = 0;
  for (uint32_t a = 0; a < 64; ++a)
    for (uint32_t b = a + 1; b < 64; ++b) {
      const double r = (s.x[b] - s.x[a]).norm();
      if (r >= 2 * h || s.t[a].cross(s.t[b]).squaredNorm() < c.eps2) continue;
      const Vec3 fab = detail::hair_pair_force(in, c, a, b);
      const Vec3 fba = detail::hair_pair_force(in, c, b, a);
      ASSERT_LT((fab + fba).norm(), 1e-12 * (fab.norm() + 1e-30)) << a << " " << b;
      ++tested;
    }
  EXPECT_GT(tested, 100);
}

TEST(LcpKernels, SolverTrajectoriesDoNotDependOnTheKernel) {
  // The whole solver with the AVX2 pair kernel and with the scalar loop, during a head shake
  // with hair-hair interaction: identical x, v, t bit for bit, for 1 and 2 threads.
  if (!detail::lcp_kernels().simd) GTEST_SKIP() << "no AVX2 on this CPU";
  Context ctx1(1), ctx2(2);
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx, 0.016);
  const auto track = anim::RigidMotionTrack::shake(Vec3::Zero(), Vec3::UnitY(), 0.7, 2, 0.0, 0.75);
  std::vector<Vec3> out[3];
  for (int k = 0; k < 3; ++k) {
    LcpSolver solver(LcpParams{}, sc.init.model, &sc.body);
    solver.use_simd(k != 0);
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    for (int f = 0; f < 4; ++f) {
      LcpStepInput in;
      in.dt = 1.0 / 60;
      in.head = track.sample(f * in.dt);
      const auto rep = solver.step(k == 2 ? ctx1 : ctx2, in, s, ws);
      ASSERT_TRUE(rep.ok) << rep.message;
    }
    out[k] = s.x;
    out[k].insert(out[k].end(), s.v.begin(), s.v.end());
    out[k].insert(out[k].end(), s.t.begin(), s.t.end());
  }
  for (int k = 1; k < 3; ++k) {
    ASSERT_EQ(out[0].size(), out[k].size());
    for (std::size_t i = 0; i < out[0].size(); ++i)
      ASSERT_TRUE(same_bits(out[0][i], out[k][i])) << "run " << k << ", value " << i;
  }
  // The state moved (the comparison is not between two rest states).
  EXPECT_GT(
      (out[0][0] - sc.init.model.rest_x[0]).norm() + (out[0][1] - sc.init.model.rest_x[1]).norm(),
      0.0);
}

namespace {

// Runs (3.15) through lcp_geometry_terms (scalar or the given kernels) and lcp_direction_sum.
void directions_by_kernel(const detail::GeometryTermsFn terms,
                          const detail::DirectionTermInputs& tin, std::size_t np,
                          const detail::DirectionSumInputs& sin_, std::size_t i0, std::size_t i1,
                          Vec3* t) {
  std::vector<double> r(np), term(8 * np, -3.0);
  std::vector<Vec3> xh(np);
  terms(tin, 0, np, r.data(), xh.data(), term.data());
  detail::DirectionSumInputs in = sin_;
  in.term = term.data();
  detail::lcp_direction_sum(in, i0, i1, t);
}

}  // namespace

TEST(LcpKernels, DirectionUpdateFollowsItsConnections) {
  // (3.15) with theta0 = 0 at every end (cos 1, sin 0): t_i^j = x^_ij, so a particle whose ends
  // all point along one unit vector gets exactly that direction (x^_ij = -x^_ab at the tip-side
  // end); zero-length connections are skipped; root particles and particles without connections
  // keep their direction; with theta0 = 90 degrees and t_i normal to x^ the direction stays.
  const Vec3 e = Vec3(1, 2, 2) / 3.0;
  // Particles 0-4 are updated (0..3 in range); 5-8 are the far ends of the connections.
  std::vector<Vec3> x(9, Vec3::Zero());
  x[3] = Vec3(0.05, 0, 0);
  x[5] = 0.01 * e;                 // q0: 0 -> 5, x^_ab = e
  x[6] = 0.02 * e;                 // q1: 6 -> 0, x^_ab = -e, seen from 0: x^_ij = e
  x[7] = x[0];                     // q2: 0 -> 7, zero length
  x[8] = x[3] - Vec3(0, 0, 0.01);  // q3: 8 -> 3, x^_ab = z, seen from 3: -z
  std::vector<uint32_t> pa{0, 6, 0, 8}, pb{5, 0, 7, 3};
  std::vector<double> alpha{1, 2, 1, 1}, k{3, 5, 5, 1};  // q1 outweighs q0: a wrong sign flips t
  std::vector<double> cos_a{1, 1, 1, 1}, sin_a{0, 0, 0, 0}, cos_b{1, 1, 1, 0}, sin_b{0, 0, 0, 1};
  std::vector<uint8_t> root{0, 1, 0, 0, 0, 0, 0, 0, 0};
  std::vector<uint32_t> ts_off{0, 2, 2, 2, 2, 2, 2, 2, 2, 2}, ts_pairs{0, 2},
      rs_off{0, 1, 1, 1, 2, 2, 2, 2, 2, 2}, rs_pairs{1, 3};
  std::vector<Vec3> t{Vec3(0, 0, 1), Vec3::UnitY(), Vec3::UnitY(), Vec3::UnitX(), Vec3::UnitX(),
                      Vec3::UnitX(), Vec3::UnitX(), Vec3::UnitX(), Vec3::UnitX()};
  const detail::DirectionTermInputs tin{x.data(),     t.data(),    pa.data(),    pb.data(),
                                        alpha.data(), k.data(),    cos_a.data(), sin_a.data(),
                                        cos_b.data(), sin_b.data()};
  const detail::DirectionSumInputs din{ts_off.data(),   ts_pairs.data(), rs_off.data(),
                                       rs_pairs.data(), nullptr,         root.data()};
  for (int simd = 0; simd < 2; ++simd) {
    const auto kern = detail::lcp_kernels(simd == 1);
    std::vector<Vec3> tt = t;
    directions_by_kernel(kern.geometry_terms, tin, pa.size(), din, 0, 4, tt.data());
    EXPECT_LT((tt[0] - e).norm(), 1e-15) << tt[0].transpose();
    EXPECT_TRUE(tt[1] == Vec3::UnitY());
    EXPECT_TRUE(tt[2] == Vec3::UnitY());
    // q3 seen from its tip-side end: x^_ij = -z; theta0 = 90 degrees in the plane of t and x^.
    EXPECT_LT((tt[3] - Vec3::UnitX()).norm(), 1e-15);
    EXPECT_TRUE(tt[4] == Vec3::UnitX());  // outside the range
  }
}

TEST(LcpKernels, DirectionTermsGiveThePerEndSumBitForBit) {
  // The connection-major form (terms per connection, then per particle the sum) against the
  // direct per-end form of (3.15), for random connections with zero-length ones, theta0 of
  // 0 and 90 degrees and directions along x^ (p = 0): the same bits, scalar and AVX2.
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = 60, np = 187;
  std::vector<Vec3> x(n), t(n);
  std::vector<uint8_t> root(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = Vec3(u(rng), u(rng), u(rng)) * 0.02;
    t[i] = Vec3(u(rng), u(rng), u(rng)).normalized();
    root[i] = i % 11 == 3;
  }
  std::vector<uint32_t> pa(np), pb(np);
  std::vector<double> alpha(np), k(np), cos_a(np), sin_a(np), cos_b(np), sin_b(np);
  for (std::size_t q = 0; q < np; ++q) {
    pa[q] = uint32_t(rng() % n);
    pb[q] = uint32_t((pa[q] + 1 + rng() % (n - 1)) % n);
    alpha[q] = 1 + 0.5 * u(rng);
    k[q] = q % 17 == 4 ? 0.0 : 40 * (1.5 + u(rng));
    const double ca = q % 9 == 0 ? 1.0 : u(rng), cb = q % 10 == 1 ? 0.0 : u(rng);
    cos_a[q] = ca;
    sin_a[q] = std::sqrt(std::max(0.0, 1 - ca * ca));
    cos_b[q] = -cb;
    sin_b[q] = std::sqrt(std::max(0.0, 1 - cb * cb));
  }
  x[pb[5]] = x[pa[5]];  // zero length
  x[pb[8]] = x[pa[8]];
  t[pa[12]] = (x[pb[12]] - x[pa[12]]).normalized();  // t along x^: p = 0 at that end
  // CSR by role.
  std::vector<uint32_t> ts_off(n + 1, 0), rs_off(n + 1, 0), ts_pairs, rs_pairs;
  for (std::size_t i = 0; i < n; ++i) {
    for (uint32_t q = 0; q < np; ++q) {
      if (pa[q] == i) ts_pairs.push_back(q);
      if (pb[q] == i) rs_pairs.push_back(q);
    }
    ts_off[i + 1] = uint32_t(ts_pairs.size());
    rs_off[i + 1] = uint32_t(rs_pairs.size());
  }
  // The per-end form: each particle sums its ends directly, skipping zero-length connections.
  std::vector<Vec3> ref = t;
  for (std::size_t i = 0; i < n; ++i) {
    if (root[i]) continue;
    const Vec3 ti = t[i];
    Vec3 acc = Vec3::Zero();
    double bsum = 0;
    auto add = [&](uint32_t q, double sign, double c0, double s0) {
      const Vec3 d = x[pb[q]] - x[pa[q]];
      const double r = d.norm();
      const Vec3 xh = sign * (d * (1.0 / r));
      if (!(r > 0)) return;
      const double ak = alpha[q] * k[q];
      const double dd = ti.dot(xh);
      const double pn = (ti - dd * xh).norm();
      const double sp = pn > 1e-12 ? ak * s0 / pn : 0.0;
      acc += (ak * c0 - sp * dd) * xh;
      bsum += sp;
    };
    for (uint32_t e = ts_off[i]; e < ts_off[i + 1]; ++e)
      add(ts_pairs[e], 1.0, cos_a[ts_pairs[e]], sin_a[ts_pairs[e]]);
    for (uint32_t e = rs_off[i]; e < rs_off[i + 1]; ++e)
      add(rs_pairs[e], -1.0, cos_b[rs_pairs[e]], sin_b[rs_pairs[e]]);
    acc += bsum * ti;
    const double an = acc.norm();
    if (an > 1e-300 && std::isfinite(an)) ref[i] = acc / an;
  }
  detail::DirectionTermInputs tin{x.data(), t.data(),     pa.data(),    pb.data(),    alpha.data(),
                                  k.data(), cos_a.data(), sin_a.data(), cos_b.data(), sin_b.data()};
  detail::DirectionSumInputs din{ts_off.data(),   ts_pairs.data(), rs_off.data(),
                                 rs_pairs.data(), nullptr,         root.data()};
  for (int simd = 0; simd < 2; ++simd) {
    const auto kern = detail::lcp_kernels(simd == 1);
    if (simd == 1 && !kern.simd) GTEST_SKIP() << "no AVX2 on this CPU";
    std::vector<Vec3> tt = t;
    directions_by_kernel(kern.geometry_terms, tin, np, din, 0, n, tt.data());
    for (std::size_t i = 0; i < n; ++i)
      ASSERT_TRUE(same_bits(tt[i], ref[i])) << "simd " << simd << " particle " << i << ": "
                                            << tt[i].transpose() << " vs " << ref[i].transpose();
  }
}

TEST(LcpKernels, GatherBalancesEveryPairAndSpring) {
  // Random particles with connection ends of each role and lower and upper list entries, with
  // and without hair-hair lists: each particle's force is its springs and pairs with the right
  // signs, and the forces of all particles sum to zero up to rounding.
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = 150;
  // Connections a -> b and pairs i < j drawn at random; CSR lists built from them.
  std::vector<std::vector<uint32_t>> ts(n), rs(n), lower(n), upper(n);
  std::vector<Vec3> spring_f, pair_f;
  for (uint32_t q = 0; q < 600; ++q) {
    const uint32_t a = uint32_t(rng() % n), b = uint32_t(rng() % n);
    if (a == b) continue;
    ts[a].push_back(uint32_t(spring_f.size()));
    rs[b].push_back(uint32_t(spring_f.size()));
    spring_f.push_back(Vec3(u(rng), u(rng), u(rng)));
  }
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (int k = 0; k < 700; ++k) {
    uint32_t a = uint32_t(rng() % n), b = uint32_t(rng() % n);
    if (a == b) continue;
    if (a > b) std::swap(a, b);
    pairs.push_back({a, b});
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  // Pair slots in list order of the lower end; the lists sorted by neighbour index.
  std::vector<uint32_t> pair_off(n + 1, 0);
  for (const auto& p : pairs) ++pair_off[p.first + 1];
  for (std::size_t i = 0; i < n; ++i) pair_off[i + 1] += pair_off[i];
  pair_f.resize(pairs.size());
  for (auto& f : pair_f) f = Vec3(u(rng), u(rng), u(rng));
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> lists(n);  // (neighbour, slot)
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    lists[pairs[k].first].push_back({pairs[k].second, uint32_t(k)});
    lists[pairs[k].second].push_back({pairs[k].first, uint32_t(k)});
  }
  std::vector<uint32_t> nbr_off{0}, nbr_upper, nbr_pair;
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(lists[i].begin(), lists[i].end());
    nbr_upper.push_back(nbr_off.back());
    for (const auto& e : lists[i]) {
      if (e.first < i) ++nbr_upper.back();
      nbr_pair.push_back(e.second);
    }
    nbr_off.push_back(uint32_t(nbr_pair.size()));
  }
  auto csr = [](const std::vector<std::vector<uint32_t>>& l, std::vector<uint32_t>& off,
                std::vector<uint32_t>& flat) {
    off.assign(1, 0);
    for (const auto& v : l) {
      flat.insert(flat.end(), v.begin(), v.end());
      off.push_back(uint32_t(flat.size()));
    }
  };
  std::vector<uint32_t> ts_off, ts_flat, rs_off, rs_flat;
  csr(ts, ts_off, ts_flat);
  csr(rs, rs_off, rs_flat);
  for (int hh = 0; hh < 2; ++hh) {
    detail::GatherInputs in;
    in.ts_off = ts_off.data();
    in.ts_pairs = ts_flat.data();
    in.rs_off = rs_off.data();
    in.rs_pairs = rs_flat.data();
    in.spring_f = spring_f.data();
    in.hh = hh == 1;
    in.nbr_off = nbr_off.data();
    in.nbr_upper = nbr_upper.data();
    in.nbr_pair = nbr_pair.data();
    in.pair_off = pair_off.data();
    in.pair_f = pair_f.data();
    std::vector<Vec3> fb(n, Vec3::Constant(9));
    detail::lcp_gather(in, 0, n, fb.data());
    for (std::size_t i = 0; i < n; ++i) {  // the same sum written out
      Vec3 f = Vec3::Zero();
      for (uint32_t q : ts[i]) f += spring_f[q];
      for (uint32_t q : rs[i]) f -= spring_f[q];
      if (hh)
        for (const auto& e : lists[i])
          f += e.first > i ? pair_f[e.second] : Vec3(-pair_f[e.second]);
      EXPECT_LT((fb[i] - f).norm(), 1e-12) << "hh " << hh << ", particle " << i;
    }
    Vec3 total = Vec3::Zero();
    double scale = 0;
    for (const auto& f : fb) {
      total += f;
      scale += f.norm();
    }
    EXPECT_LT(total.norm(), 1e-12 * scale) << "hh " << hh;
  }
}

TEST(LcpKernels, SpringsStretchCompressAndDamp) {
  // Stretched and compressed springs (compression scale), zero-length connections (no force),
  // with and without the alpha update (3.14): each force equals the damped spring along x^ with
  // the scaled stiffness when compressed, and a spring at rest with equal end velocities exerts
  // no force.
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = 80, np = 203;
  std::vector<uint32_t> pa(np), pb(np);
  std::vector<double> l0(np), damp(np), r(np), k(np), ar(n), at(n);
  std::vector<Vec3> xh(np), v(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[i] = Vec3(u(rng), u(rng), u(rng));
    ar[i] = 1 + 0.5 * u(rng);
    at[i] = 1 + 0.5 * u(rng);
  }
  for (std::size_t q = 0; q < np; ++q) {
    pa[q] = uint32_t(rng() % n);
    pb[q] = uint32_t((pa[q] + 1 + rng() % (n - 1)) % n);
    l0[q] = 0.01 * (1.5 + u(rng));
    r[q] = q % 13 == 2 ? 0.0 : l0[q] * (1 + 0.3 * u(rng));
    damp[q] = 1e-3 * (1.5 + u(rng));
    k[q] = 50 * (1.5 + u(rng));
    xh[q] = Vec3(u(rng), u(rng), u(rng)).normalized();
  }
  r[7] = l0[7];         // at rest ...
  v[pb[7]] = v[pa[7]];  // ... with equal end velocities
  for (int with_alpha = 0; with_alpha < 2; ++with_alpha) {
    std::vector<double> alpha_a(np, 1.25);
    detail::SpringInputs in;
    in.pair_a = pa.data();
    in.pair_b = pb.data();
    in.l0 = l0.data();
    in.damp = damp.data();
    in.conn_r = r.data();
    in.conn_xh = xh.data();
    in.k = k.data();
    in.v = v.data();
    in.compression_scale = 0.25;
    if (with_alpha) {
      in.alpha_r = ar.data();
      in.alpha_t = at.data();
    }
    std::vector<Vec3> fa(np, Vec3::Constant(5));
    in.alpha = alpha_a.data();
    detail::lcp_springs(in, 1, np, fa.data());
    EXPECT_TRUE(fa[0] == Vec3::Constant(5));  // outside the range
    int compressed = 0;
    for (std::size_t q = 1; q < np; ++q) {
      const double ak = alpha_a[q] * k[q], ext = r[q] - l0[q];
      const double kk = ext < 0 ? 0.25 * ak : ak;
      const double dv = (v[pb[q]] - v[pa[q]]).dot(xh[q]);
      if (r[q] > 0) {
        EXPECT_LT((fa[q] - (kk * ext + damp[q] * std::sqrt(kk) * dv) * xh[q]).norm(), 1e-12) << q;
      }
      if (with_alpha) {
        EXPECT_EQ(alpha_a[q], 0.5 * (ar[pb[q]] + at[pa[q]]));
      }
      if (r[q] == 0) {
        EXPECT_TRUE(fa[q] == Vec3::Zero());
      }
      compressed += r[q] > 0 && r[q] < l0[q];
    }
    EXPECT_TRUE(fa[7] == Vec3::Zero());
    EXPECT_GT(compressed, 40);
    // The AVX2 springs (four connections per step, scalar tail) give the same bits, for every
    // start and end of the range modulo the vector width.
    const auto kern = detail::lcp_kernels(true);
    if (!kern.simd) continue;
    for (std::size_t q0 : {0, 1, 2, 3})
      for (std::size_t q1 : {np, np - 1, np - 2, np - 3}) {
        std::vector<double> alpha_s(np, 1.25), alpha_r(np, 1.25);
        std::vector<Vec3> fs(np, Vec3::Constant(5)), fr(np, Vec3::Constant(5));
        in.alpha = alpha_s.data();
        kern.springs(in, q0, q1, fs.data());
        in.alpha = alpha_r.data();
        detail::lcp_springs(in, q0, q1, fr.data());
        for (std::size_t q = 0; q < np; ++q) {
          ASSERT_TRUE(same_bits(fs[q], fr[q])) << q0 << ".." << q1 << " connection " << q;
          ASSERT_EQ(std::memcmp(&alpha_s[q], &alpha_r[q], sizeof(double)), 0) << q;
        }
      }
  }
}

TEST(LcpKernels, ConnectionGeometryIsTheUnitVectorAndLength) {
  // r = |x_b - x_a| and x^ = x_ab / r for every connection of the range (nothing outside it);
  // the AVX2 version gives the same bits for every range start and end modulo the vector width.
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = 50, np = 131;
  std::vector<Vec3> x(n);
  for (auto& p : x) p = Vec3(u(rng), u(rng), u(rng)) * 0.02;
  std::vector<uint32_t> pa(np), pb(np);
  for (std::size_t q = 0; q < np; ++q) {
    pa[q] = uint32_t(rng() % n);
    pb[q] = uint32_t((pa[q] + 1 + rng() % (n - 1)) % n);
  }
  const auto kern = detail::lcp_kernels(true);
  for (std::size_t q0 : {0, 1, 2, 3})
    for (std::size_t q1 : {np, np - 1, np - 2, np - 3}) {
      std::vector<double> r(np, -1.0), rs(np, -1.0);
      std::vector<Vec3> xh(np, Vec3::Constant(9)), xs(np, Vec3::Constant(9));
      detail::lcp_geometry(x.data(), pa.data(), pb.data(), q0, q1, r.data(), xh.data());
      for (std::size_t q = 0; q < np; ++q) {
        if (q < q0 || q >= q1) {
          EXPECT_EQ(r[q], -1.0);
          EXPECT_TRUE(xh[q] == Vec3::Constant(9));
          continue;
        }
        const Vec3 d = x[pb[q]] - x[pa[q]];
        EXPECT_NEAR(r[q], d.norm(), 1e-16);
        EXPECT_NEAR(xh[q].norm(), 1.0, 1e-14);
        EXPECT_LT((xh[q] * r[q] - d).norm(), 1e-16);
      }
      if (!kern.simd) continue;
      kern.geometry(x.data(), pa.data(), pb.data(), q0, q1, rs.data(), xs.data());
      for (std::size_t q = 0; q < np; ++q) {
        ASSERT_EQ(std::memcmp(&r[q], &rs[q], sizeof(double)), 0) << q0 << ".." << q1 << " " << q;
        ASSERT_TRUE(same_bits(xh[q], xs[q])) << q0 << ".." << q1 << " " << q;
      }
    }
}

TEST(LcpKernels, AirDensityAndPressureGiveTheScalarBits) {
  // The SPH air loops (§3.6): lists of random lengths (tails of 0-3 entries after the blocks of
  // four) over particles on both kernel pieces and beyond 2h, with a coincident pair (r = 0:
  // skipped by the pressure force) and a list entry of a particle to itself.
  const double h = 0.01;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t n = 300;
  std::vector<Vec3> x(n);
  std::vector<double> p_rho2(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = Vec3(u(rng), u(rng), u(rng)) * 2.5 * h;
    p_rho2[i] = 1e-3 * (1.2 + u(rng));
  }
  x[7] = x[3];
  std::vector<uint32_t> off{0}, nb;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t len = rng() % 23;
    for (std::size_t k = 0; k < len; ++k) nb.push_back(uint32_t(rng() % n));
    if (i == 3) nb.push_back(7);
    if (i == 9) nb.push_back(9);
    off.push_back(uint32_t(nb.size()));
  }
  detail::AirInputs in;
  in.x = x.data();
  in.off = off.data();
  in.nb = nb.data();
  in.mass = 2.4e-6;
  in.kernel = SphKernel(h);
  in.p_rho2 = p_rho2.data();
  const auto scalar = detail::lcp_kernels(false), fast = detail::lcp_kernels(true);
  std::vector<double> rho_s(n), rho_f(n);
  std::vector<Vec3> f_s(n), f_f(n);
  scalar.air_density(in, 0, n, rho_s.data());
  fast.air_density(in, 0, n, rho_f.data());
  scalar.air_pressure(in, 0, n, f_s.data());
  fast.air_pressure(in, 0, n, f_f.data());
  for (std::size_t i = 0; i < n; ++i) {
    ASSERT_EQ(std::memcmp(&rho_s[i], &rho_f[i], sizeof(double)), 0) << i;
    ASSERT_TRUE(same_bits(f_s[i], f_f[i])) << i;
    ASSERT_TRUE(f_s[i].allFinite()) << i;  // the coincident pair and the self entry are skipped
  }
  // Against the definitions: particle 3 lists 7 at r = 0 (density W(0), no force from it).
  const SphKernel K(h);
  double rho = in.mass * K.w(0.0);
  Vec3 f = Vec3::Zero();
  for (uint32_t e = off[3]; e < off[4]; ++e) {
    const Vec3 d = x[nb[e]] - x[3];
    const double r = d.norm();
    rho += in.mass * sph_w(h, r);
    if (r > 0) f += in.mass * in.mass * (p_rho2[3] + p_rho2[nb[e]]) * sph_dw(h, r) / r * d;
  }
  EXPECT_NEAR(rho_s[3], rho, 1e-12 * rho);
  EXPECT_LT((f_s[3] - f).norm(), 1e-12 * (1 + f.norm()));
  if (!fast.simd) GTEST_SKIP() << "no AVX2 on this CPU: only the scalar loops were compared";
}

TEST(LcpKernels, AirDragKernelGivesTheScalarBits) {
  // The air-hair drag (§3.6): air particles with lists of random lengths (tails of 0-3 after the
  // blocks of four) of hair particles on both kernel pieces, beyond the coupling radius (no
  // drag) and coincident with the air particle (full drag).
  const double rc = 0.01;  // coupling radius 2 h_c
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t na = 200, nh = 300;
  std::vector<Vec3> xa(na), va(na), xh(nh), vh(nh);
  std::vector<double> mu(nh);
  for (auto& p : xa) p = Vec3(u(rng), u(rng), u(rng)) * 1.2 * rc;
  for (auto& p : va) p = Vec3(3 + u(rng), u(rng), u(rng));
  for (auto& p : xh) p = Vec3(u(rng), u(rng), u(rng)) * 1.2 * rc;
  for (auto& p : vh) p = Vec3(u(rng), u(rng), u(rng));
  for (auto& m : mu) m = 1e-6 * (1.5 + u(rng));
  xh[11] = xa[5];
  std::vector<uint32_t> off{0}, nb;
  for (std::size_t i = 0; i < na; ++i) {
    const std::size_t len = rng() % 19;
    for (std::size_t k = 0; k < len; ++k) nb.push_back(uint32_t(rng() % nh));
    if (i == 5) nb.push_back(11);
    off.push_back(uint32_t(nb.size()));
  }
  const SphKernel Kc(rc / 2);
  detail::AirDragInputs in;
  in.x = xa.data();
  in.v = va.data();
  in.hair_x = xh.data();
  in.hair_v = vh.data();
  in.mu = mu.data();
  in.off = off.data();
  in.nb = nb.data();
  in.drag = 150;
  in.kernel = Kc;
  in.inv_w0 = 1.0 / Kc.w(0.0);
  const auto scalar = detail::lcp_kernels(false), fast = detail::lcp_kernels(true);
  std::vector<Vec3> f_s(nb.size()), f_f(nb.size());
  scalar.air_drag(in, 0, na, f_s.data());
  fast.air_drag(in, 0, na, f_f.data());
  std::size_t beyond = 0;
  for (std::size_t i = 0; i < na; ++i)
    for (uint32_t e = off[i]; e < off[i + 1]; ++e) {
      ASSERT_TRUE(same_bits(f_s[e], f_f[e])) << i << " " << e;
      // Against the definition with Monaghan's piecewise kernel.
      const double r = (xa[i] - xh[nb[e]]).norm();
      const Vec3 f =
          in.drag * mu[nb[e]] * sph_w(rc / 2, r) / sph_w(rc / 2, 0.0) * (va[i] - vh[nb[e]]);
      ASSERT_LT((f_s[e] - f).norm(), 1e-12 * (1e-9 + f.norm())) << e;
      if (r >= rc) {
        ASSERT_EQ(f_s[e], Vec3::Zero()) << e;
        ++beyond;
      }
    }
  EXPECT_GT(beyond, 0u);           // the case was exercised
  const uint32_t e5 = off[6] - 1;  // coincident: the full drag d mu (v_a - v_h)
  EXPECT_LT((f_s[e5] - in.drag * mu[11] * (va[5] - vh[11])).norm(), 1e-12);
  if (!fast.simd) GTEST_SKIP() << "no AVX2 on this CPU: only the scalar loops were compared";
}
