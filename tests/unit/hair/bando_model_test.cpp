// Bando 2003 loosely connected particles behind the HairSimulation interface (ADR 0010): how a
// groom becomes particles (spacing, root particles, pillar coordinate s), the groom at rest, a
// uniformly moving head (Galilean invariance), gravity with body collision, air drag, settling,
// determinism for any thread count, and refused parameters.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/hair/hair_model_bando2003.hpp"

using namespace follicle;
using ::testing::HasSubstr;

namespace {

geom::TriMesh sphere(double r, int nu = 48, int nv = 24) {
  geom::TriMesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      m.positions.emplace_back(r * std::sin(th) * std::cos(ph), r * std::cos(th),
                               r * std::sin(th) * std::sin(ph));
    }
  auto id = [&](int i, int j) { return (j * nu) + (i % nu); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
    }
  m.compute_normals();
  return m;
}

// `n` strands of 21 points, 5 mm apart, out of the upper half of a sphere of radius 0.09 m: first
// along the normal, then bending down.
hair::HairModelSetup setup(int n) {
  hair::HairModelSetup s;
  for (int k = 0; k < n; ++k) {
    const double ph = 2.399963 * k, cz = 0.2 + 0.75 * double(k) / n;  // golden-angle spiral
    const double sz = std::sqrt(1 - cz * cz);
    const Vec3 nrm(sz * std::cos(ph), cz, sz * std::sin(ph));
    std::vector<Vec3f> pts;
    Vec3 p = 0.09 * nrm;
    Vec3 d = nrm;
    for (int i = 0; i < 21; ++i) {
      pts.push_back(p.cast<float>());
      d = (d + Vec3(0, -0.15, 0)).normalized();
      p += 0.005 * d;
    }
    s.rest.strands.add_strand(pts);
  }
  s.hull.radii = Vec3(0.09, 0.09, 0.09);
  s.head_mesh = std::make_shared<const geom::TriMesh>(sphere(0.09));
  return s;
}

hair::HairEnvironment calm(double) {
  return hair::HairEnvironment{};
}

double max_dist(const geom::StrandSet& a, const geom::StrandSet& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.points.size(); ++i)
    d = std::max(d, double((a.points[i] - b.points[i]).norm()));
  return d;
}

}  // namespace

TEST(BandoModel, TheGroomBecomesSpacedChainsOfParticles) {
  const Context ctx(2, 1);
  const auto s = setup(600);
  hair::BandoParams p;
  p.spacing = 0.01;
  p.strand_spacing = 0.015;
  const hair::BandoParticles bp = hair::bando_particles(ctx, s.rest, p, 7);
  ASSERT_GT(bp.chains.size(), 20u);
  ASSERT_LT(bp.chains.size(), 600u);
  EXPECT_EQ(bp.dropped, 0u);
  const auto& m = bp.model;
  std::size_t total = 0;
  for (std::size_t c = 0; c < bp.chains.size(); ++c) {
    const auto& ch = bp.chains[c];
    total += ch.size();
    // 0.1 m strands at 0.01 m: 11 particles, 2 held by the head (s < 0), tip on the strand's tip.
    ASSERT_EQ(ch.size(), 11u) << c;
    for (std::size_t k = 0; k < ch.size(); ++k) {
      EXPECT_EQ(m.root[ch[k]], k < 2 ? 1 : 0) << c << " " << k;
      EXPECT_EQ(m.uvs[ch[k]].z() < 0, k < 2);
      EXPECT_NEAR(m.rest_t[ch[k]].norm(), 1.0, 1e-12);
      if (k > 0) {
        const double d = (m.rest_x[ch[k]] - m.rest_x[ch[k - 1]]).norm();
        EXPECT_NEAR(d, 0.01, 5e-4) << c << " " << k;
        // The direction points along the strand (to the next particle).
        EXPECT_GT(m.rest_t[ch[k - 1]].dot((m.rest_x[ch[k]] - m.rest_x[ch[k - 1]]) / d), 0.99);
      }
    }
    const uint32_t src = bp.chain_strand[c];
    const uint32_t tip = s.rest.strands.offsets[src + 1] - 1;
    EXPECT_LT((m.rest_x[ch.back()] - s.rest.strands.points[tip].cast<double>()).norm(), 1e-6);
  }
  EXPECT_EQ(total, m.size());
  // The simulated strands' roots are at least strand_spacing apart.
  for (std::size_t a = 0; a < bp.chains.size(); ++a)
    for (std::size_t b = a + 1; b < bp.chains.size(); ++b)
      ASSERT_GE((m.rest_x[bp.chains[a][0]] - m.rest_x[bp.chains[b][0]]).norm(), 0.015 - 1e-7);
  // Every particle is held by the head, and the mass is shared equally.
  const auto att = hair::lcp_attached(m);
  for (char a : att) ASSERT_EQ(a, 1);
  double mass = 0;
  for (double mi : m.mass) mass += mi;
  EXPECT_NEAR(mass, p.total_mass, 1e-12);
}

