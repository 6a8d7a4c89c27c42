// Behaviour of the LCP hair (Bando 2003 ch. 3): hair-body collision during a head shake,
// hair-hair interaction between crossing sheets (Fig. 3.7 c vs d), and a look at the back hair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "../../unit/hair/lcp_test_scenes.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/lcp_scenario_bando2003.hpp"
#include "follicle/hair/sph_air_bando2003.hpp"
#include "follicle/image/image_io.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {
// Back view (looking along +z from behind the head, x mirrored): head disc, and each particle as
// a short stroke along its hair direction, drawn far to near.
image::ImageRGB8 lcp_back_view(const std::vector<Vec3>& x, const std::vector<Vec3>& t, int W) {
  image::ImageRGB8 img(W, W, 230);
  const double scale = W / 0.5;
  auto px = [&](const Vec3& q) { return Vec2(W / 2 - q.x() * scale, W * 0.3 - q.y() * scale); };
  for (int y = 0; y < W; ++y)
    for (int xx = 0; xx < W; ++xx) {
      const double qx = -(xx - W / 2) / scale, qy = (W * 0.3 - y) / scale;
      if (qx * qx + qy * qy < 0.01) {
        img.at(xx, y, 0) = 225;
        img.at(xx, y, 1) = 190;
        img.at(xx, y, 2) = 160;
      }
    }
  std::vector<std::size_t> order(x.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return x[a].z() > x[b].z() || (x[a].z() == x[b].z() && a < b);
  });
  for (std::size_t i : order) {
    const Vec2 a = px(x[i] - 0.012 * t[i]), b = px(x[i] + 0.012 * t[i]);
    const double shade = std::clamp(0.5 - 4.0 * x[i].z(), 0.3, 1.0);  // nearer = brighter
    for (int k = 0; k <= 24; ++k)
      for (int w = -1; w <= 1; ++w) {
        const Vec2 p = a + (b - a) * (k / 24.0);
        const int u = int(p.x()) + w, v = int(p.y());
        if (u < 0 || v < 0 || u >= W || v >= W) continue;
        img.at(u, v, 0) = uint8_t(150 * shade);
        img.at(u, v, 1) = uint8_t(95 * shade);
        img.at(u, v, 2) = uint8_t(45 * shade);
      }
  }
  return img;
}
}  // namespace

TEST(LcpPhysics, NoParticleEndsInsideTheHeadDuringAShake) {
  Context ctx(2);
  auto sc = test::lcp_small_scene(ctx, 0.016);
  LcpParams p;
  LcpSolver solver(p, sc.init.model, &sc.body);
  LcpState s = solver.rest_state();
  LcpWorkspace ws;
  const auto track = anim::RigidMotionTrack::shake(Vec3::Zero(), Vec3::UnitY(), 0.7, 2, 0.0, 0.75);
  const double dt = 1.0 / 60;
  double worst = 0;
  for (int k = 0; k < 45; ++k) {
    LcpStepInput in;
    in.dt = dt;
    in.head = track.sample(k * dt);
    const auto rep = solver.step(ctx, in, s, ws);
    ASSERT_TRUE(rep.ok) << rep.message;
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (!sc.init.model.root[i]) worst = std::max(worst, 0.1 - s.x[i].norm());
  }
  std::size_t inside = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (!sc.init.model.root[i] && s.x[i].norm() < 0.1 - 1e-3) ++inside;
  std::printf("head shake: %zu particles, deepest penetration during the shake %.2f mm\n",
              s.x.size(), worst * 1e3);
  EXPECT_EQ(inside, 0u);
  EXPECT_LT(worst, p.contact.threshold);  // transient penetration stays within the contact band
}

