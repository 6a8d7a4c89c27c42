#include "follicle/hair/sph_air_bando2003.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/hair/sph_kernel.hpp"

namespace follicle::hair {

namespace {
constexpr std::size_t kAirChunk = 256;  // air particles per task of the density/pressure loops
}  // namespace

void SphAirParams::validate() const {
  validate_params(*this, "sph_air");
  for (int k = 0; k < 3; ++k)
    if (!(box_max[k] > box_min[k] + spacing))
      fail_at("sph_air.box_max", "box must be larger than one spacing along every axis");
  if (wind_velocity.norm() < 1e-9) fail_at("sph_air.wind_velocity", "must not be zero");
}

SphAir::SphAir(const Context& ctx, const SphAirParams& params) : m_p(params) {
  m_p.validate();
  m_axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(m_p.wind_velocity[k]) > std::abs(m_p.wind_velocity[m_axis])) m_axis = k;
  m_sign = m_p.wind_velocity[m_axis] > 0 ? 1.0 : -1.0;
  const double a = m_p.spacing;
  m_mass = m_p.air_density * a * a * a;
  m_h = m_p.h_factor * a;
  const Vec3 ext = m_p.box_max - m_p.box_min;
  double count = 1;
  for (int k = 0; k < 3; ++k) count *= std::floor(ext[k] / a);
  if (count > double(m_p.max_particles))
    fail_at("sph_air.spacing", "the box needs {} air particles, more than max_particles = {}",
            count, m_p.max_particles);
  // Fill the box layer by layer along the wind axis (deterministic order).
  const int nl = int(std::floor(ext[m_axis] / a));
  m_phase = 0.5 * a;  // the newest layer sits half a spacing inside the inflow face
  for (int l = 0; l < nl; ++l) spawn_layer((l + 0.5) * a);
  // rho0: the density of an interior lattice particle (3.1), so the resting lattice has P = 0.
  double rho = 0;
  const int r = int(std::ceil(2 * m_h / a));
  for (int i = -r; i <= r; ++i)
    for (int j = -r; j <= r; ++j)
      for (int k = -r; k <= r; ++k)
        rho += m_mass * sph_w(m_h, a * std::sqrt(double(i * i + j * j + k * k)));
  m_rho0 = rho;
  (void)ctx;
}

void SphAir::spawn_layer(double offset) {
  // A lattice layer at distance `offset` downstream of the inflow face.
  const double a = m_p.spacing;
  const int u = (m_axis + 1) % 3, w = (m_axis + 2) % 3;
  const Vec3 ext = m_p.box_max - m_p.box_min;
  const int nu = int(std::floor(ext[u] / a)), nw = int(std::floor(ext[w] / a));
  const double face = m_sign > 0 ? m_p.box_min[m_axis] : m_p.box_max[m_axis];
  for (int j = 0; j < nw; ++j)
    for (int i = 0; i < nu; ++i) {
      if (int(m_x.size()) >= m_p.max_particles) return;
      Vec3 x;
      x[m_axis] = face + m_sign * offset;
      x[u] = m_p.box_min[u] + (i + 0.5) * a;
      x[w] = m_p.box_min[w] + (j + 0.5) * a;
      m_x.push_back(x);
      m_v.push_back(m_p.wind_velocity);
    }
}

Vec3 SphAir::mean_velocity_in(const Vec3& lo, const Vec3& hi, std::size_t* count) const {
  Vec3 s = Vec3::Zero();
  std::size_t c = 0;
  for (std::size_t i = 0; i < m_x.size(); ++i)
    if ((m_x[i].array() >= lo.array()).all() && (m_x[i].array() <= hi.array()).all()) {
      s += m_v[i];
      ++c;
    }
  if (count) *count = c;
  return c ? Vec3(s / double(c)) : Vec3::Zero();
}

Vec3 SphAir::momentum() const {
  Vec3 p = Vec3::Zero();
  for (const auto& v : m_v) p += m_mass * v;
  return p;
}