TEST(BandoModel, AtRestTheHairIsTheGroomAndAHeadPoseMovesItRigidly) {
  const Context ctx(2, 1);
  const auto s = setup(400);
  hair::BandoParams p;
  p.strand_spacing = 0.02;
  auto sim = hair::make_bando2003(ctx, p, s);
  EXPECT_STREQ(sim->model(), "bando2003");
  geom::StrandSet out;
  sim->strands(hair::HeadMotion{}, out);
  ASSERT_EQ(out.num_strands(), 400u);
  ASSERT_EQ(out.num_points(), s.rest.strands.num_points());
  EXPECT_LT(max_dist(out, s.rest.strands), 1e-5);
  hair::HeadMotion head;
  head.position = Vec3(0.1, 0.2, 0.3);
  head.rotation = Quat(Eigen::AngleAxisd(0.4, Vec3::UnitY()));
  sim->strands(head, out);
  for (std::size_t i = 0; i < out.num_points(); i += 37) {
    const Vec3 e = head.position + head.rotation * s.rest.strands.points[i].cast<double>();
    ASSERT_LT((out.points[i].cast<double>() - e).norm(), 1e-5) << i;
  }
}

TEST(BandoModel, EveryStrandSimulatedGivesTheChainsThemselves) {
  const Context ctx(1, 1);
  const auto s = setup(12);  // roots far apart: every strand is simulated
  hair::BandoParams p;
  p.spacing = 0.02;
  auto sim = hair::make_bando2003(ctx, p, s);
  geom::StrandSet out;
  sim->strands(hair::HeadMotion{}, out);
  ASSERT_EQ(out.num_strands(), 12u);
  for (std::size_t k = 0; k < 12; ++k) EXPECT_EQ(out.strand_size(k), 6u) << k;  // 0.1 m / 0.02
}

TEST(BandoModel, AHeadInUniformMotionIsAnInertialFrame) {
  // Without gravity or drag, a head moving at constant velocity is an inertial frame: the hair
  // moves relative to it exactly as on a head at rest (Galilean invariance of the §3.6 head-frame
  // formulation; the hair still relaxes a little under its own pressure and springs).
  const Context ctx(2, 1);
  const auto s = setup(200);
  hair::BandoParams p;
  p.strand_spacing = 0.02;
  p.dynamics.air_drag = 0.0;
  const Vec3 vel(0.7, -0.2, 0.4);
  geom::StrandSet still, moving;
  for (const Vec3& v : {Vec3(Vec3::Zero()), vel}) {
    auto sim = hair::make_bando2003(ctx, p, s);
    auto env = [&](double t) {
      hair::HairEnvironment e;
      e.gravity = Vec3::Zero();
      e.head.position = v * t;
      e.head.velocity = v;
      return e;
    };
    ASSERT_TRUE(sim->advance(ctx, 0.5, env).ok);
    EXPECT_EQ(sim->steps(), 60u);  // 0.5 s at dt = 1/120 s
    hair::HeadMotion head = env(sim->time()).head;
    head.position = Vec3::Zero();  // compare in the head frame
    sim->strands(head, v.norm() > 0 ? moving : still);
  }
  EXPECT_LT(max_dist(moving, still), 1e-6);
}