namespace {
// Two sheets of hanging strands (2 layers each), `gap` apart in z, moving towards each other.
struct Sheets {
  LcpModel model;
  std::vector<int> sheet;
};
Sheets crossing_sheets(const Context& ctx) {
  const double a = 0.01;
  std::vector<Vec3> x, t, uvs;
  std::vector<int> sheet;
  for (int sh = 0; sh < 2; ++sh)
    for (int layer = 0; layer < 2; ++layer)
      for (int k = 0; k < 16; ++k)
        for (int i = 0; i < 10; ++i) {
          const double z = (sh == 0 ? -0.035 : 0.035) + (layer - 0.5) * a;
          const double xo = sh == 0 ? 0.0 : 0.5 * a;
          x.push_back(Vec3(xo + a * i, -a * k, z));
          t.push_back(-Vec3::UnitY());
          uvs.push_back(Vec3(i / 10.0, sh * 0.5, a * (k - 0.5)));
          sheet.push_back(sh);
        }
  LcpInitParams ip;
  ip.spacing = a;
  Sheets out;
  out.model = connect_particles(ctx, x, t, uvs, std::vector<double>(x.size(), 2e-5), ip);
  out.sheet = sheet;
  return out;
}

// Minimum over time of mean z(sheet 1) - mean z(sheet 0): negative when the sheets passed
// through each other.
double sheet_separation(bool hair_hair, const char* integrator = "leapfrog") {
  Context ctx(2);
  Sheets sh = crossing_sheets(ctx);
  for (std::size_t q = 0; q < sh.model.num_pairs(); ++q)
    EXPECT_EQ(sh.sheet[sh.model.pair_a[q]], sh.sheet[sh.model.pair_b[q]]);
  LcpParams p;
  p.integrator = integrator;
  p.hair_hair = hair_hair;
  p.gravity = Vec3::Zero();
  p.air_drag = 0;
  LcpSolver solver(p, sh.model);
  LcpState s = solver.rest_state();
  for (std::size_t i = 0; i < s.v.size(); ++i)
    if (!sh.model.root[i]) s.v[i] = Vec3(0, 0, sh.sheet[i] == 0 ? 1.0 : -1.0);
  LcpWorkspace ws;
  double min_sep = 1e9;
  for (int k = 0; k < 40; ++k) {
    LcpStepInput in;
    in.dt = 1.0 / 400;
    const auto rep = solver.step(ctx, in, s, ws);
    EXPECT_TRUE(rep.ok) << rep.message;
    double z[2] = {0, 0};
    int c[2] = {0, 0};
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (sh.model.uvs[i].z() > 0.05) {  // the lower, free part of the sheets
        z[sh.sheet[i]] += s.x[i].z();
        ++c[sh.sheet[i]];
      }
    min_sep = std::min(min_sep, z[1] / c[1] - z[0] / c[0]);
  }
  return min_sep;
}
}  // namespace

// Fig. 3.7 c vs d: two sheets moving towards each other at 1 m/s each.
TEST(LcpPhysics, HairHairInteractionStopsCrossingSheets) {
  const double with = sheet_separation(true), without = sheet_separation(false);
  std::printf("crossing sheets: min separation with hair-hair %.1f mm, without %.1f mm\n",
              with * 1e3, without * 1e3);
  EXPECT_GT(with, 0.0);     // they do not pass through each other (Fig. 3.7 c)
  EXPECT_LT(without, 0.0);  // they do (Fig. 3.7 d)
}

// ---------------------------------------------------------------------------------------------
// The implicit integrator (ADR 0014) against the leapfrog reference on physical cases.

// Fig. 3.7 again: the sheets stop each other with the implicit step too, pass through each other
// without hair-hair interaction, and the closest approach agrees with the leapfrog's.
TEST(LcpImplicit, CrossingSheetsAgreeWithTheLeapfrog) {
  const double lf = sheet_separation(true);
  const double with = sheet_separation(true, "implicit"),
               without = sheet_separation(false, "implicit");
  std::printf(
      "crossing sheets, implicit: min separation with hair-hair %.1f mm (leapfrog %.1f mm), "
      "without %.1f mm\n",
      with * 1e3, lf * 1e3, without * 1e3);
  EXPECT_GT(with, 0.0);
  EXPECT_LT(without, 0.0);
  EXPECT_NEAR(with, lf, 0.25 * lf);
}

