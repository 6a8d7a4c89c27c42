#include "follicle/hair/lcp_scenario_bando2003.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"

namespace follicle::hair {

geom::TriMesh lcp_sphere_mesh(double radius, int nlat, int nlon) {
  geom::TriMesh m;
  m.positions.push_back({0, radius, 0});
  for (int i = 1; i < nlat; ++i) {
    const double th = kPi * i / nlat;
    for (int j = 0; j < nlon; ++j) {
      const double ph = 2 * kPi * j / nlon;
      m.positions.push_back(
          radius * Vec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)));
    }
  }
  m.positions.push_back({0, -radius, 0});
  const int south = int(m.positions.size()) - 1;
  auto id = [&](int i, int j) { return 1 + (i - 1) * nlon + (j % nlon); };
  for (int j = 0; j < nlon; ++j) m.faces.push_back({0, id(1, j), id(1, j + 1)});
  for (int i = 1; i < nlat - 1; ++i)
    for (int j = 0; j < nlon; ++j) {
      m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int j = 0; j < nlon; ++j) m.faces.push_back({id(nlat - 1, j), south, id(nlat - 1, j + 1)});
  m.compute_normals();
  return m;
}

geom::TriMesh lcp_box_mesh(const Vec3& centre, const Vec3& half_extents) {
  geom::TriMesh m;
  for (int k = 0; k < 8; ++k)
    m.positions.push_back(centre + Vec3((k & 1) ? half_extents.x() : -half_extents.x(),
                                        (k & 2) ? half_extents.y() : -half_extents.y(),
                                        (k & 4) ? half_extents.z() : -half_extents.z()));
  // Two triangles per side, counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.faces.push_back({q[0], q[1], q[2]});
    m.faces.push_back({q[0], q[2], q[3]});
  }
  m.compute_normals();
  return m;
}

LcpStrandBlock lcp_strand_block(int nx, int nz, int len, double a) {
  LcpStrandBlock b;
  const std::size_t n =
      std::size_t(std::max(nx, 0)) * std::size_t(std::max(nz, 0)) * std::size_t(std::max(len, 0));
  b.x.reserve(n);
  b.t.reserve(n);
  b.uvs.reserve(n);
  for (int k = 0; k < len; ++k)
    for (int j = 0; j < nz; ++j)
      for (int i = 0; i < nx; ++i) {
        b.x.push_back(Vec3(a * i, -a * k, a * j));
        b.t.push_back(-Vec3::UnitY());
        b.uvs.push_back(Vec3(double(i) / nx, double(j) / nz, a * (k - 1.5)));
      }
  return b;
}

int LcpWindCoupling::air_every(const Context& ctx, const SphAir& air, double dt) {
  const double k = std::floor(air.stable_step(ctx, true) / dt);
  return std::isfinite(k) && k > 1 ? int(std::min(k, 1e6)) : 1;
}

LcpStepReport LcpWindCoupling::step(const Context& ctx, const LcpSolver& solver, LcpState& s,
                                    LcpWorkspace& ws, SphAir& air, double dt) {
  if (m_calls++ % m_every == 0) {
    const sim::StepReport ar = air.step(ctx, m_every * dt, s.x, s.v, solver.model().mass, &m_force);
    if (!ar.ok) {
      LcpStepReport r;
      static_cast<sim::StepReport&>(r) = ar;
      return r;
    }
  }
  LcpStepInput in;
  in.dt = dt;
  in.external_force = &m_force;
  return solver.step(ctx, in, s, ws);
}

