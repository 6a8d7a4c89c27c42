#include "follicle/hair/lcp_scenario_bando2003.hpp"

#include <cmath>

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

LcpScenario::LcpScenario(const Context& ctx, const LcpScenarioParams& params, const LcpParams& lcp)
    : m_p(params) {
  m_p.validate();
  const double R = m_p.head_radius;
  m_head = lcp_sphere_mesh(R);
  auto P = [R](double polar, double az) -> Vec3 {
    return R *
           Vec3(std::sin(polar) * std::cos(az), std::cos(polar), -std::sin(polar) * std::sin(az));
  };
  ScalpCurves curves;
  const double p0 = 0.3, p1 = 1.9, a0 = 0.35 * kPi, a1 = 0.65 * kPi;
  for (int i = 0; i <= 4; ++i) {
    curves[0].push_back(P(p1, a0 + (a1 - a0) * i / 4));
    curves[1].push_back(P(p1 + (p0 - p1) * i / 4, a1));
    curves[2].push_back(P(p0, a1 + (a0 - a1) * i / 4));
    curves[3].push_back(P(p0 + (p1 - p0) * i / 4, a0));
  }
  ScalpParams sp;
  sp.max_length = m_p.hair_length;
  sp.root_depth = std::max(sp.root_depth, m_p.spacing);
  m_scalp = Scalp::trim(m_head, curves, sp);
  sim::VoxelPlanesParams vp;
  vp.voxel_size = std::max(0.01, m_p.spacing);
  m_body = std::make_unique<sim::VoxelPlanes>(sim::VoxelPlanes::build({&m_head}, vp, 3));
  LcpInitParams ip;
  ip.spacing = m_p.spacing;
  ip.total_mass = m_p.total_mass;
  ip.whirl_point = P(0.3, kPi / 2);
  LcpInit init = initialize_lcp(ctx, m_scalp, ip, m_body.get());
  m_solver = std::make_unique<LcpSolver>(lcp, std::move(init.model), m_body.get());
  m_state = std::move(init.state);
  if (m_p.shake) {
    const int cycles = 1000;
    m_track = anim::RigidMotionTrack::shake(Vec3::Zero(), Vec3::UnitY(), m_p.shake_angle, cycles,
                                            0.0, cycles * m_p.shake_period);
  }
  if (m_p.wind) {
    SphAirParams ap;
    ap.spacing = m_p.air_spacing;
    ap.wind_velocity = Vec3(0, 0, -m_p.wind_speed);
    ap.box_min = Vec3(-0.2, -R - m_p.hair_length - 0.05, -0.4);
    ap.box_max = Vec3(0.2, 0.05, -0.02);
    m_air.emplace(ctx, ap);
  }
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

LcpStepReport LcpScenario::step(const Context& ctx, double dt) {
  LcpStepInput in;
  in.dt = dt;
  in.head = head_pose();
  if (m_air) {
    lcp_world(m_state, in.head, &m_wx, &m_wv);
    const sim::StepReport ar =
        m_air->step(ctx, dt, m_wx, m_wv, m_solver->model().mass, &m_wind_force);
    if (!ar.ok) {
      LcpStepReport r;
      static_cast<sim::StepReport&>(r) = ar;
      return r;
    }
    in.external_force = &m_wind_force;
  }
  return m_solver->step(ctx, in, m_state, m_ws);
}

}  // namespace follicle::hair