namespace {
struct SagResult {
  double mean_y = 0, tip_y = 0, stretch = 0;
  int substeps = 0;
};
// The small sphere scene hanging under gravity from its rest shape, 1/60 s steps, with more air
// drag than the default so that the swing settles into the static shape.
SagResult static_sag(const char* integrator, int threads = 2, LcpState* out = nullptr,
                     int frames = 180) {
  Context ctx(threads);
  const auto sc = test::lcp_small_scene(ctx, 0.012, 0.12);
  LcpParams p;
  p.integrator = integrator;
  p.air_drag = 8;
  LcpSolver solver(p, sc.init.model, &sc.body);
  LcpState s = solver.rest_state();
  LcpWorkspace ws;
  SagResult r;
  for (int k = 0; k < frames; ++k) {
    LcpStepInput in;
    in.dt = 1.0 / 60;
    const auto rep = solver.step(ctx, in, s, ws);
    EXPECT_TRUE(rep.ok) << rep.message;
    r.substeps += rep.substeps;
  }
  const auto& m = solver.model();
  int nf = 0, nt = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (m.root[i]) continue;
    r.mean_y += s.x[i].y();
    ++nf;
    if (m.uvs[i].z() > 0.08) {
      r.tip_y += s.x[i].y();
      ++nt;
    }
  }
  r.mean_y /= nf;
  r.tip_y /= std::max(nt, 1);
  for (std::size_t q = 0; q < m.num_pairs(); ++q)
    r.stretch += (s.x[m.pair_b[q]] - s.x[m.pair_a[q]]).norm() / m.l0[q];
  r.stretch /= double(m.num_pairs());
  if (out) *out = s;
  return r;
}
}  // namespace

// Hair draped on a head: after 3 s under gravity both integrations come to nearly the same
// hanging shape, the implicit one in a small fraction of the sub-steps. Not to the same bits of
// shape: the hair rests on the head with Coulomb friction (3.22)/(3.23), which holds any of a range
// of rest shapes, and the two paths (the implicit step damps the first swing more) end at
// different ones; they differ by less than half the particle spacing (12 mm).
TEST(LcpImplicit, HairOnAHeadSettlesAsWithTheLeapfrog) {
  const SagResult lf = static_sag("leapfrog"), im = static_sag("implicit");
  std::printf(
      "static sag: mean y %.2f / %.2f mm, tips %.2f / %.2f mm, stretch %.4f / %.4f, "
      "sub-steps %d / %d (leapfrog / implicit)\n",
      lf.mean_y * 1e3, im.mean_y * 1e3, lf.tip_y * 1e3, im.tip_y * 1e3, lf.stretch, im.stretch,
      lf.substeps, im.substeps);
  EXPECT_NEAR(im.mean_y, lf.mean_y, 0.006);
  EXPECT_NEAR(im.tip_y, lf.tip_y, 0.006);
  EXPECT_NEAR(im.stretch, lf.stretch, 0.005);
  EXPECT_LT(im.substeps * 5, lf.substeps);
}

// The same bits for one and two threads.
TEST(LcpImplicit, IdenticalForOneAndTwoThreads) {
  LcpState a, b;
  static_sag("implicit", 1, &a, 60);
  static_sag("implicit", 2, &b, 60);
  ASSERT_EQ(a.x.size(), b.x.size());
  for (std::size_t i = 0; i < a.x.size(); ++i) {
    ASSERT_EQ(a.x[i], b.x[i]) << i;
    ASSERT_EQ(a.v[i], b.v[i]) << i;
    ASSERT_EQ(a.t[i], b.t[i]) << i;
  }
}