LcpScenario::LcpScenario(const Context& ctx, const LcpScenarioParams& params, const LcpParams& lcp,
                         const geom::TriMesh* head_mesh, const image::ImageF* length_map)
    : m_p(params) {
  m_p.validate();
  const double R = m_p.head_radius;
  auto P = [R](double polar, double az) -> Vec3 {
    return R *
           Vec3(std::sin(polar) * std::cos(az), std::cos(polar), -std::sin(polar) * std::sin(az));
  };
  ScalpCurves curves;
  Vec3 whirl;
  if (head_mesh) {
    head_mesh->check("lcp head mesh");
    m_head = *head_mesh;
    if (!m_head.has_normals()) m_head.compute_normals();
    m_mesh_head = true;
    const LcpMeshHeadParams& mh = m_p.mesh_head;
    curves = {mh.curve0, mh.curve1, mh.curve2, mh.curve3};
    for (int k = 0; k < 4; ++k) {
      const auto& a = curves[k];
      const auto& b = curves[(k + 1) % 4];
      if (a.size() >= 2 && !b.empty() && (a.back() - b.front()).norm() > 1e-3)
        fail_at(fmt::format("mesh_head.curve{}", k),
                "ends at ({:.4f}, {:.4f}, {:.4f}) but curve{} starts at ({:.4f}, {:.4f}, {:.4f}); "
                "the four curves must form a closed loop",
                a.back().x(), a.back().y(), a.back().z(), (k + 1) % 4, b.front().x(), b.front().y(),
                b.front().z());
    }
    whirl = mh.whirl_point;
    if (mh.torso) m_torso = lcp_box_mesh(mh.torso_centre, mh.torso_half_extents);
  } else {
    m_head = lcp_sphere_mesh(R);
    const double p0 = 0.3, p1 = 1.9, a0 = 0.35 * kPi, a1 = 0.65 * kPi;
    for (int i = 0; i <= 4; ++i) {
      curves[0].push_back(P(p1, a0 + (a1 - a0) * i / 4));
      curves[1].push_back(P(p1 + (p0 - p1) * i / 4, a1));
      curves[2].push_back(P(p0, a1 + (a0 - a1) * i / 4));
      curves[3].push_back(P(p0 + (p1 - p0) * i / 4, a0));
    }
    whirl = P(0.3, kPi / 2);
  }
  ScalpParams sp;
  sp.max_length = m_p.hair_length;
  sp.root_depth = std::max(sp.root_depth, m_p.spacing);
  m_scalp = Scalp::trim(m_head, curves, sp);
  if (length_map && !length_map->empty()) m_scalp.set_length_map(*length_map);
  sim::VoxelPlanesParams vp;
  vp.voxel_size = std::max(0.01, m_p.spacing);
  std::vector<const geom::TriMesh*> body{&m_head};
  if (!m_torso.faces.empty()) body.push_back(&m_torso);
  m_body = std::make_unique<sim::VoxelPlanes>(sim::VoxelPlanes::build(body, vp, 3));
  LcpInitParams ip;
  ip.spacing = m_p.spacing;
  ip.total_mass = m_p.total_mass;
  ip.whirl_point = whirl;
  ip.w_n = m_p.root_normal_weight;
  ip.cantilever_sag = m_p.cantilever_sag;
  LcpInit init = initialize_lcp(ctx, m_scalp, ip, m_body.get());
  // Blow-up detection from the physics of the scenario, not a fixed number: hair may legitimately
  // move (in the head frame) as fast as the wind, plus the head's own swing at the hair's tips,
  // plus a free fall over the hair's length. The limit is twice that sum (at least the solver's
  // max_speed): a 40 m/s wind used to stop at frame 1 on the fixed 30 m/s.
  LcpParams lp = lcp;
  {
    double reach = 0;  // [m] farthest head point from the pivot, plus the hair
    const Vec3 pivot = m_mesh_head ? m_p.mesh_head.pivot : Vec3::Zero();
    for (const Vec3& x : m_head.positions) reach = std::max(reach, (x - pivot).norm());
    reach += m_p.hair_length;
    const double swing = m_p.shake ? m_p.shake_angle * 2 * kPi / m_p.shake_period * reach : 0.0;
    const double wind = m_p.wind ? m_p.wind_speed : 0.0;
    const double fall = std::sqrt(2 * lcp.gravity.norm() * m_p.hair_length);
    lp.max_speed = std::max(lcp.max_speed, 2 * (wind + swing + fall));
  }
  m_max_speed = lp.max_speed;
  m_solver = std::make_unique<LcpSolver>(lp, std::move(init.model), m_body.get());
  m_state = std::move(init.state);
  if (m_p.settle_time > 0) settle(ctx, lp);
  const Vec3 pivot = m_mesh_head ? m_p.mesh_head.pivot : Vec3::Zero();
  if (m_p.shake) {
    const int cycles = 1000;
    m_track =
        anim::RigidMotionTrack::shake(pivot, Vec3::UnitY(), m_p.shake_angle, cycles,
                                      m_p.shake_start, m_p.shake_start + cycles * m_p.shake_period);
  }
  if (m_p.wind) {
    SphAirParams ap;
    ap.spacing = m_p.air_spacing;
    ap.wind_velocity = Vec3(0, 0, -m_p.wind_speed);
    // The inflow moves at exactly the wind speed (100 m/s tripped a 100 m/s limit by 5e-6 m/s):
    // air may reach twice the wind speed before it counts as a blow-up.
    ap.max_speed = std::max(ap.max_speed, 2 * m_p.wind_speed);
    if (m_mesh_head) {
      // The box around the hanging hair, from the front of the hair's roots (the wind enters
      // there) to 0.3 m behind the hair, reaching 0.08 m beyond it on the other sides.
      Eigen::AlignedBox3d hb;
      for (const auto& x : m_state.x) hb.extend(x);
      ap.box_min = hb.min() - Vec3(0.08, 0.08, 0.3);
      ap.box_max = hb.max() + Vec3(0.08, 0.03, 0.0);
    } else {
      ap.box_min = Vec3(-0.2, -R - m_p.hair_length - 0.05, -0.4);
      ap.box_max = Vec3(0.2, 0.05, -0.02);
    }
    m_air.emplace(ctx, ap);
  }
}