TEST(BandoModel, HairFallsStaysOutsideTheHeadAndIsDeterministic) {
  const auto s = setup(300);
  hair::BandoParams p;
  p.strand_spacing = 0.015;
  geom::StrandSet a, b;
  for (int threads : {1, 2}) {
    const Context ctx(threads, 1);
    auto sim = hair::make_bando2003(ctx, p, s);
    const auto rep = sim->advance(ctx, 0.5, calm);
    ASSERT_TRUE(rep.ok) << rep.message;
    sim->strands(hair::HeadMotion{}, threads == 1 ? a : b);
  }
  ASSERT_EQ(a.points, b.points);  // bit-identical for 1 and 2 threads
  double mean_dy = 0, inside = 0;
  for (std::size_t k = 0; k < a.num_strands(); ++k) {
    const uint32_t tip = a.offsets[k + 1] - 1;
    mean_dy += double(a.points[tip].y() - s.rest.strands.points[tip].y());
    inside = std::max(inside, 0.09 - double(a.points[tip].norm()));
  }
  EXPECT_LT(mean_dy / double(a.num_strands()), -0.005);
  EXPECT_LT(inside, 0.01);
}

TEST(BandoModel, MovingAirDragsTheHairAlong) {
  const Context ctx(2, 1);
  const auto s = setup(200);
  hair::BandoParams p;
  p.strand_spacing = 0.02;
  auto sim = hair::make_bando2003(ctx, p, s);
  auto breeze = [](double) {
    hair::HairEnvironment e;
    e.gravity = Vec3::Zero();
    e.air_velocity = Vec3(3.0, 0.0, 0.0);
    return e;
  };
  ASSERT_TRUE(sim->advance(ctx, 0.3, breeze).ok);
  geom::StrandSet out;
  sim->strands(hair::HeadMotion{}, out);
  double dx = 0;
  for (std::size_t k = 0; k < out.num_strands(); ++k) {
    const uint32_t tip = out.offsets[k + 1] - 1;
    dx += double(out.points[tip].x() - s.rest.strands.points[tip].x());
  }
  EXPECT_GT(dx / double(out.num_strands()), 0.002);
}

TEST(BandoModel, SettlingDrapesTheGroomAndResetReturnsThere) {
  const Context ctx(2, 1);
  const auto s = setup(200);
  hair::BandoParams p;
  p.strand_spacing = 0.02;
  p.settle_time = 0.4;
  auto sim = hair::make_bando2003(ctx, p, s);
  geom::StrandSet settled, again;
  sim->strands(hair::HeadMotion{}, settled);
  EXPECT_GT(max_dist(settled, s.rest.strands), 0.005);
  ASSERT_TRUE(sim->advance(ctx, 0.1, calm).ok);
  sim->reset();
  EXPECT_EQ(sim->steps(), 0u);
  sim->strands(hair::HeadMotion{}, again);
  EXPECT_EQ(again.points, settled.points);
}

TEST(BandoModel, BadParametersAreRefusedWithTheirKey) {
  const Context ctx(1, 1);
  const auto s = setup(50);
  auto error = [&](const hair::BandoParams& p) -> std::string {
    try {
      hair::make_bando2003(ctx, p, s);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  hair::BandoParams p;
  p.dynamics.gravity = Vec3(0, -1, 0);
  EXPECT_THAT(error(p), HasSubstr("dynamics.gravity"));
  p = {};
  p.max_particles = 10;
  EXPECT_THAT(error(p), HasSubstr("max_particles"));
  p = {};
  p.spacing = 0.0;
  EXPECT_THAT(error(p), HasSubstr("spacing"));
  p = {};
  p.dt = std::nan("");
  EXPECT_THAT(error(p), HasSubstr("dt"));
}