namespace {
// One straight strand of 60 particles 5 mm apart (two of them roots), 10 mg each, hanging along -y.
struct Strand {
  static constexpr double a = 0.005, mass = 1e-5;
  static constexpr int len = 60;
  LcpModel model;
  explicit Strand(const Context& ctx) {
    const LcpStrandBlock block = lcp_strand_block(1, 1, len, a);
    LcpInitParams ip;
    ip.spacing = a;
    model = connect_particles(ctx, block.x, block.t, block.uvs,
                              std::vector<double>(block.x.size(), mass), ip);
  }
  // The strand's axial stiffness E A_eff [N]: a uniform strain e stretches every connection by
  // e l0 and n = l0 / a of them cross any cut, so the tension is e sum_q alpha k l0^2 / a over the
  // root-side connections of a particle in the middle. (Not E A: (3.10) gives every particle the
  // modulus E over its connections, and a connection two spacings long crosses two cuts.)
  double axial_stiffness(const Context& ctx, const LcpSolver& solver) const {
    LcpWorkspace ws;
    const LcpState s = solver.rest_state();
    solver.solve_alpha(ctx, s, ws);
    const uint32_t mid = len / 2;
    double k = 0;
    for (std::size_t q = 0; q < model.num_pairs(); ++q)
      if (model.pair_b[q] == mid) k += ws.alpha[q] * ws.k[q] * model.l0[q] * model.l0[q] / a;
    return k;
  }
};
}  // namespace

// Static sag of a hanging strand under its own weight (no hair-hair interaction, no body): the
// tip drops by mu g L^2 / (2 E A_eff), mu = m / a. Both integrations settle there.
TEST(LcpImplicit, AHangingStrandSagsAsTheAnalyticBarWithBothIntegrators) {
  Context ctx(2);
  const Strand strand(ctx);
  double sag[2] = {0, 0}, expect = 0;
  int subs[2] = {0, 0};
  for (int mode = 0; mode < 2; ++mode) {
    LcpParams p;
    p.integrator = mode == 0 ? "leapfrog" : "implicit";
    p.hair_hair = false;
    p.air_drag = 20;  // settles within the run
    LcpSolver solver(p, strand.model);
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    for (int k = 0; k < 120; ++k) {
      LcpStepInput in;
      in.dt = 1.0 / 60;
      const auto rep = solver.step(ctx, in, s, ws);
      ASSERT_TRUE(rep.ok) << rep.message;
      subs[mode] += rep.substeps;
    }
    const std::size_t tip = s.x.size() - 1;
    sag[mode] = solver.model().rest_x[tip].y() - s.x[tip].y();
    const double L = Strand::a * (Strand::len - 2);
    expect = Strand::mass / Strand::a * 9.81 * L * L / (2 * strand.axial_stiffness(ctx, solver));
  }
  std::printf(
      "hanging strand: tip sag %.4f mm (leapfrog, %d sub-steps), %.4f mm (implicit, %d), "
      "bar %.4f mm\n",
      sag[0] * 1e3, subs[0], sag[1] * 1e3, subs[1], expect * 1e3);
  EXPECT_NEAR(sag[0], expect, 0.1 * expect);
  EXPECT_NEAR(sag[1], sag[0], 0.02 * sag[0]);
  EXPECT_LT(subs[1] * 10, subs[0]);
}

namespace {
// A single straight strand (len particles, spacing a, hanging along -y from two root particles),
// no gravity, every free particle given 5 cm/s away from the root at t = 0: a fixed-free bar.
// The stretch wave that starts at the held root stops each particle it passes; when it reaches
// the free tip, at t = L / c, it reflects and turns the tip's velocity round. Returns the time the
// tip's velocity first turns towards the root.
double tip_reversal_time(const char* integrator, double* c_analytic) {
  Context ctx(2);
  const Strand strand(ctx);
  LcpParams p;
  p.integrator = integrator;
  p.gravity = Vec3::Zero();
  p.air_drag = 0;
  p.spring_damping = 0;
  p.hair_hair = false;
  LcpSolver solver(p, strand.model);
  LcpState s = solver.rest_state();
  const auto& m = solver.model();
  const std::size_t tip = s.x.size() - 1;
  for (std::size_t i = 0; i < s.x.size(); ++i)
    if (!m.root[i]) s.v[i] = Vec3(0, -0.05, 0);
  *c_analytic = std::sqrt(strand.axial_stiffness(ctx, solver) * Strand::a / Strand::mass);
  LcpWorkspace ws;
  const double dt = 5e-4;
  for (int k = 0; k < 4000; ++k) {
    LcpStepInput in;
    in.dt = dt;
    const auto rep = solver.step(ctx, in, s, ws);
    EXPECT_TRUE(rep.ok) << rep.message;
    if (s.v[tip].y() > 0) return (k + 1) * dt;
  }
  return -1;
}
}  // namespace

