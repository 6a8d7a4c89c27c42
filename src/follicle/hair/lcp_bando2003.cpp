#include "follicle/hair/lcp_bando2003.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/resources.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/hair/sph_kernel.hpp"

namespace follicle::hair {

namespace {
constexpr double kOrphanAlignment = 0.1;  // a_ij floor of a forced root-side connection
constexpr double kTetherFraction = 0.95;  // a lone root-side spring keeps k = c W(h_s, 0.95 2h_s)
}  // namespace

void LcpInitParams::validate() const {
  validate_params(*this, "lcp_init");
  if (gravity_dir.norm() < 1e-9) fail_at("lcp_init.gravity_dir", "must not be the zero vector");
  if (std::abs(w_t) + std::abs(w_n) <= 0) fail_at("lcp_init.w_n", "w_t and w_n are both zero");
}

void LcpParams::validate() const {
  validate_params(*this, "lcp");
  if (integrator != "leapfrog" && integrator != "implicit") {
    const std::string hint = did_you_mean(integrator, {"leapfrog", "implicit"});
    fail_at("lcp.integrator", "expected \"leapfrog\" or \"implicit\", got \"{}\"{}", integrator,
            hint.empty() ? std::string() : fmt::format(" (did you mean \"{}\"?)", hint));
  }
  contact.validate();
}

Vec3 root_direction(const Vec3& n_w, const Vec3& n, double w_t, double w_n) {
  // (3.4) t_r = -w_t {n_w - (n_w . n) n} + w_n n
  return -w_t * (n_w - n_w.dot(n) * n) + w_n * n;
}

std::vector<double> sph_density(const Context& ctx, const std::vector<Vec3>& x,
                                const std::vector<double>& mass, double h) {
  if (x.size() != mass.size())
    fail("sph_density: {} positions but {} masses", x.size(), mass.size());
  if (!(h > 0)) fail("sph_density: smoothing length {} must be > 0", h);
  ParticleGrid grid;
  grid.build(x, 2 * h);
  std::vector<double> rho(x.size());
  parallel_for(ctx, 0, x.size(), [&](std::size_t i) {
    double r = mass[i] * sph_w(h, 0.0);
    grid.for_each_candidate(x[i], [&](uint32_t j) {
      if (j == i) return;
      const double d = (x[j] - x[i]).norm();
      if (d < 2 * h) r += mass[j] * sph_w(h, d);  // (3.1)
    });
    rho[i] = r;
  });
  return rho;
}

// ---------------------------------------------------------------------------------------------
// Initialisation (§3.3.1)

LcpModel connect_particles(const Context& ctx, const std::vector<Vec3>& x,
                           const std::vector<Vec3>& t_in, const std::vector<Vec3>& uvs,
                           const std::vector<double>& mass, const LcpInitParams& p) {
  p.validate();
  const std::size_t n = x.size();
  if (n < 2) fail_at("lcp", "need at least 2 particles, got {}", n);
  if (t_in.size() != n || uvs.size() != n || mass.size() != n)
    fail_at("lcp", "particle arrays differ in size: {} positions, {} directions, {} uvs, {} masses",
            n, t_in.size(), uvs.size(), mass.size());
  LcpModel m;
  m.rest_x = x;
  m.rest_t.resize(n);
  m.uvs = uvs;
  m.mass = mass;
  m.root.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!x[i].allFinite() || !t_in[i].allFinite() || !uvs[i].allFinite())
      fail_at(fmt::format("lcp.particles[{}]", i), "position, direction or (u,v,s) not finite");
    if (t_in[i].norm() < 1e-12)
      fail_at(fmt::format("lcp.particles[{}]", i), "hair direction is the zero vector");
    if (!(mass[i] > 0) || !std::isfinite(mass[i]))
      fail_at(fmt::format("lcp.particles[{}]", i), "mass {} must be > 0", mass[i]);
    m.rest_t[i] = t_in[i].normalized();
    m.root[i] = uvs[i].z() < 0 ? 1 : 0;
  }
  const auto& t = m.rest_t;
  // h_s and h are set from the Poisson-disc radius r, the intended inter-particle distance of
  // §3.3.1 ("a little larger/smaller than the initial average inter-particle distance"). The
  // measured mean nearest-neighbour distance is NOT used: where the initial hair shape makes
  // strands converge (hanging hair) it shrinks and would leave sparser particles unconnected.
  m.spacing = p.spacing;
  m.h_s = p.hs_factor * m.spacing;
  m.h = p.h_factor * m.spacing;

  // Candidate pairs within 2 h_s.
  ParticleGrid grid;
  grid.build(x, 2 * m.h_s);
  std::vector<uint32_t> off, nb;
  grid.neighbour_lists(ctx, x, 2 * m.h_s, off, nb);
  struct Cand {
    uint32_t a, b;
    double l0, c, ca, cb, strength;
  };
  std::vector<Cand> cands;
  std::vector<Cand> fallback(n);
  std::vector<double> fallback_a(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (uint32_t q = off[i]; q < off[i + 1]; ++q) {
      const uint32_t j = nb[q];
      if (j <= i || (m.root[i] && m.root[j])) continue;
      const Vec3 d = x[j] - x[i];
      const double l0 = d.norm();
      if (l0 <= 0) continue;
      const Vec3 xh = d / l0;
      // theta0_ij: angle between t_i and x_ij; theta0_ji: angle between t_j and the same pair
      // direction x_ij (measuring it against x_ji instead would make every aligned pair fail the
      // sign test of (3.6)).
      const double ci = t[i].dot(xh), cj = t[j].dot(xh);
      const double a = ci * cj > 0 ? std::abs((ci + cj) / 2) : 0.0;  // (3.6)
      if (a <= 0) continue;
      if (a < p.a0) {
        // Remember the best root-side partner of each end: a particle without any root-side
        // connection would fall off freely (added below; not in the paper).
        const uint32_t tip = ci > 0 ? j : uint32_t(i);
        if (a > fallback_a[tip]) {
          fallback_a[tip] = a;
          fallback[tip] = ci > 0 ? Cand{uint32_t(i), j, l0, a * l0, ci, cj, 0}
                                 : Cand{j, uint32_t(i), l0, a * l0, -cj, -ci, 0};
        }
        continue;
      }
      Cand c;
      if (ci > 0) {  // j lies towards the tip of i
        c = {uint32_t(i), j, l0, a * l0, ci, cj, 0};
      } else {
        c = {j, uint32_t(i), l0, a * l0, -cj, -ci, 0};
      }
      c.c = a * l0;                         // (3.5) c_ij = a_ij l0_ij
      c.strength = c.c * sph_w(m.h_s, l0);  // initial spring coefficient (3.7)
      cands.push_back(c);
    }
  {
    std::vector<char> has_root_side(n, 0);
    for (const auto& c : cands) has_root_side[c.b] = 1;
    for (std::size_t i = 0; i < n; ++i)
      if (!m.root[i] && !has_root_side[i] && fallback_a[i] > 0) {
        Cand c = fallback[i];
        c.strength = c.c * sph_w(m.h_s, c.l0);
        cands.push_back(c);
      }
  }
  {
    // A particle that still has no root-side partner (its neighbours within 2 h_s all lie beside
    // it) is tied to the nearest neighbour with a smaller arc length s, with a small alignment
    // floor, so that every particle starts attached to the head (not in the paper).
    std::vector<char> has_root_side(n, 0);
    for (const auto& c : cands) has_root_side[c.b] = 1;
    for (std::size_t i = 0; i < n; ++i) {
      if (m.root[i] || has_root_side[i]) continue;
      double best = 4 * m.h_s * m.h_s;
      uint32_t bj = uint32_t(-1);
      for (uint32_t q = off[i]; q < off[i + 1]; ++q) {
        const uint32_t j = nb[q];
        const double d2 = (x[j] - x[i]).squaredNorm();
        if (uvs[j].z() < uvs[i].z() && d2 < best && d2 > 0) {
          best = d2;
          bj = j;
        }
      }
      if (bj == uint32_t(-1)) continue;
      const Vec3 d = x[i] - x[bj];
      const double l0 = d.norm();
      const Vec3 xh = d / l0;
      const double a = std::max(std::abs((t[bj].dot(xh) + t[i].dot(xh)) / 2), kOrphanAlignment);
      Cand c{bj, uint32_t(i), l0, a * l0, t[bj].dot(xh), t[i].dot(xh), 0};
      c.strength = c.c * sph_w(m.h_s, l0);
      cands.push_back(c);
    }
  }
  // Remove the weakest connections while both ends keep more than N_n (never a tip-side end's
  // last root-side connection).
  std::vector<uint32_t> order(cands.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t u, uint32_t w) { return cands[u].strength < cands[w].strength; });
  std::vector<int> deg(n, 0);
  for (const auto& c : cands) {
    ++deg[c.a];
    ++deg[c.b];
  }
  std::vector<int> nroot(n, 0);
  for (const auto& c : cands) ++nroot[c.b];
  std::vector<char> keep(cands.size(), 1);
  for (uint32_t q : order) {
    const auto& c = cands[q];
    if (deg[c.a] > p.n_n && deg[c.b] > p.n_n && nroot[c.b] > 1) {
      keep[q] = 0;
      --deg[c.a];
      --deg[c.b];
      --nroot[c.b];
    }
  }
  for (std::size_t q = 0; q < cands.size(); ++q) {
    if (!keep[q]) continue;
    const auto& c = cands[q];
    m.pair_a.push_back(c.a);
    m.pair_b.push_back(c.b);
    m.l0.push_back(c.l0);
    m.c.push_back(c.c);
    m.cos_a.push_back(c.ca);
    m.cos_b.push_back(c.cb);
  }
  m.adj_offsets.assign(n + 1, 0);
  for (std::size_t q = 0; q < m.l0.size(); ++q) {
    ++m.adj_offsets[m.pair_a[q] + 1];
    ++m.adj_offsets[m.pair_b[q] + 1];
  }
  for (std::size_t i = 0; i < n; ++i) m.adj_offsets[i + 1] += m.adj_offsets[i];
  m.adj_pairs.resize(m.adj_offsets[n]);
  std::vector<uint32_t> fill(m.adj_offsets.begin(), m.adj_offsets.end() - 1);
  for (std::size_t q = 0; q < m.l0.size(); ++q) {
    m.adj_pairs[fill[m.pair_a[q]]++] = uint32_t(q);
    m.adj_pairs[fill[m.pair_b[q]]++] = uint32_t(q);
  }
  const auto rho = sph_density(ctx, x, mass, m.h);
  double rs = 0;
  std::size_t rc = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!m.root[i]) {
      rs += rho[i];
      ++rc;
    }
  m.rest_density = rc ? rs / double(rc) : 0.0;
  return m;
}