double SphAir::stable_step(const Context& ctx, bool coupled) const {
  const double vmax = deterministic_reduce(
      ctx, m_x.size(), kAirChunk, 0.0,
      [&](std::size_t i0, std::size_t i1) {
        double m = 0;
        for (std::size_t i = i0; i < i1; ++i) m = std::max(m, m_v[i].norm());
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
  double sub = m_p.cfl * m_h / (std::sqrt(m_p.k_p) + vmax + 1e-9);
  if (m_p.drag > 0 && coupled) sub = std::min(sub, m_p.cfl / m_p.drag);
  return sub;
}

sim::StepReport SphAir::step(const Context& ctx, double dt, const std::vector<Vec3>& hair_x,
                             const std::vector<Vec3>& hair_v, const std::vector<double>& hair_mass,
                             std::vector<Vec3>* force_on_hair) {
  sim::StepReport rep;
  const std::size_t nh = hair_x.size();
  struct Check {
    std::size_t bad = SIZE_MAX;  // first non-finite or too fast particle
    bool non_finite = false;     // some particle is NaN/Inf
    double vmax = 0;             // fastest finite speed
    bool outside = false;        // some particle left the box
  };
  auto outside = [&](const Vec3& x) {
    return (x.array() < m_p.box_min.array()).any() || (x.array() > m_p.box_max.array()).any();
  };
  if (hair_v.size() != nh || hair_mass.size() != nh || !(dt > 0) || !std::isfinite(dt)) {
    rep.ok = false;
    rep.message = "sph_air: hair arrays differ in size or dt is not > 0";
    return rep;
  }
  if (force_on_hair) force_on_hair->resize(nh);
  const double rc = m_p.coupling_radius;
  const double h = m_h;
  const SphKernel K(h), Kc(rc / 2);  // air-air; air-hair coupling (zero beyond rc)
  const double inv_wc0 = 1.0 / Kc.w(0.0);
  std::vector<Vec3>& impulse = m_impulse;
  impulse.resize(nh);
  m_mu.resize(nh);  // reduced mass of each hair particle with an air particle
  parallel_for(
      ctx, 0, nh,
      [&](std::size_t i) {
        impulse[i] = Vec3::Zero();
        m_mu[i] = hair_mass[i] * m_mass / (hair_mass[i] + m_mass);
      },
      4096);
  if (nh) m_hair_grid.build(ctx, hair_x, rc);
  double t = 0;
  int guard = 0;
  while (t < dt - 1e-12 && guard++ < 100000) {
    const std::size_t n = m_x.size();
    const double sub = std::min(stable_step(ctx, nh > 0), dt - t);
    // Air-air: density (3.1) and pressure (no tension).
    const double cell = std::max(2 * h, rc);
    m_grid.build(ctx, m_x, cell);
    m_grid.neighbour_lists(ctx, m_x, 2 * h, m_off, m_nb);
    m_rho.resize(n);
    m_pr.resize(n);
    m_pr_rho2.resize(n);
    detail::AirInputs ain;
    ain.x = m_x.data();
    ain.off = m_off.data();
    ain.nb = m_nb.data();
    ain.mass = m_mass;
    ain.kernel = K;
    ain.p_rho2 = m_pr_rho2.data();
    parallel_chunks(ctx, n, kAirChunk, [&](std::size_t i0, std::size_t i1) {
      m_kernels.air_density(ain, i0, i1, m_rho.data());  // (3.1)
      for (std::size_t i = i0; i < i1; ++i) {
        const double rho = m_rho[i];
        m_pr[i] = m_p.k_p * std::max(rho - m_rho0, 0.0);
        m_pr_rho2[i] = m_pr[i] / (rho * rho);  // P/rho^2 of (3.16), once per particle
      }
    });
    // Air-hair pairs: lists from each air particle to the hair within rc; the drag of each pair
    // is evaluated once (force on the hair particle, the air particle gets the negation) and
    // summed per hair particle in entry order, i.e. air-index order (deterministic; equal and
    // opposite by construction). The sum is one serial pass over the entries (about two per
    // hair particle): cheaper than transposing the lists for a parallel gather.
    if (nh) {
      m_hair_grid.cross_lists(ctx, m_x, hair_x, rc, m_aoff, m_anb);  // air -> hair
      m_drag.resize(m_anb.size());
      detail::AirDragInputs din;
      din.x = m_x.data();
      din.v = m_v.data();
      din.hair_x = hair_x.data();
      din.hair_v = hair_v.data();
      din.mu = m_mu.data();
      din.off = m_aoff.data();
      din.nb = m_anb.data();
      din.drag = m_p.drag;
      din.kernel = Kc;
      din.inv_w0 = inv_wc0;
      parallel_chunks(ctx, n, kAirChunk, [&](std::size_t i0, std::size_t i1) {
        m_kernels.air_drag(din, i0, i1, m_drag.data());
      });
      m_hair_sum.resize(nh);
      parallel_for(
          ctx, 0, nh, [&](std::size_t i) { m_hair_sum[i] = Vec3::Zero(); }, 4096);
      for (std::size_t e = 0; e < m_anb.size(); ++e) m_hair_sum[m_anb[e]] += m_drag[e];
    }
    m_acc.resize(n);
    parallel_chunks(ctx, n, kAirChunk, [&](std::size_t i0, std::size_t i1) {
      m_kernels.air_pressure(ain, i0, i1, m_acc.data());  // (3.16)
      for (std::size_t i = i0; i < i1; ++i) {
        Vec3 f = m_acc[i];
        if (nh)
          for (uint32_t e = m_aoff[i]; e < m_aoff[i + 1]; ++e) f -= m_drag[e];
        m_acc[i] = f / m_mass;
      }
    });
    if (nh)
      parallel_for(
          ctx, 0, nh, [&](std::size_t hi) { impulse[hi] += m_hair_sum[hi] * sub; }, 4096);
    parallel_for(ctx, 0, n, [&](std::size_t i) {
      m_v[i] += m_acc[i] * sub;  // symplectic Euler (leapfrog in kick-drift form)
      m_x[i] += m_v[i] * sub;
    });
    t += sub;
    // Blow-up check (first bad particle in index order), the fastest speed and whether any
    // particle left the box: per chunk in parallel, combined in chunk order.
    const Check chk = deterministic_reduce(
        ctx, n, kAirChunk, Check{},
        [&](std::size_t i0, std::size_t i1) {
          Check c;
          for (std::size_t i = i0; i < i1; ++i) {
            const double sp = m_v[i].norm();
            const bool finite = m_x[i].allFinite() && m_v[i].allFinite();
            if ((!finite || sp > m_p.max_speed) && c.bad == SIZE_MAX) c.bad = i;
            c.non_finite |= !finite;
            if (std::isfinite(sp)) c.vmax = std::max(c.vmax, sp);
            c.outside |= outside(m_x[i]);
          }
          return c;
        },
        [](Check a, const Check& b) {
          if (a.bad == SIZE_MAX) a.bad = b.bad;
          a.non_finite |= b.non_finite;
          a.vmax = std::max(a.vmax, b.vmax);
          a.outside |= b.outside;
          return a;
        });
    rep.max_speed = std::max(rep.max_speed, chk.vmax);
    if (chk.bad != SIZE_MAX) {
      // As marking every bad particle: the first index; NaN/Inf named when any particle is.
      if (chk.non_finite)
        rep.mark_non_finite(chk.bad);
      else
        rep.mark_blow_up(chk.bad);
      if (force_on_hair) force_on_hair->assign(nh, Vec3::Zero());
      rep.finish("sph_air", m_p.max_speed);
      return rep;
    }
    // Remove particles that left the box (order kept: deterministic), then feed the inflow.
    if (chk.outside) {
      std::size_t k = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (outside(m_x[i])) continue;
        m_x[k] = m_x[i];
        m_v[k] = m_v[i];
        ++k;
      }
      m_x.resize(k);
      m_v.resize(k);
    }
    m_phase += std::abs(m_p.wind_velocity[m_axis]) * sub;
    while (m_phase >= m_p.spacing) {
      m_phase -= m_p.spacing;
      spawn_layer(m_phase);
    }
  }
  if (force_on_hair)
    parallel_for(
        ctx, 0, nh, [&](std::size_t i) { (*force_on_hair)[i] = impulse[i] / dt; }, 4096);
  return rep;
}

}  // namespace follicle::hair