// A stretch wave's speed along a strand: the tip of a fixed-free strand turns back when the wave
// from the root arrives, at L / c. Both integrations agree with each other and with
// c = sqrt(E A_eff / mu) of the strand's connections (3.7)-(3.14) and cross-section (3.9).
TEST(LcpImplicit, AStretchWaveRunsAlongAStrandAtTheSameSpeed) {
  double c = 0;
  const double lf = tip_reversal_time("leapfrog", &c), im = tip_reversal_time("implicit", &c);
  const double L = Strand::a * (Strand::len - 2);  // the free part of the strand
  std::printf(
      "strand wave: tip turns at %.1f ms (leapfrog), %.1f ms (implicit), L/c = %.1f ms "
      "(c = %.2f m/s)\n",
      lf * 1e3, im * 1e3, L / c * 1e3, c);
  ASSERT_GT(lf, 0);
  ASSERT_GT(im, 0);
  EXPECT_NEAR(im, lf, 0.1 * lf);
  EXPECT_NEAR(lf, L / c, 0.1 * (L / c));
}

TEST(LcpPhysics, BackHairHangsUnderGravityPicture) {
  // Back hair on a sphere head after 1.5 s under gravity: every particle stays within its hair
  // length (plus slack) of its root point on the scalp, the connections are on average barely
  // stretched, and the tips hang below the roots. Writes a back view for inspection.
  Context ctx(2);
  LcpScenarioParams sp;
  sp.spacing = 0.016;
  LcpScenario sc(ctx, sp);
  const auto& m = sc.solver().model();
  for (int k = 0; k < 45; ++k) {
    const auto rep = sc.step(ctx, 1.0 / 30);
    ASSERT_TRUE(rep.ok) << rep.message;
  }
  const auto& s = sc.state();
  double tip_y = 0, root_y = 0, worst = 0;
  int nt = 0, nr = 0;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const double si = m.uvs[i].z();
    if (si > 0.15) {
      tip_y += s.x[i].y();
      ++nt;
    } else if (m.root[i]) {
      root_y += s.x[i].y();
      ++nr;
    }
    if (m.root[i]) continue;
    const Vec3 r = sc.scalp().point({m.uvs[i].x(), m.uvs[i].y()}).position;
    worst = std::max(worst, (s.x[i] - r).norm() - (1.1 * si + 2 * m.spacing));
  }
  double stretch = 0;
  for (std::size_t q = 0; q < m.num_pairs(); ++q)
    stretch += (s.x[m.pair_b[q]] - s.x[m.pair_a[q]]).norm() / m.l0[q];
  stretch /= double(m.num_pairs());
  ASSERT_GT(nt, 0);
  ASSERT_GT(nr, 0);
  std::printf(
      "back hair: %zu particles, tips y %.3f, roots y %.3f, mean stretch %.4f, worst excess "
      "%.1f mm\n",
      s.x.size(), tip_y / nt, root_y / nr, stretch, worst * 1e3);
  EXPECT_LE(worst, 0.0) << "a particle is farther from its root than its hair length allows";
  EXPECT_LT(stretch, 1.1);
  EXPECT_LT(tip_y / nt, root_y / nr - 0.05);
  const auto dir = test::scratch_dir("lcp_back_hair");
  image::write_png(dir / "back_hair.png", lcp_back_view(s.x, s.t, 400));
  std::printf("picture: %s\n", (dir / "back_hair.png").c_str());
}