void LcpScenario::settle(const Context& ctx, const LcpParams& lcp) {
  // A solver on the same model with extra air drag, the head still and no wind.
  LcpParams sp = lcp;
  sp.air_drag = std::max(lcp.air_drag, m_p.settle_drag);
  const LcpSolver solver(sp, m_solver->model(), m_body.get());
  const double dt = 1.0 / 120.0;
  const int steps = std::max(1, int(std::lround(m_p.settle_time / dt)));
  LcpStepInput in;
  in.dt = m_p.settle_time / steps;
  ctx.log().info("lcp: settling {} s of simulated time ({} steps of {} particles)", m_p.settle_time,
                 steps, m_state.x.size());
  Progress progress("settling hair", std::size_t(steps), ctx.progress());
  for (int k = 0; k < steps; ++k) {
    in.head.t = m_state.time;
    const LcpStepReport r = solver.step(ctx, in, m_state, m_ws);
    if (!r.ok)
      fail_at("lcp_scenario.settle_time", "the hair blew up while settling: {}", r.message);
    progress.tick();
  }
  std::fill(m_state.v.begin(), m_state.v.end(), Vec3::Zero());
  m_state.time = 0;
  m_ws = LcpWorkspace{};
}

anim::RigidSample LcpScenario::head_pose() const {
  if (m_track) return m_track->sample(m_state.time);
  anim::RigidSample s;
  s.t = m_state.time;
  return s;
}

void LcpScenario::world(std::vector<Vec3>& x, std::vector<Vec3>* t) const {
  lcp_world(m_state, head_pose(), &x, nullptr, t);
}

void LcpScenario::restore(const LcpState& s) {
  if (s.x.size() != m_state.x.size() || s.v.size() != s.x.size() || s.t.size() != s.x.size())
    throw Error(fmt::format("lcp: a state of {} particles restored into a scenario of {}",
                            s.x.size(), m_state.x.size()));
  m_state = s;
}

LcpStepReport LcpScenario::step(const Context& ctx, double dt,
                                const std::vector<Vec3>* extra_force) {
  LcpStepInput in;
  in.dt = dt;
  in.head = head_pose();
  const std::size_t n = m_state.x.size();
  if (extra_force && extra_force->size() != n) {
    LcpStepReport r;
    r.ok = false;
    r.message = fmt::format("lcp: {} extra forces for {} particles", extra_force->size(), n);
    return r;
  }
  in.external_force = extra_force;
  if (m_air) {
    lcp_world(m_state, in.head, &m_wx, &m_wv);
    const sim::StepReport ar =
        m_air->step(ctx, dt, m_wx, m_wv, m_solver->model().mass, &m_wind_force);
    if (!ar.ok) {
      LcpStepReport r;
      static_cast<sim::StepReport&>(r) = ar;
      return r;
    }
    if (extra_force)
      for (std::size_t i = 0; i < n; ++i) m_wind_force[i] += (*extra_force)[i];
    in.external_force = &m_wind_force;
  }
  return m_solver->step(ctx, in, m_state, m_ws);
}

}  // namespace follicle::hair