namespace {

uint64_t cell_key(const Vec3& p, double s, double r) {
  auto f = [](double v) {
    return uint64_t(uint32_t(int64_t(std::floor(v)) + (1 << 15)) & 0xFFFFu);
  };
  return f(p.x() / r) | (f(p.y() / r) << 16) | (f(p.z() / r) << 32) | (f(s / r) << 48);
}

struct Chain {
  Vec3 x, t;
};

// The particle is the end of a cantilever chain of length s_i from its root (Anjyo et al. 1992
// as used by §3.3.1). Hand-written here: each segment bends towards gravity by the moment of the
// remaining strand, dtheta = (w/EI) (L - s)^2 / 2 sin(phi) ds, never past the gravity direction,
// and a segment entering the body is turned along the body plane.
Chain cantilever_chain(const ScalpPoint& sp, const Vec3& tr, double L, double s,
                       const LcpInitParams& p, const sim::VoxelPlanes* body) {
  if (s <= 0) return {sp.position + s * tr, tr};  // (3.3) root particles
  const Vec3 g = p.gravity_dir.normalized();
  const int nseg = p.cantilever_segments;
  const double ds = std::max(L, s) / nseg;
  Vec3 x = sp.position, d = tr;
  double arc = 0;
  while (arc < s - 1e-12) {
    const double seg = std::min(ds, s - arc);
    const Vec3 axis = d.cross(g);
    const double sphi = axis.norm();
    if (sphi > 1e-12) {
      const double phi = std::atan2(sphi, d.dot(g));
      const double rem = std::max(L - arc, 0.0);
      const double dth = std::min(phi, p.cantilever_sag * rem * rem / 2 * sphi * seg);
      d = Eigen::AngleAxisd(dth, axis / sphi) * d;
    }
    if (body) {
      const Vec3 q = x + d * seg;
      if (const sim::BodyPlane* pl = body->find(q)) {
        const double dist = (q - pl->p).dot(pl->n);
        if (dist < p.body_clearance) {
          const double dn = d.dot(pl->n);
          if (dn < 0) d = (d - dn * pl->n);
          d += (p.body_clearance - dist) / seg * pl->n;
          d.normalize();
        }
      }
    }
    x += d * seg;
    arc += seg;
  }
  return {x, d};
}

}  // namespace

// The order of the points along a Morton (Z-order) curve over their bounding box (21 bits per
// axis; ties keep the input order).
std::vector<uint32_t> lcp_zorder(const std::vector<Vec3>& x) {
  const std::size_t n = x.size();
  Vec3 lo = x[0], hi = x[0];
  for (const Vec3& xi : x) {
    lo = lo.cwiseMin(xi);
    hi = hi.cwiseMax(xi);
  }
  const double ext = std::max((hi - lo).maxCoeff(), 1e-12);
  auto spread = [](uint64_t v) {  // 21 bits -> every third bit
    v &= 0x1FFFFF;
    v = (v | v << 32) & 0x1F00000000FFFFull;
    v = (v | v << 16) & 0x1F0000FF0000FFull;
    v = (v | v << 8) & 0x100F00F00F00F00Full;
    v = (v | v << 4) & 0x10C30C30C30C30C3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
  };
  std::vector<uint64_t> code(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 f = (x[i] - lo) / ext * double((1 << 21) - 1);
    code[i] = spread(uint64_t(f.x())) | spread(uint64_t(f.y())) << 1 | spread(uint64_t(f.z())) << 2;
  }
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return code[a] < code[b]; });
  return order;
}

std::vector<char> lcp_attached(const LcpModel& m) {
  const std::size_t n = m.size();
  std::vector<char> att(n, 0);
  std::vector<uint32_t> stack;
  for (std::size_t i = 0; i < n; ++i)
    if (m.root[i]) {
      att[i] = 1;
      stack.push_back(uint32_t(i));
    }
  while (!stack.empty()) {
    const uint32_t i = stack.back();
    stack.pop_back();
    for (uint32_t e = m.adj_offsets[i]; e < m.adj_offsets[i + 1]; ++e) {
      const uint32_t q = m.adj_pairs[e];
      if (m.pair_a[q] != i) continue;  // follow root-side -> tip-side only
      const uint32_t b = m.pair_b[q];
      if (!att[b]) {
        att[b] = 1;
        stack.push_back(b);
      }
    }
  }
  return att;
}