TEST(LcpPhysics, ScenarioRestoreReplaysTheSameFrames) {
  // LcpScenario::restore puts the hair back into an earlier state: stepping again from there
  // gives bit-identical frames although the solver's neighbour lists and cached connection
  // geometry were built for the later state (they must be rebuilt, not reused). A state of
  // another size is refused.
  Context ctx(2);
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  LcpParams lp;
  lp.integrator = "implicit";
  LcpScenario sc(ctx, sp, lp);
  ASSERT_TRUE(sc.step(ctx, 1.0 / 60).ok);
  const LcpState start = sc.state();
  std::vector<LcpState> first;
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(sc.step(ctx, 1.0 / 60).ok);
    first.push_back(sc.state());
  }
  ASSERT_GT((first.back().x[first.back().x.size() - 1] - start.x[start.x.size() - 1]).norm(), 1e-4)
      << "the hair must move for the replay to mean anything";
  sc.restore(start);
  EXPECT_EQ(sc.state().time, start.time);
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(sc.step(ctx, 1.0 / 60).ok);
    const auto& s = sc.state();
    ASSERT_EQ(s.x.size(), first[k].x.size());
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      ASSERT_EQ(s.x[i], first[k].x[i]) << "frame " << k << " particle " << i;
      ASSERT_EQ(s.v[i], first[k].v[i]) << "frame " << k << " particle " << i;
    }
  }
  LcpState wrong = start;
  wrong.x.pop_back();
  EXPECT_THROW(sc.restore(wrong), follicle::Error);
}

TEST(LcpPhysics, ScenarioExtraForcePushesTheHair) {
  // LcpScenario::step's extra force (the parting force of lcp.part) is applied in the world
  // frame: a steady +x push moves the free hair towards +x against the same scenario without
  // it; a force array of the wrong size is reported, not applied.
  Context ctx(2);
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  sp.hair_length = 0.15;
  LcpScenario still(ctx, sp), pushed(ctx, sp);
  const auto& m = pushed.solver().model();
  std::vector<Vec3> f(m.size(), Vec3::Zero());
  for (std::size_t i = 0; i < m.size(); ++i) f[i] = Vec3(2.0 * 9.81 * m.mass[i], 0, 0);
  const std::vector<Vec3> wrong(m.size() + 1, Vec3::Zero());
  const auto bad = pushed.step(ctx, 1.0 / 30, &wrong);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.message.find("extra forces"), std::string::npos) << bad.message;
  EXPECT_EQ(pushed.time(), 0.0);
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(still.step(ctx, 1.0 / 30).ok);
    const auto rep = pushed.step(ctx, 1.0 / 30, &f);
    ASSERT_TRUE(rep.ok) << rep.message;
  }
  double dx = 0;
  int n = 0;
  for (std::size_t i = 0; i < m.size(); ++i)
    if (m.uvs[i].z() > 0.08) {
      dx += pushed.state().x[i].x() - still.state().x[i].x();
      ++n;
    }
  ASSERT_GT(n, 0);
  EXPECT_GT(dx / n, 0.01) << "mean +x displacement of the lower hair [m]";
}

TEST(LcpPhysics, WindPushesHairAndHairSlowsWind) {
  // Two-way coupling (§3.6, Fig. 3.9): SPH air blowing along -z through the back hair pushes it
  // downwind, and the air behind the hair is slower than in the same wind without hair.
  Context ctx(2);
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  sp.hair_length = 0.15;
  LcpScenario calm(ctx, sp);
  sp.wind = true;
  sp.wind_speed = 3.0;
  sp.air_spacing = 0.025;
  LcpScenario windy(ctx, sp);
  SphAirParams ap = windy.air()->params();
  SphAir empty(ctx, ap);  // the same wind with no hair
  const std::vector<Vec3> none;
  const std::vector<double> no_mass;
  for (int k = 0; k < 12; ++k) {
    ASSERT_TRUE(calm.step(ctx, 1.0 / 30).ok);
    const auto rep = windy.step(ctx, 1.0 / 30);
    ASSERT_TRUE(rep.ok) << rep.message;
    ASSERT_TRUE(empty.step(ctx, 1.0 / 30, none, none, no_mass, nullptr).ok);
  }
  const auto& m = calm.solver().model();
  double zc = 0, zw = 0;
  int n = 0;
  for (std::size_t i = 0; i < m.size(); ++i)
    if (m.uvs[i].z() > 0.08) {
      zc += calm.state().x[i].z();
      zw += windy.state().x[i].z();
      ++n;
    }
  ASSERT_GT(n, 0);
  zc /= n;
  zw /= n;
  // Behind the hair (downwind = more negative z than the hair), in the hair's shadow.
  const Vec3 lo(-0.06, -0.25, -0.32), hi(0.06, -0.02, -0.2);
  std::size_t c1 = 0, c2 = 0;
  const double v_hair = -windy.air()->mean_velocity_in(lo, hi, &c1).z();
  const double v_free = -empty.mean_velocity_in(lo, hi, &c2).z();
  std::printf(
      "wind: hair tips z %.1f mm (calm %.1f mm); air speed behind hair %.2f m/s (%zu), "
      "without hair %.2f m/s (%zu)\n",
      zw * 1e3, zc * 1e3, v_hair, c1, v_free, c2);
  ASSERT_GT(c1, 10u);
  ASSERT_GT(c2, 10u);
  EXPECT_LT(zw, zc - 0.005);         // pushed downwind (-z)
  EXPECT_LT(v_hair, 0.97 * v_free);  // the hair slows the wind
}

