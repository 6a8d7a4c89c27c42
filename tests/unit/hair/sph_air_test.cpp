// SPH air (Bando 2003 §3.6, hair/sph_air_bando2003): outflow/inflow bookkeeping and the
// blow-up report of SphAir::step.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "follicle/hair/sph_air_bando2003.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {
SphAirParams small_box() {
  SphAirParams p;
  p.wind_velocity = Vec3(2, 0, 0);
  p.box_min = Vec3(0, 0, 0);
  p.box_max = Vec3(0.2, 0.1, 0.1);
  p.spacing = 0.02;
  return p;
}
}  // namespace

TEST(SphAir, OutflowRemovesAndInflowRefillsTheBox) {
  // 10 x 5 x 5 lattice sites; the wind carries a layer out every spacing / |v| = 10 ms and the
  // inflow spawns one, so the count stays within a layer of the full box and every particle
  // stays inside it.
  Context ctx(2);
  const SphAirParams p = small_box();
  SphAir air(ctx, p);
  ASSERT_EQ(air.size(), 250u);
  const std::vector<Vec3> none;
  const std::vector<double> no_mass;
  for (int k = 0; k < 40; ++k) {
    const auto rep = air.step(ctx, 2.5e-3, none, none, no_mass, nullptr);
    ASSERT_TRUE(rep.ok) << rep.message;
    EXPECT_GE(air.size(), 225u);
    EXPECT_LE(air.size(), 275u);
    for (const auto& x : air.positions()) {
      ASSERT_TRUE((x.array() >= 0).all()) << x.transpose();
      ASSERT_TRUE((x.array() <= p.box_max.array()).all()) << x.transpose();
    }
  }
  // 0.1 s at 2 m/s: every initial particle has left; the air still moves with the wind.
  EXPECT_NEAR(air.mean_velocity_in(Vec3(0, 0, 0), Vec3(0.2, 0.1, 0.1)).x(), 2.0, 0.2);
}

TEST(SphAir, SpeedAboveTheLimitIsReportedAsABlowUpAtTheFirstParticle) {
  Context ctx(2);
  SphAirParams p = small_box();
  p.max_speed = 1.0;  // below the inflow speed: every particle is too fast
  SphAir air(ctx, p);
  const std::vector<Vec3> hx{Vec3(0.1, 0.05, 0.05)}, hv{Vec3::Zero()};
  const std::vector<double> hm{1e-6};
  std::vector<Vec3> f{Vec3(1, 2, 3)};
  const auto rep = air.step(ctx, 1e-3, hx, hv, hm, &f);
  EXPECT_FALSE(rep.ok);
  EXPECT_TRUE(rep.blow_up);
  EXPECT_FALSE(rep.non_finite);
  EXPECT_EQ(rep.first_bad, 0u);
  EXPECT_NE(rep.message.find("blow-up"), std::string::npos) << rep.message;
  EXPECT_EQ(f[0], Vec3::Zero());  // no force from a failed step
}

TEST(SphAir, NonFiniteHairVelocityIsReportedAsNaN) {
  // A NaN hair velocity reaches the air through the drag: the air particles within the
  // coupling radius of that hair particle become NaN, reported as such (not as a blow-up) with
  // the first of them in index order.
  Context ctx(2);
  SphAirParams p = small_box();
  SphAir air(ctx, p);
  const std::vector<Vec3> hx{Vec3(0.1, 0.05, 0.05)};
  const std::vector<Vec3> hv{Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)};
  const std::vector<double> hm{1e-6};
  std::vector<Vec3> f;
  const auto rep = air.step(ctx, 1e-3, hx, hv, hm, &f);
  EXPECT_FALSE(rep.ok);
  EXPECT_TRUE(rep.non_finite);
  ASSERT_LT(rep.first_bad, air.size());
  EXPECT_FALSE(air.positions()[rep.first_bad].allFinite());
  for (std::size_t i = 0; i < rep.first_bad; ++i)  // the first NaN particle in index order
    ASSERT_TRUE(air.positions()[i].allFinite()) << i;
  EXPECT_NE(rep.message.find("NaN"), std::string::npos) << rep.message;
}

TEST(SphAir, MismatchedHairArraysFailCleanly) {
  Context ctx(1);
  SphAir air(ctx, small_box());
  const std::vector<Vec3> hx{Vec3::Zero(), Vec3::Zero()}, hv{Vec3::Zero()};
  const std::vector<double> hm{1e-6, 1e-6};
  const auto rep = air.step(ctx, 1e-3, hx, hv, hm, nullptr);
  EXPECT_FALSE(rep.ok);
  EXPECT_FALSE(rep.message.empty());
}