LcpInit initialize_lcp(const Context& ctx, const Scalp& scalp, const LcpInitParams& p,
                       const sim::VoxelPlanes* body) {
  p.validate();
  const double r = p.spacing;
  const double sr = scalp.root_depth();
  const double lmax = scalp.max_length();
  const Vec3 n_w = scalp.point(scalp.nearest_uv(p.whirl_point)).normal;
  Rng rng = Rng::stream(ctx.seed(), 0x4c4350ull);
  struct Sample {
    Vec2 uv;
    double s;
    Vec3 pos;
  };
  // Resource guard, before any dart is thrown: a saturated Poisson-disc sampling of radius r
  // fills a 3-D domain at about 0.7 / r^3 points per unit volume (random sequential packing of
  // spheres of diameter r: density ~0.38 of (pi/6) r^3), and the domain here is the scalp times
  // the pillar -s_r..L. An estimate far beyond the cap fails now with the numbers; a sampling
  // that reaches the cap anyway fails below instead of silently leaving the hair unfinished.
  const double estimate = 0.7 * scalp.area() * (lmax + sr) / (r * r * r);
  if (estimate > 2.0 * double(p.max_particles))
    fail_at("lcp_init.max_particles",
            "the scalp ({:.4g} m^2, hair up to {} m long) at spacing {} m needs about {} "
            "particles, more than the cap of {} (is the head in metres? a larger spacing or "
            "shorter hair also help)",
            scalp.area(), lmax, r, format_count(estimate), format_count(p.max_particles));
  std::vector<Sample> samples;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
  const int max_miss = p.attempts_per_particle * 50;
  int miss = 0;
  while (miss < max_miss && int(samples.size()) < p.max_particles) {
    const Vec2 uv = scalp.sample_uv(rng);
    const double L = scalp.length(uv);
    // Volume-uniform in the pillar -s_r <= s <= L(u, v).
    if (rng.uniform() * (lmax + sr) > L + sr) {
      ++miss;
      continue;
    }
    const double s = -sr + rng.uniform() * (L + sr);
    const Vec3 pos = scalp.point(uv).position;
    bool ok = true;
    for (int dw = -1; dw <= 1 && ok; ++dw)
      for (int dz = -1; dz <= 1 && ok; ++dz)
        for (int dy = -1; dy <= 1 && ok; ++dy)
          for (int dx = -1; dx <= 1 && ok; ++dx) {
            const Vec3 o(dx * r, dy * r, dz * r);
            auto it = cells.find(cell_key(pos + o, s + dw * r, r));
            if (it == cells.end()) continue;
            for (uint32_t j : it->second) {
              const Sample& q = samples[j];
              // (3.2) d^2 = |phi^-1(u1,v1) - phi^-1(u2,v2)|^2 + (s1 - s2)^2
              const double d2 = (q.pos - pos).squaredNorm() + (q.s - s) * (q.s - s);
              if (d2 < r * r) {
                ok = false;
                break;
              }
            }
          }
    if (!ok) {
      ++miss;
      continue;
    }
    miss = 0;
    cells[cell_key(pos, s, r)].push_back(uint32_t(samples.size()));
    samples.push_back({uv, s, pos});
  }
  if (int(samples.size()) >= p.max_particles && miss < max_miss)
    fail_at("lcp_init.max_particles",
            "the hair reached the cap of {} particles before the scalp ({:.4g} m^2) was full at "
            "spacing {} m; raise the cap or the spacing",
            p.max_particles, scalp.area(), r);
  if (samples.size() < 2)
    fail_at("lcp_init.spacing", "only {} particle(s) fit the scalp with spacing {} m",
            samples.size(), r);
  const std::size_t n = samples.size();
  std::vector<Vec3> x(n), t(n), uvs(n);
  std::vector<double> mass(n, p.total_mass / double(n));
  parallel_for(ctx, 0, n, [&](std::size_t i) {
    const Sample& q = samples[i];
    const ScalpPoint sp = scalp.point(q.uv);
    Vec3 tr = root_direction(n_w, sp.normal, p.w_t, p.w_n);  // (3.4)
    tr = tr.norm() > 1e-12 ? Vec3(tr.normalized()) : sp.normal;
    const Chain c = cantilever_chain(sp, tr, scalp.length(q.uv), q.s, p, body);
    x[i] = c.x;  // (3.3) along the cantilever shape instead of the straight root direction
    t[i] = c.t;
    uvs[i] = Vec3(q.uv.x(), q.uv.y(), q.s);
  });
  // Particles are numbered along a Morton (Z-order) curve of their initial positions, so that
  // particles near in space are near in memory: a particle's neighbours and connections then
  // mostly lie in the same block of indices, the block one thread works on in a sub-step loop
  // (dart throwing alone numbers them in random order over the scalp, and every loop then reads
  // much of what the other core has just written).
  {
    const std::vector<uint32_t> order = lcp_zorder(x);
    auto permute = [&](std::vector<Vec3>& v) {
      std::vector<Vec3> o(n);
      for (std::size_t i = 0; i < n; ++i) o[i] = v[order[i]];
      v.swap(o);
    };
    permute(x);
    permute(t);
    permute(uvs);
  }
  // Particles that cannot reach a root particle through root-side connections would fall off
  // the head; they are removed (iterated, as removal may cut others off) and the mass shared
  // again. Not in the paper, which does not say how isolated particles are treated.
  LcpInit out;
  for (int pass = 0;; ++pass) {
    out.model = connect_particles(ctx, x, t, uvs, mass, p);
    const std::vector<char> att = lcp_attached(out.model);
    const std::size_t nkeep = std::size_t(std::count(att.begin(), att.end(), char(1)));
    if (nkeep == x.size() || pass >= 8) break;
    if (nkeep < 2) fail_at("lcp_init", "no particle is connected to a root particle");
    std::vector<Vec3> x2, t2, uvs2;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (att[i]) {
        x2.push_back(x[i]);
        t2.push_back(t[i]);
        uvs2.push_back(uvs[i]);
      }
    ctx.log().info("lcp: removed {} particle(s) not connected to the head", x.size() - nkeep);
    x = std::move(x2);
    t = std::move(t2);
    uvs = std::move(uvs2);
    mass.assign(x.size(), p.total_mass / double(x.size()));
  }
  const std::size_t n2 = x.size();
  out.state.x = out.model.rest_x;
  out.state.t = out.model.rest_t;
  out.state.v.assign(n2, Vec3::Zero());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Dynamics
//
// Layout of a sub-step (step()): every loop runs over particles or over connections and writes
// only what its item owns: a particle's own state and the hair-hair pairs of its sorted
// neighbour list with a higher index, or one connection's values. Per-pair and per-connection
// values are then gathered in a fixed order, so results do not depend on the thread count. Six
// parallel loops per sub-step:
//   1. (particles) k_ij (3.7) + tethers of the connections of which the particle is the
//      tip-side end, W(h, r) per pair and the compact list of interacting pairs, largest
//      displacement since the list build
//   2. (particles) alpha sums (3.13), density (3.1) and pressure
//   3. (connections, then particles) alpha_ij (3.14) and the spring force per connection;
//      hair-hair forces (3.16)-(3.18) per particle
//   4. (particles) gather of the forces, accelerations and the leapfrog update
//   5. (connections) geometry |x_ab|, x^_ab at the new positions and the (3.15) terms of both
//      ends
//   6. (particles) direction update (3.15): the sum of those terms, and the blow-up check
// Each particle's connections are kept in two lists by its role (root-side / tip-side end), so
// none of the particle loops branches per connection on which end it is.

namespace {
// Particles (or connections) per task of the sub-step loops: small enough that two threads
// stay balanced over 2,000 particles (256 measured ~8 % slower on 2 cores).
constexpr std::size_t kChunk = 64;
}  // namespace

LcpSolver::LcpSolver(const LcpParams& params, LcpModel model, const sim::VoxelPlanes* body)
    : m_params(params), m_model(std::move(model)), m_body(body) {
  m_params.validate();
  const std::size_t n = m_model.size();
  if (n == 0) fail_at("lcp", "the particle model is empty");
  if (m_model.rest_x.size() != n || m_model.rest_t.size() != n || m_model.root.size() != n ||
      m_model.adj_offsets.size() != n + 1)
    fail_at("lcp", "inconsistent particle model arrays");
  if (!(m_model.h > 0) || !(m_model.h_s > 0)) fail_at("lcp", "smoothing lengths must be > 0");
  const std::size_t np = m_model.num_pairs();
  if (m_model.pair_a.size() != np || m_model.pair_b.size() != np || m_model.c.size() != np ||
      m_model.cos_a.size() != np || m_model.cos_b.size() != np ||
      m_model.adj_offsets.back() != m_model.adj_pairs.size())
    fail_at("lcp", "inconsistent connection arrays");
  for (std::size_t q = 0; q < m_model.num_pairs(); ++q)
    if (m_model.pair_a[q] >= n || m_model.pair_b[q] >= n)
      fail_at(fmt::format("lcp.pairs[{}]", q), "particle index out of range");
  for (std::size_t e = 0; e < m_model.adj_pairs.size(); ++e)
    if (m_model.adj_pairs[e] >= np)
      fail_at(fmt::format("lcp.adjacency[{}]", e), "connection index out of range");
  m_rho0 = m_params.rho0_scale * m_model.rest_density;
  m_ks = SphKernel(m_model.h_s);
  m_ea.resize(n);
  for (std::size_t i = 0; i < n; ++i) m_ea[i] = m_params.elastic_modulus * cross_section(i);
  // Connections of each particle by its role (pair_b == i: root-side partner; pair_a == i:
  // tip-side partner), in adjacency order.
  auto split = [&](bool as_b, std::vector<uint32_t>& off, std::vector<uint32_t>& pairs) {
    off.assign(n + 1, 0);
    pairs.clear();
    for (std::size_t i = 0; i < n; ++i) {
      for (uint32_t e = m_model.adj_offsets[i]; e < m_model.adj_offsets[i + 1]; ++e) {
        const uint32_t q = m_model.adj_pairs[e];
        if ((as_b ? m_model.pair_b[q] : m_model.pair_a[q]) == i) pairs.push_back(q);
      }
      off[i + 1] = uint32_t(pairs.size());
    }
  };
  split(true, m_rs_offsets, m_rs_pairs);
  split(false, m_ts_offsets, m_ts_pairs);
  // cos theta0_ij against x_ij = x_j - x_i per end: +cos_a at the root-side end, -cos_b at the
  // tip-side end (x_ij = -x_ab there); sin theta0 of each end.
  m_cos_a.resize(np);
  m_sin_a.resize(np);
  m_cos_b.resize(np);
  m_sin_b.resize(np);
  for (std::size_t q = 0; q < np; ++q) {
    const double ca = m_model.cos_a[q], cb = m_model.cos_b[q];
    m_cos_a[q] = ca;
    m_sin_a[q] = std::sqrt(std::max(0.0, 1 - ca * ca));
    m_cos_b[q] = -cb;
    m_sin_b[q] = std::sqrt(std::max(0.0, 1 - cb * cb));
  }
  m_damp.resize(np);
  for (std::size_t q = 0; q < np; ++q) {
    const double ma = m_model.mass[m_model.pair_a[q]], mb = m_model.mass[m_model.pair_b[q]];
    m_damp[q] = 2.0 * m_params.spring_damping * std::sqrt(ma * mb / (ma + mb));
  }
  if (m_rs_pairs.size() != np || m_ts_pairs.size() != np)
    fail_at("lcp", "every connection must appear once in the adjacency of each of its ends");
}

LcpState LcpSolver::rest_state() const {
  LcpState s;
  s.x = m_model.rest_x;
  s.t = m_model.rest_t;
  s.v.assign(m_model.size(), Vec3::Zero());
  return s;
}

double LcpSolver::cross_section(std::size_t i) const {
  return std::pow(m_model.mass[i] / m_params.material_density, 2.0 / 3.0);  // (3.9)
}

template <class R>
void LcpSolver::coefficients_of(std::size_t i, const LcpState& s, LcpWorkspace& ws,
                                R&& r_of) const {
  const auto& m = m_model;
  const uint32_t r0 = m_rs_offsets[i], r1 = m_rs_offsets[i + 1];
  for (uint32_t e = r0; e < r1; ++e) {
    const uint32_t q = m_rs_pairs[e];
    ws.k[q] = m.c[q] * m_ks.w(r_of(q));  // (3.7) k_ij = c_ij W(h_s, |x_ij|)
  }
  // A particle whose root-side springs have all drawn apart beyond 2 h_s would be free and fall
  // off the head. Its nearest root-side spring is kept at the coefficient it has at r = 2 h_s
  // minus a margin (any positive k gives the full tensile modulus through (3.13)), so the hair
  // splits laterally but never tears lengthwise (not in the paper; see docs/equations/lcp.md).
  if (m.root[i]) return;
  uint32_t best = uint32_t(-1);
  double bd = 1e300;
  for (uint32_t e = r0; e < r1; ++e) {
    const uint32_t q = m_rs_pairs[e];
    if (ws.k[q] > 0) return;  // held
    const double d = (s.x[m.pair_a[q]] - s.x[i]).squaredNorm();
    if (d < bd) {
      bd = d;
      best = q;
    }
  }
  if (best != uint32_t(-1)) ws.k[best] = m.c[best] * m_ks.w(kTetherFraction * 2 * m.h_s);
}

void LcpSolver::coefficients_from_geometry(std::size_t i, const LcpState& s,
                                           LcpWorkspace& ws) const {
  coefficients_of(i, s, ws, [&](uint32_t q) { return ws.conn_r[q]; });
}

void LcpSolver::alpha_sums_of(std::size_t i, LcpWorkspace& ws) const {
  const auto& m = m_model;
  double sr = 0, st = 0;
  for (uint32_t e = m_rs_offsets[i]; e < m_rs_offsets[i + 1]; ++e) {
    const uint32_t q = m_rs_pairs[e];
    sr += m.l0[q] * ws.k[q];  // the other end is in N_r(i)
  }
  for (uint32_t e = m_ts_offsets[i]; e < m_ts_offsets[i + 1]; ++e) {
    const uint32_t q = m_ts_pairs[e];
    st += m.l0[q] * ws.k[q];  // the other end is in N_t(i)
  }
  const double ea = m_ea[i];
  ws.alpha_r[i] = sr > 0 ? ea / sr : 0.0;  // (3.13)
  ws.alpha_t[i] = st > 0 ? ea / st : 0.0;
}

void LcpSolver::alpha_of(std::size_t i, LcpWorkspace& ws) const {
  // (3.14): a = pair_a is root-side (in N_r(b)), b = i is tip-side (in N_t(a)).
  for (uint32_t e = m_rs_offsets[i]; e < m_rs_offsets[i + 1]; ++e) {
    const uint32_t q = m_rs_pairs[e];
    ws.alpha[q] = 0.5 * (ws.alpha_r[i] + ws.alpha_t[m_model.pair_a[q]]);
  }
}

void LcpSolver::alpha_sweeps(const Context& ctx, LcpWorkspace& ws) const {
  // Optional balancing (not in the paper): the average (3.14) satisfies neither (3.10) nor
  // (3.11) exactly. Each sweep scales alpha_ij by the geometric mean of E / E_{r,b} and
  // E / E_{t,a} of its two ends (iterative proportional fitting); still linear time.
  const auto& m = m_model;
  const std::size_t n = m.size(), np = m.num_pairs();
  for (int sweep = 0; sweep < m_params.alpha_sweeps; ++sweep) {
    parallel_for(ctx, 0, n, [&](std::size_t i) {
      double er = 0, et = 0;
      for (uint32_t e = m.adj_offsets[i]; e < m.adj_offsets[i + 1]; ++e) {
        const uint32_t q = m.adj_pairs[e];
        const double c = m.l0[q] * ws.alpha[q] * ws.k[q];
        if (m.pair_b[q] == i)
          er += c;
        else
          et += c;
      }
      const double ea = m_ea[i];
      ws.alpha_r[i] = er > 0 ? ea / er : 1.0;  // reused as correction factors
      ws.alpha_t[i] = et > 0 ? ea / et : 1.0;
    });
    parallel_for(ctx, 0, np, [&](std::size_t q) {
      ws.alpha[q] *= std::sqrt(ws.alpha_r[m.pair_b[q]] * ws.alpha_t[m.pair_a[q]]);
    });
  }
}

void LcpSolver::solve_alpha(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const {
  const auto& m = m_model;
  const std::size_t np = m.num_pairs(), n = m.size();
  ws.k.resize(np);
  ws.alpha.resize(np);
  ws.alpha_r.resize(n);
  ws.alpha_t.resize(n);
  parallel_for(ctx, 0, n, [&](std::size_t i) {
    coefficients_of(i, s, ws,
                    [&](uint32_t q) { return (s.x[m.pair_b[q]] - s.x[m.pair_a[q]]).norm(); });
  });
  // (3.13), after all tethers are set (a root-side end reads k of connections whose tip-side
  // end may have just raised them).
  parallel_for(ctx, 0, n, [&](std::size_t i) { alpha_sums_of(i, ws); });
  parallel_for(ctx, 0, n, [&](std::size_t i) { alpha_of(i, ws); });
  alpha_sweeps(ctx, ws);
}

double LcpSolver::stiffness_rate(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const {
  const auto& m = m_model;
  solve_alpha(ctx, s, ws);
  const double w2 = deterministic_reduce(
      ctx, m.size(), 1024, 0.0,
      [&](std::size_t i0, std::size_t i1) {
        double w = 0;
        for (std::size_t i = i0; i < i1; ++i) {
          double ks = 0;
          for (uint32_t e = m.adj_offsets[i]; e < m.adj_offsets[i + 1]; ++e)
            ks += ws.alpha[m.adj_pairs[e]] * ws.k[m.adj_pairs[e]];
          w = std::max(w, ks / m.mass[i]);
        }
        return w;
      },
      [](double a, double b) { return std::max(a, b); });
  // The explicit hair-hair damping (3.17)/(3.18) needs d dt < 1 as well (per reduced mass).
  const auto& P = m_params;
  double rate = std::sqrt(w2) * std::max(1.0, 2 * P.spring_damping);  // damping 2 zeta omega
  if (P.hair_hair) {
    rate = std::max(rate, std::max(P.collision_damping, P.friction_damping));
    rate = std::max(rate, std::sqrt(P.k_a) / m.h);  // a pressure wave crossing h (3.16)
  }
  rate = std::max(rate, P.air_drag);
  if (P.body_collision && m_body) rate = std::max(rate, std::sqrt(P.contact.k_r));  // (3.24)
  return rate;
}

void LcpSolver::tensile_moduli(const LcpWorkspace& ws, std::vector<double>& e_r,
                               std::vector<double>& e_t) const {
  const auto& m = m_model;
  e_r.assign(m.size(), 0.0);
  e_t.assign(m.size(), 0.0);
  for (std::size_t q = 0; q < m.num_pairs(); ++q) {
    const double c = m.l0[q] * ws.alpha[q] * ws.k[q];
    e_r[m.pair_b[q]] += c;  // (3.10)
    e_t[m.pair_a[q]] += c;  // (3.11)
  }
  for (std::size_t i = 0; i < m.size(); ++i) {
    const double a = cross_section(i);
    e_r[i] /= a;
    e_t[i] /= a;
  }
}

void LcpSolver::rebuild_neighbours(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const {
  // Verlet lists: all pairs within R = 2h + skin. A pair now closer than 2h was closer than
  // 2h + 2 d_max at the build, d_max the largest displacement since; so the lists stay complete
  // while 2 d_max < skin (rebuilt a little earlier to stay clear of rounding).
  const double h = m_model.h;
  const double R = 2 * h + m_params.neighbour_skin * 2 * h;
  ws.grid.build(ctx, s.x, R);
  ws.grid.neighbour_lists(ctx, s.x, R, ws.nbr_offsets, ws.nbrs);
  if (!sort_and_mirror(ctx, ws.nbr_offsets, ws.nbrs, ws.nbr_mirror))
    fail("lcp: neighbour lists are not symmetric (internal error)");
  ws.nbr_built_x = s.x;
  ws.nbr_shift = Vec3::Zero();  // displacements are measured from here
  ws.nbr_radius = R;
  ++ws.nbr_builds;
}

namespace {
/// Whether a and b hold the same bits (compared in parallel chunks).
bool same_bits(const Context& ctx, const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  if (a.size() != b.size()) return false;
  return deterministic_reduce(
             ctx, a.size(), 16384, 1,
             [&](std::size_t i0, std::size_t i1) {
               return int(std::memcmp(a.data() + i0, b.data() + i0, (i1 - i0) * sizeof(Vec3)) == 0);
             },
             [](int x, int y) { return x & y; }) != 0;
}
}  // namespace

/// max |x_i - x_i(list build) - u|^2 over i0 <= i < i1 (0 for an empty range).
double LcpSolver::max_shift2(const LcpState& s, const LcpWorkspace& ws, const Vec3& u,
                             std::size_t i0, std::size_t i1) {
  double m = 0;
  for (std::size_t i = i0; i < i1; ++i)
    m = std::max(m, (s.x[i] - ws.nbr_built_x[i] - u).squaredNorm());
  return m;
}

bool LcpSolver::lists_hold(const Context& ctx, const LcpState& s, LcpWorkspace& ws,
                           double lim) const {
  // A pair now closer than 2h was closer than 2h + |d_i - d_j| at the build (d: displacement
  // since then), and |d_i - d_j| <= |d_i - u| + |d_j - u| for any common shift u. So the lists
  // hold every pair within 2h while max_i |d_i - u| < skin / 2 for some u (lim is a little below
  // skin / 2, clear of rounding). The chunks measured max |d - u|^2 for u = ws.nbr_shift (zero
  // after a build: the classic test); when that fails, u = the centre of the box of all
  // displacements is tried (two more passes), which halves the bound when the hair moves as a
  // whole (wind, head motion with the roots fixed), and kept for the next checks.
  const double lim2 = lim * lim;
  double c2 = 0;
  for (double c : ws.chunk_shift) c2 = std::max(c2, c);
  if (c2 < lim2) return true;
  const std::size_t n = s.x.size();
  using Box = std::pair<Vec3, Vec3>;
  const Box box = deterministic_reduce(
      ctx, n, 4096, Box(Vec3::Constant(INFINITY), Vec3::Constant(-INFINITY)),
      [&](std::size_t i0, std::size_t i1) {
        Box b(Vec3::Constant(INFINITY), Vec3::Constant(-INFINITY));
        for (std::size_t i = i0; i < i1; ++i) {
          const Vec3 d = s.x[i] - ws.nbr_built_x[i];
          b.first = b.first.cwiseMin(d);
          b.second = b.second.cwiseMax(d);
        }
        return b;
      },
      [](const Box& a, const Box& b) {
        return Box(a.first.cwiseMin(b.first), a.second.cwiseMax(b.second));
      });
  const Vec3 u = 0.5 * (box.first + box.second);
  if (!u.allFinite()) return false;
  const double e2 = deterministic_reduce(
      ctx, n, 4096, 0.0,
      [&](std::size_t i0, std::size_t i1) { return max_shift2(s, ws, u, i0, i1); },
      [](double a, double b) { return std::max(a, b); });
  if (!(e2 < lim2)) return false;
  ws.nbr_shift = u;
  return true;
}

/// For sorted and mirrored lists: the first entry of each list with a neighbour index above the
/// particle's own (nbr_upper), the pair slots of each particle (pair_off) and the pair slot of
/// every entry (nbr_pair).
void LcpSolver::pair_index(const Context& ctx, LcpWorkspace& ws) {
  const auto& off = ws.nbr_offsets;
  const auto& nb = ws.nbrs;
  const std::size_t n = off.empty() ? 0 : off.size() - 1;
  auto& upper = ws.nbr_upper;
  upper.resize(n);
  parallel_for(ctx, 0, n, [&](std::size_t i) {
    upper[i] = uint32_t(
        std::upper_bound(nb.begin() + off[i], nb.begin() + off[i + 1], uint32_t(i)) - nb.begin());
  });
  ws.pair_off.resize(n + 1);
  ws.pair_off[0] = 0;
  for (std::size_t i = 0; i < n; ++i) ws.pair_off[i + 1] = ws.pair_off[i] + (off[i + 1] - upper[i]);
  ws.nbr_pair.resize(nb.size());
  ws.pair_i.resize(ws.pair_off[n]);
  ws.pair_j.resize(ws.pair_off[n]);
  parallel_for(ctx, 0, n, [&](std::size_t i) {
    // A lower entry's pair is the upper entry nbr_mirror[e] of particle j = nbrs[e].
    for (uint32_t e = off[i]; e < upper[i]; ++e) {
      const uint32_t j = nb[e];
      ws.nbr_pair[e] = ws.pair_off[j] + (ws.nbr_mirror[e] - upper[j]);
    }
    for (uint32_t e = upper[i]; e < off[i + 1]; ++e) {
      const uint32_t slot = ws.pair_off[i] + (e - upper[i]);
      ws.nbr_pair[e] = slot;
      ws.pair_i[slot] = uint32_t(i);
      ws.pair_j[slot] = nb[e];
    }
  });
}

void LcpSolver::pair_scratch(LcpWorkspace& ws) {
  const std::size_t npairs = ws.pair_off.empty() ? 0 : ws.pair_off.back();
  ws.pair_w.resize(npairs);
  ws.pair_f.resize(npairs);
  ws.act_i.resize(npairs);
  ws.act_j.resize(npairs);
  ws.act_slot.resize(npairs);
  const std::size_t n = ws.nbr_offsets.empty() ? 0 : ws.nbr_offsets.size() - 1;
  ws.act_count.resize((n + kChunk - 1) / kChunk);
}

void LcpSolver::density_of(std::size_t i, LcpWorkspace& ws, double w0) const {
  const auto& m = m_model;
  double rho = m.mass[i] * w0;
  // (3.1), in list order: pairs below nbr_upper[i] were evaluated by the other end.
  const uint32_t e0 = ws.nbr_offsets[i], eu = ws.nbr_upper[i], e1 = ws.nbr_offsets[i + 1];
  for (uint32_t e = e0; e < eu; ++e) rho += m.mass[ws.nbrs[e]] * ws.pair_w[ws.nbr_pair[e]];
  const uint32_t p0 = ws.pair_off[i];  // pair slot of entry e >= eu: p0 + (e - eu)
  for (uint32_t e = eu; e < e1; ++e) rho += m.mass[ws.nbrs[e]] * ws.pair_w[p0 + (e - eu)];
  ws.density[i] = rho;
  ws.pressure[i] = m_params.k_a * (rho - m_rho0);  // P = k_a (rho - rho0)
  ws.p_rho2[i] = ws.pressure[i] / (rho * rho);
}

void LcpSolver::pair_forces(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const {
  // The caller may have built ws.nbrs itself (any order, any radius >= 2h): sort and mirror.
  if (m_params.hair_hair && !ws.nbr_offsets.empty()) {
    if (!sort_and_mirror(ctx, ws.nbr_offsets, ws.nbrs, ws.nbr_mirror))
      fail("lcp: pair_forces needs symmetric neighbour lists without self entries");
    pair_index(ctx, ws);
  }
  pair_forces_sorted(ctx, s, ws);
}

detail::SpringInputs LcpSolver::spring_inputs(const LcpState& s, LcpWorkspace& ws,
                                              bool with_alpha) const {
  detail::SpringInputs in;
  in.pair_a = m_model.pair_a.data();
  in.pair_b = m_model.pair_b.data();
  in.l0 = m_model.l0.data();
  in.damp = m_damp.data();
  in.conn_r = ws.conn_r.data();
  in.conn_xh = ws.conn_xh.data();
  in.k = ws.k.data();
  in.alpha = ws.alpha.data();
  if (with_alpha) {
    in.alpha_r = ws.alpha_r.data();
    in.alpha_t = ws.alpha_t.data();
  }
  in.v = s.v.data();
  in.compression_scale = m_params.compression_scale;
  return in;
}

void LcpSolver::active_pairs_of(std::size_t c, const LcpState& s, LcpWorkspace& ws,
                                const detail::HairPairConsts& pc) const {
  // W(h, r) of every pair slot of the particles of chunk c (0 beyond 2h) and the compact list of
  // the pairs that interact (0 < r < 2h).
  const std::size_t n = m_model.size();
  const std::size_t s0 = ws.pair_off[c * kChunk], s1 = ws.pair_off[std::min(n, (c + 1) * kChunk)];
  ws.act_count[c] = uint32_t(m_kernels.active(s.x.data(), ws.pair_i.data(), ws.pair_j.data(), pc,
                                              s0, s1, ws.pair_w.data(), ws.act_i.data(),
                                              ws.act_j.data(), ws.act_slot.data()));
}

detail::HairPairConsts LcpSolver::pair_consts(const SphKernel& K, double inv_w0) const {
  detail::HairPairConsts c;
  c.kernel = K;
  c.inv_w0 = inv_w0;
  c.r2max = 4 * m_model.h * m_model.h;
  c.eps2 = m_params.colinear_eps * m_params.colinear_eps;
  c.collision_damping = m_params.collision_damping;
  c.friction_damping = m_params.friction_damping;
  return c;
}

void LcpSolver::hair_pairs_of(std::size_t c, const LcpState& s, LcpWorkspace& ws,
                              const detail::HairPairConsts& pc) const {
  // Hair-hair force (3.16)-(3.18) on i from j, once per interacting pair (i < j) of the
  // particles of chunk c, as listed by active_pairs_of; j gets the negation. One batch for the
  // chunk: AVX2 runs across pairs of different particles (a particle has only about three).
  const detail::HairPairInputs in{s.x.data(), s.v.data(), s.t.data(), m_model.mass.data(),
                                  ws.p_rho2.data()};
  const std::size_t n = m_model.size();
  const std::size_t s0 = ws.pair_off[c * kChunk], s1 = ws.pair_off[std::min(n, (c + 1) * kChunk)];
  // A zero force in every slot of the chunk, then the interacting ones: the slots are still in
  // cache when the kernel writes (a separate fill pass streamed the whole array once more).
  std::fill(ws.pair_f.begin() + std::ptrdiff_t(s0), ws.pair_f.begin() + std::ptrdiff_t(s1),
            Vec3::Zero());
  m_kernels.forces(in, pc, ws.act_i.data() + s0, ws.act_j.data() + s0, ws.act_slot.data() + s0,
                   ws.act_count[c], ws.pair_f.data());
}

detail::GatherInputs LcpSolver::gather_inputs(const LcpWorkspace& ws, bool hh) const {
  detail::GatherInputs g;
  g.ts_off = m_ts_offsets.data();
  g.ts_pairs = m_ts_pairs.data();
  g.rs_off = m_rs_offsets.data();
  g.rs_pairs = m_rs_pairs.data();
  g.spring_f = ws.spring_f.data();
  g.hh = hh;
  if (hh) {
    g.nbr_off = ws.nbr_offsets.data();
    g.nbr_upper = ws.nbr_upper.data();
    g.nbr_pair = ws.nbr_pair.data();
    g.pair_off = ws.pair_off.data();
    g.pair_f = ws.pair_f.data();
  }
  return g;
}

void LcpSolver::pair_forces_sorted(const Context& ctx, const LcpState& s, LcpWorkspace& ws) const {
  const auto& m = m_model;
  const auto& p = m_params;
  const std::size_t n = m.size(), np = m.num_pairs();
  ws.force.resize(n);
  ws.spring_f.resize(np);
  ws.conn_r.resize(np);
  ws.conn_xh.resize(np);
  ws.geom_owner = nullptr;  // the geometry below is not step()'s cache
  const detail::SpringInputs sin = spring_inputs(s, ws, false);
  parallel_chunks(ctx, np, kChunk, [&](std::size_t q0, std::size_t q1) {
    geometry_of(q0, q1, s, ws);
    m_kernels.springs(sin, q0, q1, ws.spring_f.data());
  });
  const bool hh = p.hair_hair && ws.nbr_offsets.size() == n + 1 && ws.density.size() == n &&
                  ws.pressure.size() == n && ws.nbr_mirror.size() == ws.nbrs.size() &&
                  ws.nbr_upper.size() == n && ws.pair_off.size() == n + 1 &&
                  ws.nbr_pair.size() == ws.nbrs.size();
  if (hh) {
    ws.p_rho2.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      ws.p_rho2[i] = ws.pressure[i] / (ws.density[i] * ws.density[i]);
    pair_scratch(ws);
    const SphKernel K(m.h);
    const detail::HairPairConsts pc = pair_consts(K, 1.0 / K.w(0.0));
    parallel_for(
        ctx, 0, ws.act_count.size(),
        [&](std::size_t c) {
          active_pairs_of(c, s, ws, pc);
          hair_pairs_of(c, s, ws, pc);
        },
        1);
  }
  const detail::GatherInputs gin = gather_inputs(ws, hh);
  parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
    detail::lcp_gather(gin, i0, i1, ws.force.data());
  });
}

void LcpSolver::geometry_of(std::size_t q0, std::size_t q1, const LcpState& s,
                            LcpWorkspace& ws) const {
  m_kernels.geometry(s.x.data(), m_model.pair_a.data(), m_model.pair_b.data(), q0, q1,
                     ws.conn_r.data(), ws.conn_xh.data());
}

detail::DirectionTermInputs LcpSolver::direction_term_inputs(const LcpState& s,
                                                             const LcpWorkspace& ws) const {
  detail::DirectionTermInputs d;
  d.x = s.x.data();
  d.t = s.t.data();
  d.pair_a = m_model.pair_a.data();
  d.pair_b = m_model.pair_b.data();
  d.alpha = ws.alpha.data();
  d.k = ws.k.data();
  d.cos_a = m_cos_a.data();
  d.sin_a = m_sin_a.data();
  d.cos_b = m_cos_b.data();
  d.sin_b = m_sin_b.data();
  return d;
}

detail::DirectionSumInputs LcpSolver::direction_sum_inputs(const double* term) const {
  detail::DirectionSumInputs d;
  d.ts_off = m_ts_offsets.data();
  d.ts_pairs = m_ts_pairs.data();
  d.rs_off = m_rs_offsets.data();
  d.rs_pairs = m_rs_pairs.data();
  d.term = term;
  d.root = m_model.root.data();
  return d;
}

void LcpSolver::update_directions(const Context& ctx, LcpState& s, const LcpWorkspace& ws) const {
  // (3.15) from the current positions (the geometry and terms computed here as in step()).
  const auto& m = m_model;
  const std::size_t np = m.num_pairs();
  std::vector<double> r(np), term(8 * np);
  std::vector<Vec3> xh(np);
  const detail::DirectionTermInputs tin = direction_term_inputs(s, ws);
  parallel_chunks(ctx, np, kChunk, [&](std::size_t q0, std::size_t q1) {
    m_kernels.geometry_terms(tin, q0, q1, r.data(), xh.data(), term.data());
  });
  const detail::DirectionSumInputs din = direction_sum_inputs(term.data());
  parallel_chunks(ctx, m.size(), kChunk, [&](std::size_t i0, std::size_t i1) {
    detail::lcp_direction_sum(din, i0, i1, s.t.data());
  });
}

LcpStepReport LcpSolver::step(const Context& ctx, const LcpStepInput& in, LcpState& s,
                              LcpWorkspace& ws) const {
  if (m_params.integrator == "implicit") return step_implicit(ctx, in, s, ws);
  LcpStepReport rep;
  const auto& m = m_model;
  const auto& P = m_params;
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
  ws.k.resize(np);
  ws.alpha.resize(np);
  ws.alpha_r.resize(n);
  ws.alpha_t.resize(n);
  ws.spring_f.resize(np);
  ws.force.resize(n);
  ws.density.resize(n);
  ws.pressure.resize(n);
  ws.p_rho2.resize(n);
  // Connection geometry: still valid when the positions are those it was computed from.
  const bool geom_valid = ws.geom_owner == this && ws.conn_r.size() == np &&
                          ws.conn_xh.size() == np && same_bits(ctx, ws.geom_x, s.x);
  ws.conn_r.resize(np);
  ws.conn_xh.resize(np);
  ws.dir_term.resize(8 * np);
  ws.geom_owner = nullptr;                  // set again below once it matches s.x
  if (!geom_valid) ws.shift_ready = false;  // the positions are not those measured last
  if (!geom_valid)
    parallel_chunks(ctx, np, kChunk,
                    [&](std::size_t q0, std::size_t q1) { geometry_of(q0, q1, s, ws); });
  // Sub-steps: at least params.substeps; with cfl > 0 enough that the stiffest particle's spring
  // frequency omega = sqrt(sum alpha k / m) satisfies omega dt <= cfl (explicit leapfrog).
  int nsub = P.substeps;
  // ws.k/ws.alpha already hold the values for the current positions (computed with the rate).
  const double rate = stiffness_rate(ctx, s, ws);
  bool alpha_fresh = true;
  // A step the leapfrog cannot take stably is refused before it starts (state untouched), with
  // the reason: more sub-steps than max_substeps allows, or fixed sub-steps (cfl = 0) beyond
  // omega dt <= 2.
  if (P.cfl > 0) {
    const double need = std::ceil(in.dt * rate / P.cfl);
    if (!(need <= P.max_substeps)) {
      rep.ok = false;
      rep.message = fmt::format(
          "lcp: this step of {} s needs {} leapfrog sub-steps (stiffness rate {:.4g} 1/s, cfl "
          "{}), more than lcp.dynamics.max_substeps = {}; raise max_substeps, lower the "
          "stiffness or damping, or use \"integrator\": \"implicit\"",
          in.dt, need, rate, P.cfl, P.max_substeps);
      return rep;
    }
    nsub = std::max(nsub, int(need));
  } else if (!(in.dt / nsub * rate <= 2.0)) {
    rep.ok = false;
    rep.message = fmt::format(
        "lcp: fixed sub-steps of {} s (cfl = 0, substeps = {}) exceed the leapfrog's stability "
        "limit: stiffness rate {:.4g} 1/s times the sub-step is {:.3g} > 2; set "
        "lcp.dynamics.cfl > 0 or raise substeps",
        in.dt / nsub, nsub, rate, in.dt / nsub * rate);
    return rep;
  }
  const double dt = in.dt / nsub;
  const anim::RigidSample& hd = in.head;
  const Mat3 R = hd.rotation, Rt = R.transpose();
  const Vec3 g_h = Rt * P.gravity;
  // Inertial (fictitious) accelerations of the head frame, in head coordinates.
  const Vec3 A_h = Rt * hd.acceleration, w_h = Rt * hd.angular_velocity,
             al_h = Rt * hd.angular_acceleration, V_h = Rt * hd.velocity;
  const Vec3 piv = hd.pivot;
  ws.accel.resize(n);
  ws.contact.resize(n);  // every sub-step writes every particle's entry (step 4)
  ws.penetration.resize(n);
  ws.geom_x.resize(n);
  const std::size_t nchunks = (n + kChunk - 1) / kChunk;
  ws.chunk_shift.resize(nchunks);
  ws.chunk_check.resize(nchunks);
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
  }
  for (int sub = 0; sub < nsub; ++sub) {
    const bool do_alpha = !alpha_fresh;
    alpha_fresh = false;
    // 1. k_ij (3.7) from the shared geometry, W per pair, displacement since the list build.
    bool rebuild = false;
    if (hh) {
      rebuild = skin <= 0 || ws.nbr_built_x.size() != n || ws.nbr_radius != Rn ||
                ws.nbr_offsets.size() != n + 1 || ws.nbr_mirror.size() != ws.nbrs.size();
      // The displacements were measured at the end of the last sub-step (same positions): a
      // failed check rebuilds before the pass below instead of redoing it.
      if (!rebuild && ws.shift_ready) {
        rebuild = !lists_hold(ctx, s, ws, 0.49 * skin);
        if (rebuild) ++ws.nbr_early_builds;
      }
      if (rebuild) rebuild_neighbours(ctx, s, ws);
      if (rebuild || ws.nbr_upper.size() != n || ws.pair_off.size() != n + 1 ||
          ws.nbr_pair.size() != ws.nbrs.size())
        pair_index(ctx, ws);
      pair_scratch(ws);
    }
    const bool checked = rebuild || ws.shift_ready;  // no displacement test in the pass
    ws.shift_ready = false;
    for (int attempt = 0; attempt < 2; ++attempt) {
      const Vec3 u = ws.nbr_shift;
      parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
        if (do_alpha)
          for (std::size_t i = i0; i < i1; ++i)
            coefficients_of(i, s, ws, [&](uint32_t q) { return ws.conn_r[q]; });
        if (hh && !checked) ws.chunk_shift[i0 / kChunk] = max_shift2(s, ws, u, i0, i1);
        if (hh) active_pairs_of(i0 / kChunk, s, ws, pc);
      });
      if (!hh || checked) break;
      if (lists_hold(ctx, s, ws, 0.49 * skin)) break;  // every pair within 2h is still listed
      // The particles moved apart by more than the skin allows: rebuild and redo.
      rebuild = true;
      rebuild_neighbours(ctx, s, ws);
      pair_index(ctx, ws);
      pair_scratch(ws);
    }
    // 2. alpha sums (3.13), density (3.1) and pressure.
    parallel_for(
        ctx, 0, n,
        [&](std::size_t i) {
          if (do_alpha) alpha_sums_of(i, ws);
          if (hh) density_of(i, ws, w0);
        },
        kChunk);
    if (do_alpha && P.alpha_sweeps > 0) {
      parallel_for(ctx, 0, n, [&](std::size_t i) { alpha_of(i, ws); });
      alpha_sweeps(ctx, ws);
    }
    const bool alpha_here = do_alpha && P.alpha_sweeps == 0;
    // 3. alpha (3.14) and springs once per connection (indices 0 .. np - 1), hair-hair forces
    // once per pair (particle i at index np + i): one parallel loop over both.
    const std::size_t nconn = (np + kChunk - 1) / kChunk;
    const detail::SpringInputs sin = spring_inputs(s, ws, alpha_here);  // (3.14) if alpha_here
    parallel_for(
        ctx, 0, nconn + (hh ? nchunks : 0),
        [&](std::size_t c) {
          if (c >= nconn) return hair_pairs_of(c - nconn, s, ws, pc);
          m_kernels.springs(sin, c * kChunk, std::min(np, (c + 1) * kChunk), ws.spring_f.data());
        },
        1);
    // 4. Gather, accelerations and the leapfrog update (each particle reads only its own state
    // besides the per-pair forces): v(t + dt/2) = v(t - dt/2) + a(t) dt, x(t + dt) = x(t) +
    // v(t + dt/2) dt.
    const detail::GatherInputs gin = gather_inputs(ws, hh);
    parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
      detail::lcp_gather(gin, i0, i1, ws.force.data());
      for (std::size_t i = i0; i < i1; ++i) {
        const Vec3 force = ws.force[i];
        if (m.root[i]) {
          ws.accel[i] = Vec3::Zero();
          ws.contact[i] = 0;
          ws.penetration[i] = 0;
          s.x[i] = m.rest_x[i];
          s.v[i] = Vec3::Zero();
          continue;
        }
        const double mi = m.mass[i];
        const Vec3 r = s.x[i] - piv;  // head-frame lever arm about the pivot
        Vec3 a = force / mi + g_h;
        // Inertial forces due to head movement (§3.6).
        a -= A_h + al_h.cross(r) + w_h.cross(w_h.cross(r)) + 2.0 * w_h.cross(s.v[i]);
        // Air friction against still air: world velocity = V + omega x r + v.
        a -= P.air_drag * (V_h + w_h.cross(r) + s.v[i]);
        if (in.external_force) a += Rt * (*in.external_force)[i] / mi;
        uint8_t c = 0;
        double pdepth = 0;
        if (P.body_collision && m_body) {
          if (const sim::BodyPlane* pl = m_body->find(s.x[i])) {
            const Vec3 ac = sim::body_contact_accel(*pl, s.x[i], s.v[i], a, dt, P.contact);
            if (ac.squaredNorm() > 0) c = 1;
            a += ac;
            pdepth = std::max(0.0, -(s.x[i] - pl->p).dot(pl->n));
          }
        }
        ws.contact[i] = c;
        ws.penetration[i] = pdepth;
        ws.accel[i] = a;
        s.v[i] += a * dt;
        s.x[i] += s.v[i] * dt;
      }
    });
    // 5. Connection geometry at the new positions with the terms of (3.15) of both ends, then
    // per particle the new direction (3.15) and the blow-up check: first non-finite or too fast
    // particle, in index order.
    const detail::DirectionTermInputs tin = direction_term_inputs(s, ws);
    parallel_chunks(ctx, np, kChunk, [&](std::size_t q0, std::size_t q1) {
      m_kernels.geometry_terms(tin, q0, q1, ws.conn_r.data(), ws.conn_xh.data(),
                               ws.dir_term.data());
    });
    const double vlim = P.max_speed;
    const detail::DirectionSumInputs din = direction_sum_inputs(ws.dir_term.data());
    // With the hair-hair lists: the displacement since their build, for the next sub-step's test.
    const bool measure = hh && ws.nbr_built_x.size() == n;
    const Vec3 u = ws.nbr_shift;
    const bool last = sub + 1 == nsub;
    parallel_chunks(ctx, n, kChunk, [&](std::size_t i0, std::size_t i1) {
      detail::lcp_direction_sum(din, i0, i1, s.t.data());  // (3.15)
      LcpWorkspace::ChunkCheck c;
      if (measure) ws.chunk_shift[i0 / kChunk] = max_shift2(s, ws, u, i0, i1);
      for (std::size_t i = i0; i < i1; ++i) {
        const double sp = s.v[i].norm();
        const bool bad =
            !std::isfinite(sp) || !s.x[i].allFinite() || !s.t[i].allFinite() || sp > vlim;
        if (bad && c.bad == SIZE_MAX) c.bad = i;
        if (std::isfinite(sp)) c.vmax = std::max(c.vmax, sp);
        c.contacts += ws.contact[i];
        c.max_pen = std::max(c.max_pen, ws.penetration[i]);
        if (last) ws.geom_x[i] = s.x[i];  // the positions the connection geometry is of
      }
      ws.chunk_check[i0 / kChunk] = c;
    });
    ws.shift_ready = measure;
    s.time += dt;
    rep.substeps = sub + 1;
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
    if (chk.bad != SIZE_MAX) {
      const double sp = s.v[chk.bad].norm();
      if (std::isfinite(sp) && s.x[chk.bad].allFinite() && s.t[chk.bad].allFinite())
        rep.mark_blow_up(chk.bad);
      else
        rep.mark_non_finite(chk.bad);
      rep.message = fmt::format(
          "lcp: blow-up at t = {:.5f} s: particle {} has speed {} m/s (limit {} m/s) or a "
          "non-finite value; reduce the time step or the stiffness",
          s.time, chk.bad, sp, vlim);
      return rep;
    }
  }
  ws.geom_owner = this;  // geom_x was filled in the last sub-step's final pass
  return rep;
}

void lcp_world(const LcpState& s, const anim::RigidSample& hd, std::vector<Vec3>* x,
               std::vector<Vec3>* v, std::vector<Vec3>* t) {
  const std::size_t n = s.x.size();
  if (x) x->resize(n);
  if (v) v->resize(n);
  if (t) t->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 X = hd.apply(s.x[i]);
    if (x) (*x)[i] = X;
    if (v) (*v)[i] = hd.point_velocity(X) + hd.rotation * s.v[i];
    if (t) (*t)[i] = hd.rotation * s.t[i];
  }
}

}  // namespace follicle::hair