TEST(LcpPhysics, TheBlowUpLimitFollowsThePhysicsAndTheTopOfTheWindRangeRuns) {
  // Before: a 40 m/s wind stopped at frame 1 on the fixed 30 m/s hair limit ("particle has speed
  // 30.02 m/s"), and 100 m/s (the top of wind_speed's range) tripped the air's own 100 m/s limit
  // by 5e-6 m/s. The limits now follow the scenario: twice the wind + the shake's swing + a free
  // fall over the hair length, and twice the wind for the air.
  Context ctx(2);
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  sp.hair_length = 0.15;
  const LcpScenario calm(ctx, sp);
  EXPECT_EQ(calm.max_speed(), LcpParams{}.max_speed);  // 2 sqrt(2 g L) = 3.4 m/s < 30 m/s
  sp.shake = true;
  sp.shake_angle = 0.7;
  sp.shake_period = 0.5;
  LcpParams low;
  low.max_speed = 1e-3;  // the physical bound shows through
  const LcpScenario shaking(ctx, sp, low);
  EXPECT_NEAR(shaking.max_speed(),
              2 * (0.7 * 2 * M_PI / 0.5 * (0.1 + 0.15) + std::sqrt(2 * 9.81 * 0.15)), 0.05);
  sp.shake = false;
  sp.wind = true;
  sp.air_spacing = 0.03;
  for (const double w : {40.0, 100.0}) {
    sp.wind_speed = w;
    LcpScenario s(ctx, sp);
    EXPECT_GE(s.max_speed(), 2 * w);
    EXPECT_GE(s.air()->params().max_speed, 2 * w);
    for (int k = 0; k < 6; ++k) {
      const auto rep = s.step(ctx, 1.0 / 60);
      ASSERT_TRUE(rep.ok) << w << " m/s, frame " << k << ": " << rep.message;
    }
    for (const Vec3& x : s.state().x) ASSERT_TRUE(x.allFinite());
  }
}

TEST(LcpPhysics, AirAtItsOwnStableStepMovesTheHairAsTheTightCoupling) {
  // Multi-rate coupling (as `follicle bench lcp-wind` and, coarser, the scenes run it): the SPH
  // air advances at its own stable step (SphAir::stable_step, k hair sub-steps), its mean drag
  // held over the next k hair sub-steps. Against an air step with every hair sub-step, the hair
  // block is blown the same distance and the air slowed the same within a few per cent.
  Context ctx(2);
  const double a = 0.005;
  const int len = 40, nx = 10, nz = 6;
  const LcpStrandBlock block = lcp_strand_block(nx, nz, len, a);
  const std::vector<Vec3>& x = block.x;
  LcpInitParams ip;
  ip.spacing = a;
  std::vector<double> mass(x.size(), 0.05 / 1e5);  // the lcp-wind block's particle mass
  LcpParams p;
  p.substeps = 1;
  p.cfl = 0;
  const LcpSolver solver(p, connect_particles(ctx, block.x, block.t, block.uvs, mass, ip));
  SphAirParams ap;
  ap.wind_velocity = Vec3(0, 0, -3);
  ap.box_min = Vec3(-0.03, -a * len - 0.03, -0.06);
  ap.box_max = Vec3(a * nx + 0.03, 0.03, a * nz + 0.06);
  ap.spacing = 0.012;
  ap.coupling_radius = 2 * a;
  LcpState s0 = solver.rest_state();
  LcpWorkspace probe;
  const double dt = LcpParams{}.cfl / solver.stiffness_rate(ctx, s0, probe);
  const int k = LcpWindCoupling::air_every(ctx, SphAir(ctx, ap), dt);
  ASSERT_GE(k, 4) << "the air's stable step should be several hair sub-steps";
  Vec3 disp[2];
  double air_vz[2];
  for (int mode = 0; mode < 2; ++mode) {
    const int every = mode == 0 ? 1 : k;
    LcpState s = solver.rest_state();
    LcpWorkspace ws;
    SphAir air(ctx, ap);
    LcpWindCoupling coupling(every);
    for (int step = 0; step < 40 * k; ++step) {
      const auto r = coupling.step(ctx, solver, s, ws, air, dt);
      ASSERT_TRUE(r.ok) << r.message;
    }
    disp[mode] = Vec3::Zero();
    for (std::size_t i = 0; i < x.size(); ++i) disp[mode] += (s.x[i] - x[i]) / double(x.size());
    air_vz[mode] = air.mean_velocity_in(ap.box_min, ap.box_max).z();
  }
  std::printf(
      "k = %d: mean hair displacement z %.2f mm (tight) %.2f mm (multi-rate); air vz %.3f / "
      "%.3f m/s\n",
      k, 1e3 * disp[0].z(), 1e3 * disp[1].z(), air_vz[0], air_vz[1]);
  EXPECT_LT(disp[0].z(), -0.002);  // blown downwind by millimetres
  EXPECT_LT((disp[1] - disp[0]).norm(), 0.03 * disp[0].norm());
  EXPECT_NEAR(air_vz[1], air_vz[0], 0.01 * std::abs(air_vz[0]));
}

// The implicit step in motion: a head shake keeps every particle outside the head, and a wind at
// the top of its range (100 m/s) runs, finite, with the physically derived blow-up limit.
TEST(LcpImplicit, AHeadShakeAndTheTopOfTheWindRangeRun) {
  Context ctx(2);
  const auto sc = test::lcp_small_scene(ctx);
  LcpParams p;
  p.integrator = "implicit";
  LcpSolver solver(p, sc.init.model, &sc.body);
  LcpState s = solver.rest_state();
  LcpWorkspace ws;
  const auto track = anim::RigidMotionTrack::shake(Vec3::Zero(), Vec3::UnitY(), 0.7, 2, 0.0, 0.75);
  const double dt = 1.0 / 60;
  double worst = 0;
  int subs = 0;
  for (int k = 0; k < 45; ++k) {
    LcpStepInput in;
    in.dt = dt;
    in.head = track.sample(k * dt);
    const auto rep = solver.step(ctx, in, s, ws);
    ASSERT_TRUE(rep.ok) << rep.message;
    subs += rep.substeps;
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (!sc.init.model.root[i]) {
        worst = std::max(worst, 0.1 - s.x[i].norm());
      }
  }
  std::printf("head shake, implicit: %d sub-steps in 45 frames, deepest penetration %.2f mm\n",
              subs, worst * 1e3);
  EXPECT_LT(worst, p.contact.threshold);
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  sp.hair_length = 0.15;
  sp.wind = true;
  sp.air_spacing = 0.03;
  sp.wind_speed = 100;
  LcpScenario wind(ctx, sp, p);
  for (int k = 0; k < 6; ++k) {
    const auto rep = wind.step(ctx, 1.0 / 60);
    ASSERT_TRUE(rep.ok) << "frame " << k << ": " << rep.message;
  }
  for (const Vec3& x : wind.state().x) ASSERT_TRUE(x.allFinite());
}
